"""The stick-slip friction law of Khellaf & Mansouri (2024) for YADE, in Python.

Use in an ordinary YADE script (full example: yade_law/example_drag.py, README.md):

    import sys; sys.path.insert(0, "/path/to/yade_law")
    from stickslip_yade import stickslip_material, stickslip_engines
    mat = O.materials.append(stickslip_material(kn=1.2e7, nu_n=41.38))
    ... spheres / boxes / walls with material=mat ...
    O.engines = stickslip_engines(ks=9.6e6, nu_s=33.1, mu_s=0.5, mu_k=0.45, gravity=(0, -9.81, 0))

The native Law2_ScGeom_ViscElPhys_Basic applies the normal force (eq. 3, never
tensile; kn = Kn, cn = nu_n, no native shear force). A PyRunner placed before
NewtonIntegrator adds the tangential force of docs/law.md (3D form: the spring
elongation D is kept in the current tangent plane). The law's arithmetic is the
repository's numpy kernel pyref/laws.py (turn of the history, eqs. 5, 7, 8, the exact
slip timing, the energy split), imported from here; this file gathers the kinematics
from YADE and hands the forces back. With O.trackEnergy the energies go to O.energy.

Why it is written this way (measured on YADE 2023.02a, see README.md):
- YADE never calls a Python subclass of a Law2 class, and interactions take no extra
  attributes, so the per-contact state lives here, keyed by (id1, id2).
- Every attribute read from YADE costs 0.3-0.7 us, so per-contact reads are cut to
  id1, id2, iterMadeReal. For sphere-sphere contacts the normal, overlap, relative
  velocity and normal force are recomputed in numpy from body positions (3 bulk
  calls) and velocities (one read per body), with the contact's own kn, cn read
  once when it is made: the same numbers the native law used (check=True compares).
  Contacts with a non-sphere (box, wall) read normal, contact point and normal
  force from YADE, one by one (few of them).
- The law runs vectorised over all contacts; forces and torques are summed per body
  and added with one O.forces.addF/addT per body.
- The state is kept as arrays sorted by key, not as a Python dict: a dict lookup per
  contact would cost about as much as the whole law. Same semantics: a contact's
  state is dropped the first step it is not real, and a contact made again
  (different iterMadeReal) starts from D = 0.
Limits: spheres, boxes and walls; no clumps, no periodic cell, interactionDetectionFactor 1;
bodies appended during a run are picked up, an erased body's id reused is not.
"""
from __future__ import annotations

import base64
import builtins
import gc
import json
import math
import numbers
import os
import sys
import uuid
from itertools import chain

import numpy as np

# The law's arithmetic lives once, in the repository's numpy kernel pyref/laws.py (it
# imports numpy only), so that this file needs no copy of it: put the repository on the
# path and check that the kernel found is this repository's own.
_REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if _REPO not in sys.path:
    sys.path.append(_REPO)
from pyref import laws as _laws  # noqa: E402

if os.path.realpath(os.path.dirname(os.path.dirname(_laws.__file__))) != os.path.realpath(_REPO):
    raise ImportError(f"stickslip_yade.py needs the law kernel of its own repository ({_REPO}/pyref/laws.py), "
                      f"but `pyref` was already imported from {os.path.dirname(_laws.__file__)}")
LawParams, rotate_history, tangential_force = _laws.LawParams, _laws.rotate_history, _laws.tangential_force
RESETS, SLIP_TIMINGS = _laws.RESETS, _laws.SLIP_TIMINGS


