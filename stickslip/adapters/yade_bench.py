"""YADE rows for `stickslip bench`: yade_law/bench_yade_law.py run in `yade -n -x`."""
from __future__ import annotations

import json
import subprocess

from .yade import RUNNER


def benchmark(reps=3):
    """Rows for `stickslip bench`: yade_law/bench_yade_law.py (>= 20 000 contacts), the
    Python law's cost per contact-step against the native frictional law, same run."""
    rows = []
    for rotation in (True, False):
        args = ["yade", "-n", "-x", str(RUNNER.parent / "bench_yade_law.py"), "--reps", str(reps)]
        if not rotation:
            args.append("--no-rotation")
        p = subprocess.run(args, capture_output=True, text=True, timeout=3600, cwd=RUNNER.parent)
        got = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
        if p.returncode != 0 or not got:
            raise RuntimeError(f"yade benchmark failed (exit {p.returncode}): {p.stderr.strip()[-300:]}")
        r = json.loads(got[-1][7:])
        rot = "rotation on" if rotation else "rotation off"
        for case, key in (("stick-slip law (PyRunner), us per contact-step", "law_us"),
                          ("native InteractionLoop (Ig2 + frictional Law2), us per contact-step", "native_loop_us"),
                          ("ratio law / native InteractionLoop", "ratio"),
                          ("whole step, native frictional, us per contact-step", "step_native_us"),
                          ("whole step, stick-slip, us per contact-step", "step_stickslip_us")):
            rows.append({"benchmark": "yade", "case": f"{case} ({rot})", "contacts": r["contacts"],
                         "value": r[key]})
    return rows
