# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip drum-study`: avalanches in the turning drum, stock history against
stick-slip (issue 24; the findings: docs/drum.md).

A matrix of runs of cases/drum.toml on LIGGGHTS with MPI (all cores), one after another.
The cost is stated before the first starts; each run's results stay on disk under
`runs/<label>/` (summary.json and slope.csv: t, theta, kinetic energy, slip statistics),
so an interrupted study resumes with the runs it has not finished. Then a table
(study.csv, avalanches.csv), figures and study.md go to `--out` (docs/drum by default).
"""
from __future__ import annotations

import json
import math
import os
import shutil
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from .. import runner
from ..errors import SceneError
from ..kinds import drum
from ..scene import find, parse
from . import drum_figures

# Stock history is stick_slip with mu_k = mu_s and no tangential damping (the slip then
# drops the force to mu Fn and leaves it there: a cap, as history's; docs/law.md).
# 0.50-0.40 are the stick-slip runs' mu_s, mu_k and 2 mu_k - mu_s; 0.30, 0.20 and 0.10
# those of the contrasts (mu_k = 0.35, 0.30) and the range where the angles move.
HISTORY_MUS = (0.5, 0.45, 0.4, 0.3, 0.2, 0.1)
PAPER_NU_S = 33.10


def matrix(rate, full=True):
    """[(label, contact settings, rate, duration factor, dt factor)] of the study."""
    runs = [(f"history_mu{mu:.2f}", {"mu_s": mu, "mu_k": mu, "nu_s": 0.0}, rate, 1, 1) for mu in HISTORY_MUS]
    ss = {"mu_s": 0.5, "mu_k": 0.45, "nu_s": PAPER_NU_S}
    runs += [
        ("ss_0.50_0.45_step", dict(ss, slip_timing="step"), rate, 1, 1),
        ("ss_0.50_0.45_exact", dict(ss, slip_timing="exact"), rate, 1, 1),
        ("ss_0.50_0.45_nus0_exact", dict(ss, nu_s=0.0, slip_timing="exact"), rate, 1, 1),
        ("ss_0.50_0.45_total_step", dict(ss, reset="total", slip_timing="step"), rate, 1, 1),
        ("ss_0.50_0.35_step", dict(ss, mu_k=0.35, slip_timing="step"), rate, 1, 1),
        # Fmin = 0.1 Fn against a saw-tooth mean of 0.3 Fn: history's angles differ most
        # between those two, so this pair tells which of them a pile follows, and what
        # nu_s = 0 (no dashpot to hold a sliding contact at Fmin) changes
        ("ss_0.50_0.30_step", dict(ss, mu_k=0.30, slip_timing="step"), rate, 1, 1),
        ("ss_0.50_0.30_nus0_exact", dict(ss, mu_k=0.30, nu_s=0.0, slip_timing="exact"), rate, 1, 1),
    ]
    if full:  # the checks of the setting, each at the cost of one run: the rate halved, the step halved
        runs += [
            ("history_mu0.50_half_rate", {"mu_s": 0.5, "mu_k": 0.5, "nu_s": 0.0}, rate / 2, 1, 1),
            ("ss_0.50_0.30_step_half_dt", dict(ss, mu_k=0.30, slip_timing="step"), rate, 0.5, 0.5),
        ]
    return runs


SMOKE_LABELS = ("history_mu0.50", "ss_0.50_0.35_step")

# LIGGGHTS' speed on this scene, grain-steps per second of one run with its dumps read back,
# measured on the 2-core machine: 1 rank while another run uses the other core, 3.0e9
# grain-steps in 360 s; 2 ranks, the engine 1.72e7/s (drum-engines' costs.csv) and ~40 s of
# reading a run. Only to say beforehand what a study costs.
SPEED = {1: 8.3e6, 2: 1.4e7}
# The avalanche regime: the drum turns by at most MAX_TURN_PER_AVALANCHE (rad) while an
# avalanche runs, which lasts ~5 sqrt(D/g) (0.4-1.2 s measured in this drum, D = 88 mm).
MAX_TURN_PER_AVALANCHE = math.radians(1.0)
# The fill fraction (of the drum's area under the pile at packing 0.82) the study accepts.
FILL_RANGE = (0.2, 0.7)
PACKING = 0.82


def scene_data(base, settings, rate, duration, dt_factor, fill, seed):
    """The drum's TOML data with the run's settings written in."""
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    data["contact"].update(settings)
    data["gravity_rate"] = math.copysign(rate, base["gravity_rate"])
    data["time"]["duration"] = duration
    data["time"]["dt"] = base["time"]["dt"] * dt_factor
    data["output"]["every"] = max(1, int(round(base["output"]["every"] / dt_factor)))
    fills = [dict(f) for f in base["fill"]]
    if fill is not None:
        f = fills[0]
        room = math.pi * f["radius"] ** 2
        mean_area = math.pi * f["grain_radius"] ** 2 * (1 + f.get("radius_spread", 0.0) ** 2 / 3)
        f["count"] = int(round(fill * room * PACKING / mean_area))
    if seed is not None:
        fills[0]["seed"] = seed
    data["fill"] = fills
    return data


def check(scene_path, rate, fill, duration):
    """Refuse settings outside the avalanche regime or a fill that cannot be made: one line."""
    base = tomllib.loads(Path(scene_path).read_text())
    ring = base["ring"][0]
    diameter = 2 * (ring["radius"] - ring["grain_radius"])
    g = math.hypot(*base["gravity"])
    most = MAX_TURN_PER_AVALANCHE / (5 * math.sqrt(diameter / g))
    if not 0 < rate <= most:
        raise SceneError(f"--rate {rate:g}: must be in (0, {most:.3g}] rad/s (the avalanche regime: the drum turns "
                         f"at most {math.degrees(MAX_TURN_PER_AVALANCHE):g} deg during an avalanche of "
                         f"~5 sqrt(D/g) = {5 * math.sqrt(diameter / g):.2g} s)")
    if fill is not None and not FILL_RANGE[0] <= fill <= FILL_RANGE[1]:
        raise SceneError(f"--fill {fill:g}: must be in [{FILL_RANGE[0]}, {FILL_RANGE[1]}] (share of the drum "
                         "filled: below, no slope to measure; above, no room for it to avalanche)")
    check_duration(duration, base["analysis"]["settle"])
    return base


def check_duration(duration, settle):
    """A run must outlast its settling by a few avalanches' worth of seconds: one line if not."""
    if duration <= settle + 5:
        raise SceneError(f"--duration {duration:g}: must be > {settle + 5:g} s (the first {settle:g} s settle)")


