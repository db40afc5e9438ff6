# SPDX-License-Identifier: GPL-2.0-or-later
"""The LAMMPS plugin against pyref on the paper's cases, through the adapter (issue 30, item 3).

LAMMPS and pyref integrate the same way (velocity Verlet: forces from x(t) and v(t - dt/2),
the set-up force of step 0 without a spring increment, rows at the end of a step), and the
adapter gives the plugin the keywords that make it docs/law.md's law (history_rotation
keep_length, lever_arm contact, damping absolute, limit_damping): on the same scene and dt
they differ by the order of floating-point operations only. Row 0 is compared too: the
plugin's record is written by the set-up's force evaluation, as pyref's.

Costs (2-core machine under load): LAMMPS drag 0.5 s, tray (0.5 s simulated) 1 s, tilt
2-4 s a timing; the pyref runs are shared with the LIGGGHTS and YADE tests (paper_case);
the ranks test ~6 s, the drum ~3 s, the rest < 1 s each.
"""

import numpy as np
import pytest

from stickslip import analysis, columns
from stickslip import scene as scene_mod
from stickslip.adapters import lammps as lammps_adapter
from conftest import needs_engine, paper_case
from twin_bound import assert_round_off_apart

needs_lammps = needs_engine("lammps")


def run_lammps(name, tmp_path, ranks=1, **kw):
    sc = scene_mod.load(name, **kw)
    return sc, lammps_adapter.run(sc, tmp_path, np_ranks=ranks).timeseries


def pyref_case(name, timing, **kw):
    """pyref's run of a paper case (shared with the other tests that read it)."""
    return (paper_case(name, **kw) if timing == "step" else paper_case(name, slip_timing=timing, **kw))[1]


def assert_pyrefs_twin(sc, dl, dp):
    """LAMMPS against pyref row by row (tests/twin_bound.py's round-off bound; LAMMPS' region
    plate turns the grain's position into the plate's frame and the contact point back).
    A LAMMPS wall contact begins at zero overlap (stock's rule, lammps_plugin/README.md)
    where pyref has none, and with Fn = 0 it slips with zero force in every step: the tray's
    grain 1 starts exactly touching the left wall, until grain 2 pushes it into the wall. So
    slip flags are compared over rows that begin and end with a normal force on both (a
    grain that has overlapped a wall does not come back to exactly zero overlap)."""
    assert_round_off_apart(sc, dl, dp, slips_where_pressed=True)


# ---------------------------------------------------------------- the paper's cases, step for step

@needs_lammps
@pytest.mark.parametrize("timing", ["step", "exact"])
def test_drag_is_pyrefs_twin(tmp_path, timing):
    """Every row of the drag (2500 steps, every = 1; a primitive wall) within round-off of pyref's."""
    sc, dl = run_lammps("drag", tmp_path, slip_timing=timing)
    assert_pyrefs_twin(sc, dl, pyref_case("drag", timing))
    assert dl["grain-floor_slip"].sum() >= 5  # the saw-tooth is there


@needs_lammps
@pytest.mark.parametrize("timing", ["step", "exact"])
def test_tilt_is_pyrefs_twin(tmp_path, timing):
    """Every row of the tilt (1 s, 125 000 steps: the plate turning and stopping, the stick,
    stick-slip and sliding phases) within round-off of pyref's. The plate is a region plane
    turned by `rotate v_theta` (fix wall/gran/region/stickslip): its angle at each step is
    pyref's, its velocity at the contact LAMMPS' difference of two angles over dt."""
    sc, dl = run_lammps("tilt", tmp_path, slip_timing=timing)
    text = (tmp_path / "lammps" / "in.scene").read_text()
    assert "wall/gran/region/stickslip" in text and "rotate v_theta0" in text
    assert_pyrefs_twin(sc, dl, pyref_case("tilt", timing))
    assert dl["grain-plate_slip"].sum() > 100


@needs_lammps
@pytest.mark.parametrize("timing", ["step", "exact"])
def test_tray_is_pyrefs_twin(tmp_path, timing):
    """The tray's first 0.5 s (the impact, whose slips fix the grain-grain friction that
    holds grain 1 up; a grain pair and three primitive walls) within round-off of pyref's,
    and grain 1 held up."""
    sc, dl = run_lammps("tray", tmp_path, slip_timing=timing, duration=0.5)
    assert_pyrefs_twin(sc, dl, pyref_case("tray", timing, duration=0.5))
    assert not analysis.summarise(sc, dl)["reached_bottom"]
    assert dl["grain1-grain2_slip"].sum() > 10


