# SPDX-License-Identifier: GPL-2.0-or-later
"""Run one stickslip scene in YADE: `yade -n -x run_scene.py scene.json out.csv`.

Knows only YADE and the scene dict written by stickslip/adapters/yade.py (masses are
already those of the scene: in 2D the disk's mass per unit thickness, carried by an
"equivalent sphere" moving in the xy-plane). Only the effects the scene switches on
are put in O.engines. Prints "PROGRESS done total" lines for the adapter.
"""
import csv
import json
import math
import os
import sys
import time

# Under `yade -x` __file__ is not this script; the adapter puts yade_law/ on PYTHONPATH.
sys.path.insert(0, os.environ.get("STICKSLIP_YADE_LAW", "."))

from stickslip_yade import stickslip_engines, stickslip_material, velocity_verlet_start  # noqa: E402
from yade import O, Quaternion, Vector3, utils  # noqa: E402

WALL_HALF_SIZE = 1.0  # m: walls are boxes this wide, ...
WALL_HALF_THICKNESS = 0.01  # ... and this thick, their face on the scene's plane


def quaternion_from_y(normal):
    """Rotation taking the box's +y face normal onto `normal`."""
    y = Vector3(0, 1, 0)
    n = Vector3(*normal)
    axis = y.cross(n)
    c = max(-1.0, min(1.0, y.dot(n)))
    if axis.norm() < 1e-12:
        return Quaternion(Vector3(1, 0, 0), 0.0 if c > 0 else math.pi)
    return Quaternion(axis / axis.norm(), math.acos(c))


def build(sc):
    c, eff = sc["contact"], sc["effects"]
    mat = O.materials.append(stickslip_material(c["kn"], c["nu_n"] if eff["normal_damping"] else 0.0))
    ids = {}
    for w in sc["walls"]:  # walls first: they become id1 of their interactions
        axis = [k for k, x in enumerate(w["normal"]) if x != 0]
        if len(axis) == 1 and not (eff["moving_walls"] and w.get("rotation")):
            # an axis-aligned plane that does not turn: YADE's Wall, whose overlap is the
            # sphere's radius less its distance to the plane, the arithmetic of pyref's walls
            # (a box's overlap passes through its centre: 1e-18 m of round-off, 5e-11 of Fn)
            b = utils.wall(w["point"][axis[0]], axis=axis[0], sense=1 if w["normal"][axis[0]] > 0 else -1,
                           material=mat)
        else:  # a box, which can turn
            n = Vector3(*w["normal"])
            center = Vector3(*w["point"]) - n * WALL_HALF_THICKNESS
            b = utils.box(center=center, extents=(WALL_HALF_SIZE, WALL_HALF_THICKNESS, WALL_HALF_SIZE),
                          orientation=quaternion_from_y(w["normal"]), fixed=True, material=mat)
        if eff["moving_walls"]:
            b.state.vel = Vector3(*w["velocity"])
        ids[w["name"]] = O.bodies.append(b)
    for g in sc["grains"]:
        b = utils.sphere(center=tuple(g["position"]), radius=g["radius"], material=mat)
        b.state.mass = g["mass"]
        b.state.inertia = Vector3(g["inertia"], g["inertia"], g["inertia"])
        blocked = "".join(g["imposed"])
        if g.get("fixed"):  # held where it starts, no velocity, no spin
            blocked += "xyzXYZ"
        if sc["dimension"] == 2:
            blocked += "zXY"  # motion in the xy-plane, rotation about z only
        if not eff["rotation"]:
            blocked += "XYZ" if sc["dimension"] == 3 else "Z"
        b.state.blockedDOFs = "".join(sorted(set(blocked), key=blocked.index))
        b.state.vel = Vector3(*g["velocity"])
        b.state.angVel = Vector3(*g["angular_velocity"])
        ids[g["name"]] = O.bodies.append(b)
    turning = [(O.bodies[ids[w["name"]]], w) for w in sc["walls"] if eff["moving_walls"] and w.get("rotation")]
    O.engines = stickslip_engines(ks=c["ks"], nu_s=c["nu_s"] if eff["tangential_damping"] else 0.0,
                                  mu_s=c["mu_s"], mu_k=c["mu_k"], reset=c["reset"], slip_timing=c["slip_timing"],
                                  gravity=sc["gravity"] if eff["gravity"] else (0.0, 0.0, 0.0),
                                  rotation=eff["rotation"], backend=sc.get("backend", "python"))
    O.dt = sc["dt"]
    return ids, [TurningWall(b, w, sc["dt"]) for b, w in turning]