def plan(scene_path, out_runs, rate, duration, fill, seed, labels, full):
    base = check(scene_path, rate, fill, duration)
    chosen = [r for r in matrix(rate, full) if labels is None or r[0] in labels]
    unknown = sorted(set(labels or ()) - {r[0] for r in matrix(rate, True)})
    if unknown:
        raise SceneError(f"--only {unknown[0]}: not a run of the study (runs: {', '.join(r[0] for r in matrix(rate))})")
    jobs = []
    for label, settings, r, dur_factor, dt_factor in chosen:
        data = scene_data(base, settings, r, duration * dur_factor, dt_factor, fill, seed)
        data["name"] = f"drum_{label}"
        try:
            sc = parse(data, source=Path(scene_path))
        except SceneError as e:
            raise SceneError(f"run {label}: {e}") from None
        jobs.append((label, sc, data, Path(out_runs) / label))
    return jobs


def _done(folder, record):
    """A run is finished when its summary and slope series are on disk for the same engine
    and scene (the scene's data but its description: a reworded comment does not call for
    a rerun)."""
    def physics(r):
        return {**r, "scene": {k: v for k, v in r["scene"].items() if k != "description"}}
    try:
        return (physics(json.loads((folder / "settings.json").read_text())) == physics(record)
                and (folder / "summary.json").is_file() and (folder / "slope.csv").is_file())
    except (OSError, ValueError, KeyError, TypeError):
        return False


def _record(data, engine):
    return {"engine": engine, "scene": _jsonable(data)}


