# SPDX-License-Identifier: GPL-2.0-or-later
"""Issue 39, the granular scale in 3D: the scene format's 3D features (periodic boxes, a
rough base, the gravity ramp, rolling resistance, the bulk columns) and their refusals,
the LAMMPS-family script of the ramp, the case kinds incline3d and heap3d, the study's
smoke run and `stickslip calibrate`. The study itself is opt-in (slow)."""
from __future__ import annotations

import copy
import json
import math
import tomllib

import numpy as np
import pandas as pd
import pytest

from stickslip import columns, runner
from stickslip import scene as scene_mod
from stickslip.adapters import ramp_script
from stickslip.cli import main
from stickslip.errors import SceneError
from stickslip.kinds import heap3d, incline3d
from stickslip.scene.grains import near_pairs_periodic
from conftest import needs_engine

needs_liggghts = needs_engine("liggghts")
needs_lammps = needs_engine("lammps")

SMALL = tomllib.loads(scene_mod.find("incline3d_small").read_text())


def parse(change=None, drop=()):
    """cases/incline3d_small.toml's data, changed: change(data) edits it in place."""
    data = copy.deepcopy(SMALL)
    for path in drop:
        *head, last = path.split(".")
        t = data
        for h in head:
            t = t[h]
        del t[last]
    if change:
        change(data)
    return scene_mod.parse(data)


# ---------------------------------------------------------------- the scene format's checks

