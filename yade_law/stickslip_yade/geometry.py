# SPDX-License-Identifier: GPL-2.0-or-later
"""Per-contact geometry and kinematics (docs/law.md step 1): the normal n from id1 to id2,
the overlap delta, the lever arms a1, a2 from the bodies' centres to the points whose
velocities meet, the relative velocity and its normal and tangential parts (eq. 6), and
YADE's normal force.

Sphere pairs are recomputed in numpy from the bodies' positions (lever arms r - delta/2
to the contact point midway in the overlap); contacts with a wall, facet or box take YADE's
normal, overlap and normal force, read one by one, and the wall's side of the contact is
the point of its surface nearest the sphere's centre.

On a scene of a few contacts a step costs numpy's per-call overhead, not arithmetic, so
rows are gathered with `take` (2D fancy indexing costs four times more), scattered with
`put` on flat indices, and tests are `count_nonzero` of a comparison rather than
`any`/`min`, which are reductions (2-3 us each whatever the size); the arithmetic is the
same, bit for bit.
"""
import numpy as np

from .checks import fail
from .kernel import dot
from .kinematics import cross, rows


class Layout:
    """Which contacts are sphere pairs and which meet a wall, facet or box ("other"), with
    the ids, radii and index arrays a step needs: computed once per set of contacts (keys
    id1 << 32 | id2; `sphere`, `radius`: per body)."""

    # A sphere pair whose recomputed overlap is within this share of r1 + r2 of zero may be
    # on either side of YADE's own test (round-off of the distance): read the set again.
    TOUCH_BAND = 1e-12

    def __init__(self, keys, sphere, radius):
        i1, i2 = keys >> 32, keys & 0xFFFFFFFF
        self.i1, self.i2, self.n = i1, i2, len(keys)
        self.ss = sphere[i1] & sphere[i2]
        self.other = np.flatnonzero(~self.ss)
        self.r1, self.r2 = radius[i1], radius[i2]
        self.rsum = self.r1 + self.r2
        self.band = self.TOUCH_BAND * self.rsum
        # delta <= band_ss somewhere: a sphere pair is broken (delta < 0) or within the band
        # (other rows: -1, never); one test of the common step for both (contacts.py)
        self.band_ss = np.where(self.ss, self.band, -1.0)
        self.zero = np.zeros(self.n)  # (comparing with an array is cheaper than with 0.0)
        self.pairs = len(self.other) < self.n  # any sphere pair
        self.all_pairs = not len(self.other)
        o = self.other
        self.keys_other = keys[o]
        self.other3 = (3 * o[:, None] + np.arange(3)).ravel()  # flat indices of their (K, 3) rows
        self.o1, self.o2, self.or1, self.or2 = i1[o], i2[o], self.r1[o], self.r2[o]
        self.s1, self.s2 = sphere[self.o1], sphere[self.o2]  # which side of an "other" contact is the sphere
        self.s1_any, self.s1_all = bool(self.s1.any()), bool(self.s1.all())
        self.s2_any, self.s2_all = bool(self.s2.any()), bool(self.s2.all())
        self._flat = None

    def flat(self):
        """Indices 3 i + (0, 1, 2) of id1's and id2's force components, for one bincount."""
        if self._flat is None:
            k = np.arange(3)
            self._flat = ((3 * self.i1[:, None] + k).ravel(), (3 * self.i2[:, None] + k).ravel())
        return self._flat


def sphere_pairs(P, lay, cell, shift):
    """Centre-to-centre vector id1 -> id2 (to id2's image across a periodic boundary), its
    length and the overlap r1 + r2 - distance (meaningful for sphere pairs only); `cell`:
    each contact's cellDist, `shift`: kinematics.cell_motion."""
    if not lay.pairs:
        z = np.zeros(lay.n)
        return np.zeros((lay.n, 3)), z, z.copy()
    d = P.take(lay.i2, 0) - P.take(lay.i1, 0)
    if shift is not None:
        d += cell @ shift[0].T
    dist = np.sqrt(dot(d, d))
    return d, dist, lay.rsum - dist