def run_one(sc, data, folder, engine="liggghts", ranks=1, keep_timeseries=False, progress=True):
    """Run one drum scene unless it is on disk already; keep its slope series (slope.csv:
    t, both angles, kinetic energy, contacts, slip statistics), summary and settings. The
    run is written to <folder>.part and renamed when whole, so an interruption at any
    point loses no finished run and leaves no half one that looks finished."""
    record = _record(data, engine)
    if _done(folder, record):
        return False
    tmp = folder.with_name(folder.name + ".part")
    if tmp.exists():
        shutil.rmtree(tmp)
    _, df = runner.run_scene(sc, engine, tmp, progress=progress, ranks=ranks, write_timeseries=keep_timeseries)
    keep = ["t", "ekin", "n_contacts"] + [c for c in df.columns if c in _SLIP_COLUMNS]
    slope = df[keep].copy()
    slope.insert(1, "theta_deg", drum.slope_angles(sc, df))
    slope.insert(2, "theta_centroid_deg", drum.centroid_angles(sc, df))
    slope.to_csv(tmp / "slope.csv", index=False)
    (tmp / "settings.json").write_text(json.dumps(record, indent=1))
    if not keep_timeseries:  # the engine's own files: every grain and contact every row, gigabytes
        shutil.rmtree(tmp / engine, ignore_errors=True)
    if folder.exists():
        shutil.rmtree(folder)
    os.replace(tmp, folder)
    return True


def run_study(scene_path, out, out_runs, rate, duration, fill=None, seed=None, labels=None, full=True, ranks=1,
              jobs_at_once=1, keep_timeseries=False, progress=True, tables_only=False):
    """The matrix on LIGGGHTS: `jobs_at_once` runs side by side, each on `ranks` MPI
    processes; the cost said first, a line per run started and finished, the table and
    figures at the end."""
    jobs = plan(scene_path, out_runs, rate, duration, fill, seed, labels, full)
    todo = [j for j in jobs if not _done(j[3], _record(j[2], "liggghts"))]
    if tables_only:  # the tables and figures of the runs finished so far
        return write_results([j for j in jobs if j not in todo], Path(out))
    cost = {j[0]: estimate(j[1], ranks) / min(jobs_at_once, max(1, len(todo))) for j in todo}
    say = sys.stderr.write
    say(f"stickslip drum-study: {len(jobs)} runs, {len(jobs) - len(todo)} already on disk in {out_runs}; "
        f"{len(todo)} to run on LIGGGHTS ({jobs_at_once} at once, {ranks} MPI rank{'s' if ranks > 1 else ''} each), "
        f"about {sum(cost.values()) / 60:.0f} min\n")
    if jobs_at_once > 1:  # independent runs side by side: stickslip/parallel.py, longest first
        from .. import parallel

        tasks = [(cost[label], run_one, (sc, data, folder, "liggghts", ranks, keep_timeseries, False))
                 for label, sc, data, folder in todo]
        done = parallel.run_all(tasks, "drum-study", progress, n_workers=jobs_at_once)
        failed = [r for r in done if isinstance(r, Exception)]
        if failed:
            raise failed[0]
        return write_results(jobs, Path(out))
    t_start = time.perf_counter()
    for k, (label, sc, data, folder) in enumerate(todo):
        left = sum(cost[j[0]] for j in todo[k:])
        say(f"[{k + 1}/{len(todo)}] {label}: {sc.steps:,} steps x {len(sc.grains)} grains, ~{cost[label]:.0f} s "
            f"(study: ~{left / 60:.0f} min left, {(time.perf_counter() - t_start) / 60:.1f} min so far)\n")
        run_one(sc, data, folder, "liggghts", ranks, keep_timeseries, progress)
    return write_results(jobs, Path(out))


def estimate(sc, ranks):
    """Seconds a run takes on LIGGGHTS with `ranks` processes (SPEED), only to say beforehand."""
    return sc.steps * len(sc.grains) / SPEED.get(ranks, SPEED[1] * ranks)


_SLIP_COLUMNS = ("n_slipping", "n_slip_above_vd", "n_slip_above_vstar", "slip_fs_fn_sum")


def _jsonable(data):
    return json.loads(json.dumps(data))


def load_run(folder):
    summary = json.loads((folder / "summary.json").read_text())
    return summary, pd.read_csv(folder / "slope.csv")