def _number(name, v):
    """A finite real number (Python or numpy scalar, not bool) as float, else ValueError."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real) or not math.isfinite(v):
        raise ValueError(f"{name} = {v!r}: must be a finite number")
    return float(v)


def check_parameters(ks=None, nu_s=None, mu_s=None, mu_k=None, reset=None, slip_timing=None, kn=None,
                     nu_n=None):
    """The law's parameter rules (docs/law.md), for the parameters given (None = not given).
    Raises ValueError naming the parameter and its allowed range; returns the given values
    as a dict of floats and strings (numpy scalars become floats)."""
    out = {}
    for name, v, low, strict in (("kn", kn, 0.0, True), ("nu_n", nu_n, 0.0, False), ("ks", ks, 0.0, True),
                                 ("nu_s", nu_s, 0.0, False), ("mu_s", mu_s, 0.0, True)):
        if v is None:
            continue
        v = out[name] = _number(name, v)
        if v < low or (strict and v == low):
            raise ValueError(f"{name} = {v:g}: must be {'>' if strict else '>='} {low:g}")
    if mu_k is not None:
        v = out["mu_k"] = _number("mu_k", mu_k)
        if mu_s is None:
            raise ValueError("mu_k needs mu_s: the allowed range is [mu_s/2, mu_s]")
        mu_s = out["mu_s"]
        if not mu_s / 2 <= v <= mu_s:
            raise ValueError(f"mu_k = {v:g}: must be in [mu_s/2, mu_s] = [{mu_s / 2:g}, {mu_s:g}] "
                             f"so that 0 <= Fmin = (2 mu_k - mu_s) Fn <= mu_k Fn")
    for name, v, allowed in (("reset", reset, RESETS), ("slip_timing", slip_timing, SLIP_TIMINGS)):
        if v is None:
            continue
        if not isinstance(v, str) or v not in allowed:
            raise ValueError(f"{name} = {v!r}: must be one of {', '.join(allowed)}")
        out[name] = v
    return out


def _flag(name, v):
    if not isinstance(v, (bool, np.bool_)):
        raise ValueError(f"{name} = {v!r}: must be True or False")
    return bool(v)


def _vector3(name, v):
    """Three finite numbers (a tuple, list, numpy array or Vector3) as a tuple of floats."""
    try:
        items = None if isinstance(v, (str, bytes)) else [v[0], v[1], v[2]]
        ok = items is not None and len(v) == 3
    except (TypeError, IndexError, KeyError):
        ok = False
    if ok:
        try:
            return tuple(_number(name, x) for x in items)
        except ValueError:
            pass
    raise ValueError(f"{name} = {v!r}: must be 3 finite numbers")


def stickslip_material(kn, nu_n=0.0, density=2600.0, label=None):
    """A ViscElMat whose contacts get kn = Kn and cn = nu_n (Ip2 puts the two materials
    in series, so each side carries twice the value) and no native shear force."""
    from yade import ViscElMat

    p = check_parameters(kn=kn, nu_n=nu_n)
    density = _number("density", density)
    if not density > 0:
        raise ValueError(f"density = {density:g}: must be > 0")
    if label is not None and not isinstance(label, str):
        raise ValueError(f"label = {label!r}: must be a string")
    mat = ViscElMat(kn=2.0 * p["kn"], cn=2.0 * p["nu_n"], ks=0.0, cs=0.0, frictionAngle=0.0, density=density)
    if label:
        mat.label = label
    return mat


_LAWS = {}  # token -> StickSlipLaw, the laws of this process


def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def _rows(vectors):
    """Vector3s -> (n, 3) array. __getinitargs__() gives the three components in one
    call (0.3 us); v[0], v[1], v[2] costs 0.7 us and tuple(v) over 10 us."""
    t = [v.__getinitargs__() for v in vectors]
    return np.fromiter(chain.from_iterable(t), float, 3 * len(t)).reshape(-1, 3)  # 3x faster than np.array(t)


class StickSlipLaw:
    """The tangential law for all real interactions; `step()` runs once per time step.

    After a step, `contact(id1, id2)` gives (Fn, F_s on id1 as (3,) array, slipped
    this step, slip steps since the contact was made) or None if not touching.
    """

    def __init__(self, ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True, check=False):
        p = check_parameters(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing)
        for name, v in (("rotation", rotation), ("check", check)):
            if not isinstance(v, (bool, np.bool_)):
                raise ValueError(f"{name} = {v!r}: must be True or False")
        self.ks, self.nu_s, self.mu_s, self.mu_k = p["ks"], p["nu_s"], p["mu_s"], p["mu_k"]
        self.reset, self.slip_timing = reset, slip_timing
        # The kernel's parameters; kn and nu_n are unused there (YADE's own law gives Fn).
        self.params = LawParams("stick_slip", 0.0, 0.0, self.ks, self.nu_s, self.mu_s, self.mu_k, reset, slip_timing)
        self.rotation = bool(rotation)  # torques (and grain spin in V_s) only when rotation is simulated
        self.check = bool(check)  # compare recomputed normals / normal forces with YADE's (tests, bench)
        self.max_fn_error = 0.0  # largest |Fn - native Fn| / max(native Fn) seen with check=True
        self.checked = 0  # sphere-sphere contact-steps compared with check=True
        # Energy (O.trackEnergy): the least energy one contact took out in one step (docs/law.md,
        # "Energy": never below round-off in the step mode).
        self.min_dissipation = 0.0
        self.error = None  # the message of the error that stopped the run, if any
        self.nbodies = -1
        # Checkpoints: the scene the state below belongs to, the iteration of the law's last
        # step there (-1: none), and the token naming this law in its runner's command.
        self.token = uuid.uuid4().hex[:16]
        self._scene, self.last_iter = None, -1
        _LAWS[self.token] = self
        self._clear()

    # State carried from step to step and saved with the scene (arrays share one row per contact).
    ARRAYS = ("keys", "made", "D", "kn", "cn", "fn", "F_s", "slipped", "count")
    SCALARS = ("last_iter", "min_dissipation", "max_fn_error", "checked")

    def params_dict(self):
        return {"ks": self.ks, "nu_s": self.nu_s, "mu_s": self.mu_s, "mu_k": self.mu_k, "reset": self.reset,
                "slip_timing": self.slip_timing, "rotation": self.rotation, "check": self.check}

    def _saved_state(self, O, fresh=False):
        """The law's state as a string for O.tags (YADE saves the tags with the scene)."""
        arrays = {} if fresh else {k: getattr(self, k) for k in self.ARRAYS}
        return json.dumps({
            "version": 1, "token": self.token, "params": self.params_dict(), "iter": O.iter,
            "scalars": {"last_iter": -1} if fresh else {k: getattr(self, k) for k in self.SCALARS},
            "arrays": {k: [a.dtype.str, a.shape, base64.b64encode(np.ascontiguousarray(a).tobytes()).decode()]
                       for k, a in arrays.items()}})

    def _adopt(self, O, scene):
        """The scene is not the one the state belongs to: first step, or the scene was
        replaced (O.load, O.loadTmp, O.reload, O.reset). Take the state saved with the scene
        if it was saved at this very iteration; otherwise start afresh only where nothing is
        lost, else refuse (a silent restart of every spring would be a wrong answer)."""
        saved = O.tags["stickslip_law"] if "stickslip_law" in O.tags.keys() else None
        st = json.loads(saved) if saved else None
        ran = self._scene is not None and self.last_iter >= 0
        if st is not None and st["iter"] == O.iter:
            self._clear()
            for k, (dtype, shape, data) in st["arrays"].items():
                setattr(self, k, np.frombuffer(base64.b64decode(data), dtype=dtype).reshape(shape).copy())
            for k, v in st["scalars"].items():
                setattr(self, k, v)
        elif ran and O.iter > 0:
            why = (f"its stick-slip state was saved at iteration {st['iter']}" if st else
                   "it carries no stick-slip state (O.tags['stickslip_law'])")
            raise RuntimeError(f"stick-slip law: the scene was replaced (O.load/loadTmp/reload?) and is at iteration "
                               f"{O.iter}, but {why}: it was saved by a path that bypasses stickslip_yade's save hook "
                               f"(O.save, O.saveTmp, O.sceneToString are hooked); the springs cannot be restored")
        else:  # a new law, or a new scene from iteration 0: nothing to continue
            self._clear()
            self.last_iter = -1
        self._scene = scene
        self.nbodies = -1  # body data (State objects, radii) is the new scene's

    def _clear(self):
        z = np.zeros(0)
        self.keys, self.made = np.zeros(0, np.int64), np.zeros(0, np.int64)
        self.D, self.F_s = np.zeros((0, 3)), np.zeros((0, 3))
        self.kn, self.cn, self.fn = z, z, z
        self.slipped, self.count = np.zeros(0, bool), np.zeros(0, np.int64)

    def _refresh_bodies(self, O):
        """Per-body data that does not change during a run (redone when the body count
        changes): states, which bodies are spheres, radii, and whether ids are dense so
        that the bulk position reader lines up with ids."""
        from yade import Sphere

        bodies = list(O.bodies)
        n = len(O.bodies)
        self.states = [None] * n
        self.sphere = np.zeros(n, bool)
        self.radius = np.zeros(n)
        for b in bodies:
            if b is None:
                continue
            self.states[b.id] = b.state
            if isinstance(b.shape, Sphere):
                self.sphere[b.id], self.radius[b.id] = True, b.shape.radius
        self.dense = all(s is not None for s in self.states)
        self.nbodies = n

    def _positions(self, used):
        import yade._utils as yu

        if self.dense:  # all bodies in id order, three C++ calls
            P = np.array([yu.coordsAndDisplacements(a)[0] for a in range(3)]).T
            if len(P) == self.nbodies:
                return P
        P = np.zeros((self.nbodies, 3))
        P[used] = _rows([self.states[i].pos for i in used.tolist()])
        return P

    def step(self):
        # The step creates some 10^5 short-lived Python objects; the cyclic garbage
        # collector, triggered by them, would scan them all (about 1 us per contact).
        enabled = gc.isenabled()
        gc.disable()
        try:
            self._step()
        finally:
            if enabled:
                gc.enable()

    def _step(self):
        from yade import O

        scene = O._sceneObj
        if self._scene is None or not scene == self._scene:  # Serializable ==: the same C++ object
            self._adopt(O, scene)
        self.last_iter = O.iter
        if len(O.bodies) != self.nbodies:
            self._refresh_bodies(O)
        L = list(O.interactions)  # real (touching) interactions only
        m = len(L)
        if m == 0:
            self._clear()
            if O.trackEnergy:
                self._book(O, 0.0, 0.0, 0.0, 0.0, 0.0)
            return
        i1 = np.fromiter([I.id1 for I in L], np.int64, m)
        i2 = np.fromiter([I.id2 for I in L], np.int64, m)
        made = np.fromiter([I.iterMadeReal for I in L], np.int64, m)
        key = (i1 << 32) | i2
        dt, nb = O.dt, self.nbodies

        # Carry each contact's state from the last step; new or re-made contacts start fresh.
        D = np.zeros((m, 3))
        kn, cn, count = np.zeros(m), np.zeros(m), np.zeros(m, np.int64)
        old = np.zeros(m, bool)
        if len(self.keys):
            p = np.minimum(np.searchsorted(self.keys, key), len(self.keys) - 1)
            old = (self.keys[p] == key) & (self.made[p] == made)
            po = p[old]
            D[old], kn[old], cn[old], count[old] = self.D[po], self.kn[po], self.cn[po], self.count[po]

        ss = self.sphere[i1] & self.sphere[i2]  # sphere-sphere: geometry recomputed here
        for k in np.flatnonzero(~old).tolist():  # new contacts: their own kn, cn once
            ph = L[k].phys
            kn[k], cn[k] = ph.kn, ph.cn

        # Body kinematics at this step: x(t), v(t - dt/2), as the native law saw them.
        used = np.zeros(nb, bool)
        used[i1] = used[i2] = True
        used = np.flatnonzero(used)
        P = self._positions(used)
        V, W = np.zeros((nb, 3)), np.zeros((nb, 3))
        st = self.states
        V[used] = _rows([st[i].vel for i in used.tolist()])
        spin = used if self.rotation else used[~self.sphere[used]]  # walls may turn anyway
        if len(spin):
            W[spin] = _rows([st[i].angVel for i in spin.tolist()])

        self._finite_bodies(O, used, P, V, W)
        x1, x2 = P[i1], P[i2]
        r1, r2 = self.radius[i1], self.radius[i2]
        d = x2 - x1
        dist = np.sqrt(_dot(d, d))
        same = ss & (dist == 0)
        if same.any():
            k = int(np.flatnonzero(same)[0])
            self._fail(f"contact ({i1[k]}, {i2[k]}) at iteration {O.iter}: the two spheres have the same centre, "
                       f"so the contact has no normal direction")
        n = d / np.where(dist > 0, dist, 1.0)[:, None]  # unit normal from id1 to id2
        delta = r1 + r2 - dist
        v_rel0 = V[i1] - V[i2]
        fn = np.maximum(0.0, kn * delta + cn * _dot(v_rel0, n))  # eq. 3, as the native law
        a1 = r1[:, None] * n  # lever arms: the radii along the normal (docs/law.md step 1)
        a2 = -r2[:, None] * n
        other = np.flatnonzero(~ss)
        if len(other):  # box/wall contacts: YADE's normal, contact point and normal force
            g = [L[k].geom for k in other.tolist()]
            n[other] = _rows([x.normal for x in g])
            c = _rows([x.contactPoint for x in g])
            fn[other] = [L[k].phys.normalForce.norm() for k in other.tolist()]
            if O.trackEnergy:  # the normal spring's energy needs YADE's overlap
                delta[other] = [x.penetrationDepth for x in g]
            s1, s2 = self.sphere[i1[other]], self.sphere[i2[other]]
            a1[other] = np.where(s1[:, None], r1[other, None] * n[other], c - x1[other])
            a2[other] = np.where(s2[:, None], -r2[other, None] * n[other], c - x2[other])
        if self.check:
            self._check(L, ss, n, fn)

        # Relative velocity of id1's contact point w.r.t. id2's, tangential part (eq. 6).
        v_rel = v_rel0
        if len(spin):
            v_rel = v_rel + np.cross(W[i1], a1) - np.cross(W[i2], a2)
        V_s = v_rel - _dot(v_rel, n)[:, None] * n

        # The spring turned into the current tangent plane keeping its length, loaded by
        # this step's tangential displacement (eq. 7), the trial force (eq. 5), the slip and
        # the reset (eq. 8): all in the kernel, pyref/laws.py.
        energy = O.trackEnergy
        tan = tangential_force(rotate_history(D, n), V_s, fn, dt, self.params, energy=energy)
        F_s, D, slip = tan.force, tan.spring, tan.slipped
        bad = ~(np.isfinite(fn) & np.isfinite(F_s).all(axis=1))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            self._fail(f"non-finite force on contact ({i1[k]}, {i2[k]}) at iteration {O.iter} (Fn = {fn[k]!r}, "
                       f"F_s = {F_s[k].tolist()}): bodies at the same place, or a blown-up run")
        count = count + slip
        if energy:
            self._energy(O, tan, D, kn, delta, fn, _dot(v_rel, n), dt)

        # Forces and torques summed per body, one addF/addT per body that gets any.
        self._add(O.forces.addF, i1, i2, F_s, -F_s, nb)
        if self.rotation:
            self._add(O.forces.addT, i1, i2, np.cross(a1, F_s), np.cross(a2, -F_s), nb)

        order = np.argsort(key)  # ended contacts are not carried: their state is dropped
        self.keys, self.made, self.D = key[order], made[order], D[order]
        self.kn, self.cn, self.fn, self.F_s = kn[order], cn[order], fn[order], F_s[order]
        self.slipped, self.count = slip[order], count[order]

    def _fail(self, message):
        """Stop the run with one clear line (kept in `self.error`: YADE wraps the exception
        of a PyRunner into its own RuntimeError text)."""
        self.error = f"stick-slip law: {message}"
        raise RuntimeError(self.error)

    def _finite_bodies(self, O, used, P, V, W):
        for what, X in (("position", P), ("velocity", V), ("angular velocity", W)):
            ok = np.isfinite(X[used]).all(axis=1)
            if not ok.all():
                i = int(used[np.flatnonzero(~ok)[0]])
                self._fail(f"body {i} has a non-finite {what} {X[i].tolist()} at iteration {O.iter}: the run has "
                           f"blown up (time step above the stability limit?) or was given a non-finite value")

    def _energy(self, O, tan, D, kn, delta, fn, v_n, dt):
        """Book this step's energies in O.energy (with O.trackEnergy; YADE's keys `kinetic`
        and `gravWork` come from NewtonIntegrator): the tangential law's dissipation split
        into slips and dashpot (docs/law.md, Energy) and its spring energy Ks|D|^2/2, and,
        because Law2_ScGeom_ViscElPhys_Basic books nothing, the normal law's elastic energy
        Kn*delta^2/2 and what its dashpot took, (Fn - Kn*delta)*v_n*dt (Fn clipped at 0
        included). Cumulative entries are read back from O.energy each step, so they live
        in the scene and follow its checkpoints."""
        e_t = tan.dissipated_dashpot + tan.dissipated_slip
        if len(e_t):
            self.min_dissipation = min(self.min_dissipation, float(e_t.min()))
        self._book(O, tan.dissipated_slip.sum(), tan.dissipated_dashpot.sum(), ((fn - kn * delta) * v_n).sum() * dt,
                   0.5 * self.ks * _dot(D, D).sum(), 0.5 * (kn * delta * delta).sum())

    @staticmethod
    def _book(O, slip, dashpot, normal_damping, spring, normal_elastic):
        E = O.energy
        have = set(E.keys())
        for name, inc in (("stickslip_slip", slip), ("stickslip_dashpot", dashpot),
                          ("stickslip_normal_damping", normal_damping)):
            E[name] = (E[name] if name in have else 0.0) + float(inc)
        E["stickslip_spring"] = float(spring)
        E["stickslip_normal_elastic"] = float(normal_elastic)

    @staticmethod
    def _add(add, i1, i2, f1, f2, nb):
        tot = np.empty((nb, 3))
        for c in range(3):
            tot[:, c] = np.bincount(i1, f1[:, c], nb) + np.bincount(i2, f2[:, c], nb)
        got = np.flatnonzero(tot.any(axis=1))
        for i, f in zip(got.tolist(), tot[got].tolist()):
            add(i, f)

    def _check(self, L, ss, n, fn):
        """Recomputed sphere-sphere normals and normal forces against YADE's own."""
        k = np.flatnonzero(ss)
        if not len(k):
            return
        native_n = _rows([L[j].geom.normal for j in k.tolist()])
        native_fn = np.array([L[j].phys.normalForce.norm() for j in k.tolist()])
        err_n = float(np.abs(native_n - n[k]).max())
        err_fn = float(np.abs(native_fn - fn[k]).max() / max(native_fn.max(), 1e-300))
        self.max_fn_error = max(self.max_fn_error, err_fn)
        self.checked += len(k)
        if err_n > 1e-9 or err_fn > 1e-9:
            raise RuntimeError(f"stick-slip law: recomputed geometry differs from YADE's "
                               f"(normal {err_n:.3g}, relative Fn {err_fn:.3g})")

    def contact(self, id1, id2):
        """(Fn, F_s on id1, slipped this step, slip steps since made) or None."""
        if id1 > id2:
            got = self.contact(id2, id1)
            return None if got is None else (got[0], -got[1], got[2], got[3])
        if not len(self.keys):
            return None
        key = (id1 << 32) | id2
        p = int(np.searchsorted(self.keys, key))
        if p == len(self.keys) or self.keys[p] != key:
            return None
        return float(self.fn[p]), self.F_s[p].copy(), bool(self.slipped[p]), int(self.count[p])

    def lookup(self, id1, id2):
        """(Fn, F_s on id1, slipped this step) or None (what run_scene.py reads)."""
        got = self.contact(id1, id2)
        return None if got is None else got[:3]

    def n_contacts(self):
        return len(self.keys)


