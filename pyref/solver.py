# SPDX-License-Identifier: GPL-2.0-or-later
"""pyref: a small reference DEM solver for disks (2D) and spheres (3D) on plane walls.

Newton's law (eq. 1) is integrated by velocity Verlet, the scheme LIGGGHTS uses
(and whose positions equal YADE's leapfrog): forces at x(t+dt) use v(t+dt/2).
Contact forces come from pyref/laws.py and nowhere else. Only the effects the
scene switches on are computed (gravity, rotation, damping, moving walls).
"""
from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np

from .laws import _count_nonzero, _dot, normal_force, rotate_history, tangential_force
from .vectors import ZERO, Rotation, all_finite, cross, scatter

PAIR_BRUTE_FORCE_MAX = 64  # below this many grains, test every pair (no tree)


class Contacts(NamedTuple):
    """The touching contacts of the last force evaluation, one row each."""
    i: np.ndarray  # grain index
    j: np.ndarray  # grain index, or N + wall index
    key: np.ndarray  # i*(N+W) + j, the contact's identity
    n: np.ndarray  # (K, 3) unit normal from i to j
    fn: np.ndarray  # normal force magnitude
    force: np.ndarray  # (K, 3) tangential force on i
    slipped: np.ndarray  # bool: slipped during the last step
    delta: np.ndarray  # overlap


class _Layout(NamedTuple):
    """The rows of the touching contacts, kept while the same contacts touch."""
    pairs: tuple | None  # the candidate pairs they were found among
    sig: tuple  # bytes of the touching masks (pairs, grains x walls)
    P: int  # touching grain pairs (the first rows)
    t: np.ndarray | None  # their indices among the candidates; None: all touch
    gi: np.ndarray  # grain of each wall row
    wk: np.ndarray  # wall of each wall row
    flat: np.ndarray  # gi * W + wk, the rows' places in the grains x walls overlaps
    fixed_n: np.ndarray | None  # the wall rows' normals (i -> wall) when walls are fixed
    i: np.ndarray
    j: np.ndarray
    key: np.ndarray
    on_flat: np.ndarray  # force rows (on i, then on the pairs' j): their components' flat places in (N, 3)


class Recording(NamedTuple):
    """What a run recorded, one row every `output.every` steps (and the start). Grains,
    contacts and walls in the order the scene's [output] names them; `dim` components."""
    t: np.ndarray  # (R,)
    x: np.ndarray  # (R, G, dim) positions
    v: np.ndarray  # (R, G, dim) velocities
    w: np.ndarray | None  # (R, G, 1 in 2D or 3) spins, None without rotation
    fn: np.ndarray  # (R, C) normal force of each recorded contact (0: not touching)
    ft: np.ndarray  # (R, C, dim) tangential force on the contact's first grain
    slips: np.ndarray  # (R, C) steps with a slip since the previous row
    angle: np.ndarray  # (R, Wr) angle of each recorded wall
    n_contacts: np.ndarray | None  # (R,) with output.stats
    ekin: np.ndarray | None  # (R,) with output.stats
    energy: dict | None  # name -> (R,) with output.energy (ENERGY_FIELDS)
    steps: int
    wall_time_s: float
    slip_stats: np.ndarray | None = None  # (R, 4) with output.slip_stats (columns.SLIP_STATS)


# Energy books (output.energy): kinetic, elastic (normal + tangential springs),
# dissipated (all contact losses; of which the tangential law's slips and dashpot),
# work done by gravity and by imposed velocities / moving walls.
ENERGY_FIELDS = ("e_kin", "e_elastic", "e_dissipated", "e_slip", "e_dashpot", "w_gravity", "w_drive")


