# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip bench`: performance figures, measured side by side in one run, into
bench.csv and bench.md.

Every figure is a median over repetitions; ratios compare runs made in the same process, one
after the other (LIGGGHTS' overhead: interleaved rounds, a geometric mean of the rounds'
ratios with its 95 % interval, and callgrind's instruction counts). pyref's rows come from
stickslip/bench/pyref.py; an engine with a module `stickslip/bench/<engine>.py` providing
`benchmark(reps)` adds its own rows (LIGGGHTS plugin overhead and MPI speed-up, LAMMPS', YADE
law cost per contact-step); `--report` adds the time of `stickslip report`.
"""
from __future__ import annotations

import csv
import importlib
import os
import time
from pathlib import Path

from .. import adapters
from .pyref import effect_rows, pyref_rows

REPORT_TARGET_S = 300  # issue 25: `./run.sh report` in at most 5 minutes on 2 cores


def report_rows():
    """`stickslip report` as the README runs it (every engine, every study), timed once,
    into a temporary folder: the wall time a user waits, and where the CPU time went
    (per part: a case or a study's ladder on one engine, friction_speed, thresholds).
    On a machine shared with other work the wall time grows, the CPU times much less."""
    import tempfile

    from .. import parallel
    from ..report import build_report

    log = []
    with tempfile.TemporaryDirectory(prefix="stickslip-report-") as tmp:
        t0 = time.perf_counter()
        build_report(Path(tmp), progress=True, cpu_log=log)
        wall = time.perf_counter() - t0
    rows = [{"benchmark": "report", "case": f"stickslip report, wall time s ({parallel.workers()} processes, "
                                            f"{os.cpu_count()} cores; target <= {REPORT_TARGET_S})", "value": wall},
            {"benchmark": "report", "case": "CPU s of all its runs", "value": sum(c for _, c in log)}]
    parts = {}
    for task, cpu in log:
        parts[_part(task)] = parts.get(_part(task), 0.0) + cpu
    rows += [{"benchmark": "report", "case": f"CPU s: {name}", "value": cpu}
             for name, cpu in sorted(parts.items(), key=lambda kv: -kv[1])]
    task, cpu = max(log, key=lambda tc: tc[1])
    rows.append({"benchmark": "report", "case": f"CPU s of its longest run ({_part(task)})", "value": cpu})
    return rows


def _part(task):
    """The part of the report a task belongs to: 'case tray on yade', 'ladder tilt on
    pyref', or the study's module (friction_speed, thresholds)."""
    from ..runner import run_named

    _, fn, args = task
    if fn is run_named:
        scene, engine, _, overrides = args[:4]
        return f"{'ladder' if 'dt' in overrides else 'case'} {scene} on {engine}"
    return fn.__module__.rsplit(".", 1)[-1]


def run_bench(out: Path, reps=3, engines=None, report=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = pyref_rows(reps) + effect_rows(reps)
    ok, missing = adapters.available()
    for eng in [e for e in ok if e != "pyref" and (engines is None or e in engines)]:
        try:
            engine_bench = importlib.import_module(f"stickslip.bench.{eng}")
        except ModuleNotFoundError:
            continue
        rows += engine_bench.benchmark(reps)
    if report:
        rows += report_rows()
    fields = ["benchmark", "case", "contacts", "seconds_per_step", "contact_steps_per_s", "ratio_to_all_on", "value",
              "ci_low", "ci_high"]
    with open(out / "bench.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    lines = ["# stickslip bench", "", f"Median of {reps} repetitions per figure; ratios measured in the same run "
             "(LIGGGHTS' overhead: interleaved rounds, with the 95 % interval of the ratio; see "
             "stickslip/bench/liggghts.py).", "",
             "| benchmark | case | contacts | s/step | contact-steps/s | ratio | value | 95 % low | 95 % high |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(k)) for k in fields) + " |")
    for e, why in missing.items():
        lines.append(f"\n{e}: not measured ({why})")
    if any(r["benchmark"] == "liggghts" for r in rows):
        from .liggghts import SCALING_NOTE
        lines += ["", SCALING_NOTE]
    (out / "bench.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return rows


def _fmt(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)
