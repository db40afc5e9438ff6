# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost of the Python stick-slip law against YADE's native frictional law, same run.

    yade -n -x bench_yade_law.py [--n 20] [--steps 30] [--reps 5] [--no-rotation] [--shake V]
                                 [--slip-timing step|exact]

Builds an n x n x n cubic lattice of overlapping spheres (3 n^2 (n-1) contacts,
22 800 for n = 20) with small random velocities (up to --shake m/s; the default 1e-3
keeps every contact; 0.05 opens and closes contacts during the run), then, several
times over and interleaved (so that a busy machine slows all three alike):
  A. native: ViscElMat with ks > 0 and friction, Law2_ScGeom_ViscElPhys_Basic;
  B. stick-slip: the native normal force + the PyRunner law (yade_law/stickslip_yade/);
  C. normal only: B without the PyRunner (ks = 0, no friction), to isolate the law.
The whole step is timed in CPU time of the thread running it (time.thread_time around
O.step: the figure a user feels, less the time other processes took the core); the law's
cost is B - C. YADE's own engine timers (O.timingEnabled, wall time) are printed too.
Medians over the repetitions; figures per contact per step.
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
args = ap.parse_args(sys.argv[1:])

R, KN, KS, NU_N, NU_S, RHO = 1e-3, 1e5, 8e4, 0.0, 0.0, 2600.0
ROT = not args.no_rotation
KINDS = ("native", "stickslip", "normal")


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
    if kind == "stickslip":
        timing = {} if args.slip_timing == "step" else {"slip_timing": args.slip_timing}  # (older laws: no option)
        O.engines = stickslip_engines(ks=KS, nu_s=NU_S, mu_s=0.5, mu_k=0.45, rotation=ROT, **timing)
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
    for kind in KINDS:
        build(kind)
        contacts[kind], t = measure()
        res[kind].append(t)
        if kind == "stickslip":
            full_reads.append(getattr(stickslip_law, "full_reads", 1) - 1)  # noqa: F821 -- the first step reads all


def med(kind, name):
    return statistics.median(r.get(name, 0.0) for r in res[kind])


native, law_step, normal = med("native", "cpu"), med("stickslip", "cpu"), med("normal", "cpu")
law = law_step - normal
print(f"contacts: native {contacts['native']}, stick-slip {contacts['stickslip']}; {args.steps} steps x "
      f"{args.reps} repetitions, rotation {'on' if ROT else 'off'}, velocities up to {args.shake:g} m/s, "
      f"slip timing {args.slip_timing}; "
      f"full reads of the interaction set in the timed steps: {max(full_reads)}")
print("median cost per contact per step (us, CPU time of the stepping thread):")
print(f"  whole step, native frictional             {native:8.3f}")
print(f"  whole step, stick-slip                    {law_step:8.3f}")
print(f"  ratio stick-slip / native, whole step     {law_step / native:8.2f}")
print(f"  whole step, normal law only (no friction) {normal:8.3f}")
print(f"  stick-slip law alone (difference)         {law:8.3f}")
print(f"  (YADE timers, wall: PyRunner {med('stickslip', 'PyRunner'):.3f}, native InteractionLoop "
      f"{med('native', 'InteractionLoop'):.3f}; wall whole step native {med('native', 'wall'):.3f}, "
      f"stick-slip {med('stickslip', 'wall'):.3f})")
print("RESULT " + json.dumps({"contacts": contacts["stickslip"], "rotation": ROT, "reps": args.reps, "shake": args.shake,
                             "slip_timing": args.slip_timing,
                             "step_native_us": native, "step_stickslip_us": law_step, "ratio_step": law_step / native,
                             "step_normal_us": normal, "law_us": law,
                             "wall_step_native_us": med("native", "wall"),
                             "wall_step_stickslip_us": med("stickslip", "wall"), "full_reads": max(full_reads)}))