class Simulation:
    def __init__(self, scene, record=True, energy=None):
        self.scene = scene
        s = scene
        self.dim = s.dimension
        self.dt = s.dt
        eff = s.effects
        self.gravity_on = eff["gravity"]
        self.rotation_on = eff["rotation"]
        self.moving_walls = eff["moving_walls"]
        self.p = s.contact.law_params(eff)

        g = s.grains
        self.N = len(g)
        self.x = np.array([q.position for q in g], float)
        self.v = np.array([q.velocity for q in g], float)
        self.w = np.array([q.angular_velocity for q in g], float)  # zero unless effects.rotation
        self.r = np.array([q.radius for q in g])
        self.m = np.array([s.grain_mass(q) for q in g])
        self.inertia = np.array([s.grain_inertia(q) for q in g])
        self.imposed = np.zeros((self.N, 3), bool)
        for i, q in enumerate(g):
            for a in q.imposed:
                self.imposed[i, "xyz".index(a)] = True
        # fixed grains: every velocity component held at zero, and the spin too
        self.fixed = np.array([q.fixed for q in g], bool)
        self.any_fixed = bool(self.fixed.any())
        self.v[self.fixed] = 0.0
        self.w[self.fixed] = 0.0
        self.imposed[self.fixed] = True
        self.v_imposed = self.v.copy()
        self.any_imposed = bool(self.imposed.any())
        self.g = s.gravity if self.gravity_on else np.zeros(3)
        self.turning_gravity = self.gravity_on and bool(s.gravity_rate or s.gravity_spinup[1])
        # Per-step constants, computed once (the same numbers the step would compute).
        self.half_dt = 0.5 * self.dt
        # The step's factors as 0-d arrays: numpy multiplies by them faster than by floats.
        self.dt_0d, self.half_dt_0d = np.array(self.dt), np.array(self.half_dt)
        self.m_col, self.inertia_col, self.r_col = self.m[:, None], self.inertia[:, None], self.r[:, None]
        self.weight = self.m_col * self.g
        # The same divisors repeated along the 3 components: dividing equal shapes skips
        # numpy's broadcasting, which costs more than the division on a few grains.
        self.m_rows, self.inertia_rows = np.repeat(self.m_col, 3, 1), np.repeat(self.inertia_col, 3, 1)

        self.walls = s.walls
        self.W = len(s.walls)
        self.wall_n0 = np.array([w.normal for w in s.walls]).reshape(-1, 3)
        self.wall_p0 = np.array([w.point for w in s.walls]).reshape(-1, 3)
        self.wall_v = np.array([w.velocity for w in s.walls]).reshape(-1, 3)
        self.wall_rot_steps = [s.rotation_steps(w) if w.rotation else 0 for w in s.walls]
        self.wall_rate = [s.rotation_rate(w) if w.rotation else 0.0 for w in s.walls]
        # Fixed walls: points, normals, rates and offsets p.n never change. The offsets and
        # radii are repeated for every grain x wall (no broadcasting in _contacts).
        self.fixed_walls = (self.wall_p0, self.wall_n0, np.zeros(self.W),
                            np.tile(np.sum(self.wall_p0 * self.wall_n0, axis=1), (self.N, 1)))
        self.r_walls = np.repeat(self.r_col, self.W, 1)
        self.turning_walls = [k for k, w in enumerate(s.walls) if w.rotation]
        # Walls whose velocities are all +0 stay at p0 + 0 (what p0 + v*t*dt gives then).
        self.walls_translate = bool(self.wall_v.any() or np.signbit(self.wall_v).any())
        self.wall_p_still = self.wall_p0 + 0.0
        self.wall_turn = [Rotation(w.rotation.axis) if w.rotation else None for w in s.walls]
        self.step_no = 0

        # Contact state, kept sorted by key = i*(N+W) + j, j = grain index or N + wall.
        self.keys = np.zeros(0, np.int64)
        self.D = np.zeros((0, 3))
        self.sliding = np.zeros(0, bool)  # the static_dynamic law's state (p.has_state)
        self.pairs = None  # candidate pairs: (a, b, r_a + r_b), a < b
        self.x_at_build = None
        self._layout = None  # rows of the touching contacts (_make_layout)
        self.skin = 0.2 * float(self.r.min())

        # energy books: when the scene records them, or when asked (tests)
        self.energy = s.output.energy if energy is None else energy
        self.e_diss = 0.0  # energy taken out by the contact laws (dashpots, slips, clipping)
        self.e_slip = 0.0  # of which the tangential law's slips
        self.e_dashpot = 0.0  # and its dashpot
        self.w_grav = 0.0  # work of gravity
        self.w_drive = 0.0  # work of imposed velocities and moving walls
        self.names = {q.name: i for i, q in enumerate(g)}
        self.names.update({w.name: self.N + k for k, w in enumerate(s.walls)})
        self.slip_steps = 0
        self.last_e_t = np.zeros(0)  # per contact, what the tangential law dissipated in the last step (energy on)
        self.slip_stats = s.output.slip_stats  # output.slip_stats: |V_s| of each contact kept
        self.vs_mag = np.zeros(0)
        self.record = record
        self._setup_recording()
        # Setup forces: no time has passed, so no spring increment (as LIGGGHTS' setup).
        self.f, self.torque = self._forces(elapsed=0.0)

    # ------------------------------------------------------------ walls
    def _wall_state(self):
        """Wall points, normals and offsets p.n (per wall, or per grain x wall for fixed
        walls) at the current time, and angular rates during the last step."""
        if not self.moving_walls:
            return self.fixed_walls
        if self.walls_translate:
            p = self.wall_p0 + self.wall_v * self.step_no * self.dt
        else:
            p = self.wall_p_still.copy()
        n = self.wall_n0.copy()
        rates = np.zeros(self.W)
        for k in self.turning_walls:
            rot, nrot = self.walls[k].rotation, self.wall_rot_steps[k]
            R = self.wall_turn[k].matrix(self.wall_rate[k] * self.dt * min(self.step_no, nrot))
            p[k] = rot.pivot + R @ (p[k] - rot.pivot)
            n[k] = R @ n[k]
            rates[k] = self.wall_rate[k] if 1 <= self.step_no <= nrot else 0.0
        return p, n, rates, np.add.reduce(p * n, 1)  # (p * n).sum(axis=1), without its Python layer

    def _wall_velocity(self, wk, cp, rates):
        """Velocity of walls wk at contact points cp during the last step."""
        vw = self.wall_v.take(wk, 0)
        for k in rates.nonzero()[0]:
            rot = self.walls[k].rotation
            if self.W == 1:  # every row is this wall's (the same sums as selecting them all)
                vw += rates[k] * cross(rot.axis[None, :], cp - rot.pivot)
                continue
            sel = wk == k
            vw[sel] += rates[k] * cross(rot.axis[None, :], cp[sel] - rot.pivot)  # (the axis row broadcasts)
        return vw

    def wall_angle(self, k):
        w = self.walls[k]
        return self.wall_rate[k] * self.dt * min(self.step_no, self.wall_rot_steps[k]) if w.rotation else 0.0

    # ------------------------------------------------------------ contact detection
    def _candidate_pairs(self):
        """Pairs of grains that may touch: (a, b, r_a + r_b), with a < b."""
        N = self.N
        if N < 2:
            return None
        if N <= PAIR_BRUTE_FORCE_MAX:
            if self.pairs is None:
                self.pairs = self._pair_list(np.array(np.triu_indices(N, 1)).T)
            return self.pairs
        # Verlet list with a skin: rebuilt only when some grain has moved skin/2.
        if self.x_at_build is not None:
            moved = np.max(np.sum((self.x - self.x_at_build) ** 2, axis=1))
            if moved < (0.5 * self.skin) ** 2:
                return self.pairs
        from scipy.spatial import cKDTree
        tree = cKDTree(self.x[:, : self.dim])
        self.pairs = self._pair_list(tree.query_pairs(2 * self.r.max() + self.skin, output_type="ndarray"))
        self.x_at_build = self.x.copy()
        return self.pairs

    def _pair_list(self, pairs):
        """(a, b, r_a + r_b) of an (M, 2) array of grain pairs."""
        a, b = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
        return a, b, self.r[a] + self.r[b]

    def _contacts(self):
        """All touching grain-grain and grain-wall contacts: i, j, key, n (i -> j), overlap,
        the velocity of the walls' contact points (None when the walls are fixed: zero)
        and how many of the rows, the first ones, are grain pairs."""
        x = self.x
        pairs = self._candidate_pairs()
        pair_hit = wall_hit = None
        if pairs is not None and len(pairs[0]):
            a, b, reach = pairs
            d = x.take(b, 0) - x.take(a, 0)
            dist = np.sqrt(_dot(d, d))
            delta_p = reach - dist
            pair_hit = delta_p > ZERO
        if self.W:
            p, n, rates, offset = self._wall_state()
            delta_w = self.r_walls - (x @ n.T - offset)
            wall_hit = delta_w > ZERO
        # Which contacts touch rarely changes from one step to the next: the rows' indices
        # and keys are rebuilt only when it does.
        sig = (None if pair_hit is None else pair_hit.tobytes(), None if wall_hit is None else wall_hit.tobytes())
        lay = self._layout
        if lay is None or lay.pairs is not pairs or lay.sig != sig:
            lay = self._layout = self._make_layout(pairs, sig, pair_hit, wall_hit)
        K, P = len(lay.i), lay.P
        n_all, delta = np.empty((K, 3)), np.empty(K)  # the pairs' rows, then the walls'
        if P:
            if lay.t is not None:  # only some candidate pairs touch
                d, dist, delta_p = d.take(lay.t, 0), dist.take(lay.t), delta_p.take(lay.t)
            np.divide(d, dist[:, None], out=n_all[:P])
            delta[:P] = delta_p
        v_wall = None
        if K > P:
            dw = delta_w.take(lay.flat, out=delta[P:])  # delta_w[gi, wk]
            if self.moving_walls:
                n_w = n.take(lay.wk, 0)
                v_wall = self._wall_velocity(lay.wk, x.take(lay.gi, 0) - (self.r.take(lay.gi) - dw)[:, None] * n_w,
                                             rates)
                np.negative(n_w, out=n_all[P:])
            else:
                n_all[P:] = lay.fixed_n
        return lay.i, lay.j, lay.key, n_all, delta, v_wall, P

    def _make_layout(self, pairs, sig, pair_hit, wall_hit):
        """The rows of the contacts that touch (pair_hit over the candidate pairs,
        wall_hit over grains x walls), grain pairs first."""
        N, W = self.N, self.W
        P, t = 0, None
        i_parts, j_parts = [], []
        if pair_hit is not None:
            a, b, _ = pairs
            P = int(np.count_nonzero(pair_hit))
            if P < len(pair_hit):
                t = pair_hit.nonzero()[0]
                a, b = a.take(t), b.take(t)
            if P:
                i_parts.append(a)
                j_parts.append(b)
        z = np.zeros(0, np.int64)
        gi = wk = z
        if wall_hit is not None:
            gi, wk = wall_hit.nonzero()
            if len(gi):
                i_parts.append(gi)
                j_parts.append(N + wk)
        i = z if not i_parts else i_parts[0] if len(i_parts) == 1 else np.concatenate(i_parts)
        j = z if not j_parts else j_parts[0] if len(j_parts) == 1 else np.concatenate(j_parts)
        fixed_n = None if self.moving_walls else -self.wall_n0.take(wk, 0)
        on = np.concatenate((i, j[:P])) if P else i  # the rows' grains, then the pairs' second grains
        return _Layout(pairs, sig, P, t, gi, wk, gi * W + wk, fixed_n, i, j, i * (N + W) + j,
                       (on[:, None] * 3 + np.arange(3)).ravel())

    # ------------------------------------------------------------ forces
    def _forces(self, elapsed=None):
        """Contact (+ gravity) forces and torques at the current state; `elapsed` is the
        time over which the springs are loaded (one step, or 0 at setup)."""
        dt = self.dt if elapsed is None else elapsed
        N = self.N
        i, j, key, n, delta, v_wall, P = self._contacts()  # rows :P are grain pairs
        # Relative velocity of i's contact point with respect to j's (docs/law.md step 1);
        # a fixed wall's is zero, and v - 0 = v.
        v_rel = self.v.take(i, 0)
        if P:
            v_rel[:P] -= self.v.take(j[:P], 0)
        if v_wall is not None:
            v_rel[P:] -= v_wall
        if self.rotation_on:
            # Lever arms from each centre to the contact point, taken midway in the overlap
            # (c = r - delta/2, as LIGGGHTS and YADE place it; a wall has none):
            # w_i x (c_i n) + w_j x (c_j n) = (c_i w_i + c_j w_j) x n, both along n.
            grain_j = j < N
            j_grain = np.minimum(j, N - 1)  # j, or any grain for a wall (masked out below)
            c_i = self.r.take(i) - 0.5 * delta
            c_j = np.where(grain_j, self.r.take(j_grain) - 0.5 * delta, 0.0)
            w_j = np.where(grain_j[:, None], self.w.take(j_grain, 0), 0.0)
            v_rel = v_rel + cross(c_i[:, None] * self.w.take(i, 0) + c_j[:, None] * w_j, n)
        v_n = _dot(v_rel, n)
        V_s = v_rel - v_n[:, None] * n  # eq. 6
        fn = normal_force(delta, v_n, self.p)  # eq. 3

        # Carry each contact's spring (and state) over from the last step; new contacts start
        # at zero (static), ended contacts are dropped (their keys are simply not carried).
        sliding = None
        if not self.p.has_spring:
            D = np.zeros((len(key), 3))
        elif key is self.keys or key.tobytes() == self.keys.tobytes():  # (np.array_equal, without its overhead)
            D = rotate_history(self.D, n)  # same contacts as last step (the usual case)
            sliding = self.sliding if self.p.has_state else None
        else:
            D = np.zeros((len(key), 3))
            sliding = np.zeros(len(key), bool) if self.p.has_state else None
            if len(self.keys) and len(key):
                order = np.argsort(self.keys)
                sorted_keys = self.keys[order]
                pos = np.minimum(np.searchsorted(sorted_keys, key), len(sorted_keys) - 1)
                old = sorted_keys[pos] == key
                D[old] = rotate_history(self.D[order[pos[old]]], n[old])
                if sliding is not None:
                    sliding[old] = self.sliding[order[pos[old]]]
        tan = tangential_force(D, V_s, fn, dt, self.p, energy=self.energy, sliding=sliding)
        if self.p.has_state:
            self.sliding = tan.slipped  # (static_dynamic: sliding after a step whose force was cut)
        F_s, D, slipped = tan.force, tan.spring, tan.slipped
        if self.slip_stats:
            self.vs_mag = np.sqrt(_dot(V_s, V_s))

        if self.energy and len(key):
            self._account_contact_energy(fn, delta, v_n, tan, dt)

        self.keys, self.D = key, D
        self.n_slipped = int(_count_nonzero(slipped))
        self.slip_steps += self.n_slipped
        self.contacts = Contacts(i, j, key, n, fn, F_s, slipped, delta)

        # Forces F on i, and -F on grain j (walls take nothing), in one scatter.
        K = len(key)
        F = np.empty((K + P, 3))
        np.add(-fn[:, None] * n, F_s, out=F[:K])
        np.negative(F[:P], out=F[K:])
        on = self._layout.on_flat
        f = scatter(on, F, N)
        torque = None
        if self.rotation_on:
            # Torques (c_i n) x F_s on i and (-c_j n) x (-F_s) = c_j (n x F_s) on j.
            c = cross(n, F_s)
            torque = scatter(on, np.concatenate((c_i[:, None] * c, c_j[:P, None] * c[:P])) if P else c_i[:, None] * c,
                              N)
        if self.gravity_on:
            if self.turning_gravity:  # the gravity of the time the positions belong to
                self.g = self.scene.gravity_at(self.step_no * self.dt)
                self.weight = self.m_col * self.g
            f += self.weight
        return f, torque

    def slip_statistics(self):
        """The row's columns.SLIP_STATS over grain-grain contacts (docs in columns.py)."""
        c, p = self.contacts, self.p
        sel = c.slipped & (c.j < self.N) & (c.fn > 0)  # no normal force: no friction to count
        fn, vs = c.fn[sel], self.vs_mag[sel]
        drop = 2.0 * (p.mu_s - p.mu_k) * fn  # the force a stick phase must climb after a slip
        above_vd = vs * p.nu_s >= drop  # |V_s| >= V_d, written without dividing by nu_s = 0
        above_vstar = vs * (p.nu_s + p.ks * self.dt) >= drop
        ratio = np.sqrt(_dot(c.force[sel], c.force[sel])) / np.where(fn > 0, fn, np.inf)
        return (int(sel.sum()), int(above_vd.sum()), int(above_vstar.sum()), float(ratio.sum()))

    def _account_contact_energy(self, fn, delta, v_n, tan, dt):
        """Energy each contact took out this step. Normal: the non-elastic part of the
        force times the approach, (Fn - Kn*delta)*v_n*dt. Tangential: the law's own
        account (dashpot + slips = work received less the spring's gain, docs/law.md)."""
        e_n = (fn - self.p.kn * delta) * v_n * dt
        e_t = tan.dissipated_dashpot + tan.dissipated_slip
        self.last_e_t = e_t
        self.e_slip += float(tan.dissipated_slip.sum())
        self.e_dashpot += float(tan.dissipated_dashpot.sum())
        self.e_diss += float(e_n.sum() + e_t.sum())

    # ------------------------------------------------------------ integration
    def step(self):
        a = self.f / self.m_rows
        v_half = self.v + self.half_dt_0d * a  # (0.5 * dt) * a
        if self.any_imposed:
            v_half = np.where(self.imposed, self.v_imposed, v_half)
        x_old = self.x
        self.x = self.x + self.dt_0d * v_half
        if self.dim == 2:
            self.x[:, 2] = 0.0
            v_half[:, 2] = 0.0
        if self.rotation_on:
            w_half = self.w + self.half_dt_0d * self.torque / self.inertia_rows
            if self.dim == 2:
                w_half[:, :2] = 0.0
            if self.any_fixed:
                w_half[self.fixed] = 0.0
        f_old = self.f
        self.v = v_half
        if self.rotation_on:
            self.w = w_half
        self.step_no += 1
        self.f, self.torque = self._forces()
        self.v = v_half + self.half_dt_0d * self.f / self.m_rows
        if self.any_imposed:
            self.v = np.where(self.imposed, self.v_imposed, self.v)
        if self.dim == 2:
            self.v[:, 2] = 0.0
        if self.rotation_on:
            self.w = w_half + self.half_dt_0d * self.torque / self.inertia_rows
            if self.dim == 2:
                self.w[:, :2] = 0.0
            if self.any_fixed:
                self.w[self.fixed] = 0.0
        if self.energy:
            dx = self.x - x_old
            if self.gravity_on:
                self.w_grav += float(np.sum(self.m[:, None] * self.g * dx))
            if self.any_imposed:
                # The drive supplies whatever force keeps the imposed components fixed:
                # minus the other forces on them (trapezoid over the step).
                fc = -0.5 * (f_old + self.f)
                self.w_drive += float(np.sum(np.where(self.imposed, fc * dx, 0.0)))
            if self.moving_walls and self.W:
                self._account_wall_work()

    def _account_wall_work(self):
        """Work of moving walls on the grains: contact force on the grain times the
        wall's velocity at the contact point, over the step."""
        i, j, _, n, fn, F_s, _, delta = self.contacts
        on_wall = j >= self.N
        if on_wall.any():
            rates = self._wall_state()[2]
            i, n, delta = i[on_wall], n[on_wall], delta[on_wall]
            cp = self.x[i] + (self.r[i] - delta)[:, None] * n
            vw = self._wall_velocity(j[on_wall] - self.N, cp, rates)
            F = -fn[on_wall, None] * n + F_s[on_wall]
            self.w_drive += float(np.sum(F * vw) * self.dt)

    # ------------------------------------------------------------ energies
    def kinetic_energy(self):
        e = 0.5 * float(np.sum(self.m * _dot(self.v, self.v)))
        if self.rotation_on:
            e += 0.5 * float(np.sum(self.inertia * _dot(self.w, self.w)))
        return e

    def elastic_energy(self):
        e = 0.5 * self.p.kn * float(np.sum(self.contacts.delta**2))
        if self.p.has_spring:
            e += 0.5 * self.p.ks * float(np.sum(self.D * self.D))
        return e

    # ------------------------------------------------------------ recording
    def _setup_recording(self):
        out = self.scene.output
        self.rec_grains = np.array([self.names[g] for g in out.grains], np.int64)
        NW = self.N + self.W
        pairs = [(self.names[a], self.names[b]) for a, b in out.contacts]
        # A contact a-b is stored with i < j for grain pairs; remember the sign.
        self.rec_keys = np.array([min(a, b) * NW + max(a, b) if b < self.N else a * NW + b
                                  for a, b in pairs], np.int64)
        self.rec_sign = np.array([1.0 if (b >= self.N or a < b) else -1.0 for a, b in pairs])
        self.rec_slips = np.zeros(len(pairs), np.int64)
        self.rec_walls = [k for k, w in enumerate(self.walls) if w.name in out.walls]
        self.rows = []
        self._rec_rows_of = None  # the _Layout that _recorded_rows belong to

    def _count_slips(self):
        if not len(self.rec_keys):
            return
        if not self.n_slipped:
            return
        rec, row = self._recorded_rows()
        self.rec_slips[rec] += self.contacts.slipped[row]

    def _recorded_rows(self):
        """The recorded contacts that touch (indices into rec_keys) and their rows in
        self.contacts; kept while the same contacts touch."""
        lay = self._layout
        if self._rec_rows_of is not lay:
            lookup = {int(k): idx for idx, k in enumerate(lay.key)}
            hit = [(r, lookup[int(k)]) for r, k in enumerate(self.rec_keys) if int(k) in lookup]
            self._rec_rows = (np.array([h[0] for h in hit], np.int64), np.array([h[1] for h in hit], np.int64))
            self._rec_rows_of = lay
        return self._rec_rows

    def record_row(self):
        """One row of the Recording (see there), as a tuple of arrays."""
        d, g = self.dim, self.rec_grains
        C = len(self.rec_keys)
        fn, ft = np.zeros(C), np.zeros((C, d))
        if C:
            c = self.contacts
            rec, row = self._recorded_rows()
            fn[rec], ft[rec] = c.fn[row], c.force[row, :d] * self.rec_sign[rec, None]
        spin = None
        if self.rotation_on:
            spin = self.w.take(g, 0)[:, 2:] if d == 2 else self.w.take(g, 0)
        row = (self.step_no * self.dt, self.x.take(g, 0)[:, :d], self.v.take(g, 0)[:, :d], spin, fn, ft,
               self.rec_slips.copy(), [self.wall_angle(k) for k in self.rec_walls])
        self.rec_slips[:] = 0
        stats = (len(self.contacts.key), self.kinetic_energy()) if self.scene.output.stats else None
        slip = None
        if self.slip_stats:
            slip = self.slip_statistics()
        energy = None
        if self.energy:
            energy = (self.kinetic_energy(), self.elastic_energy(), self.e_diss, self.e_slip, self.e_dashpot,
                      self.w_grav, self.w_drive)
        self.rows.append(row + (stats, energy, slip))

    def recording(self, steps=None, wall_time_s=0.0) -> Recording:
        """The rows recorded so far (record_row), as a Recording."""
        rows = self.rows
        R, G, C, d = len(rows), len(self.rec_grains), len(self.rec_keys), self.dim
        col = lambda k, shape: np.array([r[k] for r in rows], float).reshape((R,) + shape)  # noqa: E731
        stats = self.scene.output.stats
        return Recording(
            t=col(0, ()), x=col(1, (G, d)), v=col(2, (G, d)),
            w=col(3, (G, 1 if d == 2 else 3)) if self.rotation_on else None,
            fn=col(4, (C,)), ft=col(5, (C, d)), slips=col(6, (C,)).astype(np.int64),
            angle=col(7, (len(self.rec_walls),)),
            n_contacts=np.array([r[8][0] for r in rows], np.int64) if stats else None,
            ekin=np.array([r[8][1] for r in rows]) if stats else None,
            energy={f: np.array([r[9][k] for r in rows]) for k, f in enumerate(ENERGY_FIELDS)}
            if self.energy else None,
            steps=self.step_no if steps is None else steps, wall_time_s=wall_time_s,
            slip_stats=np.array([r[10] for r in rows], float).reshape(R, 4) if self.scene.output.slip_stats else None)

    # ------------------------------------------------------------ driver
    def run(self, steps=None, progress=None) -> Recording:
        """Run the scene (or `steps` steps of it); returns the Recording."""
        steps = self.scene.steps if steps is None else steps
        every = self.scene.output.every
        t0 = time.perf_counter()
        if self.record:
            self.record_row()
        for k in range(steps):
            self.step()
            if self.record:
                self._count_slips()
                if self.step_no % every == 0:
                    self.record_row()
            if progress is not None and k % 2000 == 0:
                progress(k, steps)
            if not (all_finite(self.x) and all_finite(self.v)):
                raise FloatingPointError(f"non-finite position or velocity at step {self.step_no} "
                                         f"(t = {self.step_no * self.dt:g} s)")
        if progress is not None:
            progress(steps, steps)
        return self.recording(steps, time.perf_counter() - t0)
