# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost of the stick-slip law, compiled and in Python, against YADE's native frictional law,
measured side by side in one run.

    build/yade_law/yade-stickslip -n -x bench_yade_law.py [--n 20] [--steps 30] [--reps 5]
        [--no-rotation] [--shake V] [--slip-timing step|exact] [--kinds native,compiled,python,normal]

Builds an n x n x n cubic lattice of overlapping spheres (3 n^2 (n-1) contacts,
22 800 for n = 20) with small random velocities (up to --shake m/s; the default 1e-3
keeps every contact; 0.05 opens and closes contacts during the run), then, several
times over and interleaved (so that a busy machine slows them all alike):
  native: ViscElMat with ks > 0 and friction, Law2_ScGeom_ViscElPhys_Basic;
  compiled: the compiled law (yade_law/compiled/; YADE started through its launcher);
  python: the native normal force + the PyRunner law (yade_law/stickslip_yade/);
  normal: YADE's ViscEl law without the PyRunner (ks = 0, no friction), to isolate the
  Python law's own cost (python - normal).
The whole step is timed in CPU time of the thread running it (time.thread_time around
O.step: the figure a user feels, less the time other processes took the core). YADE's own
engine timers (O.timingEnabled, wall time) are printed too. Medians over the repetitions,
and each ratio's spread over them (its smallest and largest); figures per contact per step.
"""
import argparse
import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.environ.get("STICKSLIP_YADE_LAW", os.path.dirname(os.path.abspath(sys.argv[0]))))

import numpy as np  # noqa: E402
from stickslip_yade import stickslip_engines, stickslip_material  # noqa: E402
from yade import (O, Bo1_Sphere_Aabb, ForceResetter, Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider,  # noqa: E402
                  InteractionLoop, Ip2_ViscElMat_ViscElMat_ViscElPhys, Law2_ScGeom_ViscElPhys_Basic,
                  NewtonIntegrator, ViscElMat, Vector3, utils)

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=20)
ap.add_argument("--steps", type=int, default=30)
ap.add_argument("--reps", type=int, default=5)
ap.add_argument("--no-rotation", action="store_true")
ap.add_argument("--shake", type=float, default=1e-3)
ap.add_argument("--slip-timing", default="step", choices=("step", "exact"))
ap.add_argument("--kinds", default="native,compiled,python,normal",
                help="which to run, of native, compiled, python, normal (compiled needs the launcher)")
ap.add_argument("--callgrind", action="store_true",
                help="run ./callgrind_on.sh before the timed steps (under callgrind's --instr-atstart=no: only "
                     "those steps are counted; stickslip/bench/yade.py)")
args = ap.parse_args(sys.argv[1:])

R, KN, KS, NU_N, NU_S, RHO = 1e-3, 1e5, 8e4, 0.0, 0.0, 2600.0
ROT = not args.no_rotation
KINDS = tuple(args.kinds.split(","))
if set(KINDS) - {"native", "compiled", "python", "normal"}:
    ap.error(f"--kinds {args.kinds}: each must be one of native, compiled, python, normal")


def build(kind):
    O.reset()
    if kind == "native":  # ks, friction angle atan(mu_s): the classic elastic-plastic spring
        mat = ViscElMat(kn=2 * KN, cn=2 * NU_N, ks=2 * KS, cs=2 * NU_S, frictionAngle=np.arctan(0.5), density=RHO)
    else:
        mat = stickslip_material(KN, NU_N, density=RHO)
    O.materials.append(mat)
    rng = np.random.default_rng(1)
    d = 2 * R * 0.999  # 0.1 % overlap: every lattice neighbour touches
    for i in range(args.n):
        for j in range(args.n):
            for k in range(args.n):
                b = utils.sphere((i * d, j * d, k * d), R, material=mat)
                b.state.vel = Vector3(*rng.uniform(-args.shake, args.shake, 3))
                if not ROT:
                    b.state.blockedDOFs = "XYZ"
                O.bodies.append(b)
    if kind in ("compiled", "python"):
        O.engines = stickslip_engines(ks=KS, nu_s=NU_S, mu_s=0.5, mu_k=0.45, rotation=ROT, slip_timing=args.slip_timing,
                                      backend="cpp" if kind == "compiled" else "python")
    else:
        O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
                     InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
                                     [Law2_ScGeom_ViscElPhys_Basic()]),
                     NewtonIntegrator(damping=0.0)]
    O.dt = 1e-6
    O.step()  # contacts are made (and the law's per-contact kn, cn read) here
    O.step()
    O.timingEnabled = True


def measure():
    for e in O.engines:
        e.execTime = 0
    n0 = O.interactions.countReal()
    cpu, wall = 0.0, 0.0
    for _ in range(args.steps):
        c0, w0 = time.thread_time(), time.perf_counter()
        O.step()
        cpu += time.thread_time() - c0
        wall += time.perf_counter() - w0
    n = (n0 + O.interactions.countReal()) / 2 * args.steps  # contact-steps
    t = {type(e).__name__: e.execTime * 1e-9 / n * 1e6 for e in O.engines}  # execTime is in ns
    t["cpu"], t["wall"] = cpu / n * 1e6, wall / n * 1e6
    return n0, t


res = {k: [] for k in KINDS}
contacts, full_reads = {}, []
for rep in range(args.reps):
    for kind in (KINDS if rep % 2 == 0 else KINDS[::-1]):  # (the order alternates: no side always goes first)
        build(kind)
        if args.callgrind:
            os.system("./callgrind_on.sh")
        contacts[kind], t = measure()
        res[kind].append(t)
        if kind == "python":
            full_reads.append(stickslip_law.full_reads - 1)  # noqa: F821 -- the first step reads all


def med(kind, name):
    return statistics.median(r.get(name, 0.0) for r in res[kind])


def ratio(kind):
    """The whole step of `kind` against the native law's: the median of the repetitions'
    ratios, and their smallest and largest (each repetition measures both back to back)."""
    r = [a["cpu"] / b["cpu"] for a, b in zip(res[kind], res["native"])]
    return statistics.median(r), min(r), max(r)


out = {"contacts": contacts, "rotation": ROT, "reps": args.reps, "shake": args.shake, "slip_timing": args.slip_timing,
       "steps": args.steps, "rounds": {kind: [r["cpu"] for r in res[kind]] for kind in KINDS}}
print(f"contacts: {contacts}; {args.steps} steps x {args.reps} repetitions, rotation {'on' if ROT else 'off'}, "
      f"velocities up to {args.shake:g} m/s, slip timing {args.slip_timing}")
print("median cost per contact per step (us, CPU time of the stepping thread):")
for kind in KINDS:
    out[f"step_{kind}_us"] = med(kind, "cpu")
    out[f"wall_step_{kind}_us"] = med(kind, "wall")
    line = f"  whole step, {kind:9s} {med(kind, 'cpu'):8.3f}"
    if kind != "native" and "native" in KINDS:
        m, lo, hi = ratio(kind)
        out[f"ratio_{kind}"], out[f"ratio_{kind}_range"] = m, [lo, hi]
        line += f"   {m:6.3f} x native ({lo:.3f}-{hi:.3f})"
    print(line)
if "python" in KINDS and "normal" in KINDS:
    out["python_law_us"] = med("python", "cpu") - med("normal", "cpu")
    out["full_reads"] = max(full_reads)
    print(f"  the Python law alone (python - normal) {out['python_law_us']:8.3f}; full reads of the interaction set "
          f"in the timed steps: {max(full_reads)}")
if "compiled" in KINDS and "native" in KINDS:
    print(f"  (YADE timers, wall: InteractionLoop native {med('native', 'InteractionLoop'):.3f}, "
          f"compiled {med('compiled', 'InteractionLoop'):.3f})")
print("RESULT " + json.dumps(out))
