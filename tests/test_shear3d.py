# SPDX-License-Identifier: GPL-2.0-or-later
"""Issue 51: the sheared layer (kind shear3d, cases/shear3d.toml): the scene format's driven lid
and its refusals, the kind read from known series, the lid driven on LIGGGHTS and LAMMPS
(small scene), and the study's map, round trip and shear groups as planned (labels, pairs,
fills, cost). The study's runs are opt-in (`stickslip study-3d`)."""
from __future__ import annotations

import copy
import math
import tomllib

import numpy as np
import pandas as pd
import pytest

from stickslip import runner
from stickslip import scene as scene_mod
from stickslip.errors import SceneError
from stickslip.kinds import shear3d
from conftest import needs_engine

SMALL = tomllib.loads(scene_mod.find("shear3d_small").read_text())


def parse(change):
    data = copy.deepcopy(SMALL)
    change(data)
    return scene_mod.parse(data)


@pytest.mark.parametrize("change, message", [
    (lambda d: (d["periodic"].pop("y"), d["base"][0].update(size=[5.0, 5.0])),
     "lid: a driven lid spans a box periodic in x and y"),
    (lambda d: d["lid"].pop("stiffness"), "lid.stiffness: missing (required)"),
    (lambda d: d["lid"].update(stiffness=0.0), "lid.stiffness = 0: must be > 0"),
    (lambda d: d["lid"].update(pressure=-1.0), "lid.pressure = -1: must be >= 0"),
    (lambda d: d["lid"].update(size=[5.0, 5.0]), "lid.size: a lid spans the periodic box (leave size out)"),
    (lambda d: d["lid"].update(colour="red"), "lid.colour"),
    (lambda d: d["lid"].update(origin=[0.0, 0.0, 5.0]), "start overlapping"),
    (lambda d: d["analysis"].pop("steady_after"), "analysis.steady_after: missing (required)"),
])
def test_lid_scene_errors_are_one_line(change, message):
    with pytest.raises(SceneError) as e:
        parse(change)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_the_lid_is_a_slab_of_its_own_that_moves():
    sc = scene_mod.load("shear3d_small")
    lid = sc.lid_grains()
    assert len(lid) == round(1.14 * 25) and all(g.name.startswith("lid") and not g.fixed for g in lid)
    assert not set(g.name for g in lid) & set(g.name for g in sc.moving_grains())  # the bed's grains alone move one by one
    assert min(g.position[2] for g in lid) > max(g.position[2] + g.radius for g in sc.moving_grains())
    assert sc.lid.area == 25.0 and sc.features()["lid"] == "a driven lid (lid)"
    assert shear3d.normal_stress(sc) == pytest.approx(10.0 + len(lid) * 1.0 / 25.0)  # m = 1, g = 1


@pytest.mark.parametrize("engine", ["pyref", "yade", "deme"])
def test_engines_without_the_lid_refuse_it_in_one_line(engine, tmp_path):
    from stickslip import adapters

    with pytest.raises(ValueError) as e:
        adapters.get(engine).run(scene_mod.load("shear3d_small"), tmp_path)
    assert str(e.value).endswith("a driven lid (lid)") and "\n" not in str(e.value)


def _series(sc, force, vx, z=None):
    """A shear3d time series: rows every 0.1 s from 0, the lid's force and velocity given."""
    n = len(force)
    return pd.DataFrame({"t": np.arange(n) * 0.1, "lid_x": 0.0, "lid_z": z if z is not None else np.full(n, 4.0),
                         "lid_vx": vx, "lid_force": force})