class TurningWall:
    """A wall turned about its pivot as pyref turns it (Scene.rotation_rate, rotation_steps):
    before YADE's iteration k its box is put at angle theta_k = rate dt min(k, n) exactly, with
    the rigid velocity field of the step that brought it there (rate for 1 <= k <= n, else 0;
    the forces of step k see that motion). YADE's RotationEngine would instead give the box's
    centre the chord velocity of its next step, whose centripetal part, omega^2 dt/2 times the
    centre's distance to the pivot (1e-8 m/s for the tilt's plate), the contact's dashpot reads
    as the plate pressing on the grain."""

    def __init__(self, body, wall, dt):
        r = wall["rotation"]
        self.body, self.dt, self.rate, self.steps = body, dt, r["rate"], r["steps"]
        self.pivot, self.axis = Vector3(*r["pivot"]), Vector3(*r["axis"])
        self.velocity = Vector3(*wall["velocity"])
        self.center0, self.ori0 = Vector3(body.state.pos), Quaternion(body.state.ori)

    def place(self, k):
        angle = self.rate * self.dt * min(k, self.steps)
        rate = self.rate if 1 <= k <= self.steps else 0.0
        turn = Quaternion(self.axis, angle)
        s = self.body.state
        s.pos = self.pivot + turn * (self.center0 + self.velocity * (k * self.dt) - self.pivot)
        s.ori = turn * self.ori0
        s.angVel = self.axis * rate
        s.vel = self.velocity + s.angVel.cross(s.pos - self.pivot)


def gravity_at(sc, t):
    """The scene's gravity turned about z by its angle at t (stickslip Scene.gravity_angle:
    the same arithmetic)."""
    g = sc["gravity"]
    rate0, t0 = sc.get("gravity_spinup", (0.0, 0.0))
    rate = sc.get("gravity_rate", 0.0)
    a = rate0 * t + (rate - rate0) * (t - t0) if t > t0 else rate0 * t
    c, s = math.cos(a), math.sin(a)
    return Vector3(c * g[0] - s * g[1], s * g[0] + c * g[1], g[2])


def slip_stats(sc, law, kin, walls):
    """columns.SLIP_STATS of the step just made, from the law's arrays and the kinematics
    the law saw in it (`kin`: positions, velocities, spins of every body before the step):
    grain-grain contacts pressed together that slipped, those sliding at or above V_d and
    V*, and their summed |Fs|/Fn (stickslip/columns.py)."""
    import numpy as np

    c = sc["contact"]
    if not len(law.keys):
        return [0, 0, 0, 0.0]
    i1, i2 = law.keys >> 32, law.keys & 0xFFFFFFFF
    sel = law.slipped & (law.fn > 0) & ~np.isin(i1, walls) & ~np.isin(i2, walls)
    i1, i2 = i1[sel], i2[sel]
    x, v, w, r = kin
    d = x[i2] - x[i1]
    dist = np.linalg.norm(d, axis=1)
    n = d / dist[:, None]
    half = 0.5 * (r[i1] + r[i2] - dist)
    v_rel = v[i1] - v[i2] + np.cross((r[i1] - half)[:, None] * w[i1] + (r[i2] - half)[:, None] * w[i2], n)
    vs = np.linalg.norm(v_rel - np.sum(v_rel * n, axis=1)[:, None] * n, axis=1)
    fn = law.fn[sel]
    nu_s = c["nu_s"] if sc["effects"]["tangential_damping"] else 0.0
    drop = 2.0 * (c["mu_s"] - c["mu_k"]) * fn
    ratio = np.linalg.norm(law.F_s[sel], axis=1) / fn
    return [int(sel.sum()), int(np.sum(vs * nu_s >= drop)), int(np.sum(vs * (nu_s + c["ks"] * sc["dt"]) >= drop)),
            float(ratio.sum())]


