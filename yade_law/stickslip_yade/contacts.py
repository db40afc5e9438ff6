# SPDX-License-Identifier: GPL-2.0-or-later
"""Contact bookkeeping: the law's state, one row per contact, and how a step finds its
contacts cheaply.

Every read from YADE costs 0.3-0.7 us, a whole-scene read of the interactions ~0.3 us per
contact. So when the law ran at the previous iteration, the contacts are last step's minus
those whose overlap became negative (sphere pairs: recomputed; other shapes: YADE's
geometry, read anyway), plus contacts made in this step, whose number is YADE's count of
real interactions less the survivors; only then are the bodies that gained one asked for
their interactions (per-body counts, one C++ call). Anything inconsistent, a sphere pair
within round-off of touching, a body appended or erased, a skipped iteration or a loaded
scene: the whole set is read again, a contact carried over only if YADE's iterMadeReal says
it was not broken and made again meanwhile.
"""
import numpy as np

from . import geometry
from .checks import check_new_contact, fail


def key(i1, i2):
    """A contact's key: id1 << 32 | id2 (ints or int64 arrays)."""
    return (i1 << 32) | i2


class ContactSet:
    """The contacts of the law's last step and their state."""

    # State carried from step to step, one row per contact, and saved with the scene: the
    # key, YADE's iterMadeReal, cellDist (periodic cells), the spring D, each contact's kn
    # and cn (read from YADE once), the last normal and tangential forces, slipped in the
    # last step, slip steps since the contact was made.
    ARRAYS = ("keys", "made", "cell", "D", "kn", "cn", "fn", "F_s", "slipped", "count")

    def __init__(self):
        self.full_reads = 0  # steps that read the whole interaction set (diagnostics, bench)
        self.clear()

    def clear(self):
        z = np.zeros(0)
        self.keys, self.made = np.zeros(0, np.int64), np.zeros(0, np.int64)
        self.cell = np.zeros((0, 3), np.int64)
        self.D, self.F_s = np.zeros((0, 3)), np.zeros((0, 3))
        self.kn, self.cn, self.fn = z, z, z
        self.slipped, self.count = np.zeros(0, bool), np.zeros(0, np.int64)
        self.forget()

    def forget(self):
        """Caches derived from the arrays and from YADE objects (rebuilt on demand)."""
        self.keyset = None  # the keys as a Python set (membership of candidate new contacts)
        self.sorted = None  # {key: row}, for row()
        self.idx = None  # geometry.Layout of the contacts (see index)
        self.wrappers = {}  # key -> YADE Interaction of contacts with a non-sphere

    def take(self, rows, keyset_updated=False):
        """Keep the contacts `rows` (an index or boolean array), in that order."""
        for k in self.ARRAYS:
            setattr(self, k, getattr(self, k)[rows])
        self.sorted = self.idx = None
        if not keyset_updated:
            self.keyset = None

    def append(self, new):
        """Append contacts (a dict of per-contact arrays, missing ones start at zero)."""
        m = len(new["keys"])
        if not m:
            return
        for k in self.ARRAYS:
            cur = getattr(self, k)
            add = new[k] if k in new else np.zeros((m,) + cur.shape[1:], cur.dtype)
            setattr(self, k, np.concatenate((cur, add)))
        if self.keyset is not None:
            self.keyset.update(new["keys"].tolist())
        self.sorted = self.idx = None

    def index(self, bodies, keys=None):
        """The geometry.Layout of `keys` (default: the law's contacts, cached while they do
        not change)."""
        if keys is not None:
            return geometry.Layout(keys, bodies.sphere, bodies.radius)
        if self.idx is None:
            self.idx = geometry.Layout(self.keys, bodies.sphere, bodies.radius)
        return self.idx

    def row(self, k):
        """The row of the contact with key k, or None."""
        if self.sorted is None:  # key -> row, rebuilt when the set of contacts changes
            self.sorted = dict(zip(self.keys.tolist(), range(len(self.keys))))
        return self.sorted.get(k)

    # ------------------------------------------------------------ finding this step's contacts
    def find(self, O, bodies, P, shift, it, continuing):
        """This step's contacts (the state arrays updated: broken ones dropped, new ones
        appended with fresh springs) and their geometry (geometry.assemble's dict)."""
        geo = self._fast(O, bodies, P, shift, it) if continuing else None
        if geo is None:
            geo = self._full(O, bodies, P, shift)
        return geo

    def _fast(self, O, bodies, P, shift, it):
        """Last step's contacts less the broken ones plus this step's new ones, from YADE's
        counts; None when the whole set must be read (see the module docstring)."""
        keys = self.keys
        lay = self.index(bodies)
        ss, other, pairs = lay.ss, lay.other, lay.pairs
        d, dist, delta = geometry.sphere_pairs(P, lay, self.cell, shift)
        # (the common step: no sphere pair broken nor near touching, one test for both)
        near = pairs and np.count_nonzero(delta <= lay.band_ss)
        if near and np.count_nonzero(np.abs(delta) <= lay.band_ss):
            return None
        g = geometry.with_walls(O, self.wrappers, lay.keys_other, P, lay, shift, self.cell)
        n_alive, broken = len(keys), None
        if (near and np.count_nonzero((delta < 0.0) & ss)) or g["nbroken"]:
            broken = delta < 0  # Law2_ScGeom_ViscElPhys_Basic drops a contact when its overlap < 0
            if len(other):
                broken &= ss
                broken[other] = g["broken"]
            n_alive -= int(broken.sum())
        made = O.interactions.countReal() - n_alive
        if made < 0 or made > max(16, n_alive // 8):  # many new contacts: one full read is cheaper
            return None
        if n_alive < len(keys):
            if self.keyset is not None:
                self.keyset.difference_update(keys[broken].tolist())
            alive = ~broken
            remap = np.cumsum(alive) - 1
            kept = ~g["broken"]
            g = {k: v[kept] for k, v in g.items() if k != "nbroken"}
            d, dist, delta = d[alive], dist[alive], delta[alive]
            self.take(alive, keyset_updated=True)
            lay = self.index(bodies)  # (its other rows: those of g)
        geo = geometry.assemble(lay, d, dist, delta, g)
        if made:
            new = self._new_ones(O, bodies, made, lay.i1, lay.i2)
            if new is None:
                return None
            geo = self._add(O, bodies, P, shift, geo, *new, it)
        return geo

    def _new_ones(self, O, bodies, made, i1, i2):
        """The `made` contacts YADE has and the law has not: bodies with more real
        interactions than the law knows ask YADE for theirs (numIntrsOfEachBody, withBody)."""
        import yade._utils as yu

        nb = bodies.n
        known = np.bincount(i1, minlength=nb) + np.bincount(i2, minlength=nb)
        extra = np.array(yu.numIntrsOfEachBody(), np.int64)[:nb] - known
        if (extra < 0).any() or int(extra.sum()) != 2 * made:
            return None
        if self.keyset is None:
            self.keyset = set(self.keys.tolist())
        found = {}
        for b in np.flatnonzero(extra > 0).tolist():
            for I in O.interactions.withBody(b):
                k = key(I.id1, I.id2)
                if k not in self.keyset:
                    found[k] = I
        if len(found) != made:
            return None
        order = sorted(found)  # the same order whatever YADE's container order (checkpoints)
        return np.array(order, np.int64), [found[k] for k in order], None

    def _full(self, O, bodies, P, shift):
        """Read the whole set of real interactions; carry the state of contacts that were
        real at the law's last step and not broken and made again since (iterMadeReal)."""
        self.full_reads += 1
        L = O.interactions.all(True)  # real interactions only
        m = len(L)
        i1 = np.fromiter([I.id1 for I in L], np.int64, m)
        i2 = np.fromiter([I.id2 for I in L], np.int64, m)
        made = np.fromiter([I.iterMadeReal for I in L], np.int64, m)
        keys = key(i1, i2)
        order = np.argsort(keys)
        keys, made, L = keys[order], made[order], [L[j] for j in order.tolist()]
        hit, old = np.zeros(len(self.keys), bool), np.zeros(0, np.int64)
        if len(self.keys) and m:
            p = np.minimum(np.searchsorted(keys, self.keys), m - 1)
            hit = (keys[p] == self.keys) & (made[p] == self.made)
            old = p[hit]
        self.take(hit)  # carried contacts keep the law's order
        self.forget()
        is_new = np.ones(m, bool)
        is_new[old] = False
        new = np.flatnonzero(is_new)
        lay = self.index(bodies)
        other = lay.other
        for j in other.tolist():
            self.wrappers[int(self.keys[j])] = L[old[j]]
        d, dist, delta = geometry.sphere_pairs(P, lay, self.cell, shift)
        g = geometry.with_walls(O, self.wrappers, lay.keys_other, P, lay, shift, self.cell)
        if g["nbroken"]:
            fail("internal: a real interaction has no geometry")
        geo = geometry.assemble(lay, d, dist, delta, g)
        return self._add(O, bodies, P, shift, geo, keys[new], [L[j] for j in new.tolist()], made[new], None)

    def _add(self, O, bodies, P, shift, geo, keys, inters, made, it):
        """Append new contacts (fresh springs, their kn, cn and cellDist read once; `made`:
        YADE's iterMadeReal, or None: made at iteration `it`) and their geometry to `geo`."""
        if not len(keys):
            return geo
        m = len(keys)
        phys = [I.phys for I in inters]
        kn = np.fromiter([p.kn for p in phys], float, m)
        cn = np.fromiter([p.cn for p in phys], float, m)
        for I, p in zip(inters, phys):
            check_new_contact(I, p)
        if shift is not None:
            cell = np.array([I.cellDist.__getinitargs__() for I in inters], np.int64).reshape(m, 3)
        else:
            cell = np.zeros((m, 3), np.int64)
        self.append({"keys": keys, "made": np.full(m, it, np.int64) if made is None else made,
                     "cell": cell, "kn": kn, "cn": cn})
        for k, I in zip(keys.tolist(), inters):
            self.wrappers[k] = I
        lay = self.index(bodies, keys)
        i1, i2, ss = lay.i1, lay.i2, lay.ss
        d, dist, delta = geometry.sphere_pairs(P, lay, cell, shift)
        g = geometry.with_walls(O, self.wrappers, lay.keys_other, P, lay, shift, cell)
        if g["nbroken"]:
            fail("internal: a new real interaction has no geometry")
        new = geometry.assemble(lay, d, dist, delta, g)
        if (ss & (dist == 0)).any():
            k = int(np.flatnonzero(ss & (dist == 0))[0])
            fail(f"contact ({i1[k]}, {i2[k]}) at iteration {O.iter}: the two spheres have the same centre, "
                 f"so the contact has no normal direction")
        return geometry.join(geo, new)


def same_as_yade(O, keys):
    """check=True: the contact set the law found (fast path or full read) against YADE's real
    interactions."""
    theirs = {key(I.id1, I.id2) for I in O.interactions.all(True)}
    ours = set(keys.tolist())
    if theirs != ours or len(ours) != len(keys):
        miss, extra = sorted(theirs - ours)[:3], sorted(ours - theirs)[:3]
        fail(f"contact set differs from YADE's at iteration {O.iter}: missing "
             f"{[(k >> 32, k & 0xFFFFFFFF) for k in miss]}, extra {[(k >> 32, k & 0xFFFFFFFF) for k in extra]}")