def with_walls(O, wrappers, keys, P, lay, shift, cell):
    """Contacts with a wall, box or facet (the "other" rows of `lay`, their keys `keys`,
    cellDist `cell`): YADE's normal, overlap and normal force, read one by one (about 2.5 us
    each; `wrappers`: key -> YADE Interaction, kept between steps); `broken` where the
    interaction is no longer real; the centres x1, x2 of both sides (id2's image across a
    periodic boundary), from which `arms` finds the lever arms if they are needed."""
    m = len(keys)
    broken = np.zeros(m, bool)
    if not m:
        return {"broken": broken, "nbroken": 0}
    rows, nbroken = [], 0
    for j, k in enumerate(keys.tolist()):
        I = wrappers.get(k)
        if I is None:
            I = wrappers[k] = O.interactions[k >> 32, k & 0xFFFFFFFF]
        g = I.geom
        if g is None:
            broken[j] = True
            nbroken += 1
            wrappers.pop(k, None)
            rows.append((0.0,) * 5)
        else:
            rows.append(g.normal.__getinitargs__() + (g.penetrationDepth, I.phys.normalForce.norm()))
    A = np.array(rows).reshape(m, 5)
    x2 = P.take(lay.o2, 0)
    if shift is not None:
        x2 = x2 + cell[lay.other] @ shift[0].T
    return {"broken": broken, "nbroken": nbroken, "n": A[:, 0:3], "delta": A[:, 3], "fn": A[:, 4],
            "x1": P.take(lay.o1, 0), "x2": x2}


def arms(lay, geo):
    """The lever arms (a1, a2) of the "other" contacts, one row each, from the centres to the
    points whose velocities meet; computed when first asked for (only turning walls and
    spinning spheres need them) and kept in `geo`."""
    if "a1o" not in geo:
        n, delta, x1, x2, r1, r2 = geo["no"], geo["do"], geo["x1o"], geo["x2o"], lay.or1, lay.or2
        # The wall's (facet's, box's) side of the contact is the point of its surface nearest
        # the sphere's centre, x - (r - delta) n: the wall moves there (docs/law.md step 1, as
        # pyref and LIGGGHTS; YADE's contactPoint is midway in the overlap for facets and boxes).
        half = 0.5 * delta  # a sphere's lever arm reaches midway into the overlap (docs/law.md)
        if not lay.s1_any:  # YADE puts the wall first: id1 the wall, id2 the sphere
            surface = x2 - (r2 - delta)[:, None] * n
        elif lay.s1_all:
            surface = x1 + (r1 - delta)[:, None] * n
        else:
            surface = np.where(lay.s1[:, None], x1 + (r1 - delta)[:, None] * n, x2 - (r2 - delta)[:, None] * n)
        geo["a1o"] = arm(lay.s1, lay.s1_any, lay.s1_all, r1 - half, n, surface, x1)
        geo["a2o"] = arm(lay.s2, lay.s2_any, lay.s2_all, -(r2 - half), n, surface, x2)
    return geo["a1o"], geo["a2o"]


def arm(sphere, any_, all_, r, n, surface, centre):
    """Lever arm: r*n for a sphere (r: its radius less half the overlap, docs/law.md step 1),
    else from the centre to the point on the wall's surface."""
    if not any_:
        return surface - centre
    if all_:
        return r[:, None] * n
    return np.where(sphere[:, None], r[:, None] * n, surface - centre)


def assemble(lay, d, dist, delta, g):
    """Per-contact geometry: sphere pairs from the recomputed distance (lever arms r - delta/2
    along the normal, docs/law.md step 1), the others from with_walls (and, one row per
    "other" contact, their normals, overlaps and centres for `arms`)."""
    other = lay.other
    if not len(other):
        z = np.zeros((0, 3))
        g = {"n": z, "delta": np.zeros(0), "x1": z, "x2": z}
    elif not lay.pairs:  # walls, facets, boxes only
        return {"i1": lay.i1, "i2": lay.i2, "ss": lay.ss, "n": g["n"], "delta": g["delta"], "fn": g["fn"],
                "other": other, "no": g["n"], "do": g["delta"], "x1o": g["x1"], "x2o": g["x2"]}
    positive = dist > lay.zero
    n = d / (dist if np.count_nonzero(positive) == len(dist) else np.where(positive, dist, 1.0))[:, None]
    fn = np.zeros(lay.n)
    if len(other):
        n.put(lay.other3, g["n"])
        delta[other], fn[other] = g["delta"], g["fn"]
    return {"i1": lay.i1, "i2": lay.i2, "ss": lay.ss, "n": n, "delta": delta, "fn": fn, "other": other,
            "no": g["n"], "do": g["delta"], "x1o": g["x1"], "x2o": g["x2"]}


def join(geo, new):
    """The geometry of two lists of contacts, one after the other."""
    out = {k: np.concatenate((geo[k], new[k])) for k in geo}
    out["other"] = np.concatenate((geo["other"], new["other"] + len(geo["i1"])))
    return out