STUDY_COLUMNS = ("label", "mu_s", "mu_k", "nu_s", "reset", "slip_timing", "rate_rad_s", "dt_s", "duration_s",
                 "avalanches", "slides", "theta_start_mean_deg", "theta_start_se_deg", "theta_stop_mean_deg",
                 "theta_stop_se_deg", "delta_theta_mean_deg", "delta_theta_se_deg",
                 "theta_start_centroid_mean_deg", "theta_start_centroid_se_deg", "theta_stop_centroid_mean_deg",
                 "theta_stop_centroid_se_deg", "delta_theta_centroid_mean_deg", "delta_theta_centroid_se_deg",
                 "avalanche_share_above_vd",
                 "avalanche_share_above_vstar", "avalanche_slip_fs_fn", "wall_time_s")


def write_results(jobs, out):
    out.mkdir(parents=True, exist_ok=True)
    rows, events = [], []
    for label, sc, _, folder in jobs:
        run_summary, slope = load_run(folder)
        # measured again from the slope series: the figures follow kinds/drum.py as it is now
        summary = dict(run_summary, **drum.summarise(sc, slope, slope["theta_deg"], slope["theta_centroid_deg"]))
        c = sc.contact
        row = {"label": label, "mu_s": c.mu_s, "mu_k": c.mu_k, "nu_s": c.nu_s, "reset": c.reset,
               "slip_timing": c.slip_timing, "rate_rad_s": abs(sc.gravity_rate), "dt_s": sc.dt,
               "duration_s": sc.duration}
        row.update({k: summary.get(k, math.nan) for k in STUDY_COLUMNS if k not in row})
        rows.append(row)
        for e in summary["avalanche_list"]:
            events.append({"label": label, **e})
    study = pd.DataFrame(rows, columns=STUDY_COLUMNS)
    study.to_csv(out / "study.csv", index=False)
    pd.DataFrame(events).to_csv(out / "avalanches.csv", index=False)
    figs = drum_figures.draw(out, study, pd.DataFrame(events), {j[0]: j[3] for j in jobs})
    (out / "study.md").write_text(_table(study, figs))
    print(f"wrote {out / 'study.csv'}, {out / 'avalanches.csv'}, {out / 'study.md'} and {len(figs)} figures")
    return study


