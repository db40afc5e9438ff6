# SPDX-License-Identifier: GPL-2.0-or-later
"""The report's studies: what accuracy costs (precision.py), friction against sliding
speed (friction_speed.py), and the speed above which every step slips (thresholds.py).

`plan(out, cases, engines)` returns their runs as tasks for parallel.run_all and the
function that turns the results into the report's section (Markdown).
"""
from __future__ import annotations

import csv
import math

from . import friction_speed, precision, thresholds
from .. import scene as scene_mod

# The engines run each ladder from the scene's dt up (factors >= 1); the reference engine
# runs it all. Below the scene's dt an engine's error is the reference's (the engine tests
# hold them equal at equal dt: LIGGGHTS to round-off, YADE within its half-kick start
# difference), and its cost grows as 1/dt, which the coarser steps already show.
ENGINE_MIN_FACTOR = 1.0
# The reference: LIGGGHTS where it is installed (pyref's twin to round-off at equal steps,
# and it makes the finest steps of a one- or two-grain case in a second or two where pyref
# takes minutes: the tilt's and tray's ladders were 180 of the report's ~490 CPU s), else
# pyref.
REFERENCES = ("liggghts", "pyref")


def reference(engines):
    return next(e for e in REFERENCES if e in engines or e == "pyref")


def plan(out, cases, engines):
    ref = reference(engines)
    parts = [precision.plan(case, engines, out / "precision" / case, reference=ref,
                            engine_min_factor=ENGINE_MIN_FACTOR) for case in cases]
    parts.append(friction_speed.plan(out / "friction_speed"))
    parts.append(thresholds.plan(out / "thresholds"))
    tasks = [t for part_tasks, _ in parts for t in part_tasks]

    def finish(results):
        got, k = [], 0
        for part_tasks, fin in parts:
            got.append(fin(results[k:k + len(part_tasks)]))
            k += len(part_tasks)
        return _section(out, cases, got[: len(cases)], got[-2], got[-1], ref)

    return tasks, finish


def _section(out, cases, ladders, speed_rows, threshold_rows, ref):
    lines = ["", "## What accuracy costs in time", "",
             "Each case over a ladder of time steps, in both slip timings (dashed: `step`, the paper's; solid: "
             f"`exact`). Errors are measured against the exact-timing {ref} run at the finest step of the ladder, "
             "a converged answer ([docs/precision.md](../docs/precision.md) shows how far it is from the dt → 0 "
             f"limit); error measures per case in `stickslip/kinds/`. {ref} runs every step of the ladder; the "
             f"other engines run the scene's dt and the coarser ones (below it their errors are {ref}'s, which the "
             "test suite holds them to, and their cost scales as 1/dt).", ""]
    for case, (csv_path, orders) in zip(cases, ladders):
        d = out / "precision" / case
        rows = list(csv.DictReader(open(csv_path)))
        scene_dt = scene_mod.load(case).dt
        lines += [f"### {case}", "", f"Data: [{csv_path.name}](precision/{case}/{csv_path.name}). "
                  + precision.warned_line(csv_path), "",
                  "| engine | timing | measure | error at the scene's dt | fitted order |", "|---|---|---|---|---|"]
        for (eng, timing, measure), p in sorted(orders.items()):
            at = [r for r in rows if r["engine"] == eng and r["slip_timing"] == timing
                  and math.isclose(float(r["dt_s"]), scene_dt, rel_tol=1e-9)]
            err = float(at[0][f"err_{measure}"]) if at else math.nan
            lines.append(f"| {eng} | {timing} | {measure} | {err:.3g} | {p:.2f} |")
        lines += ["", f"![work-precision](precision/{case}/precision_{case}_work.png)",
                  f"![error vs dt](precision/{case}/precision_{case}_dt.png)", ""]
        standard = {f"precision_{case}_work.png", f"precision_{case}_dt.png"}
        for extra in sorted(p for p in d.glob("*.png") if p.name not in standard):  # the kind's own
            lines += [f"![{case}: {extra.stem}](precision/{case}/{extra.name})", ""]
    lines += ["## Friction against sliding speed", "",
              "Drag scene at imposed speeds over four decades, mean |Fs|/Fn over whole saw-tooth periods, at three "
              "time steps in each slip timing (pyref). With `step` timing the friction falls to 2μk−μs once every "
              "step slips, at a speed set by dt (dotted lines); with `exact` timing only the dashpot threshold "
              "remains (black). Largest difference between the time steps at one speed: "
              f"step {friction_speed.spread(speed_rows, 'step'):.3g}, exact "
              f"{friction_speed.spread(speed_rows, 'exact'):.3g}. "
              "Data: [friction_speed.csv](friction_speed/friction_speed.csv).", "",
              "![friction vs speed](friction_speed/friction_speed.png)", ""]
    worst = max(abs(r["rel_diff"]) for r in threshold_rows)
    lines += ["## Speed above which every step slips (step timing)", "",
              f"Measured (bisection, drag case) against V* = 2(μs−μk)Fn/(Ks·dt + νs) for {len(threshold_rows)} "
              f"pairs of dt and νs: largest difference {worst:.2%}. Data: [thresholds.csv](thresholds/thresholds.csv).",
              "", "![thresholds](thresholds/thresholds.png)", ""]
    return "\n".join(lines) + "\n"
