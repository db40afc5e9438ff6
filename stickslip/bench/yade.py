# SPDX-License-Identifier: GPL-2.0-or-later
"""YADE: the stick-slip law's whole step, compiled and in Python, against YADE's native
frictional law, measured side by side in one run (yade_law/bench_yade_law.py), with
callgrind's instruction counts beside the times.

    python -m stickslip.bench.yade [--rounds 7] [--steps 30] [--n 20] [--callgrind-steps 5] [--no-callgrind]

Times: each round builds the n x n x n lattice (22 800 contacts for n = 20) once per law and
times the whole step in CPU time of the stepping thread, the laws one after the other in an
order that alternates from round to round; each ratio is the geometric mean of the rounds'
ratios with its 95 % interval (ratio_interval.py). Counts: the same scene under callgrind,
counting only YADE's step (`Scene::moveToNextTimeStep`) over the last steps, one process per
law; a count does not move with the machine's load. About 4 min on 2 cores with the defaults.
Also the rows of `stickslip bench` (benchmark()).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from . import callgrind
from .ratio_interval import ratio_interval
from ..adapters.yade import RUNNER, scene_dict
from ..adapters.yade_cpp import LAUNCHER

BENCH = RUNNER.parent / "bench_yade_law.py"
STEP = "yade::Scene::moveToNextTimeStep()"  # YADE's whole step


def _bench(args, launcher=LAUNCHER, cwd=None):
    p = subprocess.run([str(launcher), "-n", "-x", str(BENCH), *args], capture_output=True, text=True, timeout=3600,
                       cwd=cwd or RUNNER.parent)
    got = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    if p.returncode != 0 or not got:
        raise RuntimeError(f"yade benchmark failed (exit {p.returncode}): {(p.stdout + p.stderr).strip()[-400:]}")
    return json.loads(got[-1][7:])


def timed(rounds, steps, n, timing="step", rotation=True, shake=1e-3, kinds=("native", "compiled", "python")):
    """{kind: (µs per contact-step, median), ratio to native (geometric mean, low, high)}."""
    args = ["--reps", str(rounds), "--steps", str(steps), "--n", str(n), "--slip-timing", timing, "--shake", str(shake),
            "--kinds", ",".join(kinds)] + ([] if rotation else ["--no-rotation"])
    r = _bench(args)
    out = {"contacts": r["contacts"]["native"]}
    for kind in kinds:
        out[kind] = r[f"step_{kind}_us"]
        if kind != "native":
            out[f"{kind}/native"] = ratio_interval(list(zip(r["rounds"]["native"], r["rounds"][kind])))
    return out


def counted(steps, n, timing="step", kinds=("native", "compiled")):
    """{kind: instructions per contact-step of YADE's whole step}, from callgrind."""
    out = {}
    # YADE itself under callgrind, from the compiled law's prefix (the launcher would start it
    # through a shell); the launcher's layout check first, as the launcher would run it
    subprocess.run([str(LAUNCHER), "-n", "-x", "/dev/null"], check=True, capture_output=True, timeout=600)
    for kind in kinds:
        with tempfile.TemporaryDirectory(prefix="yade-callgrind-") as tmp:
            cmd = ["yade", "-n", "-x", str(BENCH), "--reps", "1", "--steps", str(steps), "--n", str(n),
                   "--slip-timing", timing, "--kinds", kind, "--callgrind"]
            env = dict(os.environ, OMP_NUM_THREADS="1", YADE_PREFIX=str(LAUNCHER.parent / "prefix"))
            profiles = callgrind.count(cmd, tmp, function=STEP, env=env, on_request=True)
            got = [x for x in (Path(tmp) / "callgrind.txt").read_text().splitlines() if x.startswith("RESULT ")]
            contacts = json.loads(got[-1][7:])["contacts"][kind]
            out[kind] = sum(callgrind.total(p) for p in profiles) / (contacts * steps)
    return out


def small_scene_us_per_step(steps=10000, backend="python"):
    """Wall time per step of run_scene.py on the drag scene (one grain on a floor, a row
    per step), as `stickslip report` runs its two-grain scenes."""
    from .. import scene as scene_mod

    sc = scene_mod.load("drag", duration=steps * 2e-6)
    launcher = LAUNCHER if backend == "cpp" else "yade"
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "scene.json").write_text(json.dumps(dict(scene_dict(sc), backend=backend)))
        p = subprocess.run([str(launcher), "-n", "-x", str(RUNNER), "scene.json", "out.csv"], capture_output=True,
                           text=True, timeout=600, cwd=tmp,
                           env=dict(os.environ, STICKSLIP_YADE_LAW=str(RUNNER.parent)))
    wall = [float(x.split()[1]) for x in p.stdout.splitlines() if x.startswith("WALLTIME")]
    if p.returncode != 0 or not wall:
        raise RuntimeError(f"yade run_scene failed (exit {p.returncode}): {p.stdout.strip()[-300:]}")
    return wall[0] / sc.steps * 1e6


