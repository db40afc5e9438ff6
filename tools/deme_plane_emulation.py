#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The paper's one-grain cases (drag, tilt) as DEM-Engine computes a grain on a plane, on
the CPU: what the engine's float geometry does to them, with and without the force model's
own distance in double (deme_model/stick_slip.cu, step 0).

    .venv/bin/python tools/deme_plane_emulation.py [drag|tilt ...] [--steps N] [--every N]

Each step does what DEM-Engine 3.0.19's sphere-plane force kernel does before the model
(DEMCalcForceKernels_Primitive.cu, DEMCollisionKernels_SphSph.cuh):
  - the plate's quaternion is the adapter's prescription (adapters/deme.turning_prescription)
    of the engine's time, which the engine hands it as float, cast to float, and turns the
    plane's normal in float (applyOriQToVector3): a normal 1 +- ~2e-7 long;
  - the plane's point is its owner plus the turned relative position (wall_placement);
  - the distance is dot(A - B, n) in double, returned as float (planeSignedDistance), and
    the overlap is the float radius less it; the contact point and lever arms follow;
then calls the force model through the CPU shim (stickslip/contract/deme_shim.py, the same .cu file) and
moves the grain by the engine's centred difference, v(t + dt/2) = v(t - dt/2) + dt a,
x += dt v(t + dt/2), spin held at zero. Positions are kept in double (the engine's grid,
box/2^38, is finer than anything here).

Two runs per case: "engine overlap" hands the model no positions, so it keeps overlapDepth
(as before step 0); "model distance" hands it A's centre, B's point and A's radius, as the
engine does. Each prints, beside pyref's double run of the same scene, what the GPU check
compares (tools/deme_gpu_check.py): Fn / (W cos beta) before the first slip, the first
slip, and the case's own figures. What it leaves out: the engine's float velocities and
forces outside the model, its contact detection, and its non-deterministic sums (one
contact: none). Cost: ~1 s per 10 000 steps and run; pyref's run beside it.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tools")]

F32 = np.float32


def plate_quaternion(scene, w, angle):
    """The prescribed quaternion (x, y, z, w) of a wall turned by angle, cast to float as the
    adapter's prescription does."""
    if w.rotation is None:
        return (F32(0), F32(0), F32(0), F32(1))
    a = np.asarray(w.rotation.axis, float)
    a = a / np.linalg.norm(a)
    s = math.sin(0.5 * angle)
    return (F32(a[0] * s), F32(a[1] * s), F32(a[2] * s), F32(math.cos(0.5 * angle)))


def conjugate(q):
    return (-q[0], -q[1], -q[2], q[3])


