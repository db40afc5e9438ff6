# SPDX-License-Identifier: GPL-2.0-or-later
"""StickSlipLaw: the tangential law for all real interactions, one step per time step.

A step: the bodies' states (kinematics.py), this step's contacts and their geometry
(contacts.py, geometry.py), the law's arithmetic (the repository's kernel pyref/laws.py:
the spring turned into the tangent plane, eqs. 5, 7, 8, the slip), the energy books
(energy.py), then the forces and torques back to YADE, summed per body.
"""
import gc
import math
import uuid
from itertools import repeat

import numpy as np

from . import checkpoints, checks, contacts, energy, geometry
from .checks import LawError
from .contacts import ContactSet, key
from .kernel import LawParams, rotate_history, tangential_force
from .kinematics import Bodies, cell_motion, cross, finite_sum


class StickSlipLaw:
    """The tangential law for all real interactions; `step()` runs once per time step.

    After a step, `contact(id1, id2)` gives (Fn, F_s on id1 as (3,) array, slipped
    this step, slip steps since the contact was made) or None if not touching; the
    per-contact arrays (keys id1 << 32 | id2, D, fn, F_s, slipped, count) are those of
    `contacts` (contacts.ContactSet).
    """

    def __init__(self, ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True, check=False):
        p = checks.check_parameters(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing)
        self.ks, self.nu_s, self.mu_s, self.mu_k = p["ks"], p["nu_s"], p["mu_s"], p["mu_k"]
        self.reset, self.slip_timing = reset, slip_timing
        # The kernel's parameters; kn and nu_n are unused there (YADE's own law gives Fn).
        self.params = LawParams("stick_slip", None, None, self.ks, self.nu_s, self.mu_s, self.mu_k, reset, slip_timing)
        self.rotation = checks.flag("rotation", rotation)  # torques (and grain spin in V_s) only if rotation is on
        self.check = checks.flag("check", check)  # compare recomputed normals / normal forces with YADE's
        self.max_fn_error = 0.0  # largest |Fn - native Fn| / max(native Fn) seen with check=True
        self.checked = 0  # sphere-sphere contact-steps compared with check=True
        self.set_checks = 0  # steps whose contact set check=True compared with YADE's
        # Energy (O.trackEnergy): the least energy one contact took out in one step (docs/law.md,
        # "Energy"; >= 0 in the step mode when nu_s/Ks <= dt).
        self.min_dissipation = 0.0
        self.error = None  # the message of the error that stopped the run, if any
        self.setup_step = False  # True: the next step loads no spring (verlet_start.py)
        self.n_slipped = 0  # contacts that slipped in the last step
        self.contacts = ContactSet()
        self.bodies = None  # kinematics.Bodies of the scene, None: to be read
        # Checkpoints: the scene the state belongs to, the iteration of the law's last step
        # there (-1: none), and the token naming this law in its runner's command.
        self.token = uuid.uuid4().hex[:16]
        self.scene, self.last_iter = None, -1
        self.validated = None  # the engine list last validated (checks.validate_scene)

    def params_dict(self):
        return {"ks": self.ks, "nu_s": self.nu_s, "mu_s": self.mu_s, "mu_k": self.mu_k, "reset": self.reset,
                "slip_timing": self.slip_timing, "rotation": self.rotation, "check": self.check}

    # ------------------------------------------------------------------ the step
    def step(self):
        # The step creates many short-lived Python objects; the cyclic garbage collector,
        # triggered by them, would scan them all (about 1 us per contact).
        enabled = gc.isenabled()
        gc.disable()
        try:
            self._step()
        except LawError as e:  # kept: YADE wraps a PyRunner's exception into its own text
            self.error = str(e)
            raise
        finally:
            if enabled:
                gc.enable()

    def _step(self):
        from yade import O

        scene = O._sceneObj
        if self.scene is None or not scene == self.scene:  # Serializable ==: the same C++ object
            checkpoints.adopt(self, O, scene)
        it = O.iter
        continuing = it == self.last_iter + 1
        if self.bodies is None or self.bodies.changed(O):
            self.bodies = Bodies(O)
            self.contacts.keyset = self.contacts.idx = None
            self.validated = None  # validate the scene again
            continuing = False
        bodies = self.bodies
        engines = O.engines
        if self.validated is None or engines != self.validated:  # (Serializable ==: the same C++ object)
            checks.validate_scene(engines, self.token, bodies)
            self.validated = list(engines)
        self.last_iter = it
        # A setup step (verlet_start.py) evaluates the forces at the current state with no
        # time elapsed for the springs, as pyref's and LIGGGHTS' setup does.
        dt = 0.0 if self.setup_step else O.dt
        self.setup_step = False
        P, V, W = bodies.states_now(it)
        shift = cell_motion(O)

        c = self.contacts
        geo = c.find(O, bodies, P, shift, it, continuing)
        if self.check:
            contacts.same_as_yade(O, c.keys)
            self.set_checks += 1
        if len(c.keys) == 0:
            self.n_slipped = 0
            if O.trackEnergy:
                energy.book(O, 0.0, 0.0, 0.0, 0.0, 0.0)
            return
        lay = c.index(bodies)  # (the rows of geo)
        i1, i2, n, delta, fn = lay.i1, lay.i2, geo["n"], geo["delta"], geo["fn"]
        v_n, V_s, sv = geometry.velocities(lay, geo, V, W, self.rotation, c.cell, shift)
        if lay.pairs:
            fn = geometry.sphere_pair_fn(lay, geo, c.kn, c.cn, v_n, sv)
        if self.check:
            err, k = geometry.same_as_yade(O, geo, fn)
            self.max_fn_error, self.checked = max(self.max_fn_error, err), self.checked + k

        # The spring turned into the current tangent plane keeping its length, loaded by
        # this step's tangential displacement (eq. 7), the trial force (eq. 5), the slip and
        # the reset (eq. 8): all in the kernel, pyref/laws.py.
        book = O.trackEnergy
        tan = tangential_force(rotate_history(c.D, n), V_s, fn, dt, self.params, energy=book)
        F_s = tan.force
        apart = delta <= lay.zero
        if np.count_nonzero(apart):  # YADE's real interactions include spheres touching a wall or facet at zero
            # overlap; for the law that is no contact yet (docs/law.md step 3): no force, no spring
            F_s[apart], tan.spring[apart], tan.slipped[apart] = 0.0, 0.0, False
            if book:
                tan.dissipated_dashpot[apart] = tan.dissipated_slip[apart] = 0.0
        if not (finite_sum(fn) and finite_sum(F_s)):
            checks.finite_forces(it, i1, i2, fn, F_s)
        c.D, c.fn, c.F_s, c.slipped = tan.spring, fn, F_s, tan.slipped
        self.n_slipped = np.count_nonzero(tan.slipped)
        if self.n_slipped:
            c.count = c.count + tan.slipped
        if book:
            self.min_dissipation = min(self.min_dissipation,
                                       energy.book_step(O, tan, self.ks, c.kn, delta, fn, v_n, dt))
        self._apply(O, lay, geo, F_s)

    def _apply(self, O, lay, geo, F_s):
        """Forces and torques summed per body (in contact order: one bincount over the flat
        components), then one addF (and addT) per body that gets any."""
        n, delta, other = geo["n"], geo["delta"], lay.other
        nb = self.bodies.n
        f1, f2 = lay.flat()
        flat = F_s.ravel()
        F = (np.bincount(f1, flat, 3 * nb) - np.bincount(f2, flat, 3 * nb)).reshape(nb, 3)
        if not self.rotation:
            ids, F = nonzero_rows(F)
            list(map(O.forces.addF, ids, F, repeat(False)))
            return
        # Torques a1 x F_s on id1 and a2 x (-F_s) on id2; for sphere pairs c1 (n x F_s), c2 (n x F_s),
        # c = r - delta/2 (docs/law.md step 6).
        nF = cross(n, F_s)
        t1 = (lay.r1 - 0.5 * delta)[:, None] * nF
        t2 = (lay.r2 - 0.5 * delta)[:, None] * nF
        if len(other):
            a1, a2 = geometry.arms(lay, geo)
            Fo = F_s.take(other, 0)
            t1.put(lay.other3, cross(a1, Fo))
            t2.put(lay.other3, -cross(a2, Fo))
        T = (np.bincount(f1, t1.ravel(), 3 * nb) + np.bincount(f2, t2.ravel(), 3 * nb)).reshape(nb, 3)
        ids, F, T = nonzero_rows(F, T)
        # (permanent=False given: boost.python then skips filling the default, 15 % faster)
        list(map(O.forces.addF, ids, F, repeat(False)))
        list(map(O.forces.addT, ids, T, repeat(False)))

    # ------------------------------------------------------------------ queries
    # the per-contact arrays, as before the contact bookkeeping had its own class
    keys = property(lambda self: self.contacts.keys)
    D = property(lambda self: self.contacts.D)
    fn = property(lambda self: self.contacts.fn)
    F_s = property(lambda self: self.contacts.F_s)
    slipped = property(lambda self: self.contacts.slipped)
    count = property(lambda self: self.contacts.count)
    full_reads = property(lambda self: self.contacts.full_reads)

    def contact(self, id1, id2):
        """(Fn, F_s on id1, slipped this step, slip steps since made) or None."""
        if id1 > id2:
            got = self.contact(id2, id1)
            return None if got is None else (got[0], -got[1], got[2], got[3])
        c = self.contacts
        p = c.row(key(int(id1), int(id2)))
        if p is None:
            return None
        return float(c.fn[p]), c.F_s[p].copy(), bool(c.slipped[p]), int(c.count[p])

    def has_slipped(self, id1, id2):
        """True if the contact (id1, id2) touches and slipped in the last step (cheaper than
        contact(): what run_scene.py asks every step)."""
        c = self.contacts
        p = c.row(key(int(id1), int(id2)) if id1 < id2 else key(int(id2), int(id1)))
        return p is not None and bool(c.slipped[p])

    def lookup(self, id1, id2):
        """(Fn, F_s on id1, slipped this step) or None (what run_scene.py reads)."""
        got = self.contact(id1, id2)
        return None if got is None else got[:3]

    def n_contacts(self):
        return len(self.contacts.keys)


# Up to this many bodies the per-body lists are filtered in plain Python: numpy's
# any/flatnonzero/fancy indexing cost 2-3 us each whatever the size.
FEW = 64


def nonzero_rows(F, T=None):
    """(ids, F rows, T rows) as lists, of the bodies whose F (or T) has a non-zero component
    (NaN counts, as in numpy's any); bodies with neither get no addF/addT call."""
    nb = len(F)
    if nb <= FEW:
        Fl = F.tolist()
        if T is None:
            got = [i for i in range(nb) if any(Fl[i])]
            return got, [Fl[i] for i in got]
        Tl = T.tolist()
        got = [i for i in range(nb) if any(Fl[i]) or any(Tl[i])]
        if len(got) == nb:
            return got, Fl, Tl
        return got, [Fl[i] for i in got], [Tl[i] for i in got]
    if T is None:
        got = np.flatnonzero(F.any(axis=1))
        return got.tolist(), F.take(got, 0).tolist()
    got = np.flatnonzero(F.any(axis=1) | T.any(axis=1))
    if len(got) == nb:  # every body: no copies
        return range(nb), F.tolist(), T.tolist()
    return got.tolist(), F.take(got, 0).tolist(), T.take(got, 0).tolist()