def main(scene_path, out_path):
    sc = json.load(open(scene_path))
    ids, turning = build(sc)
    import builtins

    import numpy as np

    law = builtins.stickslip_law
    dim, every, steps, dt = sc["dimension"], sc["every"], sc["steps"], sc["dt"]
    out = sc["output"]
    # the column names come from stickslip/columns.py (through the adapter); the rows below
    # give their values in that order (grains, contacts, walls, stats), checked at row 0
    header = sc["columns"]
    pairs = []
    for a, b in out["contacts"]:
        ia, ib = ids[a], ids[b]
        key, sign = ((ia, ib), 1.0) if ia < ib else ((ib, ia), -1.0)
        pairs.append((key, sign))
    wall_rot = {w["name"]: w["rotation"] for w in sc["walls"] if w.get("rotation")}
    slips = [0] * len(pairs)
    states = [O.bodies[ids[g]].state for g in out["grains"]]
    wall_ids = np.array([ids[w["name"]] for w in sc["walls"]], np.int64)
    radius = np.array([b.shape.radius if hasattr(b.shape, "radius") else 0.0 for b in O.bodies])

    def kinematics():
        st = [b.state for b in O.bodies]
        return (np.array([s.pos.__getinitargs__() for s in st]), np.array([s.vel.__getinitargs__() for s in st]),
                np.array([s.angVel.__getinitargs__() for s in st]), radius)

    def grains_now():
        """(x, v, spin) of the recorded grains, as tuples (one read per vector)."""
        return [(s.pos.__getinitargs__(), s.vel.__getinitargs__(), s.angVel.__getinitargs__()) for s in states]

    def row(step, before, kin):
        """Row `step`: the state at t = step dt as velocity Verlet (pyref, LIGGGHTS) reports it.
        YADE's step from iteration `step` computed the forces at x(t) from v(t - dt/2) (the
        state `before` it) and left v(t + dt/2); the velocity at t is their mean."""
        after = grains_now() if step else before  # (row 0: the start, v(0) as given)
        r = [step * dt]
        for (x, v0, w0), (_, v1, w1) in zip(before, after):
            r += list(x[:dim]) + [0.5 * (v0[q] + v1[q]) for q in range(dim)]
            if sc["effects"]["rotation"]:
                r += [0.5 * (w0[q] + w1[q]) for q in ((2,) if dim == 2 else (0, 1, 2))]
        for k, (key, sign) in enumerate(pairs):
            fn, f, _ = law.lookup(*key) or (0.0, (0.0, 0.0, 0.0), False)
            ft = [sign * f[q] for q in range(3)]
            r += [fn, math.sqrt(sum(x * x for x in ft))] + ft[:dim] + [slips[k]]
            slips[k] = 0
        for w in out["walls"]:
            rot = wall_rot.get(w)
            r += [rot["rate"] * dt * min(step, rot["steps"]) if rot else 0.0]
        if out["stats"]:
            # kinetic energy at t (translation and spin): each body's mean of its velocities at
            # t - dt/2 and t + dt/2 (row 0: the velocities given)
            ek = 0.0
            for b in O.bodies:
                if b.dynamic:
                    s = b.state
                    v0, w0 = kin[1][b.id]
                    v, w = (0.5 * (v0 + s.vel), 0.5 * (w0 + s.angVel)) if step else (v0, w0)
                    ek += 0.5 * (s.mass * v.squaredNorm() + sum(s.inertia[q] * w[q] ** 2 for q in range(3)))
            r += [len(law.keys), ek]
        if out.get("slip_stats"):
            r += slip_stats(sc, law, kin[0], wall_ids)
        return r

    turning_g = sc.get("gravity_rate", 0.0) or sc.get("gravity_spinup", (0.0, 0.0))[1]
    newton = next((e for e in O.engines if type(e).__name__ == "NewtonIntegrator"), None)

    def kin_before(step):
        """What the row needs of the state before the step: the bodies' velocities (stats)
        and the law's kinematics (slip_stats), only for the steps that write a row."""
        if step % every:
            return None
        vel = ({b.id: (Vector3(b.state.vel), Vector3(b.state.angVel)) for b in O.bodies if b.dynamic}
               if out["stats"] else None)  # (copies: a State's vectors are views of YADE's own)
        return (kinematics() if out.get("slip_stats") else None), vel

    # Iteration 0 is velocity Verlet's setup (forces at x(0) from v(0), no spring loading,
    # half a kick): from there on YADE's iteration k computes pyref's forces of step k.
    if turning_g and sc["effects"]["gravity"]:
        newton.gravity = gravity_at(sc, 0.0)
    for w in turning:
        w.place(0)
    before, kin = grains_now(), kin_before(0)
    velocity_verlet_start(law)
    rows = [row(0, before, kin)]
    if len(rows[0]) != len(header):
        raise RuntimeError(f"run_scene.py writes {len(rows[0])} values a row for {len(header)} columns")
    t0 = time.perf_counter()
    for step in range(1, steps + 1):
        if turning_g and sc["effects"]["gravity"]:  # the gravity of the positions this step's forces act on
            newton.gravity = gravity_at(sc, step * dt)
        for w in turning:
            w.place(step)
        if step % every == 0:
            before, kin = grains_now(), kin_before(step)
        O.step()
        if law.n_slipped:  # (most steps slip nowhere: no per-contact look-up)
            for k, (key, _) in enumerate(pairs):
                if law.has_slipped(*key):
                    slips[k] += 1
        if step % every == 0:
            rows.append(row(step, before, kin))
            bad = [h for h, v in zip(header, rows[-1]) if not math.isfinite(v)]
            if bad:
                raise RuntimeError(f"non-finite {', '.join(bad[:4])} at step {step} (t = {step * dt:g} s)")
        if step % 5000 == 0:
            print(f"PROGRESS {step} {steps}", flush=True)
    wall = time.perf_counter() - t0
    with open(out_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    print(f"WALLTIME {wall}", flush=True)


def law_error(e):
    """The law's own one-line message for an error raised inside its PyRunner (YADE wraps
    it into "PyRunner error. COMMAND: ... ERROR: <message> ... STACK TRACE ...")."""
    import builtins

    law = getattr(builtins, "stickslip_law", None)
    if law is not None and law.error:
        return law.error
    text = str(e)
    if "ERROR:" in text:
        text = text.split("ERROR:", 1)[1].strip()
    return text.splitlines()[0] if text else type(e).__name__


if __name__ == "__main__":
    # One line on stdout for the adapter (and the user), the traceback only in the log.
    import traceback

    try:
        main(sys.argv[1], sys.argv[2])
    except ValueError as e:  # a bad parameter
        print(f"ERROR {e}", flush=True)
        sys.exit(3)
    except RuntimeError as e:  # the run failed (the law refused a scene, or values went non-finite)
        traceback.print_exc(file=sys.stderr)
        print(f"ERROR {law_error(e)}", flush=True)
        sys.exit(4)
    except Exception as e:  # noqa: BLE001 -- anything else, still one line
        traceback.print_exc(file=sys.stderr)
        print(f"ERROR run_scene.py: {type(e).__name__}: {e}", flush=True)
        sys.exit(5)
    sys.exit(0)