def benchmark(reps=3):
    """Rows for `stickslip bench`: the whole step of the compiled and the Python law against
    YADE's native frictional law (>= 20 000 contacts, side by side in one run), with contacts
    kept and with contacts opening and closing, both timings; and the two-grain per-step cost."""
    rows = []
    for rotation, shake, timing in ((True, 1e-3, "step"), (False, 1e-3, "step"), (True, 0.2, "step"),
                                    (True, 1e-3, "exact")):
        r = timed(reps, 60 if shake > 1e-3 else 30, 20, timing, rotation, shake)
        what = ("rotation on" if rotation else "rotation off") + (
            "" if shake <= 1e-3 else f", velocities up to {shake:g} m/s: contacts open and close") + (
            ", slip_timing exact" if timing == "exact" else "")
        for case, value in (("whole step, native frictional law, us per contact-step", r["native"]),
                            ("whole step, compiled stick-slip law, us per contact-step", r["compiled"]),
                            ("whole step, Python stick-slip law, us per contact-step", r["python"]),
                            ("ratio compiled / native, whole step", r["compiled/native"][0]),
                            ("ratio Python / native, whole step", r["python/native"][0])):
            rows.append({"benchmark": "yade", "case": f"{case} ({what})", "contacts": r["contacts"], "value": value})
    for backend in ("cpp", "python"):
        rows.append({"benchmark": "yade", "case": f"two-grain drag scene through run_scene.py ({backend} law), us per step",
                     "contacts": 1, "value": small_scene_us_per_step(backend=backend)})
    return rows


def _ratio(r):
    m, lo, hi = r
    return f"{m:.3f} ({lo:.3f}-{hi:.3f})"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds of the timed part")
    ap.add_argument("--steps", type=int, default=30, help="timed steps per law and round")
    ap.add_argument("--n", type=int, default=20, help="the lattice's side: 3 n^2 (n - 1) contacts")
    ap.add_argument("--callgrind-steps", type=int, default=5, help="steps counted by callgrind per law")
    ap.add_argument("--no-callgrind", action="store_true", help="times only")
    a = ap.parse_args(argv)
    if not LAUNCHER.is_file():
        print(f"bench.yade: {LAUNCHER} missing: ./run.sh setup builds the compiled YADE law", file=sys.stderr)
        return 2
    print(f"YADE, {3 * a.n * a.n * (a.n - 1)} contacts, whole step per contact-step; ratio to YADE's native frictional "
          f"law (Law2_ScGeom_ViscElPhys_Basic): geometric mean of {a.rounds} rounds (95 % interval); callgrind: "
          f"instructions over {a.callgrind_steps} steps", flush=True)
    print(f"{'law':26s} {'us':>7s} {'ratio (time)':>22s} {'instr.':>8s} {'ratio (instr.)':>14s}")
    for timing in ("step", "exact"):
        kinds = ("native", "compiled", "python")
        t = timed(a.rounds, a.steps, a.n, timing, kinds=kinds)
        c = {} if a.no_callgrind or not callgrind.available() else counted(a.callgrind_steps, a.n, timing)
        for kind in kinds:
            name = f"{kind} ({timing} timing)" if kind != "native" else "native"
            if kind == "native" and timing == "exact":
                continue
            cols = [f"{t[kind]:7.3f}", f"{_ratio(t[f'{kind}/native']) if kind != 'native' else '1':>22s}"]
            if kind in c:
                cols += [f"{c[kind]:8.0f}", f"{c[kind] / c['native']:14.4f}"]
            print(f"{name:26s} " + " ".join(cols), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
