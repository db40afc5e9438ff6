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
  attributes, so the per-contact state lives here, in arrays with one row per contact
  (keys id1 << 32 | id2), and is saved with the scene through O.tags (checkpoints).
- Every attribute read from YADE costs 0.3-0.7 us per contact, about a whole step of
  YADE's native law. So in a step the law reads no per-contact attribute of a sphere
  pair: the contacts are last step's minus those whose overlap turned negative plus
  those YADE's counts say are new (StickSlipLaw docstring); normal, overlap, relative
  velocity and normal force are recomputed in numpy from the bodies' states, read in
  one C++ call (YADE's MPI helper Subdomain.getStateValuesFromIds), with each contact's
  kn, cn read once when it is made: the numbers the native law used (check=True
  compares them, and the contact set, every step). Facet, wall and box contacts read
  YADE's normal, contact point, overlap and normal force one by one.
- Forces and torques are summed per body and added with one O.forces.addF/addT per body.
- What the law cannot handle is refused at the first step (StickSlipLaw._validate).
"""
from __future__ import annotations

import array
import base64
import builtins
import gc
import json
import math
import numbers
import os
import sys
import uuid
from itertools import chain, repeat

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
_dot = _laws._dot  # row-wise dot products of (K, 3) arrays
RESETS, SLIP_TIMINGS = _laws.RESETS, _laws.SLIP_TIMINGS


def _number(name, v):
    """A finite real number (Python or numpy scalar, not bool) as float, else ValueError."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real) or not math.isfinite(v):
        raise ValueError(f"{name} = {v!r}: must be a finite number")
    return float(v)


def check_parameters(ks=None, nu_s=None, mu_s=None, mu_k=None, reset=None, slip_timing=None, kn=None,
                     nu_n=None):
    """The law's parameter rules (docs/law.md), for the parameters given (None = not given):
    the kernel's one checker (pyref/laws.py). Raises ValueError naming the parameter and
    its allowed range; returns the given values (numpy scalars become floats)."""
    given = dict(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing, kn=kn, nu_n=nu_n)
    return _laws.check_parameters(**{k: v for k, v in given.items() if v is not None})


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

# What the law handles: the shapes of the bodies (with the bound functor each needs) and
# the geometry functors (the shape that meets spheres). Contacts with a Facet, Wall or Box
# take YADE's geometry; sphere pairs are recomputed (docs/law.md step 1).
BO1 = {"Sphere": "Bo1_Sphere_Aabb", "Facet": "Bo1_Facet_Aabb", "Wall": "Bo1_Wall_Aabb", "Box": "Bo1_Box_Aabb"}
IG2 = {"Ig2_Sphere_Sphere_ScGeom": "Sphere", "Ig2_Sphere_Sphere_ScGeom6D": "Sphere",
       "Ig2_Facet_Sphere_ScGeom": "Facet", "Ig2_Facet_Sphere_ScGeom6D": "Facet",
       "Ig2_Wall_Sphere_ScGeom": "Wall", "Ig2_Box_Sphere_ScGeom": "Box", "Ig2_Box_Sphere_ScGeom6D": "Box"}


def _rows(vectors):
    """Vector3s -> (n, 3) array. __getinitargs__() gives the three components in one
    call (0.3 us); v[0], v[1], v[2] costs 0.7 us and tuple(v) over 10 us."""
    t = [v.__getinitargs__() for v in vectors]
    return np.fromiter(chain.from_iterable(t), float, 3 * len(t)).reshape(-1, 3)  # 3x faster than np.array(t)


def _cross(a, b):
    """Row-wise a x b; np.cross costs about ten times more on (K, 3) arrays."""
    c = np.empty_like(a)
    c[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    c[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    c[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return c


def _key(i1, i2):
    return (i1 << 32) | i2


class StickSlipLaw:
    """The tangential law for all real interactions; `step()` runs once per time step.

    After a step, `contact(id1, id2)` gives (Fn, F_s on id1 as (3,) array, slipped
    this step, slip steps since the contact was made) or None if not touching.

    How a step finds its contacts cheaply (every read from YADE costs 0.3-0.7 us, a
    whole-scene read of the interactions ~0.3 us per contact): when the law ran at the
    previous iteration, the contacts are last step's minus those whose overlap became
    negative (sphere pairs: recomputed here; other shapes: YADE's geometry, read anyway),
    plus contacts made in this step, whose number is YADE's count of real interactions
    less the survivors; only then are the bodies that gained one asked for their
    interactions (per-body counts, one C++ call). Anything inconsistent, a sphere pair
    within round-off of touching, a body appended or erased, a skipped iteration or a
    loaded scene: the whole set is read again, a contact carried over only if YADE's
    iterMadeReal says it was not broken and made again meanwhile.
    """

    # State carried from step to step, one row per contact, and saved with the scene.
    ARRAYS = ("keys", "made", "cell", "D", "kn", "cn", "fn", "F_s", "slipped", "count")
    SCALARS = ("last_iter", "min_dissipation", "max_fn_error", "checked")
    # A sphere pair whose recomputed overlap is within this share of r1 + r2 of zero may be
    # on either side of YADE's own test (round-off of the distance): read the set again.
    TOUCH_BAND = 1e-12

    def __init__(self, ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True, check=False):
        p = check_parameters(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing)
        self.ks, self.nu_s, self.mu_s, self.mu_k = p["ks"], p["nu_s"], p["mu_s"], p["mu_k"]
        self.reset, self.slip_timing = reset, slip_timing
        # The kernel's parameters; kn and nu_n are unused there (YADE's own law gives Fn).
        self.params = LawParams("stick_slip", None, None, self.ks, self.nu_s, self.mu_s, self.mu_k, reset, slip_timing)
        self.rotation = _flag("rotation", rotation)  # torques (and grain spin in V_s) only if rotation is simulated
        self.check = _flag("check", check)  # compare recomputed normals / normal forces with YADE's (tests, bench)
        self.max_fn_error = 0.0  # largest |Fn - native Fn| / max(native Fn) seen with check=True
        self.checked = 0  # sphere-sphere contact-steps compared with check=True
        # Energy (O.trackEnergy): the least energy one contact took out in one step (docs/law.md,
        # "Energy"; >= 0 in the step mode when nu_s/Ks <= dt).
        self.min_dissipation = 0.0
        self.error = None  # the message of the error that stopped the run, if any
        self.setup_step = False  # True: the next step loads no spring (velocity_verlet_start)
        self.full_reads = 0  # steps that read the whole interaction set (diagnostics, bench)
        self.set_checks = 0  # steps whose contact set check=True compared with YADE's
        self.nbodies = -1
        # Checkpoints: the scene the state below belongs to, the iteration of the law's last
        # step there (-1: none), and the token naming this law in its runner's command.
        self.token = uuid.uuid4().hex[:16]
        self._scene, self.last_iter = None, -1
        self._engines = None  # the engine list last validated (_validate)
        _LAWS[self.token] = self
        self._clear()

    def params_dict(self):
        return {"ks": self.ks, "nu_s": self.nu_s, "mu_s": self.mu_s, "mu_k": self.mu_k, "reset": self.reset,
                "slip_timing": self.slip_timing, "rotation": self.rotation, "check": self.check}

    # ------------------------------------------------------------------ state
    def _clear(self):
        z = np.zeros(0)
        self.keys, self.made = np.zeros(0, np.int64), np.zeros(0, np.int64)
        self.cell = np.zeros((0, 3), np.int64)  # cellDist of each contact (periodic cells)
        self.D, self.F_s = np.zeros((0, 3)), np.zeros((0, 3))
        self.kn, self.cn, self.fn = z, z, z
        self.slipped, self.count = np.zeros(0, bool), np.zeros(0, np.int64)
        self._forget()

    def _forget(self):
        """Caches derived from the arrays and from YADE objects (rebuilt on demand)."""
        self._keyset = None  # the keys as a Python set (membership of candidate new contacts)
        self._sorted = None  # {key: row}, for contact()
        self._idx = None  # ids, sphere-pair flags and radii per contact (see _index)
        self._wrappers = {}  # key -> YADE Interaction of contacts with a non-sphere

    def _take(self, rows, keyset_updated=False):
        """Keep the contacts `rows` (an index or boolean array), in that order."""
        for k in self.ARRAYS:
            setattr(self, k, getattr(self, k)[rows])
        self._sorted = self._idx = None
        if not keyset_updated:
            self._keyset = None

    def _append(self, new):
        """Append contacts (a dict of per-contact arrays, missing ones start at zero)."""
        m = len(new["keys"])
        if not m:
            return
        for k in self.ARRAYS:
            cur = getattr(self, k)
            add = new[k] if k in new else np.zeros((m,) + cur.shape[1:], cur.dtype)
            setattr(self, k, np.concatenate((cur, add)))
        if self._keyset is not None:
            self._keyset.update(new["keys"].tolist())
        self._sorted = self._idx = None

    def _index(self, keys=None):
        """(i1, i2, sphere pair?, indices of the other contacts, r1, r2, r1 + r2) of `keys` (default:
        the law's contacts, cached while they do not change)."""
        if keys is not None or self._idx is None:
            k = self.keys if keys is None else keys
            i1, i2 = k >> 32, k & 0xFFFFFFFF
            ss = self.sphere[i1] & self.sphere[i2]
            r1, r2 = self.radius[i1], self.radius[i2]
            idx = (i1, i2, ss, np.flatnonzero(~ss), r1, r2, r1 + r2)
            if keys is not None:
                return idx
            self._idx = idx
        return self._idx

    def _saved_state(self, O, fresh=False):
        """The law's state as a string for O.tags (YADE saves the tags with the scene)."""
        arrays = {} if fresh else {k: getattr(self, k) for k in self.ARRAYS}
        return json.dumps({
            "version": 2, "token": self.token, "params": self.params_dict(), "iter": O.iter,
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
        self._clear()
        if st is not None and st["iter"] == O.iter:
            for k, (dtype, shape, data) in st["arrays"].items():
                setattr(self, k, np.frombuffer(base64.b64decode(data), dtype=dtype).reshape(shape).copy())
            for k, v in st["scalars"].items():
                setattr(self, k, v)
        elif ran and O.iter > 0:
            why = (f"its stick-slip state was saved at iteration {st['iter']}" if st else
                   "it carries no stick-slip state (O.tags['stickslip_law'])")
            self._fail(f"the scene was replaced (O.load/loadTmp/reload?) and is at iteration {O.iter}, but {why}: "
                       f"it was saved by a path that bypasses stickslip_yade's save hook (O.save, O.saveTmp, "
                       f"O.sceneToString are hooked); the springs cannot be restored")
        else:  # a new law, or a new scene from iteration 0: nothing to continue
            self.last_iter = -1
        self._scene = scene
        self.nbodies = -1  # body data is the new scene's

    # ------------------------------------------------------------------ bodies
    def _refresh_bodies(self, O):
        """Per-body data that does not change during a run, redone when bodies are appended
        or erased: which ids exist, which bodies are spheres, their radii."""
        from yade import Sphere

        n = len(O.bodies)
        exists, sphere, radius = np.zeros(n, bool), np.zeros(n, bool), np.zeros(n)
        self.states = [None] * n  # for the reader of last resort
        self.shapes = {}  # shape class name -> the first body with it
        for b in O.bodies:
            if b is None:
                continue
            exists[b.id] = True
            self.states[b.id] = b.state
            self.shapes.setdefault(type(b.shape).__name__, b.id)
            if isinstance(b.shape, Sphere):
                sphere[b.id], radius[b.id] = True, b.shape.radius
        self.sphere, self.radius = sphere, radius
        self.ids = np.flatnonzero(exists)
        self._idlist = self.ids.tolist()
        self.nbodies, self.nexisting = n, len(self.ids)
        self.nspheres = int(sphere.sum())
        self._engines = None  # validate the scene again (_validate)
        try:  # one C++ call reads pos, vel, angVel (and ori) of listed bodies (YADE's MPI helper)
            from yade.wrapper import Subdomain

            self._reader = Subdomain().getStateValuesFromIds
        except ImportError:
            self._reader = None
        self._keyset = self._idx = None

    def _bodies_changed(self, O):
        """Appended (the length grows) or erased since the last refresh. The bulk reader must
        never be handed an erased id (YADE aborts). YADE's BodyContainer turns on
        `useRedirection` at the first erase (while `enableRedirection`, the default): until
        then nothing was erased; after it, count the bodies that exist every step
        (coordsAndDisplacements skips erased ones, one C++ call)."""
        bodies = O.bodies
        if len(bodies) != self.nbodies:
            return True
        if bodies.enableRedirection and not bodies.useRedirection:
            return False
        import yade._utils as yu

        return len(yu.coordsAndDisplacements(0)[0]) != self.nexisting

    def _kinematics(self):
        """x(t), v(t - dt/2), omega(t - dt/2) of every body, as (nbodies, 3) arrays."""
        nb, k = self.nbodies, len(self._idlist)
        if self._reader is not None:
            A = np.frombuffer(array.array("d", self._reader(self._idlist)), float).reshape(k, 13)  # (faster than fromiter)
        else:
            st = [self.states[i] for i in self._idlist]
            A = np.hstack([_rows([s.pos for s in st]), _rows([s.vel for s in st]), _rows([s.angVel for s in st])])
        if k == nb:
            return A[:, 0:3], A[:, 3:6], A[:, 6:9], A
        P, V, W = np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3))
        P[self.ids], V[self.ids], W[self.ids] = A[:, 0:3], A[:, 3:6], A[:, 6:9]
        return P, V, W, A

    # ------------------------------------------------------------------ the step
    def step(self):
        # The step creates many short-lived Python objects; the cyclic garbage collector,
        # triggered by them, would scan them all (about 1 us per contact).
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
        it = O.iter
        continuing = it == self.last_iter + 1
        if self._bodies_changed(O):
            self._refresh_bodies(O)
            continuing = False
        engines = O.engines
        if self._engines is None or len(engines) != len(self._engines) or not all(
                a == b for a, b in zip(engines, self._engines)):
            self._validate(O, engines)
        self.last_iter = it
        # A setup step (velocity_verlet_start) evaluates the forces at the current state with
        # no time elapsed for the springs, as pyref's and LIGGGHTS' setup does.
        dt = 0.0 if self.setup_step else O.dt
        self.setup_step = False
        P, V, W, A = self._kinematics()
        if not math.isfinite(A.sum()):  # (one reduction; the culprit is looked for only if needed)
            self._finite_bodies(it, P, V, W)
        if not self.rotation:
            W = np.where(self.sphere[:, None], 0.0, W)  # walls, facets, boxes may turn anyway
        shift = self._cell(O)

        # Contacts of this step and their geometry (normal n from id1 to id2, overlap, lever
        # arms a1, a2 from the centres to the contact point, YADE's Fn for non-sphere pairs).
        geo = self._contacts_fast(O, P, shift) if continuing else None
        if geo is None:
            geo = self._contacts_full(O, P, shift)
        if self.check:
            self._check_set(O)
        m = len(self.keys)
        if m == 0:
            if O.trackEnergy:
                self._book(O, 0.0, 0.0, 0.0, 0.0, 0.0)
            return
        i1, i2, n, delta, a1, a2, fn = (geo[k] for k in ("i1", "i2", "n", "delta", "a1", "a2", "fn"))

        # Relative velocity of id1's contact point w.r.t. id2's (docs/law.md step 1); across a
        # periodic boundary id2's image also moves with the cell; tangential part (eq. 6).
        v_rel = V[i1] - V[i2]
        ss, other = geo["ss"], geo["other"]
        if self.rotation and not len(other) == len(i1):  # w1 x a1 - w2 x a2 = (c1 w1 + c2 w2) x n for sphere pairs
            # lever arms c = r - delta/2 to the contact point midway in the overlap (docs/law.md)
            half = 0.5 * delta[:, None]
            v_rel += _cross((self.radius[i1][:, None] - half) * W[i1] + (self.radius[i2][:, None] - half) * W[i2], n)
        if len(other):  # lever arms to YADE's contact point; walls and facets may turn
            o1, o2 = i1[other], i2[other]
            vo = V[o1] - V[o2]
            for w, a, sign in ((W[o1], a1, 1.0), (W[o2], a2, -1.0)):
                if w.any():
                    vo += sign * _cross(w, a[other])
            v_rel[other] = vo
        v_fn = None
        if shift is not None:
            sv = self.cell @ shift[1].T
            v_rel -= sv
        v_n = _dot(v_rel, n)
        V_s = v_rel - v_n[:, None] * n
        # Eq. 3 as the native law computes it, never tensile, for the pairs recomputed here.
        if len(other) < len(i1):
            v_fn = v_n
            if shift is not None:
                # YADE 2023.02a's Law2_ScGeom_ViscElPhys_Basic adds the cell's shift velocity
                # with the wrong sign (v1 - v2 + shiftVel): its normal dashpot sees
                # v_n + 2 n.shiftVel across a deforming periodic boundary. Fn is the force YADE
                # applies, so it is computed the same way here (the friction limit must hold for
                # the force applied); V_s uses the true relative velocity (measured: the
                # overlap grows at 1.99e-4 m/s where YADE's dashpot sees -1.80e-3 m/s).
                v_fn = v_n + 2.0 * _dot(sv, n)
            if not len(other):  # all sphere pairs (no masks: they copy)
                fn = np.maximum(0.0, self.kn * delta + self.cn * v_fn)
            else:
                fn[ss] = np.maximum(0.0, self.kn[ss] * delta[ss] + self.cn[ss] * v_fn[ss])
        if self.check:
            self._check(O, geo, fn)

        # The spring turned into the current tangent plane keeping its length, loaded by
        # this step's tangential displacement (eq. 7), the trial force (eq. 5), the slip and
        # the reset (eq. 8): all in the kernel, pyref/laws.py.
        energy = O.trackEnergy
        tan = tangential_force(rotate_history(self.D, n), V_s, fn, dt, self.params, energy=energy)
        F_s = tan.force
        apart = delta <= 0
        if apart.any():  # YADE's real interactions include spheres touching a wall or facet at zero
            # overlap; for the law that is no contact yet (docs/law.md step 3): no force, no spring
            F_s[apart], tan.spring[apart], tan.slipped[apart] = 0.0, 0.0, False
            if energy:
                tan.dissipated_dashpot[apart] = tan.dissipated_slip[apart] = 0.0
        if not math.isfinite(fn.sum() + F_s.sum()):  # (a sum is finite only if all its terms are)
            k = int(np.flatnonzero(~(np.isfinite(fn) & np.isfinite(F_s).all(axis=1)))[0])
            self._fail(f"non-finite force on contact ({i1[k]}, {i2[k]}) at iteration {it} (Fn = {fn[k]!r}, "
                       f"F_s = {F_s[k].tolist()}): bodies at the same place, or a blown-up run")
        self.D, self.fn, self.F_s, self.slipped = tan.spring, fn, F_s, tan.slipped
        self.count = self.count + tan.slipped
        if energy:
            self._energy(O, tan, self.kn, delta, fn, v_n, dt)
        self._apply(O, i1, i2, F_s, n, a1, a2, other, delta)

    def _cell(self, O):
        """Periodic cell: (hSize, velGrad @ prevHSize), so that id2's image across the boundary
        sits at x2 + hSize @ cellDist and moves with v2 + velGrad @ prevHSize @ cellDist (the
        cell's own motion over the last step, as YADE's Cell::intrShiftVel); None otherwise."""
        if not O.periodic:
            return None
        c = O.cell
        H, G, Hp = (np.array(c.hSize), np.array(c.velGrad), np.array(c.prevHSize))
        return H, G @ Hp

    def _sphere_geometry(self, P, idx, cell, shift):
        """Centre-to-centre vector id1 -> id2 (to id2's image across a periodic boundary), its
        length and the overlap r1 + r2 - distance (meaningful for sphere pairs only)."""
        i1, i2, ss, other, r1, r2, rsum = idx
        if not ss.any():
            z = np.zeros(len(i1))
            return np.zeros((len(i1), 3)), z, z.copy()
        d = P[i2] - P[i1]
        if shift is not None:
            d += cell @ shift[0].T
        dist = np.sqrt(_dot(d, d))
        return d, dist, rsum - dist

    def _contacts_fast(self, O, P, shift):
        """Last step's contacts less the broken ones plus this step's new ones, from YADE's
        counts; None when the whole set must be read (see the class docstring)."""
        keys = self.keys
        idx = self._index()
        i1, i2, ss, other, r1, r2, rsum = idx
        d, dist, delta = self._sphere_geometry(P, idx, self.cell, shift)
        pairs = len(other) < len(keys)
        if pairs and (np.abs(delta) <= self.TOUCH_BAND * rsum)[ss].any():
            return None
        g = self._other_geometry(O, keys[other], P, idx, other, shift)
        n_alive, broken = len(keys), None
        if (pairs and delta[ss].min() < 0) or g["broken"].any():
            broken = delta < 0  # Law2_ScGeom_ViscElPhys_Basic drops a contact when its overlap < 0
            if len(other):
                broken &= ss
                broken[other] = g["broken"]
            n_alive -= int(broken.sum())
        made = O.interactions.countReal() - n_alive
        if made < 0 or made > max(16, n_alive // 8):  # many new contacts: one full read is cheaper
            return None
        if n_alive < len(keys):
            if self._keyset is not None:
                self._keyset.difference_update(keys[broken].tolist())
            alive = ~broken
            remap = np.cumsum(alive) - 1
            kept = ~g["broken"]
            g = {k: v[kept] for k, v in g.items()}
            other = remap[other[kept]]
            d, dist, delta = d[alive], dist[alive], delta[alive]
            self._take(alive, keyset_updated=True)
            idx = self._index()
        geo = self._assemble(idx, d, dist, delta, other, g)
        if made:
            new = self._find_new(O, made, idx[0], idx[1])
            if new is None:
                return None
            geo = self._add_new(O, P, shift, geo, *new)
        return geo

    def _find_new(self, O, made, i1, i2):
        """The `made` contacts YADE has and the law has not: bodies with more real
        interactions than the law knows ask YADE for theirs (numIntrsOfEachBody, withBody)."""
        import yade._utils as yu

        nb = self.nbodies
        known = np.bincount(i1, minlength=nb) + np.bincount(i2, minlength=nb)
        extra = np.array(yu.numIntrsOfEachBody(), np.int64)[:nb] - known
        if (extra < 0).any() or int(extra.sum()) != 2 * made:
            return None
        if self._keyset is None:
            self._keyset = set(self.keys.tolist())
        found = {}
        for b in np.flatnonzero(extra > 0).tolist():
            for I in O.interactions.withBody(b):
                k = _key(I.id1, I.id2)
                if k not in self._keyset:
                    found[k] = I
        if len(found) != made:
            return None
        order = sorted(found)  # the same order whatever YADE's container order (checkpoints)
        return np.array(order, np.int64), [found[k] for k in order], None

    def _contacts_full(self, O, P, shift):
        """Read the whole set of real interactions; carry the state of contacts that were
        real at the law's last step and not broken and made again since (iterMadeReal)."""
        self.full_reads += 1
        L = O.interactions.all(True)  # real interactions only
        m = len(L)
        i1 = np.fromiter([I.id1 for I in L], np.int64, m)
        i2 = np.fromiter([I.id2 for I in L], np.int64, m)
        made = np.fromiter([I.iterMadeReal for I in L], np.int64, m)
        keys = _key(i1, i2)
        order = np.argsort(keys)
        keys, made, L = keys[order], made[order], [L[j] for j in order.tolist()]
        hit, old = np.zeros(len(self.keys), bool), np.zeros(0, np.int64)
        if len(self.keys) and m:
            p = np.minimum(np.searchsorted(keys, self.keys), m - 1)
            hit = (keys[p] == self.keys) & (made[p] == self.made)
            old = p[hit]
        self._take(hit)  # carried contacts keep the law's order
        self._forget()
        is_new = np.ones(m, bool)
        is_new[old] = False
        new = np.flatnonzero(is_new)
        idx = self._index()
        other = idx[3]
        for j in other.tolist():
            self._wrappers[int(self.keys[j])] = L[old[j]]
        d, dist, delta = self._sphere_geometry(P, idx, self.cell, shift)
        g = self._other_geometry(O, self.keys[other], P, idx, other, shift)
        if g["broken"].any():
            self._fail("internal: a real interaction has no geometry")
        geo = self._assemble(idx, d, dist, delta, other, g)
        return self._add_new(O, P, shift, geo, keys[new], [L[j] for j in new.tolist()], made[new])

    def _add_new(self, O, P, shift, geo, keys, inters, made):
        """Append new contacts (fresh springs, their kn, cn and cellDist read once) and their
        geometry to `geo`."""
        if not len(keys):
            return geo
        m = len(keys)
        phys = [I.phys for I in inters]
        kn = np.fromiter([p.kn for p in phys], float, m)
        cn = np.fromiter([p.cn for p in phys], float, m)
        for I, p in zip(inters, phys):
            # YADE's ViscEl law adds no shear force only with zero friction, and then only if
            # its spring is on or its shear dashpot off (ks = 0 with cs > 0 damps tangentially).
            if p.tangensOfFrictionAngle != 0 or (p.ks == 0 and p.cs != 0):
                self._fail(f"contact ({I.id1}, {I.id2}) has tan(frictionAngle) = {p.tangensOfFrictionAngle:g}, "
                           f"ks = {p.ks:g}, cs = {p.cs:g}: YADE's ViscEl law would add its own tangential force; "
                           f"give the bodies stickslip_material(...) (or ViscElMat with frictionAngle = 0)")
        if shift is not None:
            cell = np.array([I.cellDist.__getinitargs__() for I in inters], np.int64).reshape(m, 3)
        else:
            cell = np.zeros((m, 3), np.int64)
        self._append({"keys": keys, "made": np.full(m, self.last_iter, np.int64) if made is None else made,
                      "cell": cell, "kn": kn, "cn": cn})
        for k, I in zip(keys.tolist(), inters):
            self._wrappers[k] = I
        idx = self._index(keys)
        i1, i2, ss, other = idx[:4]
        d, dist, delta = self._sphere_geometry(P, idx, cell, shift)
        g = self._other_geometry(O, keys[other], P, idx, other, shift, cell)
        if g["broken"].any():
            self._fail("internal: a new real interaction has no geometry")
        new = self._assemble(idx, d, dist, delta, other, g)
        if (ss & (dist == 0)).any():
            k = int(np.flatnonzero(ss & (dist == 0))[0])
            self._fail(f"contact ({i1[k]}, {i2[k]}) at iteration {O.iter}: the two spheres have the same centre, "
                       f"so the contact has no normal direction")
        new["other"] = new["other"] + len(geo["i1"])
        out = {}
        for k in geo:
            a, b = geo[k], new[k]
            if a is None and b is None:  # lever arms: none while all contacts are sphere pairs
                out[k] = None
                continue
            a = np.zeros((len(geo["i1"]), 3)) if a is None else a
            b = np.zeros((len(new["i1"]), 3)) if b is None else b
            out[k] = np.concatenate((a, b))
        return out

    def _assemble(self, idx, d, dist, delta, other, g):
        """Per-contact geometry: sphere pairs from the recomputed distance (lever arms r - delta/2
        along the normal, docs/law.md step 1), the others from YADE's."""
        i1, i2, ss, _, r1, r2, _ = idx
        if len(other) and len(other) == len(i1):  # no sphere pair
            return {"i1": i1, "i2": i2, "ss": ss, "n": g["n"], "delta": g["delta"], "a1": g["a1"], "a2": g["a2"],
                    "fn": g["fn"], "other": np.asarray(other, np.int64)}
        n = d / (dist if len(dist) and dist.min() > 0 else np.where(dist > 0, dist, 1.0))[:, None]
        fn = np.zeros(len(i1))
        a1 = a2 = None  # sphere pairs need no arrays of lever arms (c1 n, -c2 n: see _step, _apply)
        if len(other):
            a1, a2 = (r1 - 0.5 * delta)[:, None] * n, -(r2 - 0.5 * delta)[:, None] * n
            n[other], delta[other], fn[other] = g["n"], g["delta"], g["fn"]
            a1[other], a2[other] = g["a1"], g["a2"]
        return {"i1": i1, "i2": i2, "ss": ss, "n": n, "delta": delta, "a1": a1, "a2": a2, "fn": fn,
                "other": np.asarray(other, np.int64)}

    def _other_geometry(self, O, keys, P, idx, other, shift, cell=None):
        """Contacts with a wall, box or facet (rows `other` of idx, cellDist `cell`, default
        the law's): YADE's normal, contact point, overlap and normal force, read one by one
        (about 2.5 us each); `broken` where the interaction is no longer real."""
        m = len(keys)
        broken = np.zeros(m, bool)
        if not m:
            return {"broken": broken}
        wr, rows = self._wrappers, []
        for j, k in enumerate(keys.tolist()):
            I = wr.get(k)
            if I is None:
                I = wr[k] = O.interactions[k >> 32, k & 0xFFFFFFFF]
            g = I.geom
            if g is None:
                broken[j] = True
                wr.pop(k, None)
                rows.append((0.0,) * 5)
            else:
                rows.append(g.normal.__getinitargs__() + (g.penetrationDepth, I.phys.normalForce.norm()))
        A = np.array(rows).reshape(m, 5)
        n, delta = A[:, 0:3], A[:, 3]
        i1, i2, r1, r2 = idx[0][other], idx[1][other], idx[4][other], idx[5][other]
        x2 = P[i2]
        if shift is not None:
            x2 = x2 + (self.cell[other] if cell is None else cell[other]) @ shift[0].T
        # The wall's (facet's, box's) side of the contact is the point of its surface nearest
        # the sphere's centre, x - (r - delta) n: the wall moves there (docs/law.md step 1, as
        # pyref and LIGGGHTS; YADE's contactPoint is midway in the overlap for facets and boxes).
        s1 = self.sphere[i1]
        surface = np.where(s1[:, None], P[i1] + (r1 - delta)[:, None] * n, x2 - (r2 - delta)[:, None] * n)
        half = 0.5 * delta  # a sphere's lever arm reaches midway into the overlap (docs/law.md)
        return {"broken": broken, "n": n, "delta": delta, "fn": A[:, 4],
                "a1": self._arm(s1, r1 - half, n, surface - P[i1]),
                "a2": self._arm(self.sphere[i2], -(r2 - half), n, surface - x2)}

    @staticmethod
    def _arm(sphere, r, n, to_point):
        """Lever arm: r*n for a sphere (r: its radius less half the overlap, docs/law.md step 1),
        else centre -> contact point."""
        if not sphere.any():
            return to_point
        if sphere.all():
            return r[:, None] * n
        return np.where(sphere[:, None], r[:, None] * n, to_point)

    def _validate(self, O, engines):
        """Refuse, at the first step and whenever the engines or bodies change, whatever the
        law cannot handle, naming it: a contact that never reaches the law, or gets a second
        tangential force, must not run silently."""
        from yade.wrapper import Collider, InteractionLoop, NewtonIntegrator, PyRunner

        def where(kind):
            return [k for k, e in enumerate(engines) if isinstance(e, kind)]

        loops, newton = where(InteractionLoop), where(NewtonIntegrator)
        mine = [k for k in where(PyRunner) if f".step('{self.token}')" in engines[k].command]
        if len(loops) != 1 or len(newton) != 1:
            self._fail(f"O.engines has {len(loops)} InteractionLoop and {len(newton)} NewtonIntegrator: the law works "
                       f"with one of each (see stickslip_engines or yade_law/README.md, 'Your own engine list')")
        if len(mine) > 1 or (mine and not loops[0] < mine[0] < newton[0]):
            self._fail("the stick-slip runner must appear once, after the InteractionLoop and before "
                       "NewtonIntegrator (as stickslip_runner(...) in yade_law/README.md)")
        loop = engines[loops[0]]
        for what, functors, allowed in (
                ("Law2", loop.lawDispatcher.functors, ("Law2_ScGeom_ViscElPhys_Basic",)),
                ("Ip2", loop.physDispatcher.functors, ("Ip2_ViscElMat_ViscElMat_ViscElPhys",)),
                ("Ig2", loop.geomDispatcher.functors, tuple(IG2))):
            for f in functors:
                name = type(f).__name__
                if name not in allowed:
                    self._fail(f"{name} in the InteractionLoop: the stick-slip law works with {what} functors "
                               f"{', '.join(allowed)} only")
        geoms = {IG2[type(f).__name__] for f in loop.geomDispatcher.functors}
        bounds = {type(f).__name__ for e in engines if isinstance(e, Collider)
                  for f in getattr(getattr(e, "boundDispatcher", None), "functors", ())}
        for shape, body in self.shapes.items():
            if shape == "Clump":  # clumps have no bound; their members collide
                continue
            if shape not in BO1:
                self._fail(f"body {body} is a {shape}: the stick-slip law handles Sphere, Facet, Wall, Box and "
                           f"clumps of spheres")
            if BO1[shape] not in bounds:
                self._fail(f"body {body} is a {shape} but the collider has no {BO1[shape]}: it would never touch "
                           f"anything")
            needed = shape != "Sphere" or self.nspheres > 1
            if "Sphere" in self.shapes and needed and shape not in geoms:
                self._fail(f"body {body} is a {shape} but the InteractionLoop has no Ig2 functor for {shape}-Sphere "
                           f"contacts (Ig2_{shape}_Sphere_ScGeom): spheres would pass through it")
        self._engines = list(engines)

    def _apply(self, O, i1, i2, F_s, n, a1, a2, other, delta):
        """Forces and torques summed per body, then one addF (and addT) per body that gets any."""
        nb = self.nbodies
        F = np.empty((nb, 3))
        for c in range(3):
            F[:, c] = np.bincount(i1, F_s[:, c], nb) - np.bincount(i2, F_s[:, c], nb)
        if not self.rotation:
            got = np.flatnonzero(F.any(axis=1))
            list(map(O.forces.addF, got.tolist(), F[got].tolist(), repeat(False)))
            return
        # Torques a1 x F_s on id1 and a2 x (-F_s) on id2; for sphere pairs c1 (n x F_s), c2 (n x F_s),
        # c = r - delta/2 (docs/law.md step 6).
        nF = _cross(n, F_s)
        t1 = (self.radius[i1] - 0.5 * delta)[:, None] * nF
        t2 = (self.radius[i2] - 0.5 * delta)[:, None] * nF
        if len(other):
            t1[other] = _cross(a1[other], F_s[other])
            t2[other] = -_cross(a2[other], F_s[other])
        T = np.empty((nb, 3))
        for c in range(3):
            T[:, c] = np.bincount(i1, t1[:, c], nb) + np.bincount(i2, t2[:, c], nb)
        got = np.flatnonzero(F.any(axis=1) | T.any(axis=1))
        if len(got) == nb:  # every body: no copies
            ids, F, T = range(nb), F.tolist(), T.tolist()
        else:
            ids, F, T = got.tolist(), F[got].tolist(), T[got].tolist()
        # (permanent=False given: boost.python then skips filling the default, 15 % faster)
        list(map(O.forces.addF, ids, F, repeat(False)))
        list(map(O.forces.addT, ids, T, repeat(False)))

    # ------------------------------------------------------------------ checks, errors, energy
    def _fail(self, message):
        """Stop the run with one clear line (kept in `self.error`: YADE wraps the exception
        of a PyRunner into its own RuntimeError text)."""
        self.error = f"stick-slip law: {message}"
        raise RuntimeError(self.error)

    def _finite_bodies(self, it, P, V, W):
        for what, X in (("position", P), ("velocity", V), ("angular velocity", W)):
            ok = np.isfinite(X).all(axis=1)
            if not ok.all():
                i = int(np.flatnonzero(~ok)[0])
                self._fail(f"body {i} has a non-finite {what} {X[i].tolist()} at iteration {it}: the run has "
                           f"blown up (time step above the stability limit?) or was given a non-finite value")

    def _energy(self, O, tan, kn, delta, fn, v_n, dt):
        """Book this step's energies in O.energy (with O.trackEnergy; YADE's keys `kinetic`
        and `gravWork` come from NewtonIntegrator): the tangential law's dissipation split
        into slips and dashpot (docs/law.md, Energy) and its spring energy Ks|D|^2/2, and,
        because Law2_ScGeom_ViscElPhys_Basic books nothing, the normal law's elastic energy
        Kn*delta^2/2 and what its dashpot took, (Fn - Kn*delta)*v_n*dt (Fn clipped at 0
        included). Cumulative entries are read back from O.energy each step, so they live
        in the scene and follow its checkpoints."""
        e_t = tan.dissipated_dashpot + tan.dissipated_slip
        self.min_dissipation = min(self.min_dissipation, float(e_t.min()))
        D = tan.spring
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

    def _check_set(self, O):
        """The contact set the law found (fast path or full read) against YADE's real interactions."""
        theirs = {_key(I.id1, I.id2) for I in O.interactions.all(True)}
        ours = set(self.keys.tolist())
        if theirs != ours or len(ours) != len(self.keys):
            miss, extra = sorted(theirs - ours)[:3], sorted(ours - theirs)[:3]
            self._fail(f"contact set differs from YADE's at iteration {O.iter}: missing "
                       f"{[(k >> 32, k & 0xFFFFFFFF) for k in miss]}, extra {[(k >> 32, k & 0xFFFFFFFF) for k in extra]}")
        self.set_checks += 1

    def _check(self, O, geo, fn):
        """Recomputed sphere-sphere normals and normal forces against YADE's own."""
        k = np.flatnonzero(geo["ss"])
        if not len(k):
            return
        inters = [O.interactions[int(a), int(b)] for a, b in zip(geo["i1"][k], geo["i2"][k])]
        native_n = _rows([I.geom.normal for I in inters])
        native_fn = np.array([I.phys.normalForce.norm() for I in inters])
        err_n = float(np.abs(native_n - geo["n"][k]).max())
        err_fn = float(np.abs(native_fn - fn[k]).max() / max(native_fn.max(), 1e-300))
        self.max_fn_error = max(self.max_fn_error, err_fn)
        self.checked += len(k)
        if err_n > 1e-9 or err_fn > 1e-9:
            self._fail(f"recomputed geometry differs from YADE's (normal {err_n:.3g}, relative Fn {err_fn:.3g})")

    # ------------------------------------------------------------------ queries
    def contact(self, id1, id2):
        """(Fn, F_s on id1, slipped this step, slip steps since made) or None."""
        if id1 > id2:
            got = self.contact(id2, id1)
            return None if got is None else (got[0], -got[1], got[2], got[3])
        if self._sorted is None:  # key -> row, rebuilt when the set of contacts changes
            self._sorted = dict(zip(self.keys.tolist(), range(len(self.keys))))
        p = self._sorted.get(_key(int(id1), int(id2)))
        if p is None:
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


def stickslip_runner(ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True, check=False):
    """The law's PyRunner, for an engine list of your own: place it right after the
    InteractionLoop and before NewtonIntegrator (yade_law/README.md, "Your own engine list").
    The law object is published as `builtins.stickslip_law`."""
    from yade import PyRunner

    law = StickSlipLaw(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    builtins.stickslip_law = law
    # initRun=True: otherwise the first step runs without the tangential force.
    return PyRunner(command=_runner_command(law.token), iterPeriod=1, initRun=True, updateGlobals=False,
                    label="stickslip_runner")


def stickslip_engines(ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", gravity=(0.0, 0.0, 0.0),
                      damping=0.0, rotation=True, extra=(), check=False):
    """The engine list for O.engines: collision detection (spheres, facets, walls, boxes),
    YADE's ViscEl law for the normal force, this law, `extra` engines (e.g. a
    RotationEngine), then Newton's integration. The law object is published as
    `builtins.stickslip_law` (a PyRunner's command runs in __main__)."""
    from yade import (Bo1_Box_Aabb, Bo1_Facet_Aabb, Bo1_Sphere_Aabb, Bo1_Wall_Aabb, ForceResetter,
                      Ig2_Box_Sphere_ScGeom, Ig2_Facet_Sphere_ScGeom, Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom,
                      InsertionSortCollider, InteractionLoop, Ip2_ViscElMat_ViscElMat_ViscElPhys,
                      Law2_ScGeom_ViscElPhys_Basic, NewtonIntegrator)

    gravity = _vector3("gravity", gravity)
    damping = _number("damping", damping)
    if not 0 <= damping < 1:
        raise ValueError(f"damping = {damping!r}: must be in [0, 1)")
    extra = _extra_engines(extra)
    runner = stickslip_runner(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb(), Bo1_Wall_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(),
                         Ig2_Box_Sphere_ScGeom()],
                        [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
        runner,
        *extra,
        NewtonIntegrator(gravity=gravity, damping=damping),
    ]


def insert_stickslip(engines, ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True,
                     check=False):
    """Your engine list with the law's runner put right after its InteractionLoop. The list
    is not otherwise changed: its InteractionLoop must already use
    Ip2_ViscElMat_ViscElMat_ViscElPhys and Law2_ScGeom_ViscElPhys_Basic (the law checks the
    rest at its first step)."""
    from yade.wrapper import InteractionLoop

    engines = list(engines)
    loops = [k for k, e in enumerate(engines) if isinstance(e, InteractionLoop)]
    if len(loops) != 1:
        raise ValueError(f"engines has {len(loops)} InteractionLoop: insert_stickslip needs exactly one")
    for what, functors, want in (("Ip2", engines[loops[0]].physDispatcher.functors,
                                  "Ip2_ViscElMat_ViscElMat_ViscElPhys"),
                                 ("Law2", engines[loops[0]].lawDispatcher.functors, "Law2_ScGeom_ViscElPhys_Basic")):
        names = [type(f).__name__ for f in functors]
        if names != [want]:
            raise ValueError(f"engines: the InteractionLoop's {what} functors are {names}; the stick-slip law needs "
                             f"[{want}()] there (YADE's ViscEl law gives the normal force)")
    runner = stickslip_runner(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    return engines[:loops[0] + 1] + [runner] + engines[loops[0] + 1:]


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


def velocity_verlet_start(law=None):
    """Make YADE's first step the start of velocity Verlet (pyref, LIGGGHTS), for a run that
    must be their twin; call it once, instead of the first O.step().

    YADE's leapfrog takes a body's velocity as v(t - dt/2): its first step computes the
    forces from v(0), loads every spring by V_s dt and gives the whole kick
    v(dt/2) = v(0) + dt F(0)/m. Velocity Verlet evaluates the forces at the start with no
    time elapsed (the springs not loaded) and gives half a kick. This step does the same:
    the law's forces at x(0), v(0) as a setup evaluation (law.setup_step), then each
    dynamic sphere gets v(dt/2) = v(0) + dt/2 F(0)/m (the mean of YADE's v(0) and
    v(0) + dt F(0)/m), x(dt) = x(0) + dt v(dt/2), and its spin likewise. From then on
    leapfrog and velocity Verlet give the same positions and forces."""
    import builtins

    from yade import O, Quaternion, Sphere, Vector3

    law = builtins.stickslip_law if law is None else law
    if O.iter != 0:
        raise RuntimeError(f"velocity_verlet_start: the scene is at iteration {O.iter}; it starts a run (iteration 0)")
    bodies = [b for b in O.bodies if b is not None and b.dynamic]
    for b in bodies:
        if not isinstance(b.shape, Sphere) or b.isClump or b.isClumpMember:
            raise ValueError(f"velocity_verlet_start: body {b.id} is not a free sphere (clumps and other shapes "
                             f"are not supported)")
    # (copies: a State's vectors are views of YADE's own)
    start = [(Vector3(b.state.pos), Vector3(b.state.vel), Vector3(b.state.angVel), Quaternion(b.state.ori))
             for b in bodies]
    law.setup_step = True
    O.step()
    dt = O.dt
    for b, (x0, v0, w0, q0) in zip(bodies, start):
        s = b.state
        v = v0 + 0.5 * (s.vel - v0)
        s.vel, s.pos = v, x0 + dt * v
        w = w0 + 0.5 * (s.angVel - w0)
        if w != s.angVel:
            s.angVel = w
            s.ori = (Quaternion(w / w.norm(), w.norm() * dt) * q0) if w.norm() > 0 else q0