@needs_lammps
def test_3d_oblique_plane_exact_timing_is_pyrefs_twin(tmp_path):
    """3D: a sphere launched across a plane inclined by tan(beta) = 0.3 (a still region
    plane on LAMMPS), exact slip timing, sliding with the dashpot above its threshold while
    gravity turns V_s (tests/test_liggghts_engine.py's incline, regime dashpot_slide: every
    slipping step slides at Fmin along -V_s after its first slip, E4), every row within
    round-off of pyref's. ~1 s on LAMMPS, ~3 s on pyref."""
    from conftest import run_pyref
    from test_liggghts_engine import incline_scene

    sc = incline_scene(0.45, 0.1, v0=0.05, duration=0.03)
    dl = lammps_adapter.run(sc, tmp_path).timeseries
    assert "region r0 plane" in (tmp_path / "lammps" / "in.scene").read_text()
    dp, _ = run_pyref(sc)
    assert_pyrefs_twin(sc, dl, dp)
    assert dl["g-plane_slip"].sum() > 500


@needs_lammps
def test_one_and_two_ranks_are_identical(tmp_path):
    """The few-grain scenes on 1 and 2 MPI ranks give the same bits: each grain has at most
    one pair contact, so no force is summed in another order when a pair straddles the
    ranks (LAMMPS splits the tray's box along x, between its two grains: the grain pair is
    computed on one rank and its force sent to the other). Short runs: on 2 ranks every step
    waits for both, and on a loaded machine a rank waits for a time slice (measured up to
    15 ms a step); the tray's first 0.01 s holds the impact of grain 1 on grain 2 (at ~1 ms)
    and its slips, the tilt's first 0.005 s a turning region wall on a rank without the grain
    (a region wall's history crossing ranks: test_lammps_region_wall.py). ~3 s."""
    for name, kw, grid in (("tray", {"duration": 0.01}, "2 by 1 by 1"), ("tilt", {"duration": 0.005}, None)):
        sc, d1 = run_lammps(name, tmp_path / f"{name}1", **kw)
        _, d2 = run_lammps(name, tmp_path / f"{name}2", ranks=2, **kw)
        assert d1.equals(d2), name
        log = (tmp_path / f"{name}2" / "lammps" / "log.lammps").read_text()
        assert "on 2 procs" in log and (grid is None or f"{grid} MPI processor grid" in log), name
        if name == "tray":
            assert d1["grain1-grain2_slip"].sum() > 0


@needs_lammps
def test_drum_is_pyrefs_step_for_step(tmp_path):
    """The drum's first 0.05 s (3125 steps: the fill falls, hits the ring and itself, ~300
    contacts, rolling, slips, turning gravity) on LAMMPS and pyref: round-off amplified by
    the pile's chaos (the difference grows ~e-fold every 3-4 ms, docs/drum.md: 1e-20 m at the
    first contacts, 1e-13 m at 0.05 s; grains part by ~0.2 s). Any difference in the physics
    shows far above 1e-10 m (lever arms of r instead of r - delta/2 gave 1.6e-8 m 0.01 s
    after the first contacts, tests/test_drum.py). Counts (slips, contacts) are equal."""
    sc = scene_mod.load("drum", duration=0.05, every=125)
    dl = lammps_adapter.run(sc, tmp_path).timeseries
    _, dp = paper_case("drum", duration=0.05, every=125)
    assert list(dl.columns) == list(dp.columns)
    pos = [c for c in dp.columns if c.endswith(("_x", "_y"))]
    assert np.abs(dl[pos].to_numpy() - dp[pos].to_numpy()).max() < 1e-10
    assert dp["n_slipping"].sum() > 100
    for c in ("n_slipping", "n_slip_above_vd", "n_slip_above_vstar", "n_contacts"):
        assert (dl[c] == dp[c]).all(), c
    assert np.abs(dl["slip_fs_fn_sum"] - dp["slip_fs_fn_sum"]).max() < 1e-9
    assert np.abs(dl["ekin"] - dp["ekin"]).max() < 1e-9 * dp["ekin"].max()