def step(token):
    """What the law's PyRunner runs each step. In a process that did not build the law
    (a scene loaded by O.load in a new process) the law is rebuilt from the parameters
    saved with the scene and published as `builtins.stickslip_law`."""
    law = _LAWS.get(token)
    if law is None:
        law = _law_from_scene(token)
    law.step()


def _law_from_scene(token):
    from yade import O

    if "stickslip_law" not in O.tags.keys():
        raise RuntimeError(f"stick-slip law: this scene's runner names law {token}, which this process has not "
                           f"built, and the scene carries no saved law (O.tags['stickslip_law']): it was saved by a "
                           f"path that bypasses stickslip_yade's save hook; the springs cannot be restored")
    st = json.loads(O.tags["stickslip_law"])
    law = StickSlipLaw(**st["params"])
    del _LAWS[law.token]
    law.token = token  # the name the saved runner uses
    _LAWS[token] = law
    builtins.stickslip_law = law
    return law


def _runner_command(token):
    """One expression, compiled by PyRunner every step (so kept short): this module, imported
    from its own folder if the process has not imported it yet (O.load in a new process),
    runs the law named by `token`."""
    here = os.path.dirname(os.path.abspath(__file__))
    return (f"(__import__('sys').modules.get('stickslip_yade') or (__import__('sys').path.append({here!r}), "
            f"__import__('stickslip_yade'))[1]).step({token!r})")


