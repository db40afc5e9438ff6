# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip drum-engines`: the turning drum (cases/drum.toml) across engines (issue 24, 5).

Three parts, each written to --out (docs/drum by default) and linked from docs/drum.md:
- costs: each engine on the drum's first COST_DURATION s (the fill falls and packs into
  ~350 contacts), side by side in one call: grain-steps per second of the engine's own
  loop, the MPI engines (LIGGGHTS, LAMMPS) on 1 and 2 ranks (costs.csv; the runs
  themselves in --runs, not beside the table: their logs name this machine's folders);
- divergence: the drum's first DIVERGENCE_DURATION s on pyref and every engine (the MPI
  engines on 1 and 2 ranks), every grain recorded every few steps: how far each engine's grains are from
  pyref's as time goes on (engines_divergence.csv and .png). The engines solve the same
  equations, so they start equal to round-off; a pile is chaotic, so any difference,
  round-off included, grows by a constant factor per unit time until the trajectories
  have parted (the fitted e-folding time is printed);
- statistics: each engine but pyref runs the drum for --duration s (resumable, kept in
  --runs like the study's runs), and their avalanche means are compared with their
  standard errors (engines.csv): after the trajectories part, engines can only agree in
  distribution. Rows of engines not run this time stay in engines.csv when they are of
  the same duration (a YADE run of 40 s takes over half an hour), and every z is against
  the first engine of the table (ENGINES' order: LIGGGHTS before YADE and LAMMPS).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from .. import runner
from ..adapters import ENGINES
from .drum_study import check_duration, load_run, run_one
from ..kinds import drum
from ..scene import find, load, parse

COST_DURATION = 1.0  # s: the fill falls (0.2 s) and sits as a pile of ~360 contacts
DIVERGENCE_DURATION = 0.4  # s: round-off grows to the grains' size well before (measured)
DIVERGENCE_EVERY = 25  # steps between records
# the part of the divergence curve the e-folding time is fitted to: above round-off's
# floor, below the size where grains have simply gone different ways (m)
FIT_RANGE = (1e-13, 1e-5)


def _with_two_ranks(engines):
    """(engine, ranks) of each engine on one rank, then of the MPI engines on two."""
    return [(e, 1) for e in engines] + [(e, 2) for e in engines if e in runner.MPI_ENGINES]


def costs(out, engines, work, progress=False):
    """Each engine's cost on the drum's first COST_DURATION s; the MPI engines also on 2 ranks
    (their runs in `work`, the table in `out`)."""
    sc = load("drum", duration=COST_DURATION, every=1000)
    rows = []
    for engine, ranks in _with_two_ranks(engines):
        summary, _ = runner.run_scene(sc, engine, Path(work) / f"{engine}_{ranks}", progress=progress,
                                      ranks=ranks, write_timeseries=False)
        rows.append({"engine": engine, "ranks": ranks, "steps": summary["steps"], "grains": len(sc.grains),
                     "wall_time_s": summary["wall_time_s"],
                     "grain_steps_per_s": summary["steps"] * len(sc.grains) / summary["wall_time_s"]})
    table = pd.DataFrame(rows)
    for engine in runner.MPI_ENGINES:
        one = table[(table.engine == engine) & (table.ranks == 1)]
        two = table[(table.engine == engine) & (table.ranks == 2)]
        if len(one) and len(two):
            table.loc[two.index, "speedup_vs_1_rank"] = float(one.wall_time_s.iloc[0] / two.wall_time_s.iloc[0])
    Path(out).mkdir(parents=True, exist_ok=True)
    table.to_csv(Path(out) / "costs.csv", index=False)
    return table


def divergence(out, engines, work, progress=False):
    """Largest distance (m) between a grain on each engine and the same grain on pyref, at
    every record of the drum's first DIVERGENCE_DURATION s; and the e-folding time of its
    growth, fitted where it is between FIT_RANGE's bounds."""
    sc = load("drum", duration=DIVERGENCE_DURATION, every=DIVERGENCE_EVERY)
    names, _ = drum.mobile(sc)
    cols = [f"{n}_{a}" for n in names for a in "xy"]
    runs = {}
    for engine, ranks in [("pyref", 1)] + _with_two_ranks([e for e in engines if e != "pyref"]):
        _, df = runner.run_scene(sc, engine, Path(work) / f"{engine}_{ranks}", progress=progress, ranks=ranks,
                                 write_timeseries=False)
        runs[f"{engine}_{ranks}"] = df
    ref = runs.pop("pyref_1")
    p = ref[cols].to_numpy().reshape(len(ref), -1, 2)
    table = pd.DataFrame({"t": ref["t"], "n_contacts": ref["n_contacts"]})
    xy = {key: df[cols].to_numpy().reshape(len(df), -1, 2) for key, df in runs.items()}
    for key, q in xy.items():
        table[f"{key}_vs_pyref_m"] = np.linalg.norm(q - p, axis=2).max(axis=1)
    for engine in runner.MPI_ENGINES:  # the same engine, sums in another order
        if f"{engine}_1" in xy and f"{engine}_2" in xy:
            table[f"{engine}_2_vs_{engine}_1_m"] = np.linalg.norm(xy[f"{engine}_2"] - xy[f"{engine}_1"],
                                                                  axis=2).max(axis=1)
    Path(out).mkdir(parents=True, exist_ok=True)
    table.to_csv(Path(out) / "engines_divergence.csv", index=False)
    fits = {c: efolding_time(table["t"].to_numpy(), table[c].to_numpy()) for c in table.columns if c.endswith("_m")}
    _plot_divergence(out, table, fits)
    return table, fits


def efolding_time(t, d):
    """(e-folding time, first and last t of the fit) of d(t) where d is within FIT_RANGE:
    a least-squares line through log d."""
    on = (d > FIT_RANGE[0]) & (d < FIT_RANGE[1])
    if on.sum() < 5:
        return math.nan, math.nan, math.nan
    slope = np.polyfit(t[on], np.log(d[on]), 1)[0]
    return (1.0 / slope if slope > 0 else math.nan), float(t[on].min()), float(t[on].max())


def _name(column):
    """'liggghts_2_vs_pyref_m' -> 'liggghts (2 ranks) vs pyref'."""
    def one(key):
        engine, _, ranks = key.partition("_")
        return f"{engine} ({ranks} rank{'s' if ranks != '1' else ''})" if engine in runner.MPI_ENGINES else engine
    return " vs ".join(one(k) for k in column[:-2].split("_vs_"))


def _plot_divergence(out, table, fits):
    from ..plotstyle import pyplot, save

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    for c in table.columns:
        if c.endswith("_m"):
            tau = fits[c][0]
            ax.semilogy(table["t"], np.maximum(table[c], 1e-20), lw=1,
                        label=f"{_name(c)} (e-folds every {tau * 1e3:.1f} ms)")
    ax.axhspan(*FIT_RANGE, color="0.93", label="range of the fit")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("largest distance between\na grain's two positions (m)")
    ax.legend(fontsize=7)
    return save(fig, out, "engines_divergence.png")


def statistics(out, out_runs, engines, duration, progress=True):
    """The drum run for `duration` s on each engine (kept in out_runs/engines_<engine>,
    resumed like the study's runs); their avalanche means side by side, and each mean's
    difference from the first engine's in units of the two standard errors combined."""
    import tomllib

    path = find("drum")
    data = tomllib.loads(path.read_text())  # the scene's data, kept with each run to tell it apart
    data["time"]["duration"] = duration
    sc = parse(data, source=path)
    rows = []
    for engine in engines:
        folder = Path(out_runs) / f"engines_{engine}"
        run_one(sc, data, folder, engine, 1, progress=progress)
        summary, slope = load_run(folder)
        s = drum.summarise(sc, slope, slope["theta_deg"], slope["theta_centroid_deg"])
        rows.append({"engine": engine, "duration_s": duration, "wall_time_s": summary["wall_time_s"],
                     "avalanches": s["avalanches"], "slides": s["slides"],
                     **{k: s[k] for k in s if k.endswith(("_mean_deg", "_se_deg"))}})
    table = pd.DataFrame(rows)
    path = Path(out) / "engines.csv"
    if path.is_file():  # the rows of engines not run now, of the same duration
        old = pd.read_csv(path)
        kept = old[~old.engine.isin(engines) & (old.duration_s == duration)]
        table = pd.concat([kept[[c for c in kept.columns if not c.endswith("_z")]], table], ignore_index=True)
        table = table.sort_values("engine", key=lambda e: e.map(ENGINES.index), ignore_index=True)
    for key in [k[:-len("_mean_deg")] for k in table.columns if k.endswith("_mean_deg")]:
        m, se = table[f"{key}_mean_deg"], table[f"{key}_se_deg"]
        table[f"{key}_z"] = (m - m.iloc[0]) / np.sqrt(se**2 + se.iloc[0] ** 2)
    Path(out).mkdir(parents=True, exist_ok=True)
    table.to_csv(path, index=False)
    return table


def run(out, out_runs, engines, duration, parts, progress=True):
    """The parts asked for, each one's cost said first; results to `out`."""
    import sys

    from .. import adapters
    from ..errors import SceneError

    missing = {e: adapters.get(e).available() for e in engines}
    missing = {e: why for e, why in missing.items() if why}
    if missing:
        e, why = next(iter(missing.items()))
        raise SceneError(f"--engines {e}: not available ({why})")
    if "statistics" in parts:
        check_duration(duration, load("drum").analysis["settle"])
    say = sys.stderr.write
    if "costs" in parts:
        say(f"drum-engines: costs, the drum's first {COST_DURATION} s on {', '.join(engines)} (~1-2 min)\n")
        print(costs(out, engines, Path(out_runs) / "engines_costs", progress).to_string(index=False))
    if "divergence" in parts:
        say(f"drum-engines: divergence, the drum's first {DIVERGENCE_DURATION} s on {', '.join(engines)} "
            "(pyref and YADE ~1 min each)\n")
        _, fits = divergence(out, engines, Path(out_runs) / "engines_divergence", progress)
        for key, (tau, t0, t1) in fits.items():
            say(f"  {key}: e-folding time {tau * 1e3:.2f} ms (fitted over {t0:.3f}-{t1:.3f} s)\n")
    if "statistics" in parts:
        say(f"drum-engines: statistics, {duration:g} s of the drum on {', '.join(e for e in engines if e != 'pyref')}"
            f" (YADE ~{duration * 60 / 40:.0f} min; runs kept in {out_runs})\n")
        print(statistics(out, out_runs, [e for e in engines if e != "pyref"], duration, progress).to_string(index=False))