# ---------------------------------------------------------------- every scene, the script, errors

CASES = sorted(p.stem for p in scene_mod.CASES_DIR.glob("*.toml"))


@needs_lammps
@pytest.mark.parametrize("name", [c for c in CASES if c not in ("drag", "tray", "tilt")])
def test_every_case_runs_and_writes_pyrefs_columns(tmp_path, name):
    """Each scene of cases/ that the tests above do not run, through the runner (it checks
    the columns and that every value is finite), 40 steps of it."""
    from stickslip import runner

    sc = scene_mod.load(name)
    sc = scene_mod.load(name, duration=40 * sc.dt, every=min(sc.output.every, 10))
    _, df = runner.run_scene(sc, "lammps", tmp_path, progress=False)
    assert list(df.columns) == columns.names(sc) and len(df) == 40 // sc.output.every + 1


@needs_lammps
def test_effects_off_are_left_out_of_the_script(tmp_path):
    """Only the effects a scene switches on appear in the input script."""
    sc = scene_mod.load("drag", duration=1e-5, effect_gravity=False, effect_normal_damping=False,
                        effect_tangential_damping=False)
    lammps_adapter.run(sc, tmp_path)
    text = (tmp_path / "lammps" / "in.scene").read_text()
    assert "gravity" not in text.replace("scene drag", "")
    assert "nve/sphere" not in text  # rotation off: translation only
    # gamma_n, gamma_t zero and no tangential damping (dampflag 0)
    assert " 12000000.0 9600000.0 0.0 0.0 0.5 0 limit_damping" in text
    sc = scene_mod.load("tilt", duration=1e-5, effect_rotation=True)
    lammps_adapter.run(sc, tmp_path)
    text = (tmp_path / "lammps" / "in.scene").read_text()
    assert "fix gravity all gravity" in text and "nve/sphere disc" in text and "rotate v_theta0" in text


@needs_lammps
def test_lammps_error_is_one_line(tmp_path):
    """An error inside LAMMPS reaches the user as its one-line message, not a traceback."""
    sc = scene_mod.load("drag", duration=1e-5)
    sc.contact.mu_k = 0.6  # past the scene check, so that LAMMPS itself refuses it
    with pytest.raises(ValueError) as e:
        lammps_adapter.run(sc, tmp_path)
    msg = str(e.value)
    assert "mu_k = 0.6" in msg and "[0.25, 0.5]" in msg and "\n" not in msg


def test_what_lammps_cannot_do_is_refused_in_one_line(tmp_path):
    """Energy books and the other tangential laws are refused before LAMMPS starts."""
    for kw, words in (({"energy": True}, "output.energy"), ({"law": "coulomb"}, "stick_slip only, not coulomb")):
        sc = scene_mod.load("drag", duration=1e-5, **({"law": kw["law"]} if "law" in kw else {}))
        sc.output.energy = kw.get("energy", False)
        with pytest.raises(ValueError, match=words) as e:
            lammps_adapter.run(sc, tmp_path)
        assert "\n" not in str(e.value)


@needs_lammps
def test_non_finite_output_fails_loudly(tmp_path):
    """A run whose output holds a NaN or an infinity must not come back as a time series:
    the adapter raises one clear error naming the column, time and step."""
    sc = scene_mod.load("drag", duration=1e-4)
    sc.output.every = 10
    work = tmp_path / "lammps"
    work.mkdir()
    script = lammps_adapter._Script(sc, work)
    lammps_adapter.run(sc, tmp_path)  # a real run writes the dumps ...
    text = (work / "atoms.dump").read_text().split("\n")
    k = max(i for i, line in enumerate(text) if line.startswith("1 "))
    fields = text[k].split()
    fields[5] = "nan"  # ... then one velocity becomes NaN in the last row
    text[k] = " ".join(fields)
    (work / "atoms.dump").write_text("\n".join(text))
    with pytest.raises(RuntimeError) as e:
        lammps_adapter._timeseries(script, work)
    msg = str(e.value)
    assert "non-finite" in msg and "grain_vy" in msg and "step 50" in msg and "\n" not in msg