def _store_state():
    """Before YADE serialises the scene: put the state of the law that runs in it into
    O.tags, with the iteration, so that any load can check it belongs to the scene."""
    from yade import O, PyRunner

    for e in O.engines:
        if isinstance(e, PyRunner) and "stickslip_yade" in e.command and ".step('" in e.command:
            law = _LAWS.get(e.command.rsplit(".step('", 1)[1].split("'")[0])
            if law is None:  # a loaded scene whose law has not run here: its saved state still holds
                continue
            fresh = law._scene is None or not O._sceneObj == law._scene
            O.tags["stickslip_law"] = law._saved_state(O, fresh=fresh)


def _install_save_hooks():
    """YADE's own savers (O.save, O.saveTmp, O.sceneToString) store the law's state first."""
    import yade.wrapper

    Omega = yade.wrapper.Omega
    if getattr(Omega, "_stickslip_hooked", False):
        return
    for name in ("save", "saveTmp", "sceneToString"):
        original = getattr(Omega, name)

        def hooked(self, *args, _original=original, **kw):
            _store_state()
            return _original(self, *args, **kw)

        hooked.__doc__ = original.__doc__
        setattr(Omega, name, hooked)
    Omega._stickslip_hooked = True


try:  # outside YADE (tests of check_parameters) there is nothing to hook
    _install_save_hooks()
