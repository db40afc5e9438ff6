"""Cost of the Python stick-slip law against YADE's native frictional law, same run.

    yade -n -x bench_yade_law.py [--n 20] [--steps 30] [--reps 5] [--no-rotation]

Builds an n x n x n cubic lattice of overlapping spheres (3 n^2 (n-1) contacts,
22 800 for n = 20) with small random velocities, then, several times over:
  A. native: ViscElMat with ks > 0 and friction, Law2_ScGeom_ViscElPhys_Basic;
  B. stick-slip: native normal force + the PyRunner law (stickslip_yade.py).
Times come from YADE's own engine timers (O.timingEnabled): the law's cost is the
PyRunner's time; the native law's cost cannot be timed apart from the geometry
(InteractionLoop refuses to run without a Law2), so the InteractionLoop time is
printed as the native figure (an upper bound: it also contains Ig2 geometry).
Whole-step costs of both runs are printed too. Medians over the repetitions.
"""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.environ.get("STICKSLIP_YADE_LAW", os.path.dirname(os.path.abspath(sys.argv[0]))))

import numpy as np  # noqa: E402
from stickslip_yade import stickslip_engines, stickslip_material  # noqa: E402
from yade import (O, Bo1_Sphere_Aabb, ForceResetter, Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider,  # noqa: E402
                  InteractionLoop, Ip2_ViscElMat_ViscElMat_ViscElPhys, Law2_ScGeom_ViscElPhys_Basic,
                  NewtonIntegrator, PyRunner, ViscElMat, Vector3, utils)

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=20)
ap.add_argument("--steps", type=int, default=30)
ap.add_argument("--reps", type=int, default=5)
ap.add_argument("--no-rotation", action="store_true")
args = ap.parse_args(sys.argv[1:])

R, KN, KS, NU_N, NU_S, RHO = 1e-3, 1e5, 8e4, 0.0, 0.0, 2600.0
ROT = not args.no_rotation


def build(native):
    O.reset()
    if native:  # ks, friction angle atan(mu_s): the classic elastic-plastic spring
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
                b.state.vel = Vector3(*rng.uniform(-1e-3, 1e-3, 3))
                if not ROT:
                    b.state.blockedDOFs = "XYZ"
                O.bodies.append(b)
    if native:
        O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
                     InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
                                     [Law2_ScGeom_ViscElPhys_Basic()]),
                     NewtonIntegrator(damping=0.0)]
    else:
        O.engines = stickslip_engines(ks=KS, nu_s=NU_S, mu_s=0.5, mu_k=0.45, rotation=ROT)
    O.dt = 1e-6
    O.step()  # contacts are made (and the law's per-contact kn, cn read) here
    O.timingEnabled = True


def measure():
    for e in O.engines:
        e.execTime = 0
    n0 = O.interactions.countReal()
    for _ in range(args.steps):
        O.step()
    n = (n0 + O.interactions.countReal()) / 2 * args.steps  # contact-steps
    t = {type(e).__name__: e.execTime * 1e-9 / n * 1e6 for e in O.engines}  # execTime is in ns
    t["step"] = sum(t.values())
    return n0, t


res = {"native": [], "stickslip": []}
contacts = {}
for rep in range(args.reps):
    for which in ("native", "stickslip"):
        build(which == "native")
        contacts[which], t = measure()
        res[which].append(t)


def med(which, name):
    return statistics.median(r[name] for r in res[which])


law = med("stickslip", "PyRunner")
native_loop = med("native", "InteractionLoop")
print(f"contacts: native {contacts['native']}, stick-slip {contacts['stickslip']}; "
      f"{args.steps} steps x {args.reps} repetitions, rotation {'on' if ROT else 'off'}")
print("median cost per contact per step (us):")
print(f"  stick-slip law (PyRunner)                 {law:8.3f}")
print(f"  native InteractionLoop (geometry + Law2)  {native_loop:8.3f}")
print(f"  ratio law / native                        {law / native_loop:8.1f}")
print(f"  whole step, native frictional             {med('native', 'step'):8.3f}")
print(f"  whole step, stick-slip                    {med('stickslip', 'step'):8.3f}")
print("RESULT " + json.dumps({"contacts": contacts["stickslip"], "rotation": ROT, "reps": args.reps,
                             "law_us": law, "native_loop_us": native_loop, "ratio": law / native_loop,
                             "step_native_us": med("native", "step"), "step_stickslip_us": med("stickslip", "step")}))