def test_the_kind_reads_peak_steady_dilation_and_slips_from_a_known_series():
    """tau/sigma = force / (sigma A): a peak of 0.6 within the first 4 s of drive (start 3 s),
    a steady 0.4 after 5 s with two slips (the lid at 10 x the drive's speed) each dropping
    tau/sigma from 0.45 to 0.35, and the lid 0.1 higher in the steady part than at the start.
    (The small scene's start is 6 s: the times below are shifted by it.)"""
    sc = scene_mod.load("shear3d_small")
    s_a = shear3d.normal_stress(sc) * sc.lid.area
    n, start = 170, int(round(sc.lid.start / 0.1))
    ratio = np.full(n, 0.4)
    ratio[:start + 1] = 0.0
    ratio[start + 20] = 0.6  # at 2 s of drive: the peak
    v = np.full(n, sc.lid.velocity)
    for a in (start + 70, start + 90):  # slips at 7 and 9 s of drive, after steady_after (5 s)
        ratio[a - 1], v[a:a + 2], ratio[a + 2] = 0.45, 10 * sc.lid.velocity, 0.35
    drive = np.arange(n) * 0.1 - sc.lid.start
    z = np.where(drive >= 5.0, 4.1, 4.0)
    s = shear3d.summarise(sc, _series(sc, ratio * s_a, v, z))
    assert s["shear_peak"] == pytest.approx(0.6) and s["slip_count"] == 2 and s["slip_drop"] == pytest.approx(0.1)
    steady = ratio[drive >= 5.0]
    assert s["shear_steady"] == pytest.approx(steady.mean()) and s["shear_steady_sd"] == pytest.approx(steady.std())
    assert s["shear_dilation"] == pytest.approx(0.1) and s["drive_travel"] == pytest.approx(sc.lid.velocity * drive[-1])
    short = shear3d.summarise(sc, _series(sc, ratio[:start] * s_a, v[:start]))  # ended before the drive
    assert all(math.isnan(short[k]) for k in ("shear_peak", "shear_steady", "shear_dilation"))


@pytest.mark.parametrize("engine", [pytest.param("liggghts", marks=needs_engine("liggghts")),
                                    pytest.param("lammps", marks=needs_engine("lammps"))])
def test_the_lid_is_loaded_and_driven_through_its_spring_on_the_engines(engine, tmp_path):
    """The small cell on an engine: before the start the lid rests on the layer (within 0.01 d
    of where it started along x, its spring holding it); after it, the lid follows the spring's end (within one d over a
    travel of 2 d) and the recorded force is the spring's, stiffness x (velocity x (t - start)
    - lid_x), to the column's precision; two lid grains, recorded, keep the lid's velocity
    (one body); the layer's tau / sigma is that of a frictional layer (0.1 to 1)."""
    data = copy.deepcopy(SMALL)
    data["output"]["grains"] = ["lid0", "lid7"]
    sc = scene_mod.parse(data)
    summary, df = runner.run_scene(sc, engine, tmp_path, progress=False)
    t = df["t"].to_numpy()
    before, after = (t > 2.0) & (t <= sc.lid.start), t > sc.lid.start + 1.0
    assert np.abs(df.lid_x[before]).max() < 0.01
    drive = sc.lid.velocity * np.maximum(t - sc.lid.start, 0.0)
    assert np.abs(df.lid_x[after] - drive[after]).max() < 1.0
    spring = sc.lid.stiffness * (drive - df.lid_x)
    assert np.allclose(df.lid_force, spring, rtol=1e-6, atol=1e-6 * sc.lid.stiffness)
    for g in ("lid0", "lid7"):
        assert np.allclose(df[f"{g}_vx"], df.lid_vx, atol=1e-9) and np.allclose(df[f"{g}_vy"], df.lid0_vy, atol=1e-9)
    assert 0.1 < summary["shear_steady"] < 1.0 and summary["shear_peak"] >= summary["shear_steady"]


# ---------------------------------------------------------------- the study's groups (issue 51)