except ImportError:
    pass


def stickslip_engines(ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", gravity=(0.0, 0.0, 0.0),
                      damping=0.0, rotation=True, extra=(), check=False):
    """The engine list for O.engines: collision detection, native normal law, this law,
    `extra` engines (e.g. a RotationEngine), then Newton's integration. The law object is
    published as `builtins.stickslip_law` (a PyRunner's command runs in __main__)."""
    from yade import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, Bo1_Wall_Aabb, ForceResetter, Ig2_Box_Sphere_ScGeom,
                      Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                      Ip2_ViscElMat_ViscElMat_ViscElPhys, Law2_ScGeom_ViscElPhys_Basic, NewtonIntegrator,
                      PyRunner)

    gravity = _vector3("gravity", gravity)
    damping = _number("damping", damping)
    if not 0 <= damping < 1:
        raise ValueError(f"damping = {damping!r}: must be in [0, 1)")
    extra = _extra_engines(extra)
    law = StickSlipLaw(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    builtins.stickslip_law = law
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
                        [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
        # initRun=True: otherwise the first step runs without the tangential force.
        PyRunner(command=_runner_command(law.token), iterPeriod=1, initRun=True, updateGlobals=False,
                 label="stickslip_runner"),
        *extra,
        NewtonIntegrator(gravity=gravity, damping=damping),
    ]


def _extra_engines(extra):
    """`extra`: YADE engines to run between the law and NewtonIntegrator (not a second copy
    of what the list already has)."""
    from yade.wrapper import Collider, Engine, ForceResetter, InteractionLoop, NewtonIntegrator

    if isinstance(extra, (str, bytes)) or not hasattr(extra, "__iter__"):
        raise ValueError(f"extra = {extra!r}: must be a list of YADE engines")
    extra = list(extra)
    for k, e in enumerate(extra):
        if not isinstance(e, Engine):
            raise ValueError(f"extra[{k}] = {e!r}: must be a YADE engine (e.g. RotationEngine(...))")
        if isinstance(e, (Collider, ForceResetter, InteractionLoop, NewtonIntegrator)):
            raise ValueError(f"extra[{k}] = {type(e).__name__}: stickslip_engines already has one")
    return extra