@pytest.mark.parametrize("change, message", [
    (lambda d: d.update(dimension=2, gravity=[0.0, -1.0]), "periodic: periodic boundaries are for 3D scenes"),
    (lambda d: d["periodic"].update(x=[1.0, 0.5]), "periodic.x: expected [lo, hi] with lo < hi"),
    (lambda d: d["periodic"].update(x=[0.0, 2.0]), "periodic.x = [0, 2]: must be longer than two largest diameters"),
    (lambda d: d["periodic"].update(x=[0.0, 4.0]), "outside the periodic box periodic.x = [0, 4)"),
    (lambda d: d["wall"].append({"name": "side", "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]}),
     "wall 'side': its normal has a part along the periodic axis x"),
    (lambda d: d["gravity_ramp"].update(axis=[0.0, 0.0, 1.0]), "gravity_ramp.axis = [0.0, 0.0, 1.0]: must be a "
                                                               "non-zero vector perpendicular to gravity"),
    (lambda d: d["gravity_ramp"]["phase"][1].update(duration=2.0), "gravity_ramp.phase[1]: give exactly one of"),
    (lambda d: d["gravity_ramp"]["phase"][0].pop("duration"), "gravity_ramp.phase[0]: give exactly one of"),
    (lambda d: d["gravity_ramp"].update(phase=[]), "gravity_ramp.phase: at least one"),
    (lambda d: d.update(gravity_rate=0.1), "gravity_rate = 0.1: gravity turns about z, in 2D scenes only"),
    (lambda d: d["analysis"].update(stop_phase=6), "analysis.stop_phase = 6: must be the index of a "
                                                    "gravity_ramp.phase (0 to 5)"),
    (lambda d: d["base"][0].update(number_density=5.0), "base[0].number_density = 5: at most"),
    (lambda d: d["contact"].update(rolling_mu=0.1), "contact.rolling_mu = 0.1: needs a rolling model"),
    (lambda d: d["contact"].update(rolling="epsd2"), "contact.rolling_mu = 0: must be > 0"),
    (lambda d: d["contact"].update(rolling="cdt", rolling_mu=0.1), "contact.rolling = 'cdt': must be one of"),
    (lambda d: (d["contact"].update(rolling="epsd2", rolling_mu=0.1), d["effects"].update(rotation=False)),
     "contact.rolling = 'epsd2': rolling resistance acts on spins"),
])
def test_3d_scene_errors_are_one_line(change, message):
    with pytest.raises(SceneError) as e:
        parse(change)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_a_grain_overlapping_its_neighbour_across_the_periodic_boundary_is_refused():
    def two(d):
        d["lattice"] = []
        d["grain"] = [{"name": "a", "radius": 0.5, "density": 1.9, "position": [0.2, 2.0, 3.0]},
                      {"name": "b", "radius": 0.5, "density": 1.9, "position": [4.85, 2.0, 3.0]}]
    with pytest.raises(SceneError, match="grains 'a' and 'b' start overlapping by 0.65 m"):
        parse(two)
    # the same pair without the periodic box is far apart
    x = np.array([[0.2, 2.0, 3.0], [4.85, 2.0, 3.0]])
    a, b, dist = near_pairs_periodic(x, np.array([0.5, 0.5]), {"x": (0.0, 5.0)})
    assert list(zip(a, b)) == [(0, 1)] and dist[0] == pytest.approx(0.35)


def test_the_base_is_a_slab_of_spheres_that_do_not_overlap_even_across_the_box():
    sc = parse()
    base = [g for g in sc.grains if g.fixed]
    assert len(base) == round(1.14 * 25)  # number_density x the periodic box's area
    x = np.array([g.position for g in base])
    assert x[:, 2].min() >= 0 and x[:, 2].max() <= 1.18 and x[:, :2].min() >= 0 and x[:, :2].max() < 5.0
    _, _, dist = near_pairs_periodic(x, np.full(len(x), 0.5), sc.periodic)
    assert dist.min() >= 1.0 - 1e-5  # relaxed until no overlap beyond BASE_OVERLAP of a diameter
    again = [g.position for g in parse().grains if g.fixed]
    assert np.array_equal(x, again)  # the seed makes the same base


def test_the_ramp_turns_gravity_towards_the_downhill_direction():
    sc = parse()
    assert np.allclose(sc.downhill(), [1.0, 0.0, 0.0])  # axis -y turns gravity (0, 0, -1) towards +x
    a = math.radians(30)
    assert np.allclose(sc.gravity_tilted(a), [math.sin(a), 0.0, -math.cos(a)])
    assert [p.until for p in sc.gravity_ramp.phases] == ["duration", "speed_above", "duration", "speed_below",
                                                         "speed_below", "speed_above"]
    assert columns.names(sc)[-8:] == ["com_x", "com_y", "com_z", "vcm_x", "vcm_y", "vcm_z", "tilt", "phase"]


@pytest.mark.parametrize("engine", ["pyref", "yade", "deme"])
def test_engines_without_the_3d_features_refuse_the_scene_in_one_line(engine, tmp_path):
    from stickslip import adapters

    sc = parse(lambda d: d["contact"].update(rolling="epsd2", rolling_mu=0.1))
    with pytest.raises(ValueError) as e:
        adapters.get(engine).run(sc, tmp_path)
    text = str(e.value)
    assert text.endswith("it does not support periodic boundaries (periodic), gravity ramps (gravity_ramp), "
                         "rolling resistance (contact.rolling), the bulk columns (output.bulk)") and "\n" not in text


def test_lammps_refuses_rolling_resistance_only(tmp_path):
    from stickslip.adapters import lammps

    with pytest.raises(ValueError, match=r"LAMMPS cannot run scene incline3d_small: it does not support rolling "
                                         r"resistance \(contact.rolling\)$"):
        lammps.run(parse(lambda d: d["contact"].update(rolling="epsd2", rolling_mu=0.1)), tmp_path)


# ---------------------------------------------------------------- the script both engines run

def test_the_loop_redefines_only_variables_defined_after_every_other():
    """LIGGGHTS moves a redefined variable to the end of its list (ramp_script.py): every
    variable the loop redefines must come after every variable a fix, compute or dump holds."""
    sc = parse()
    lines = ramp_script.ramp_setup(sc) + ramp_script.bulk_dump(sc, "moving", lambda d, n: "") + ramp_script.run(
        sc, lambda steps: ["thermo 1", f"run {steps}"])
    defined = [ln.split()[1] for ln in lines if ln.startswith("variable ")]
    first_loop = lines.index("run 0")
    redefined = {ln.split()[1] for ln in lines[first_loop:] if ln.startswith("variable ")}
    order = list(dict.fromkeys(defined))
    assert redefined and all(order.index(v) > order.index(w) for v in redefined for w in order if w not in redefined)
    assert "fix gravity all gravity 1.0 vector v_rp_gx v_rp_gy v_rp_gz" in lines
    assert f"run {sc.output.every} pre no post no" in lines
    assert 'if "${bk_down} < 0.001" then "jump SELF rp_phase5"' in lines
    assert 'if "${rp_n} >= 30" then "jump SELF rp_phase1"' in lines  # 3 s in intervals of 0.1 s


@pytest.mark.parametrize("engine", [pytest.param("liggghts", marks=needs_liggghts),
                                    pytest.param("lammps", marks=needs_lammps)])
def test_the_ramp_turns_by_its_rates_phase_by_phase_on_the_engines(engine, tmp_path):
    """The first 4 time units of the small incline: phase 0 holds the angle for its 3 s (30
    intervals), phase 1 turns it by 5 deg/s, 0.5 deg a row; the bulk columns follow the bed."""
    sc = scene_mod.load("incline3d_small", duration=4.0)
    _, df = runner.run_scene(sc, engine, tmp_path, progress=False)
    assert list(df.columns) == columns.names(sc) and len(df) == 41
    assert (df["phase"].iloc[:31] == 0).all() and (df["tilt"].iloc[:31] == 0).all()
    assert (df["phase"].iloc[31:] == 1).all()
    assert np.allclose(np.degrees(df["tilt"].iloc[31:]), 0.5 * np.arange(1, 11), atol=1e-9)
    assert df["com_z"].iloc[-1] < df["com_z"].iloc[0] - 0.5  # the lattice fell onto the base


# ---------------------------------------------------------------- the kinds

def _ramp_frame(speeds, phases, tilts):
    n = len(speeds)
    return pd.DataFrame({"t": np.arange(n) * 0.1, "com_x": 0.0, "com_y": 0.0, "com_z": 6.0, "vcm_x": speeds,
                         "vcm_y": 0.0, "vcm_z": 0.0, "tilt": np.radians(tilts), "phase": phases})


def test_incline_angles_are_read_where_their_phases_end():
    sc = parse()
    df = _ramp_frame([0, 0.5, 0.2, 0.0005, 0.004, 0.02], [0, 1, 4, 4, 5, 5], [0, 20, 21, 20.5, 21, 22])
    s = incline3d.summarise(sc, df)
    assert s["theta_stop_deg"] == pytest.approx(20.5) and s["theta_start_deg"] == pytest.approx(22)
    z_base = np.mean([g.position[2] + g.radius for g in sc.grains if g.fixed])
    assert s["depth_at_stop"] == pytest.approx(2 * (6.0 - z_base))
    # the run ended before the last phase's condition held: no theta_start
    s = incline3d.summarise(sc, df.iloc[:5])
    assert s["theta_stop_deg"] == pytest.approx(20.5) and math.isnan(s["theta_start_deg"])


def test_heap_flanks_of_a_known_slope():
    """A heap of grains stacked under two flanks of slope 0.5 (26.57 deg) on the small
    heap's plate: the fit reads that slope on both sides."""
    sc = scene_mod.load("heap3d_small")
    lo, hi, z0 = heap3d.plate(sc)
    names = [g.name for g in sc.grains if not g.fixed]
    row = {}
    xs = np.linspace(lo + 0.3, hi - 0.3, len(names))
    for n, x in zip(names, xs):
        r = next(g.radius for g in sc.grains if g.name == n)
        row.update({f"{n}_x": x, f"{n}_y": 1.0, f"{n}_z": z0 + 0.5 * (0.5 * (hi - lo) - abs(x - 0.5 * (lo + hi))) - r,
                    **{f"{n}_v{a}": 0.0 for a in "xyz"}})
    (left, right), height = heap3d.flanks(*heap3d.profile(sc, pd.Series(row)))
    assert left == pytest.approx(0.5, abs=0.03) and right == pytest.approx(0.5, abs=0.03)


# ---------------------------------------------------------------- the study and calibrate

@needs_liggghts
def test_study_smoke_states_its_cost_keeps_its_runs_and_resumes(tmp_path, capsys):
    args = ["study-3d", "--smoke", "--runs", str(tmp_path / "runs"), "--out", str(tmp_path / "out"), "--quiet"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "stickslip study-3d: 4 runs, 0 already on disk" in err and "4 to run (2 at once), about" in err
    runs = pd.read_csv(tmp_path / "out" / "runs.csv")
    assert len(runs) == 4 and np.isfinite(runs.loc[runs.kind == "incline", "theta_stop"]).all()
    assert np.isfinite(runs.loc[runs.kind == "heap", "theta_heap"]).all()
    assert np.isfinite(runs.loc[runs.kind == "shear", ["shear_peak", "shear_steady"]]).all().all()
    assert (tmp_path / "runs" / runs.label[runs.kind == "shear"].iloc[0] / "series.csv").is_file()
    for name in ("points.csv", "predictions.csv", "summary.md", "granular3d_curves.png", "granular3d_map.png",
                 "loo.csv", "sensitivity.csv"):
        assert (tmp_path / "out" / name).is_file()
    assert main(args) == 0  # everything is on disk: nothing runs again
    assert "to run" not in capsys.readouterr().err


def _synthetic_map(tmp_path):
    """A points.csv whose angles are linear in (mu_s, mu_k): theta_start = 20 + 20 mu_s,
    theta_stop = 15 + 20 (2 mu_k - mu_s), theta_heap = 18 + 16 (2 mu_k - mu_s), se 0.3."""
    rows = []
    pairs = [(m, m) for m in (0.2, 0.35, 0.5, 0.8)] + [(0.8, 0.5), (0.8, 0.65), (0.5, 0.35), (0.5, 0.425)]
    for ms, mk in pairs:
        for kind in ("incline", "heap"):
            f = 2 * mk - ms
            rows.append({"kind": kind, "engine": "liggghts", "group": "sweep", "mu_s": ms, "mu_k": mk,
                         "nu_s": "0" if ms == mk else "paper", "timing": "step", "rolling": 0.0,
                         "theta_start_mean": 20 + 20 * ms if kind == "incline" else np.nan, "theta_start_se": 0.3,
                         "theta_stop_mean": 15 + 20 * f if kind == "incline" else np.nan, "theta_stop_se": 0.3,
                         "theta_heap_mean": 18 + 16 * f if kind == "heap" else np.nan, "theta_heap_se": 0.3})
    path = tmp_path / "points.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    return path


def test_effective_mu_inverts_where_the_stock_curve_reaches_the_angle_once(tmp_path):
    """The mu at which stock history reaches a measured angle: linear between measured mus
    (theta_stop = 15 + 20 mu on the synthetic map: 21 is mu 0.3); none where the curve does not
    reach the angle, or reaches it twice (bent back: 19, 22, 40, 31 at mu 0.2, 0.35, 0.5, 0.8
    reaches 35 twice and 21 once)."""
    from stickslip.studies import granular3d_tables as tables

    pts = pd.read_csv(_synthetic_map(tmp_path), dtype={"nu_s": str})
    assert tables.effective_mu(pts, "theta_stop", 0.0, 21.0) == pytest.approx(0.3)
    assert math.isnan(tables.effective_mu(pts, "theta_stop", 0.0, 40.0))
    bent = pts.copy()
    bent.loc[(bent.mu_s == bent.mu_k) & (bent.mu_s == 0.5) & (bent.kind == "incline"), "theta_stop_mean"] = 40.0
    assert math.isnan(tables.effective_mu(bent, "theta_stop", 0.0, 35.0))
    assert tables.effective_mu(bent, "theta_stop", 0.0, 21.0) == pytest.approx(0.2 + 0.15 * 2 / 3)


def test_calibrate_inverts_the_map(tmp_path, capsys):
    path = _synthetic_map(tmp_path)
    # mu_s = 0.7, mu_k = 0.5: theta_start 34, theta_stop 21, theta_heap 22.8
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "21", "--map", str(path), "--json"]) == 0
    a = json.loads(capsys.readouterr().out)
    ms, mk = a["mu_s"]["value"], a["mu_k"]["value"]
    assert ms == pytest.approx(0.7, abs=0.005) and mk == pytest.approx(0.5, abs=0.005)
    # the map's standard error there, over theta_start's slope 20 deg per unit of mu_s, is
    # mu_s's (the other profiled): tests/test_calibrate.py checks it to the grid's step
    lo, hi = a["mu_s"]["range"]
    assert 0.005 < hi - ms < 0.03 and 0.005 < ms - lo < 0.03
    assert main(["calibrate", "--theta-stop", "21", "--theta-heap", "22.8", "--map", str(path)]) == 0


def _map_with_half_rates(tmp_path):
    """tmp_path/points.csv: the synthetic map with stock history mu = 0.5 also at half rate,
    stopping 0.5 deg higher there (a lag of 1.0 deg at the ramp's rates)."""
    pts = pd.read_csv(_synthetic_map(tmp_path))
    pts = pts.assign(material=["history_0.50" if a == b == 0.5 else "x" for a, b in zip(pts.mu_s, pts.mu_k)],
                     layers=0, rate_factor=1.0, silbert=False)
    half = pts[(pts.material == "history_0.50") & (pts.kind == "incline")].assign(group="check", rate_factor=0.5)
    half["theta_stop_mean"] += 0.5
    pd.concat([pts, half]).to_csv(tmp_path / "points.csv", index=False)


def test_calibrate_takes_theta_stop_at_zero_rate(tmp_path, capsys):
    """With the half-rate runs in the map (stock history mu = 0.5 stopping 0.5 deg higher at
    half rate: a lag of 1.0 deg at the ramp's rates), a target theta_stop 1 deg higher gives
    the answer the map as measured gives."""
    _map_with_half_rates(tmp_path)
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "22", "--map", str(tmp_path / "points.csv"),
                 "--details"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("note: no leave_pair_out.csv beside --map") and "\nmu_s = 0.70" in out
    assert "\nmu_k = 0.50" in out
    assert "theta_stop at zero rate: the ramp's value + 1.0 +- 0.8 deg (its lag, from half rates)" in out


def test_calibrate_takes_the_lag_to_fixed_angles_before_the_half_rate_one(tmp_path, capsys):
    """With validation.csv beside the map holding the lag the held beds measured on the 10 d
    bed (1.5 deg; the half rates' 1.0 is in the map too), a target theta_stop 1.5 deg higher
    gives the answer the map as measured gives."""
    _map_with_half_rates(tmp_path)
    pd.DataFrame({"engine": ["liggghts", "liggghts", "lammps"], "layers": [36, 18, 18],
                  "fixed_lag": [9.0, 1.5, 7.0], "fixed_lag_se": [0.1, 0.3, 0.1]}).to_csv(tmp_path / "validation.csv")
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "22.5", "--map", str(tmp_path / "points.csv"),
                 "--details"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("note: no leave_pair_out.csv beside --map") and "\nmu_s = 0.70" in out
    assert "\nmu_k = 0.50" in out
    assert "theta_stop at a fixed angle: the ramp's value + 1.5 +- 0.3 deg (its lag to beds held at fixed" in out


@pytest.mark.parametrize("argv, message", [
    (["--theta-start", "34"], "give at least two of --theta-start, --theta-stop, --theta-heap"),
    (["--theta-start", "45", "--theta-stop", "21"], "--theta-start 45: outside the measured map, which reaches "
                                                    "theta_start from 24.0 to 36.0 deg"),
    (["--theta-start", "25", "--theta-stop", "30"], "no (mu_s, mu_k) of the map gives these together"),
    (["--theta-start", "34", "--theta-stop", "21", "--rolling", "0.3"], "points.csv: column rolling has no map rows "
                                                                        "at --rolling 0.3: it was measured at 0 only"),
    (["--theta-start", "95", "--theta-stop", "21"], "must be an angle in degrees, in (0, 90)"),
])
def test_calibrate_refuses_in_one_line_with_status_2(tmp_path, capsys, argv, message):
    path = _synthetic_map(tmp_path)
    with pytest.raises(SystemExit) if "95" in argv else _nothing():
        code = main(["calibrate", *argv, "--map", str(path)])
        assert code == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def _rolling_sphere(mu_r):
    """A sphere (d = 1, m = 1) rolling along +x on a floor at 1 d/time unit (spin matched:
    no sliding), g = 1, the study's contact, for 2 time units."""
    data = {"name": "rolling", "dimension": 3, "gravity": [0.0, 0.0, -1.0],
            "effects": {"gravity": True, "rotation": True, "normal_damping": True},
            "contact": {"law": "stick_slip", "kn": 2e4, "nu_n": 7.906, "ks": 5714.285714285714, "mu_s": 0.5,
                        "mu_k": 0.5, **({"rolling": "epsd2", "rolling_mu": mu_r} if mu_r else {})},
            "time": {"dt": 5e-4, "duration": 2.0}, "output": {"every": 400, "grains": ["ball"]},
            "grain": [{"name": "ball", "radius": 0.5, "density": 1.909859317102744, "position": [0.0, 0.0, 0.49995],
                       "velocity": [1.0, 0.0, 0.0], "angular_velocity": [0.0, 2.0, 0.0]}],
            "wall": [{"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}]}
    return scene_mod.parse(data)


@needs_liggghts
def test_rolling_resistance_epsd2_with_stick_slip_on_liggghts(tmp_path):
    """epsd2's torque, capped at mu_r R Fn, slows a rolling sphere (no sliding) by
    a = mu_r g R r / (I + m r^2) = mu_r g / 1.4 (R = r on a wall): 0.1 * 2 / 1.4 = 0.143 over
    2 time units (the spring of epsd2 reaches its cap within a few steps); without it the
    sphere keeps its speed. The stick_slip combination with rolling_friction epsd2 is
    registered for the pair style and the walls (liggghts_plugin/register_combinations.cpp:
    every combination the library has with history); the incline's grains use it on pairs."""
    from stickslip.adapters import liggghts

    _, free = runner.run_scene(_rolling_sphere(0.0), "liggghts", tmp_path / "free", progress=False)
    _, slowed = runner.run_scene(_rolling_sphere(0.1), "liggghts", tmp_path / "epsd2", progress=False)
    assert free["ball_vx"].iloc[-1] == pytest.approx(1.0, abs=2e-3)
    assert 1.0 - slowed["ball_vx"].iloc[-1] == pytest.approx(0.1 * 2.0 / 1.4, rel=0.05)
    sc = scene_mod.load("incline3d_small", duration=1.0, rolling="epsd2", rolling_mu=0.1)
    runner.run_scene(sc, "liggghts", tmp_path / "incline", progress=False)
    text = (tmp_path / "incline" / "liggghts" / "in.scene").read_text()
    assert "pair_style gran model hooke/stiffness tangential stick_slip rolling_friction epsd2" in text
    assert "coefficientRollingFriction peratomtypepair 1 0.1" in text and liggghts.LAUNCHER.is_file()


DOCS = scene_mod.CASES_DIR.parent / "docs" / "granular-3d"


@pytest.mark.skipif(not (DOCS / "runs.csv").is_file(), reason="the study's results are not committed")
def test_the_committed_figures_and_tables_come_from_the_committed_runs(tmp_path):
    """`stickslip study-3d --from-csv` redraws docs/granular-3d from its runs.csv alone, and
    the tables it writes are the committed ones."""
    import shutil

    shutil.copy(DOCS / "runs.csv", tmp_path / "runs.csv")
    assert main(["study-3d", "--from-csv", "--out", str(tmp_path)]) == 0
    for name in ("points.csv", "predictions.csv", "validation.csv", "engines.csv", "hysteresis.csv", "loo.csv",
                 "interpolation.csv", "leave_pair_out.csv", "coverage.csv", "coverage_summary.csv"):
        got, committed = pd.read_csv(tmp_path / name), pd.read_csv(DOCS / name)
        pd.testing.assert_frame_equal(got, committed, check_exact=False, rtol=1e-9)
    for png in DOCS.glob("*.png"):
        assert (tmp_path / png.name).is_file()
    # a study of the validation's runs alone (`--only`) has tables and no curves to draw
    runs = pd.read_csv(DOCS / "runs.csv")
    (tmp_path / "alone").mkdir()
    runs[runs.group == "validation"].to_csv(tmp_path / "alone" / "runs.csv", index=False)
    assert main(["study-3d", "--from-csv", "--out", str(tmp_path / "alone")]) == 0
    assert (tmp_path / "alone" / "validation.csv").is_file()
    # and of the held beds alone: no ramp, so only the fixed-angle columns
    (tmp_path / "held").mkdir()
    runs[runs.kind == "hold"].to_csv(tmp_path / "held" / "runs.csv", index=False)
    assert main(["study-3d", "--from-csv", "--out", str(tmp_path / "held")]) == 0
    v = pd.read_csv(tmp_path / "held" / "validation.csv")
    assert len(v) == 4 and v.theta_stop_fixed.notna().all() and "theta_stop_zero_rate" not in v


@pytest.mark.slow
@needs_liggghts
def test_weinhart_h_stop_at_10_d_on_liggghts(tmp_path):
    """The validation of issue 39 from scratch (about 50 CPU minutes): stock history mu = 0.5
    without rolling resistance, 3 fills of the 10 d bed at the scene's rates, at half of them
    and held at the 5 fixed angles; theta_stop held at fixed angles (as Weinhart et al. ran
    theirs) and at zero rate (granular3d_tables.ramp_lag) within 0.7 deg of their fit at the
    measured depth."""
    from stickslip.studies import granular3d, granular3d_tables

    jobs = [j for j in granular3d.matrix(engines=("liggghts",))
            if j.kind in ("incline", "hold") and j.material == "history_0.50" and j.rolling == 0 and not j.layers
            and not j.silbert]
    assert sorted(j.rate_factor for j in jobs if j.kind == "incline") == [0.5] * 3 + [1.0] * 3
    assert len([j for j in jobs if j.kind == "hold"]) == 3 * len(granular3d.HOLD_ANGLES[18])
    t = granular3d.run_study(tmp_path / "out", tmp_path / "runs", jobs=jobs, progress=False)
    v = t["validation.csv"]
    assert len(v) == 1 and v["fills"].iloc[0] == 3 and bool(v["within_0.7_zero_rate"].iloc[0])
    assert v["fixed_fills"].iloc[0] == 3 and bool(v["within_0.7_fixed"].iloc[0])
    assert granular3d_tables.weinhart_theta_stop(10.0) == pytest.approx(21.98, abs=0.01)


# ---------------------------------------------------------------- theta_stop at fixed angles (kind hold3d)

HOLD = tomllib.loads(scene_mod.find("incline3d_hold").read_text())


def small_hold(angle, hold_time):
    """The small incline with cases/incline3d_hold.toml's protocol at 10 times its rates:
    flow at 28 deg, down to `angle`, held there for `hold_time`."""
    from stickslip.studies import granular3d

    data = copy.deepcopy(SMALL)
    data["analysis"] = dict(HOLD["analysis"])
    data["gravity_ramp"]["phase"] = copy.deepcopy(HOLD["gravity_ramp"]["phase"])
    for ph in data["gravity_ramp"]["phase"][1:4]:
        ph["rate"] *= 10.0
        ph["duration"] /= 10.0
    granular3d._hold(data, angle, hold_time)
    return scene_mod.parse(data)


def test_the_hold_reaches_its_angle_at_both_depths():
    """The study's held angles are where phases 1-3 end, on the 10 d and the 20 d bed (whose
    rates and durations are scaled alike), to within one interval's turn (a phase runs whole
    intervals: ramp_script.ramp_loop), and the run lasts the hold's time after them."""
    from stickslip.studies import granular3d

    for job, sc, _, _ in granular3d.plan([j for j in granular3d.matrix() if j.kind == "hold"], "runs"):
        every = sc.output.every * sc.dt
        turned = sum(ph.rate * every * math.ceil(ph.value / every - 1e-9) for ph in sc.gravity_ramp.phases[:4])
        assert math.degrees(turned) == pytest.approx(job.hold, abs=math.degrees(sc.gravity_ramp.phases[1].rate) * every)
        assert sc.gravity_ramp.phases[4].until == "speed_below"
        held = sc.duration - sum(ph.value for ph in sc.gravity_ramp.phases[:4])
        assert held == pytest.approx(granular3d.HOLD_TIME[job.layers or 18])
    with pytest.raises(SceneError, match=r"held angle 30 deg: must be in \(0, 28\)"):
        small_hold(30.0, 5.0)


def test_hold_reads_stop_and_flow_from_the_series():
    """Stopped: the hold phase ended on its condition before the run's end (time to stop from
    the hold's start, one interval before its first row); still flowing: 0 and no time."""
    from stickslip.kinds import hold3d

    sc = small_hold(20.0, 5.0)
    df = _ramp_frame([0, 0.5, 0.2, 0.01, 0.0005], [0, 3, 4, 4, 4], [0, 21, 20, 20, 20])
    s = hold3d.summarise(sc, df)
    assert s["stopped"] == 1.0 and s["theta_hold_deg"] == pytest.approx(20.0)
    assert s["time_to_stop_s"] == pytest.approx(0.4 - 0.2 + sc.output.every * sc.dt)
    df = _ramp_frame([0, 0.5, 0.2, 0.01, 0.002], [0, 3, 4, 4, 4], [0, 21, 20, 20, 20])
    s = hold3d.summarise(sc, df)
    assert s["stopped"] == 0.0 and math.isnan(s["time_to_stop_s"]) and s["speed_at_end"] == pytest.approx(0.002)
    # still flowing: steady (the last quarter as fast as the third) or slowing down (half as fast)
    steady = _ramp_frame([0, 0.5] + [0.7] * 8, [0, 3] + [4] * 8, [0, 21] + [20] * 8)
    slowing = _ramp_frame([0, 0.5] + [0.7] * 6 + [0.35] * 2, [0, 3] + [4] * 8, [0, 21] + [20] * 8)
    assert hold3d.summarise(sc, steady)["speed_trend"] == pytest.approx(1.0)
    assert hold3d.summarise(sc, slowing)["speed_trend"] == pytest.approx(0.5)
    assert math.isnan(hold3d.summarise(sc, _ramp_frame([0, 0.5, 0.2, 0.01, 0.0005], [0, 3, 4, 4, 4],
                                                       [0, 21, 20, 20, 20]))["speed_trend"])


@pytest.mark.parametrize("engine", [pytest.param("liggghts", marks=needs_liggghts),
                                    pytest.param("lammps", marks=needs_lammps)])
def test_a_bed_held_low_stops_and_one_held_high_flows(engine, tmp_path):
    """The small bed (stock history, mu = 0.5): held at 10 deg, far below its stop angle, it
    stops; held at 27 deg, above its start angle, it still flows after 10 time units."""
    low, _ = runner.run_scene(small_hold(10.0, 30.0), engine, tmp_path / "low", progress=False)
    high, _ = runner.run_scene(small_hold(27.0, 10.0), engine, tmp_path / "high", progress=False)
    assert low["stopped"] == 1.0 and low["theta_hold_deg"] == pytest.approx(10.0, abs=1e-6)
    assert low["time_to_stop_s"] < 30.0 and low["depth_at_end"] > 2.0
    assert high["stopped"] == 0.0 and high["speed_at_end"] > 0.01


def test_holds_take_the_step_between_the_highest_stop_and_the_lowest_flow():
    """A fill's theta_stop at fixed angles is the middle of the step where its bed went from
    stopping to flowing; a fill whose stops and flows interleave, or that never flowed, has none;
    the se adds the grid's step / sqrt(12) to the fills' spread."""
    from stickslip.studies import granular3d_tables as gt

    def fill(n, outcomes, layers=0):
        return [{"kind": "hold", "engine": "liggghts", "layers": layers, "fill": n, "hold_angle": a, "stopped": float(s),
                 "depth_at_stop": 10.0 if s else math.nan, "time_to_stop": 50.0 * a if s else math.nan,
                 "speed_trend": math.nan if s else 1.0 - a / 100}
                for a, s in outcomes]

    runs = pd.DataFrame(fill(1, [(21.0, 1), (21.5, 1), (22.0, 0), (22.5, 0)])
                        + fill(2, [(21.0, 1), (21.5, 0), (22.0, 0), (22.5, 0)])
                        + fill(3, [(21.0, 1), (21.5, 0), (22.0, 1), (22.5, 0)])
                        + fill(4, [(21.0, 1), (21.5, 1)]) + [{"kind": "incline", "engine": "liggghts", "layers": 0, "fill": 1}])
    h = gt.holds(runs).set_index("fill")
    assert h.loc[1, "theta_stop"] == 21.75 and h.loc[2, "theta_stop"] == 21.25
    assert h.loc[1, "highest_stopped"] == 21.5 and h.loc[1, "lowest_flowing"] == 22.0 and h.loc[1, "ordered"]
    assert not h.loc[3, "ordered"] and math.isnan(h.loc[3, "theta_stop"])
    assert math.isnan(h.loc[4, "theta_stop"]) and h.loc[1, "longest_stop"] == 50.0 * 21.5
    assert h.loc[1, "flowing_least_trend"] == pytest.approx(1.0 - 0.225)
    mean, se, n, depth = gt.fixed_angle(h.reset_index(), 18)
    assert n == 2 and mean == 21.5 and depth == 10.0
    assert se == pytest.approx(math.hypot(np.std([21.75, 21.25], ddof=1) / math.sqrt(2), 0.5 / math.sqrt(12)))


def test_the_pages_calibrate_examples_print_what_the_page_shows(capsys, monkeypatch):
    """Every `stickslip calibrate` console example of docs/granular-3d.md, run on the committed
    map from the repository's root (a measurements file's path is relative to it): its output
    (stdout, or the one error line) is the page's, line for line."""
    import re

    monkeypatch.chdir(DOCS.parent.parent)
    page = (DOCS.parent / "granular-3d.md").read_text()
    blocks = re.findall(r"```console\n\$ \.venv/bin/stickslip (calibrate [^\n]*)\n(.*?)```", page, re.S)
    assert len(blocks) >= 3 and any("--measurements" in c for c, _ in blocks)
    for command, shown in blocks:
        code = main(command.split())
        got = capsys.readouterr()
        assert (got.out if code == 0 else got.err).strip() == shown.strip(), command


def test_the_tables_scene_layers_are_the_scenes():
    """granular3d_tables.SCENE_LAYERS names the 10 d bed that runs.csv writes as layers 0: it
    is cases/incline3d.toml's lattice height, and the held beds' keys use it."""
    from stickslip.studies import granular3d, granular3d_tables

    base = tomllib.loads(scene_mod.find("incline3d").read_text())
    assert granular3d_tables.SCENE_LAYERS == base["lattice"][0]["counts"][2]
    assert granular3d_tables.bed_layers(0) == granular3d_tables.SCENE_LAYERS and granular3d_tables.bed_layers(36.0) == 36
    assert set(granular3d.HOLD_ANGLES) == {granular3d_tables.SCENE_LAYERS, granular3d.DEEP_LAYERS}