def velocities(lay, geo, V, W, rotation, cell, shift):
    """Relative velocity of id1's contact point w.r.t. id2's (docs/law.md step 1; across a
    periodic boundary id2's image also moves with the cell): (v_n, V_s (eq. 6), the cell's
    shift velocity or None). Without rotation the spheres' spins are left out (walls,
    facets, boxes may turn anyway)."""
    i1, i2, n, delta = lay.i1, lay.i2, geo["n"], geo["delta"]
    v_rel = V.take(i1, 0) - V.take(i2, 0)
    spins = np.count_nonzero(W)  # (none in a scene with rotation locked and walls still: no "other" terms)
    # the "other" rows before the sphere pairs' term is added to every row (a copy), to be put back
    vo = None if lay.all_pairs or not (spins or (rotation and lay.pairs)) else v_rel.take(lay.other, 0)
    if rotation and lay.pairs:  # w1 x a1 - w2 x a2 = (c1 w1 + c2 w2) x n for sphere pairs
        # lever arms c = r - delta/2 to the contact point midway in the overlap (docs/law.md)
        half = 0.5 * delta[:, None]
        v_rel += cross((lay.r1[:, None] - half) * W.take(i1, 0) + (lay.r2[:, None] - half) * W.take(i2, 0), n)
        turned = True  # (v_rel's "other" rows are to be put back)
    else:
        turned = False
    if vo is not None and spins:  # lever arms to the points that meet; walls and facets may turn
        for side, o, sphere, any_, all_, sign in ((0, lay.o1, lay.s1, lay.s1_any, lay.s1_all, 1.0),
                                                  (1, lay.o2, lay.s2, lay.s2_any, lay.s2_all, -1.0)):
            if rotation or not any_:
                w = W.take(o, 0)
            elif all_:
                continue  # (a sphere's spin is left out: no term)
            else:
                w = np.where(sphere[:, None], 0.0, W.take(o, 0))
            if np.count_nonzero(w):
                vo += sign * cross(w, arms(lay, geo)[side])
                turned = True
    if turned and vo is not None:
        v_rel.put(lay.other3, vo)
    sv = None
    if shift is not None:
        sv = cell @ shift[1].T
        v_rel -= sv
    v_n = dot(v_rel, n)
    V_s = v_rel - v_n[:, None] * n
    return v_n, V_s, sv


def sphere_pair_fn(lay, geo, kn, cn, v_n, sv):
    """Eq. 3 as YADE's native law computes it for the sphere pairs (kn, cn: each contact's,
    read from YADE when it was made), never tensile; the other contacts keep YADE's Fn."""
    n, delta = geo["n"], geo["delta"]
    v_fn = v_n
    if sv is not None:
        # YADE 2023.02a's Law2_ScGeom_ViscElPhys_Basic adds the cell's shift velocity
        # with the wrong sign (v1 - v2 + shiftVel): its normal dashpot sees
        # v_n + 2 n.shiftVel across a deforming periodic boundary. Fn is the force YADE
        # applies, so it is computed the same way here (the friction limit must hold for
        # the force applied); V_s uses the true relative velocity (measured: the
        # overlap grows at 1.99e-4 m/s where YADE's dashpot sees -1.80e-3 m/s).
        v_fn = v_n + 2.0 * dot(sv, n)
    fn = np.maximum(lay.zero, kn * delta + cn * v_fn)  # (0.0 as an array: cheaper, the same values)
    if lay.all_pairs:
        return fn
    out = geo["fn"]
    np.copyto(out, fn, where=lay.ss)
    return out


def same_as_yade(O, geo, fn):
    """check=True: recomputed sphere-sphere normals and normal forces against YADE's own.
    Returns (relative Fn error, sphere pairs compared)."""
    k = np.flatnonzero(geo["ss"])
    if not len(k):
        return 0.0, 0
    inters = [O.interactions[int(a), int(b)] for a, b in zip(geo["i1"][k], geo["i2"][k])]
    native_n = rows([I.geom.normal for I in inters])
    native_fn = np.array([I.phys.normalForce.norm() for I in inters])
    err_n = float(np.abs(native_n - geo["n"][k]).max())
    err_fn = float(np.abs(native_fn - fn[k]).max() / max(native_fn.max(), 1e-300))
    if err_n > 1e-9 or err_fn > 1e-9:
        fail(f"recomputed geometry differs from YADE's (normal {err_n:.3g}, relative Fn {err_fn:.3g})")
    return err_fn, len(k)
