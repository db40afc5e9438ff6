# SPDX-License-Identifier: GPL-2.0-or-later
"""YADE rows for `stickslip bench`: yade_law/bench_yade_law.py run in `yade -n -x`, and the
per-step cost of a two-grain scene through the runner (what `report` pays)."""
from __future__ import annotations

import json
import os
import subprocess
import tempfile
from pathlib import Path

from ..adapters.yade import RUNNER, scene_dict


def _bench(args):
    p = subprocess.run(["yade", "-n", "-x", str(RUNNER.parent / "bench_yade_law.py"), *args], capture_output=True,
                       text=True, timeout=3600, cwd=RUNNER.parent)
    got = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    if p.returncode != 0 or not got:
        raise RuntimeError(f"yade benchmark failed (exit {p.returncode}): {p.stderr.strip()[-300:]}")
    return json.loads(got[-1][7:])


def small_scene_us_per_step(steps=10000):
    """Wall time per step of run_scene.py on the drag scene (one grain on a floor, a row
    per step), as `stickslip report` runs its two-grain scenes."""
    from .. import scene as scene_mod

    sc = scene_mod.load("drag", duration=steps * 2e-6)
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "scene.json").write_text(json.dumps(scene_dict(sc)))
        p = subprocess.run(["yade", "-n", "-x", str(RUNNER), "scene.json", "out.csv"], capture_output=True, text=True,
                           timeout=600, cwd=tmp, env=dict(os.environ, STICKSLIP_YADE_LAW=str(RUNNER.parent)))
    wall = [float(x.split()[1]) for x in p.stdout.splitlines() if x.startswith("WALLTIME")]
    if p.returncode != 0 or not wall:
        raise RuntimeError(f"yade run_scene failed (exit {p.returncode}): {p.stdout.strip()[-300:]}")
    return wall[0] / sc.steps * 1e6


def benchmark(reps=3):
    """Rows for `stickslip bench`: yade_law/bench_yade_law.py (>= 20 000 contacts): the whole
    step with the Python law against YADE's native frictional law, measured side by side in
    one run (CPU time of the stepping thread), with contacts kept and with contacts opening
    and closing; and the two-grain per-step cost."""
    rows = []
    for rotation, shake, timing in ((True, 1e-3, "step"), (False, 1e-3, "step"), (True, 0.2, "step"),
                                    (True, 1e-3, "exact")):
        args = ["--reps", str(reps), "--shake", str(shake), "--slip-timing", timing]
        args += [] if rotation else ["--no-rotation"]
        if shake > 1e-3:
            args += ["--steps", "60"]
        r = _bench(args)
        what = ("rotation on" if rotation else "rotation off") + (
            "" if shake <= 1e-3 else f", velocities up to {shake:g} m/s: contacts open and close") + (
            ", slip_timing exact" if timing == "exact" else "")
        for case, key in (("whole step, native frictional law, us per contact-step", "step_native_us"),
                          ("whole step, stick-slip law, us per contact-step", "step_stickslip_us"),
                          ("ratio stick-slip / native, whole step", "ratio_step"),
                          ("stick-slip law alone (step - normal-only step), us per contact-step", "law_us")):
            rows.append({"benchmark": "yade", "case": f"{case} ({what})", "contacts": r["contacts"], "value": r[key]})
    rows.append({"benchmark": "yade", "case": "two-grain drag scene through run_scene.py, us per step",
                 "contacts": 1, "value": small_scene_us_per_step()})
    return rows