def test_the_map_is_dense_keeps_its_labels_and_reaches_the_lower_edge():
    """The map: >= 12 stick-slip pairs inside the triangle mu_s 0.2-0.8, mu_s/2 <= mu_k <= mu_s,
    and a row beyond it (mu_s = 1.0), so that the map's edge does not stop an answer for a target
    inside the triangle; a point on mu_k = mu_s / 2 in every row of mu_s, history on the
    diagonal, three fills, both rolling resistances, incline and heap; every run of the committed
    study keeps its label."""
    from stickslip.studies import granular3d

    sweep = [j for j in granular3d.matrix(groups=("sweep",)) if j.nu_s == "paper" or j.mu_s == j.mu_k]
    pairs = {(j.mu_s, j.mu_k) for j in sweep if j.mu_s != j.mu_k and j.timing == "step"}
    assert len([1 for s, k in pairs if 0.2 <= s <= 0.8]) >= 12 and all(s / 2 <= k < s for s, k in pairs)
    assert min(s for s, _ in pairs) == 0.2 and max(s for s, _ in pairs) > 0.8
    rows = {s for s, _ in pairs} | {j.mu_s for j in sweep if j.mu_s == j.mu_k}
    assert all((s, s / 2) in pairs for s in rows) and rows == {j.mu_s for j in sweep if j.mu_s == j.mu_k}
    for s, k in pairs | {(s, s) for s in rows}:
        for kind in ("incline", "heap"):
            for rolling in granular3d.ROLLING:
                assert sorted(j.fill for j in sweep if (j.mu_s, j.mu_k, j.kind, j.rolling) == (s, k, kind, rolling)
                              and j.nu_s in ("paper", "0") and j.timing == "step") == list(granular3d.FILLS)
    committed = scene_mod.CASES_DIR.parent / "docs" / "granular-3d" / "runs.csv"
    if committed.is_file():
        labels = {j.label for j in granular3d.matrix()}
        assert set(pd.read_csv(committed).label) <= labels


def test_the_round_trip_pairs_are_off_the_map_inside_it_on_fresh_fills():
    """>= 6 pairs spread over the triangle (every row of mu_s between the map's), none a map
    point, each on >= 3 fills the map never used, incline, heap and sheared layer."""
    from stickslip.studies import granular3d

    cov = granular3d.matrix(groups=("coverage",))
    pairs = {(j.mu_s, j.mu_k) for j in cov}
    map_points = {(j.mu_s, j.mu_k) for j in granular3d.matrix(groups=("sweep",))}
    assert len(pairs) >= 6 and not pairs & map_points
    assert all(0.2 < s < 0.8 and s / 2 <= k < s for s, k in pairs)
    assert len({s for s, _ in pairs}) >= 4 and not set(granular3d.COVERAGE_FILLS) & set(granular3d.FILLS)
    for p in pairs:
        got = sorted((j.kind, j.fill) for j in cov if (j.mu_s, j.mu_k) == p)
        assert got == sorted((k, f) for k in ("incline", "heap", "shear") for f in granular3d.COVERAGE_FILLS)
    assert all(j.rolling == 0 and j.nu_s == "paper" and j.timing == "step" for j in cov)


def test_the_shear_group_is_lines_of_fixed_mu_k_and_the_maps_points():
    from stickslip.studies import granular3d

    shear = granular3d.matrix(groups=("shear", "engines"))
    lig = {(j.mu_s, j.mu_k) for j in shear if j.kind == "shear" and j.engine == "liggghts"}
    assert set(granular3d.SHEAR_LINES) <= lig and {(m, m) for m in granular3d.MUS} | set(granular3d.MAP_PAIRS) <= lig
    for mu_k in (0.2, 0.35):
        dmu = sorted(round(s - k, 3) for s, k in lig if k == mu_k)
        assert dmu[0] == 0 and dmu[-1] >= 0.2 and len(dmu) >= 3
    assert {(j.mu_s, j.mu_k) for j in shear if j.kind == "shear" and j.engine == "lammps"} == {granular3d.SHEAR_LAMMPS}
    job = next(j for j in shear if j.kind == "shear" and j.fill == 2)
    data = granular3d.scene_data(job, tomllib.loads(scene_mod.find("shear3d").read_text()))
    assert data["lid"]["seed"] == 102 and data["base"][0]["seed"] == 2 and data["lattice"][0]["seed"] == 2


def test_the_study_says_each_groups_cost_and_runs_nothing(tmp_path, capsys):
    """`study-3d --cost-only`: runs and CPU hours per group (granular3d.estimate, measured
    costs), nothing run or written."""
    from stickslip.cli import main

    assert main(["study-3d", "--cost-only", "--groups", "coverage", "shear", "--only", "_0.27_0.17_", "history_0.20",
                 "--runs", str(tmp_path / "runs"),
                 "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "group coverage: 9 runs, 9 to run" in err and "group shear: 3 runs, 3 to run" in err
    assert "CPU hours" in err and not (tmp_path / "runs").exists() and not (tmp_path / "out").exists()
