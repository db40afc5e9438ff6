# SPDX-License-Identifier: GPL-2.0-or-later
"""What accuracy costs in time: a scene over a ladder of time steps, both slip timings.

Every run's error is measured against a converged answer: the exact-timing run at the
finest step of the ladder on the reference engine (pyref by default; `--reference
liggghts` reaches finer steps in the same time). The exact mode's own convergence
(docs/precision.md) shows that this run is converged to well below the errors
measured. The error measures are the case kind's (stickslip/kinds/<kind>.py, errors()).
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from .. import kinds, parallel, plotstyle, runner
from .. import scene as scene_mod

DEFAULT_FACTORS = (8, 4, 2, 1, 0.5, 0.25)  # x the scene's dt: 6 steps over 1.5 decades
TIMING_LINES = {"step": "--", "exact": "-"}


def ladder(sc, factors):
    """Time steps from the factors, keeping those below 0.9 of the stability limit."""
    limit = 0.9 * sc.critical_dt()
    return [sc.dt * f for f in sorted(factors, reverse=True) if sc.dt * f <= limit]


def run_precision(scene_name, engines, out: Path, factors=None, progress=True, reference="pyref",
                  timings=("step", "exact"), engine_min_factor=None):
    """The ladder on each engine in each slip timing, on every core; returns the CSV path
    and the fitted convergence orders {(engine, timing, measure): order}."""
    tasks, finish = plan(scene_name, engines, out, factors, reference, timings, engine_min_factor)
    return finish(parallel.run_all(tasks, f"precision {scene_name}", progress))


def plan(scene_name, engines, out: Path, factors=None, reference="pyref", timings=("step", "exact"),
         engine_min_factor=None):
    """The runs of a ladder as tasks for parallel.run_all, and the function that turns
    their results into the CSV, the orders and the diagrams. `engine_min_factor`: engines
    other than the reference skip steps finer than that factor of the scene's dt."""
    base = scene_mod.load(scene_name)
    kind = kinds.get(base.analysis["kind"])
    dts = ladder(base, factors or DEFAULT_FACTORS)
    if not dts:
        raise scene_mod.SceneError(f"--factors: no time step of the ladder is below 0.9 of the stability limit "
                                   f"({0.9 * base.critical_dt():.3g} s)")
    out = Path(out)
    ref_key = (reference, "exact", min(dts))
    keys = [ref_key] + [(e, m, dt) for e in dict.fromkeys([reference, *engines]) for m in timings for dt in dts
                        if (e, m, dt) != ref_key
                        and (e == reference or engine_min_factor is None or dt >= base.dt * engine_min_factor * 0.999)]
    # The ladder's coarse steps are chosen to show what the time step costs: their runs' warnings
    # (the stick phase under-resolved, an impact on too few steps) are the effect measured, so
    # they stay in each run's summary and the CSV's `warnings` column, not on the console.
    tasks = [runner.task(scene_name, eng, out / "runs" / eng / timing / f"dt_{dt:.3e}", warn=False, dt=dt,
                         slip_timing=timing, duration=kind.PRECISION_DURATION) for eng, timing, dt in keys]

    def finish(results):
        runs = {}
        for key, got in zip(keys, results):
            if isinstance(got, Exception):
                if key == ref_key:
                    raise got
                print(f"stickslip: precision: {key[0]} ({key[1]}) at dt={key[2]:g} failed: {got}")
                continue
            runs[key] = got
        return _finish(base, kind, runs, ref_key, out)

    return tasks, finish