def emulate(scene, model_distance):
    """One run (see the module's text): a pyref-like Recording of the scene's output."""
    from stickslip.contract import deme_shim as shim
    from stickslip.adapters import deme as adapter

    g, w = scene.grains[0], scene.walls[0]
    assert len(scene.grains) == 1 and len(scene.walls) == 1, "one grain on one plane"
    c, eff = scene.contact, scene.effects
    p = c.law_params(eff)
    contact = shim.Contact(f"ss_hooke_{c.slip_timing}_{c.reset}")
    for name, value in (("kn", p.kn), ("ks", p.ks), ("nu_n", p.nu_n), ("nu_s", p.nu_s), ("mu", p.mu_s),
                        ("mu_k", p.mu_k)):
        contact.pairwise(name, 1, 1, value)
    dt, every = scene.dt, scene.output.every
    steps = scene.steps
    m = scene.grain_mass(g)
    radius = F32(g.radius)
    gravity = np.array(scene.gravity[:3], float) if eff["gravity"] else np.zeros(3)
    o = adapter.origin(scene)
    x = np.array(adapter.engine_position(scene, g), float)
    v = np.array(g.velocity, float)
    imposed = [i for i, axis in enumerate("xyz") if axis in g.imposed]
    owner, rel = (np.array(a, float) for a in adapter.wall_placement(scene, w))
    normal0 = np.array(w.normal, float)
    rot_steps = scene.rotation_steps(w) if w.rotation else 0
    rate = scene.rotation_rate(w) if w.rotation else 0.0
    axis = np.asarray(w.rotation.axis, float) / np.linalg.norm(w.rotation.axis) if w.rotation else np.zeros(3)

    rows = steps // every
    t = np.arange(rows + 1) * every * dt
    xs, vs = np.zeros((rows + 1, 1, scene.dimension)), np.zeros((rows + 1, 1, scene.dimension))
    fn, ft = np.zeros((rows + 1, 1)), np.zeros((rows + 1, 1, scene.dimension))
    slips = np.zeros((rows + 1, 1), int)
    angles = np.zeros((rows + 1, 1))
    xs[0, 0], vs[0, 0] = (x + o)[:scene.dimension], v[:scene.dimension]
    last = 0
    fdt = float(F32(dt))
    for k in range(steps):
        # the prescription's angle, rate min(t + dt, stop time), of the engine's time t at the
        # step before, a double sum of the float step passed to it as float
        t_engine = float(F32(max(k - 1, 0) * fdt))
        angle = rate * min(t_engine + dt, rot_steps * dt) if k >= 1 else 0.0
        q = plate_quaternion(scene, w, angle)
        n = shim.apply_ori_q(normal0, q)  # the plane's normal, float
        b_pos = owner + shim.apply_ori_q(rel, q).astype(float)
        dist = float(F32((x - b_pos) @ n.astype(float)))  # double dot, returned as float
        overlap = float(radius) - dist
        force = np.zeros(3)
        if overlap > 0:
            area = math.pi * (float(radius) ** 2 - dist * dist)
            cp = x - n.astype(float) * (dist + overlap / 2)
            cp_b = shim.apply_ori_q((cp - owner).astype(F32), conjugate(q))
            spin = rate * axis if 1 <= k <= rot_steps else np.zeros(3)
            kin = shim.kinematics(n, v, (0, 0, 0), (0, 0, 0), spin, cp - x, cp_b, dt, k * dt,
                                  shim.SPHERE_ANALYTICAL, masses=(m, 1.0),
                                  radius=radius if model_distance else 0.0)
            if model_distance:
                force = contact.step(overlap, area, kin, x, b_pos)
            else:  # no positions: the model's distance disagrees, it keeps overlapDepth
                force = contact.step(overlap, area, kin)
        else:
            contact.wc[:] = 0
        a = force / m + gravity
        v = v + dt * a
        for i in imposed:
            v[i] = g.velocity[i]
        if scene.dimension == 2:
            v[2] = 0.0
        x = x + dt * v
        if (k + 1) % every == 0:
            r = (k + 1) // every
            nf = n.astype(float)
            fn_k = float(force @ nf) if overlap > 0 else 0.0
            xs[r, 0], vs[r, 0] = (x + o)[:scene.dimension], v[:scene.dimension]
            fn[r, 0], ft[r, 0] = fn_k, (force - fn_k * nf)[:scene.dimension]
            count = int(contact.wc[3])
            slips[r, 0], last = (count - last if count >= last else count), count
            angles[r, 0] = adapter.wall_angle(scene, w, k + 1)
    return adapter._Recording(t, xs, vs, fn, ft, slips, angles)


def report(name, steps=None, log=print, every=None):
    """The three runs of one case and their figures: {label: {figure: value}}, read every
    `every` steps (None: the scene's rows; the GPU check reads the tilt every 50)."""
    from deme_fn_ring import fn_spread
    from pyref import Simulation
    from stickslip import analysis, columns
    from stickslip import scene as scene_mod

    sc = scene_mod.load(name)
    if steps is not None:
        sc.duration = steps * sc.dt
    if every is not None:
        sc.output.every = every
    out = {}
    for label, model_distance in (("engine overlap", False), ("model distance", True), ("pyref", None)):
        t0 = time.perf_counter()
        rec = Simulation(sc).run() if model_distance is None else emulate(sc, model_distance)
        df = columns.frame(sc, rec)
        figures = {k: v for k, v in analysis.summarise(sc, df).items() if isinstance(v, (int, float))}
        figures.update({f"fn_over_w_{k}": v for k, v in fn_spread(sc, df).items()})
        out[label] = figures
        log(f"{name}, {label}: {time.perf_counter() - t0:.1f} s")
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cases", nargs="*", default=["drag", "tilt"])
    ap.add_argument("--steps", type=int, default=None, help="run this many steps, not the scene's")
    ap.add_argument("--every", type=int, default=None,
                    help="read a row every N steps, not the scene's (the GPU check reads the tilt every 50)")
    args = ap.parse_args(argv)
    for name in args.cases:
        res = report(name, args.steps, log=lambda s: print(s, file=sys.stderr, flush=True), every=args.every)
        labels = list(res)
        keys = [k for k in res["pyref"] if all(k in res[lab] for lab in labels)]
        print(f"\n{name}: " + " | ".join(labels))
        for k in keys:
            print(f"  {k:28s} " + "  ".join(f"{res[lab][k]:>14.7g}" for lab in labels))


if __name__ == "__main__":
    main()
