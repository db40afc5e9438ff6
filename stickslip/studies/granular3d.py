# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip study-3d`: what mu_s and mu_k each do to a bed of spheres (issue 39; the
findings: docs/granular-3d.md).

The matrix: cases/incline3d.toml (theta_start, theta_stop) and cases/heap3d.toml
(theta_heap) with stock history at MUS and with the stick-slip PAIRS, rolling resistance
off and on, FILLS fills each (the base's and the bed's random seeds), on LIGGGHTS; the
validation against Weinhart et al.'s h_stop (a 10 d and a 20 d bed, each also at half the
ramp's rates: the ramp's lag); the check with Silbert et al.'s stiffer contact; LAMMPS on
the validation and two stick-slip points; the map's denser points that calibrate inverts
(MAP_PAIRS), its round trip on pairs off the map (COVERAGE_PAIRS, group "coverage":
granular3d_calibration.py) and the sheared layer (cases/shear3d.toml, group "shear":
granular3d_shear.py). `groups` (GROUPS) runs some of them. The cost is stated before the first run starts (COST, measured); each finished
run stays on disk under `runs/<label>/` (summary.json and a small CSV: the ramp's series or
the heap's profile) and an interrupted study resumes with the runs it has not finished.
Then granular3d_tables.py writes the tables, figures and summary under `--out`.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import runner
from ..errors import SceneError
from ..kinds import heap3d, incline3d
from ..scene import find, parse

# Stock history: stick_slip with mu_k = mu_s and no tangential dashpot (a slip caps the force
# at mu Fn: docs/law.md). The range DEM users work in; 0.65 fills the diagonal of the map, and
# 1.0 is the map's row beyond it (MAP_PAIRS).
MUS = (0.2, 0.35, 0.5, 0.65, 0.8, 1.0)
# Stick-slip (mu_s, mu_k): mu_s and 2 mu_k - mu_s vary independently, and both land on MUS
# (2 mu_k - mu_s = 0.2, 0.5, 0.2, 0.35): each prediction is a measured history point.
PAIRS = ((0.8, 0.5), (0.8, 0.65), (0.5, 0.35), (0.5, 0.425))
# The map that calibrate inverts (issue 51): PAIRS and 8 more, 12 pairs over the law's triangle
# mu_s 0.2-0.8, mu_s / 2 <= mu_k <= mu_s, in rows of mu_s = 0.2, 0.35, 0.5, 0.65, 0.8: every row
# has a point on the lower edge mu_k = mu_s / 2 (the hull is the whole triangle, so that an
# answer for a target inside the map is not cut by the map's edge) and one half way up
# (0.15, 0.26, 0.49) or PAIRS' two; history is the diagonal. And a row beyond the triangle, mu_s =
# 1.0 (0.5, 0.75), so that an answer for a target near mu_s = 0.8 is not stopped where the map
# stops (above mu_s ~ 0.5 the angles hardly move: issue 51's round trip). A row at mu_s = 0.1
# was measured and left out: the angles curve so steeply below 0.2 that it raised the linear
# map's own error (leave-one-out) on theta_start from 0.60 to 1.38 deg, and that error, taken as
# the same everywhere, widened every answer's range (docs/granular-3d.md).
MAP_PAIRS = PAIRS + ((0.2, 0.1), (0.35, 0.175), (0.5, 0.25), (0.65, 0.325), (0.8, 0.4),
                     (0.2, 0.15), (0.35, 0.26), (0.65, 0.49), (1.0, 0.5), (1.0, 0.75))
# The round trip of calibrate (granular3d_calibration.py): pairs that are not map points, spread
# over the triangle (two a row of mu_s = 0.27, 0.43, 0.57, 0.73, one low and one high, and the
# pair of issue 51, (0.65, 0.45); then six more between them, for a tighter count), run on fills
# the map never used, incline, heap and sheared layer.
COVERAGE_PAIRS = ((0.27, 0.17), (0.27, 0.24), (0.43, 0.25), (0.43, 0.37), (0.57, 0.35), (0.57, 0.5),
                  (0.65, 0.45), (0.73, 0.45), (0.73, 0.64),
                  (0.3, 0.2), (0.4, 0.3), (0.47, 0.3), (0.6, 0.4), (0.7, 0.55), (0.77, 0.5))
COVERAGE_FILLS = (11, 12, 13)
# The sheared layer (cases/shear3d.toml, kind shear3d): a measurement that might tell mu_s from
# mu_k. Its sensitivity to mu_s - mu_k at fixed mu_k on two lines, mu_k = 0.2 (where the bulk
# still feels the contacts' friction) and 0.35 (where the incline's angles have saturated),
# mu_s - mu_k from 0 to the law's bound mu_s = 2 mu_k or 0.3; and on the map's points, so that
# calibrate can take it as a target; LAMMPS repeats one point.
SHEAR_LINES = ((0.2, 0.2), (0.3, 0.2), (0.4, 0.2), (0.35, 0.35), (0.45, 0.35), (0.55, 0.35), (0.65, 0.35))
SHEAR_LAMMPS = (0.4, 0.2)
# The paper's nu_s, as a share of nu_n: Table 2's 33.10 / 41.38 = 0.8. The scenes' nu_n
# (restitution 0.88) makes it 6.325 m sqrt(g/d).
NU_S_OVER_NU_N = 33.10 / 41.38
ROLLING = (0.0, 0.1)  # coefficientRollingFriction of LIGGGHTS' epsd2 (0: none)
FILLS = (1, 2, 3)
# The pair that also runs with exact slip timing (the paper's nu_s), and the two stick-slip
# points LAMMPS repeats.
EXACT_PAIR = (0.8, 0.5)
LAMMPS_PAIRS = ((0.8, 0.5), (0.5, 0.35))
# A deeper bed for the validation: H = 20 d (Weinhart et al.'s fit: theta_stop ~ 20.2 deg).
DEEP_LAYERS = 36
# Silbert et al.'s own contact for the stiffness check: kn = 2e5 m g/d, gamma_n = 50
# sqrt(g/d) (nu_n = 25 for a pair of m/2), dt = 1e-4 sqrt(d/g).
SILBERT = {"kn": 2.0e5, "ks": 2.0e5 * 2 / 7, "nu_n": 25.0, "dt": 1e-4}
# The validation at fixed angles (cases/incline3d_hold.toml: a flowing bed held at one angle,
# as Weinhart et al. ran theirs): the held angles (deg) by the bed's lattice layers, 0.5 deg
# apart around where the ramp put each bed's stop (its zero-rate estimate; the 20 d bed's
# 20.75 splits the step where all three fills went from stopping to flowing), and how long a
# bed is held (time units) before it counts as flowing; the deeper bed responds (h/h0)^1.5 slower.
HOLD_ANGLES = {18: (21.0, 21.5, 22.0, 22.5, 23.0), DEEP_LAYERS: (19.5, 20.0, 20.5, 20.75, 21.0)}
# LAMMPS holds each bed at the angles of the 0.5-deg steps around LIGGGHTS' stops (the
# 10 d bed's fills stopped at 21.5 or 22.0 deg and flowed at 22.0 or 22.5; the 20 d bed's at
# 20.5 and 21.0): what it costs (a 20 d run ~10 CPU minutes) kept to its validation
LAMMPS_HOLD_ANGLES = {18: (21.5, 22.0, 22.5), DEEP_LAYERS: (20.5, 21.0)}
HOLD_TIME = {18: 400.0, DEEP_LAYERS: 600.0}

# What a run costs, CPU seconds per grain-step (one process a run, 2 running at once on the
# 2-core machine), and the simulated time an incline's ramp lasts (by bed: deep or not, and
# the ramp's rate factor; a heap lasts its scene's duration), measured on the study's own
# runs (docs/granular-3d/cost.csv, runs.csv): only to say beforehand what a study costs.
SECONDS_PER_GRAIN_STEP = {"liggghts": 1.8e-7, "lammps": 1.9e-7}
INCLINE_TIME = {(False, 1.0): 355.0, (False, 0.5): 960.0, (True, 1.0): 630.0, (True, 0.5): 940.0}


@dataclass
class Job:
    """One run of the study: its folder label, the scene file, what changes in it, the engine."""
    label: str
    kind: str  # "incline" | "heap" | "hold"
    engine: str
    group: str  # "sweep" | "validation" | "check" | "engines"
    material: str  # history_0.50 | ss_0.80_0.50 ...
    mu_s: float
    mu_k: float
    nu_s: str  # "0" | "paper"
    timing: str
    rolling: float
    fill: int
    layers: int | None = None  # the incline's lattice layers (None: the scene's)
    rate_factor: float = 1.0
    silbert: bool = False
    hold: float | None = None  # the held angle, deg (kind "hold")
    data: dict = field(default_factory=dict)


def material_label(mu_s, mu_k):
    return f"history_{mu_s:.2f}" if mu_s == mu_k else f"ss_{mu_s:.2f}_{mu_k:.3g}"


def _jobs_of(kind, engine, group, mu_s, mu_k, nu_s, timing, rolling, fills, **more):
    out = []
    for fill in fills:
        mat = material_label(mu_s, mu_k)
        variant = "" if mu_s == mu_k else f"_nus{nu_s}_{timing}"
        extra = "".join(f"_{k}{v}" for k, v in sorted(more.items()) if k in ("layers", "rate_factor", "hold") and v) + (
            "_silbert" if more.get("silbert") else "")
        label = f"{kind}_{engine}_{mat}{variant}_roll{rolling:g}{extra}_fill{fill}"
        out.append(Job(label, kind, engine, group, mat, mu_s, mu_k, nu_s, timing, rolling, fill, **more))
    return out


GROUPS = ("sweep", "validation", "check", "engines", "coverage", "shear")


def matrix(fills=FILLS, checks=True, engines=("liggghts", "lammps"), groups=GROUPS):
    """Every run of the study in `groups`, the sweep first. Sized to the measured cost
    (docs/granular-3d.md, "Cost")."""
    return [j for j in _matrix(fills, checks, engines) if j.group in groups]


def _matrix(fills, checks, engines):
    jobs = []
    for kind in ("incline", "heap"):
        for rolling in ROLLING:
            for mu in MUS:
                jobs += _jobs_of(kind, "liggghts", "sweep", mu, mu, "0", "step", rolling, fills)
            for mu_s, mu_k in MAP_PAIRS:
                jobs += _jobs_of(kind, "liggghts", "sweep", mu_s, mu_k, "paper", "step", rolling, fills)
        # the variants on one pair: without the dashpot the step mode slips at every step above
        # V* (docs/law.md), so nu_s = 0 runs in the exact mode, as the drum's did; and the
        # paper's nu_s in the exact mode (step against exact timing)
        jobs += _jobs_of(kind, "liggghts", "sweep", *EXACT_PAIR, "0", "exact", 0.0, fills)
        jobs += _jobs_of(kind, "liggghts", "sweep", *EXACT_PAIR, "paper", "exact", 0.0, fills)
    # the validation: the 20 d bed (the 10 d one is the sweep's), and both at half rate, for
    # the ramp's lag (Weinhart et al. ran at fixed angles; the 20 d bed's: two fills, ~20 CPU
    # minutes each)
    jobs += _jobs_of("incline", "liggghts", "validation", 0.5, 0.5, "0", "step", 0.0, fills, layers=DEEP_LAYERS)
    jobs += _jobs_of("incline", "liggghts", "validation", 0.5, 0.5, "0", "step", 0.0, fills, rate_factor=0.5)
    jobs += _jobs_of("incline", "liggghts", "validation", 0.5, 0.5, "0", "step", 0.0, fills[:2], layers=DEEP_LAYERS,
                     rate_factor=0.5)
    # and at fixed angles, with no ramp and so no lag: does a flowing bed stop at each?
    held = [("liggghts", HOLD_ANGLES)] + ([("lammps", LAMMPS_HOLD_ANGLES)] if "lammps" in engines else [])
    for engine, angles_of in held:
        for layers, angles in angles_of.items():
            for angle in angles:
                jobs += _jobs_of("hold", engine, "validation", 0.5, 0.5, "0", "step", 0.0, fills,
                                 layers=layers if layers == DEEP_LAYERS else None, hold=angle)
    if checks:  # Silbert et al.'s own stiffness and step: ~18 CPU minutes a fill
        jobs += _jobs_of("incline", "liggghts", "check", 0.5, 0.5, "0", "step", 0.0, fills, silbert=True)
    if "lammps" in engines:
        jobs += _jobs_of("incline", "lammps", "validation", 0.5, 0.5, "0", "step", 0.0, fills)
        for mu_s, mu_k in LAMMPS_PAIRS:
            jobs += _jobs_of("incline", "lammps", "engines", mu_s, mu_k, "paper", "step", 0.0, fills)
    for kind in ("incline", "heap", "shear"):  # calibrate's round trip: pairs off the map, fills it never used
        for mu_s, mu_k in COVERAGE_PAIRS:
            jobs += _jobs_of(kind, "liggghts", "coverage", mu_s, mu_k, "paper", "step", 0.0, COVERAGE_FILLS)
    points = list(dict.fromkeys(SHEAR_LINES + tuple((m, m) for m in MUS) + MAP_PAIRS))
    for mu_s, mu_k in points:
        jobs += _jobs_of("shear", "liggghts", "shear", mu_s, mu_k, "0" if mu_s == mu_k else "paper", "step", 0.0, fills)
    if "lammps" in engines:
        jobs += _jobs_of("shear", "lammps", "engines", *SHEAR_LAMMPS, "paper", "step", 0.0, fills)
    return jobs


SCENES = {"incline": "incline3d", "heap": "heap3d", "hold": "incline3d_hold", "shear": "shear3d"}


def scene_data(job, base):
    """The scene's TOML data with the job's settings written in."""
    data = json.loads(json.dumps(base))
    c = data["contact"]
    c.update(mu_s=job.mu_s, mu_k=job.mu_k, slip_timing=job.timing)
    if job.silbert:
        c.update(kn=SILBERT["kn"], ks=SILBERT["ks"], nu_n=SILBERT["nu_n"])
        every_time = data["output"]["every"] * data["time"]["dt"]
        data["time"]["dt"] = SILBERT["dt"]
        data["output"]["every"] = int(round(every_time / SILBERT["dt"]))
    c["nu_s"] = NU_S_OVER_NU_N * c["nu_n"] if job.nu_s == "paper" else 0.0
    data["effects"]["tangential_damping"] = c["nu_s"] > 0
    if job.rolling:
        c.update(rolling="epsd2", rolling_mu=job.rolling)
    for block in data.get("base", []) + data.get("lattice", []):
        block["seed"] = job.fill
    if "lid" in data:  # the lid's own slab: another seed than the base's
        data["lid"]["seed"] = 100 + job.fill
    if job.layers:
        # a deeper bed: its flow's speed (Bagnold, ~h^1.5 at a given h/h_stop) and the time it
        # takes to reach it grow with depth, so the ramp's rates scale as (h/h0)^-1.5 (measured:
        # at the 10 d bed's rates a 20 d bed lagged its steady speed by ~3x and stopped 2 deg
        # low) and the speed that ends the fast descent as (h/h0)^0.5 (Froude scaling)
        ratio = job.layers / base["lattice"][0]["counts"][2]
        data["lattice"][0]["counts"][2] = job.layers
        for ph in data["gravity_ramp"]["phase"]:
            ph["rate"] *= ratio ** -1.5
            if "speed_below" in ph and ph["speed_below"] > 0.1:
                ph["speed_below"] *= ratio ** 0.5
            if ph.get("duration") and ph is not data["gravity_ramp"]["phase"][0]:
                # the flow's time to develop, as its response time (measured: a 20 d bed given
                # the 10 d bed's 10 time units flowed at 0.67 sqrt(gd), under the fast descent's
                # end, so its slow descent began 5 deg above the stop)
                ph["duration"] *= ratio ** 1.5
        data["time"]["duration"] *= ratio ** 2.5
    if job.hold is not None:
        _hold(data, job.hold, HOLD_TIME[job.layers or base["lattice"][0]["counts"][2]])
    if job.rate_factor != 1.0:
        for ph in data["gravity_ramp"]["phase"]:
            ph["rate"] *= job.rate_factor
        data["time"]["duration"] /= job.rate_factor
    data["name"] = f"{base['name']}_{job.label}"
    return data


def _hold(data, angle, hold_time):
    """cases/incline3d_hold.toml's phases brought to `angle`: the descent (phase 3) lasts until
    it gets there, and the run ends `hold_time` after the hold begins. A deeper bed's rates and
    durations are scaled alike above, so the angles the phases reach do not change."""
    up, down = data["gravity_ramp"]["phase"][1], data["gravity_ramp"]["phase"][3]
    top = up["rate"] * up["duration"]
    if not 0 < angle < top:
        raise SceneError(f"held angle {angle:g} deg: must be in (0, {top:g}) (the phases' highest angle)")
    down["duration"] = (top - angle) / -down["rate"]
    data["time"]["duration"] = sum(ph["duration"] for ph in data["gravity_ramp"]["phase"][:4]) + hold_time


def plan(jobs, out_runs, scenes=None):
    """[(job, scene, data, folder)], every scene checked before any run starts."""
    bases = {k: tomllib.loads(find(v).read_text()) for k, v in (scenes or SCENES).items()}
    paths = {k: find(v) for k, v in (scenes or SCENES).items()}
    out = []
    for job in jobs:
        data = scene_data(job, bases[job.kind])
        try:
            sc = parse(data, source=paths[job.kind])
        except SceneError as e:
            raise SceneError(f"run {job.label}: {e}") from None
        out.append((job, sc, data, Path(out_runs) / job.label))
    return out


def estimate(job, sc):
    """CPU seconds a run takes (SECONDS_PER_GRAIN_STEP, INCLINE_TIME), only to say beforehand."""
    if job.kind == "incline":
        sim = INCLINE_TIME[bool(job.layers), job.rate_factor]
    else:  # a heap or a sheared layer; a held bed at most (one that stops ends its run)
        sim = sc.duration
    return SECONDS_PER_GRAIN_STEP[job.engine] * len(sc.grains) * sim / sc.dt


def _record(data, engine):
    return {"engine": engine, "scene": {k: v for k, v in data.items() if k != "description"}}


def done(folder, data, engine):
    """A run is finished when its summary is on disk for the same engine and scene."""
    try:
        return (json.loads((folder / "settings.json").read_text()) == json.loads(json.dumps(_record(data, engine)))
                and (folder / "summary.json").is_file())
    except (OSError, ValueError):
        return False


def run_one(job, sc, data, folder, keep_engine_files=False):
    """Run one job unless it is on disk: its summary, and a small CSV (the incline's ramp
    series; the heap's surface profile). Written to <folder>.part and renamed when whole,
    so an interruption loses no finished run and leaves no half one that looks finished."""
    if done(folder, data, job.engine):
        return False
    tmp = folder.with_name(folder.name + ".part")
    if tmp.exists():
        shutil.rmtree(tmp)
    summary, df = runner.run_scene(sc, job.engine, tmp, progress=False, write_timeseries=False)
    if job.kind in ("incline", "hold"):
        keep = df[["t", "tilt", "phase", "com_z", "vcm_x", "vcm_y", "vcm_z", "ekin"]].copy()
        keep.insert(3, "speed", incline3d.downhill_speed(sc, df))
        keep.to_csv(tmp / "series.csv", index=False)
    elif job.kind == "shear":
        df[["t", "lid_x", "lid_z", "lid_vx", "lid_force"]].to_csv(tmp / "series.csv", index=False)
    else:
        xc, top = heap3d.profile(sc, df.iloc[-1])
        np.savetxt(tmp / "profile.csv", np.column_stack([xc, top]), delimiter=",", header="x,height", comments="")
    (tmp / "settings.json").write_text(json.dumps(_record(data, job.engine), indent=1))
    if not keep_engine_files:  # dumps of every grain: megabytes a run
        shutil.rmtree(tmp / job.engine, ignore_errors=True)
    if folder.exists():
        shutil.rmtree(folder)
    os.replace(tmp, folder)
    return True


def _task(job, sc, data, folder, keep):
    """A task for parallel.run_all: the run, then its summary read back."""
    run_one(job, sc, data, folder, keep)
    return json.loads((folder / "summary.json").read_text())


def run_study(out, out_runs, fills=FILLS, checks=True, engines=("liggghts", "lammps"), only=None, jobs_at_once=2,
              progress=True, tables_only=False, keep_engine_files=False, jobs=None, scenes=None, groups=GROUPS,
              cost_only=False):
    """The matrix (or `jobs`): the cost said first, `jobs_at_once` runs side by side, a line
    per finished run, then the tables and figures of every finished run. cost_only: say the
    cost, per group, and run nothing."""
    from . import granular3d_tables
    from .. import parallel

    jobs = jobs if jobs is not None else matrix(fills, checks, engines, groups)
    if only:
        jobs = [j for j in jobs if any(s in j.label for s in only)]
        if not jobs:
            raise SceneError(f"--only {' '.join(only)}: matches no run of the study")
    planned = plan(jobs, out_runs, scenes)
    kept = committed_rows(out, planned, out_runs)
    from_table = {p[0].label for p in planned} & set(kept.label)
    todo = [p for p in planned if not done(p[3], p[2], p[0].engine) and p[0].label not in from_table]
    say = sys.stderr.write
    if cost_only:
        for group in dict.fromkeys(p[0].group for p in planned):
            left = [p for p in todo if p[0].group == group]
            say(f"stickslip study-3d: group {group}: {sum(p[0].group == group for p in planned)} runs, {len(left)} to "
                f"run, {sum(estimate(p[0], p[1]) for p in left) / 3600:.2f} CPU hours\n")
    if not tables_only and todo:
        cost = {p[0].label: estimate(p[0], p[1]) for p in todo}
        say(f"stickslip study-3d: {len(planned)} runs, {len(planned) - len(todo) - len(from_table)} already on disk in "
            f"{out_runs}, {len(from_table)} in {Path(out) / 'runs.csv'}; "
            f"{len(todo)} to run ({jobs_at_once} at once), about {sum(cost.values()) / 60 / jobs_at_once:.0f} min "
            f"({sum(cost.values()) / 3600:.1f} CPU hours)\n")
        if not cost_only:
            t0 = time.perf_counter()
            tasks = [(cost[j.label], _task, (j, sc, data, folder, keep_engine_files)) for j, sc, data, folder in todo]
            results = parallel.run_all(tasks, "study-3d", progress, n_workers=jobs_at_once)
            failed = [(t[2][0].label, r) for t, r in zip(tasks, results) if isinstance(r, Exception)]
            say(f"stickslip study-3d: {len(todo) - len(failed)} runs finished in "
                f"{(time.perf_counter() - t0) / 60:.1f} min"
                + (f"; {len(failed)} failed, first: {failed[0][0]}: {failed[0][1]}" if failed else "") + "\n")
    if cost_only:
        return None
    finished = [p for p in planned if done(p[3], p[2], p[0].engine)]
    order = [j.label for j in matrix(fills, checks, engines, GROUPS)] + [p[0].label for p in planned]
    granular3d_tables.write_runs(finished, Path(out), kept=kept, order=list(dict.fromkeys(order)))
    return write_results(out)


def committed_rows(out, planned, out_runs):
    """The rows of out/runs.csv (the committed table) that no run on disk replaces: the
    finished runs of an earlier study, planned now or of groups not run now, kept as they
    are (a label says everything a run depends on but the scene files, which a changed scene
    does not invalidate here: delete its rows to run them again). So a study resumes in a
    checkout without the earlier study's run folders, and a study of some groups keeps the
    others' rows."""
    import pandas as pd

    path = Path(out) / "runs.csv"
    if not path.is_file():
        return pd.DataFrame({"label": []})
    rows = pd.read_csv(path)
    on_disk = {p[0].label for p in planned if done(p[3], p[2], p[0].engine)}
    return rows[~rows.label.isin(on_disk)]


def write_results(out):
    """The tables, figures and summary.md from out/runs.csv alone."""
    from . import granular3d_calibration, granular3d_figures, granular3d_shear, granular3d_tables

    out = Path(out)
    tables = granular3d_tables.write_tables(out)
    trust = granular3d_calibration.write(out, tables["points.csv"])
    shear = granular3d_shear.write(out, tables["points.csv"])
    tables.update(trust, **shear)
    figs = granular3d_figures.draw(out, tables)
    (out / "summary.md").write_text(granular3d_tables.summary(tables, figs) + granular3d_calibration.markdown(trust)
                                    + "\n" + granular3d_shear.markdown(shear))
    print(f"wrote {len(tables) + 1} tables, {len(figs)} figures and summary.md in {out}")
    return tables


# The smoke study (the test suite, `study-3d --smoke`): small scenes, two materials, one fill.
SMOKE_SCENES = {"incline": "incline3d_small", "heap": "heap3d_small", "shear": "shear3d_small"}


def smoke_jobs():
    """A study of a few seconds: history and one stick-slip pair on the small incline,
    history on the small heap, the pair on the small sheared layer."""
    return (_jobs_of("incline", "liggghts", "sweep", 0.5, 0.5, "0", "step", 0.0, (1,))
            + _jobs_of("incline", "liggghts", "sweep", 0.5, 0.35, "paper", "step", 0.0, (1,))
            + _jobs_of("heap", "liggghts", "sweep", 0.5, 0.5, "0", "step", 0.0, (1,))
            + _jobs_of("shear", "liggghts", "shear", 0.5, 0.35, "paper", "step", 0.0, (1,)))