def _table(study, figs):
    def pm(m, se):
        return "—" if not np.isfinite(m) else f"{m:.2f} ± {se:.2f}" if np.isfinite(se) else f"{m:.2f}"

    lines = ["# Drum study: the table", "",
             "Written by `stickslip drum-study` (stickslip/studies/drum_study.py); the findings: [../drum.md](../drum.md). "
             "Means over the avalanches of each run with their standard errors (std / sqrt(n)); angles in degrees.",
             "θ: fit to the middle of the surface; θc: the centroid's angle (stickslip/kinds/drum.py).", "",
             "| run | μs | μk | νs | reset | timing | rate (rad/s) | dt (s) | avalanches (slides) | θ_start | θ_stop "
             "| δθ | θc_start | θc_stop | δθc | slipping above V_d | above V* | ⟨abs(Fs)/Fn⟩ slipping |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in study.iterrows():
        angles = " | ".join(pm(r[f"{k}_mean_deg"], r[f"{k}_se_deg"])
                            for k in ("theta_start", "theta_stop", "delta_theta", "theta_start_centroid",
                                      "theta_stop_centroid", "delta_theta_centroid"))
        lines.append(f"| {r.label} | {r.mu_s:g} | {r.mu_k:g} | {r.nu_s:g} | {r.reset} | {r.slip_timing} | "
                     f"{r.rate_rad_s:g} | {r.dt_s:g} | {int(r.avalanches)} ({int(r.slides)}) | {angles} | "
                     f"{r.avalanche_share_above_vd:.2f} | {r.avalanche_share_above_vstar:.2f} | "
                     f"{r.avalanche_slip_fs_fn:.3f} |")
    lines += ["", "## Which history μ gives the same angle", "",
              "For each stick-slip run, the friction coefficients μ of stock history whose mean angle agrees with "
              "the run's within two combined standard errors (history interpolated linearly between its runs; "
              "'none': no history run agrees; drum_figures.consistent_mu).", "",
              "| run | μs | μk | 2μk−μs | θ_start | θ_stop | θc_start | θc_stop |", "|---|---|---|---|---|---|---|---|"]
    ranges = {k: drum_figures.consistent_mu(study, k) for k in ("theta_start", "theta_stop", "theta_start_centroid",
                                                                 "theta_stop_centroid")}
    for _, r in drum_figures.stick_slip(study).iterrows():
        cells = [", ".join(f"{a:.2f}–{b:.2f}" for a, b in ranges[k][r.label]) or "none" for k in ranges]
        lines.append(f"| {r.label} | {r.mu_s:g} | {r.mu_k:g} | {2 * r.mu_k - r.mu_s:.2f} | " + " | ".join(cells) + " |")
    lines += [""] + [f"![{f}]({f})" for f in figs] + [""]
    return "\n".join(lines)


DOCS = Path(__file__).resolve().parents[2] / "docs" / "drum"  # the repository's (a wheel carries no study)


def _markdown_table(df):
    def cell(v):
        if isinstance(v, float):
            return "—" if not np.isfinite(v) else f"{v:.4g}"
        return str(v)
    return "\n".join(["| " + " | ".join(df.columns) + " |", "|" + "---|" * len(df.columns)]
                     + ["| " + " | ".join(cell(v) for v in row) + " |" for row in df.itertuples(index=False)])


def report_section(report_dir, docs=DOCS):
    """The report's drum section: the finished study's table and figures, and the engines'
    comparison when `stickslip drum-engines` has written it (the report runs neither: they
    take most of an hour), or how to run them."""
    lines = ["", "## Granular scale: avalanches in a turning drum", ""]
    if not (docs / "study.csv").is_file():
        return "\n".join(lines + ["No finished drum study is present. Run it (LIGGGHTS on both cores, under an hour, "
                                  "resumable): `.venv/bin/stickslip drum-study`; it writes docs/drum/ (the findings: "
                                  "docs/drum.md).", ""])
    rel = os.path.relpath(docs, report_dir)
    findings = os.path.relpath(docs.parent / "drum.md", report_dir)
    study = pd.read_csv(docs / "study.csv")
    lines += [f"From the finished study in [{rel}/study.md]({rel}/study.md) ({len(study)} runs; the findings and the "
              f"calibration recipe: [{findings}]({findings})). Means ± standard errors, degrees.", "",
              "| run | avalanches | θ_start (fit) | θ_stop (fit) | θ_start (centroid) | θ_stop (centroid) |",
              "|---|---|---|---|---|---|"]
    for _, r in study.iterrows():
        lines.append(f"| {r.label} | {int(r.avalanches)} | " + " | ".join(
            f"{r[f'{k}_mean_deg']:.2f} ± {r[f'{k}_se_deg']:.2f}"
            for k in ("theta_start", "theta_stop", "theta_start_centroid", "theta_stop_centroid")) + " |")
    lines.append("")
    for png in sorted(docs.glob("drum_*.png")):
        lines += [f"![{png.stem}]({rel}/{png.name})", ""]
    lines += ["### The drum across engines", ""]
    heading_only = len(lines)
    if (docs / "engines_divergence.png").is_file():
        lines += ["How far each engine's grains are from pyref's over the drum's first 0.4 s (round-off grown by the "
                  f"pile's chaos; [{rel}/engines_divergence.csv]({rel}/engines_divergence.csv)):", "",
                  f"![engines_divergence]({rel}/engines_divergence.png)", ""]
    # the engines' means (centroid angles, degrees) and z = difference / combined error
    shown = {"engines.csv": ["engine", "duration_s", "avalanches", "theta_start_centroid_mean_deg",
                             "theta_start_centroid_se_deg", "theta_stop_centroid_mean_deg",
                             "theta_stop_centroid_se_deg", "theta_start_centroid_z", "theta_stop_centroid_z"],
             "costs.csv": None}
    for name, what in (("engines.csv", "avalanche statistics of the same drum on each engine"),
                       ("costs.csv", "each engine's cost on the drum")):
        if (docs / name).is_file():
            table = pd.read_csv(docs / name)
            lines += [f"{what[0].upper() + what[1:]}: [{rel}/{name}]({rel}/{name}).", "",
                      _markdown_table(table[[c for c in (shown[name] or table.columns) if c in table]]), ""]
    if len(lines) == heading_only:
        lines += ["Not measured yet: `.venv/bin/stickslip drum-engines` writes it.", ""]
    return "\n".join(lines)
