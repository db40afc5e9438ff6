"""The report's studies: what accuracy costs (precision.py), friction against sliding
speed (friction_speed.py), and the speed above which every step slips (thresholds.py)."""
from __future__ import annotations

import csv
import math

from .friction_speed import run_friction_speed, spread
from .precision import run_precision
from .thresholds import run_thresholds


def studies_section(out, cases, engines, progress):
    lines = ["", "## What accuracy costs in time", "",
             "Each case over a ladder of time steps on each engine, in both slip timings (dashed: `step`, the "
             "paper's; solid: `exact`). Errors are measured against the exact-timing pyref run at the finest step "
             "of the ladder, a converged answer (docs/precision.md shows how far it is from the dt -> 0 limit); "
             "error measures per case in `stickslip/kinds/`.", ""]
    for case in cases:
        d = out / "precision" / case
        d.mkdir(parents=True, exist_ok=True)
        csv_path, orders = run_precision(case, engines, d, progress=progress)
        rows = list(csv.DictReader(open(csv_path)))
        lines += [f"### {case}", "", f"Data: [{csv_path.name}](precision/{case}/{csv_path.name}).", "",
                  "| engine | timing | measure | error at the scene's dt | fitted order |", "|---|---|---|---|---|"]
        for (eng, timing, measure), p in sorted(orders.items()):
            at = [r for r in rows if r["engine"] == eng and r["slip_timing"] == timing
                  and math.isclose(float(r["dt_s"]), _scene_dt(case), rel_tol=1e-9)]
            err = float(at[0][f"err_{measure}"]) if at else math.nan
            lines.append(f"| {eng} | {timing} | {measure} | {err:.3g} | {p:.2f} |")
        lines += ["", f"![work-precision](precision/{case}/precision_{case}_work.png)",
                  f"![error vs dt](precision/{case}/precision_{case}_dt.png)", ""]
        standard = {f"precision_{case}_work.png", f"precision_{case}_dt.png"}
        for extra in sorted(p for p in d.glob("*.png") if p.name not in standard):  # the kind's own
            lines += [f"![{case}: {extra.stem}](precision/{case}/{extra.name})", ""]
    rows = run_friction_speed(out / "friction_speed")
    lines += ["## Friction against sliding speed", "",
              "Drag scene at imposed speeds over four decades, mean |Fs|/Fn over whole saw-tooth periods, at three "
              "time steps in each slip timing (pyref). With `step` timing the friction falls to (2μk−μs) once every "
              f"step slips, at a speed set by dt; with `exact` timing only the dashpot threshold remains. Largest "
              f"difference between the time steps at one speed: step {spread(rows, 'step'):.3g}, exact "
              f"{spread(rows, 'exact'):.3g}. Data: [friction_speed.csv](friction_speed/friction_speed.csv).", "",
              "![friction vs speed](friction_speed/friction_speed.png)", ""]
    rows = run_thresholds(out / "thresholds")
    worst = max(abs(r["rel_diff"]) for r in rows)
    lines += ["## Speed above which every step slips (step timing)", "",
              f"Measured (bisection, drag case) against V* = 2(μs−μk)Fn/(Ks·dt + νs) for {len(rows)} pairs of "
              f"dt and νs: largest difference {worst:.2%}. Data: [thresholds.csv](thresholds/thresholds.csv).", "",
              "![thresholds](thresholds/thresholds.png)", ""]
    return "\n".join(lines) + "\n"


def _scene_dt(case):
    from . import scene as scene_mod

    return scene_mod.load(case).dt