def _finish(base, kind, runs, ref_key, out):
    _, ref_summary, ref_df = runs[ref_key]
    rows = []
    for (eng, timing, dt), (sc, s, df) in sorted(runs.items(), key=lambda kv: (kv[0][0], kv[0][1], -kv[0][2])):
        is_ref = (eng, timing, dt) == ref_key
        m = kind.errors(sc, s, df, ref_summary, ref_df)
        rows.append({"engine": eng, "slip_timing": timing, "dt_s": dt, "wall_time_s": s["wall_time_s"],
                     "steps": s["steps"], "reference": is_ref, "warnings": len(s.get("notes", [])),
                     **{f"err_{k}": (math.nan if is_ref else v) for k, v in m.items()}})
    csv_path = out / f"precision_{base.name}.csv"
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    orders = _plots(base.name, rows, out, ref_key)
    kind.precision_figures(out, {k: v for k, v in runs.items() if k[0] == ref_key[0]})
    return csv_path, orders


def convergence_order(dts, errs):
    """Slope of log(error) against log(dt) over the finite, non-zero errors."""
    pts = [(math.log(d), math.log(e)) for d, e in zip(dts, errs) if e and math.isfinite(e) and e > 0]
    if len(pts) < 3:
        return math.nan
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def _plots(name, rows, out, ref_key):
    plt = plotstyle.pyplot()
    keys = [k for k in rows[0] if k.startswith("err_")]
    reference, _, dt_ref = ref_key
    orders = {}
    fig1, ax1 = plt.subplots(figsize=(7, 4.8))
    fig2, ax2 = plt.subplots(figsize=(7, 4.8))
    colors = {}
    for (eng, timing) in sorted({(r["engine"], r["slip_timing"]) for r in rows}):
        color = colors.setdefault(eng, f"C{len(colors)}")
        rr = [r for r in rows if r["engine"] == eng and r["slip_timing"] == timing and not r["reference"]]
        for k, mark in zip(keys, "os^"):
            dts = [r["dt_s"] for r in rr]
            # An error of exactly 0 has no place on a log axis: left out of the plot, kept in the CSV.
            errs = [r[k] if r[k] and r[k] > 0 else math.nan for r in rr]
            # The order is fitted above the reference's step (at it, the error of the same
            # engine's other mode, or another engine's, is not a discretisation error).
            above = [(d, e) for d, e in zip(dts, errs) if d > dt_ref * (1 + 1e-9)]
            p = convergence_order(*zip(*above)) if above else math.nan
            orders[(eng, timing, k[4:])] = p
            style = dict(color=color, ls=TIMING_LINES[timing], marker=mark)
            ax1.loglog([r["wall_time_s"] for r in rr], errs, **style, label=f"{plotstyle.label(eng, timing)}: {k[4:]}")
            ax2.loglog(dts, errs, **style, label=f"{plotstyle.label(eng, timing)}: {k[4:]} (order {p:.2f})")
    what = f"relative error vs {reference} exact timing at dt = {dt_ref:.3g} s"
    ax1.set_xlabel("wall time (s)")
    ax1.set_ylabel(what, fontsize=8)
    ax1.set_title(f"{name}: work-precision (dashed: step timing, solid: exact)")
    ax2.set_xlabel("time step dt (s)")
    ax2.set_ylabel(what, fontsize=8)
    ax2.set_title(f"{name}: error vs dt (dashed: step timing, solid: exact)")
    for ax in (ax1, ax2):
        ax.legend(fontsize=7)
    plotstyle.save(fig1, out, f"precision_{name}_work.png", dpi=110)
    plotstyle.save(fig2, out, f"precision_{name}_dt.png", dpi=110)
    return orders


def warned(csv_path):
    """(runs that warned, runs) of a ladder's CSV."""
    rows = list(csv.DictReader(open(csv_path)))
    return sum(int(r["warnings"]) > 0 for r in rows), len(rows)


def warned_line(csv_path):
    """One line on the ladder's warnings, for the report and `stickslip precision`."""
    n, m = warned(csv_path)
    return (f"{n} of the ladder's {m} runs warn (column `warnings` of {Path(csv_path).name}; each run's text in its "
            "summary.json): at its coarse steps the step timing under-resolves the stick phase, or an impact spans "
            "fewer steps than an accurate collision needs: those steps are chosen on purpose, to show what the time "
            "step costs." if n else f"None of the ladder's {m} runs warns.")
