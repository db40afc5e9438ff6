"""Per-contact geometry and kinematics (docs/law.md step 1): the normal n from id1 to id2,
the overlap delta, the lever arms a1, a2 from the bodies' centres to the points whose
velocities meet, the relative velocity and its normal and tangential parts (eq. 6), and
YADE's normal force.

Sphere pairs are recomputed in numpy from the bodies' positions (lever arms r - delta/2
to the contact point midway in the overlap); contacts with a wall, facet or box take YADE's
normal, overlap and normal force, read one by one, and the wall's side of the contact is
the point of its surface nearest the sphere's centre.
"""
import numpy as np

from .checks import fail
from .kernel import dot
from .kinematics import cross, rows


def sphere_pairs(P, idx, cell, shift):
    """Centre-to-centre vector id1 -> id2 (to id2's image across a periodic boundary), its
    length and the overlap r1 + r2 - distance (meaningful for sphere pairs only); `idx`:
    ContactSet.index, `cell`: each contact's cellDist, `shift`: kinematics.cell_motion."""
    i1, i2, ss, other, r1, r2, rsum = idx
    if not ss.any():
        z = np.zeros(len(i1))
        return np.zeros((len(i1), 3)), z, z.copy()
    d = P[i2] - P[i1]
    if shift is not None:
        d += cell @ shift[0].T
    dist = np.sqrt(dot(d, d))
    return d, dist, rsum - dist


def with_walls(O, wrappers, keys, P, idx, other, shift, cell, sphere):
    """Contacts with a wall, box or facet (rows `other` of idx, cellDist `cell`): YADE's
    normal, overlap and normal force, read one by one (about 2.5 us each; `wrappers`: key ->
    YADE Interaction, kept between steps); `broken` where the interaction is no longer real."""
    m = len(keys)
    broken = np.zeros(m, bool)
    if not m:
        return {"broken": broken}
    rows = []
    for j, k in enumerate(keys.tolist()):
        I = wrappers.get(k)
        if I is None:
            I = wrappers[k] = O.interactions[k >> 32, k & 0xFFFFFFFF]
        g = I.geom
        if g is None:
            broken[j] = True
            wrappers.pop(k, None)
            rows.append((0.0,) * 5)
        else:
            rows.append(g.normal.__getinitargs__() + (g.penetrationDepth, I.phys.normalForce.norm()))
    A = np.array(rows).reshape(m, 5)
    n, delta = A[:, 0:3], A[:, 3]
    i1, i2, r1, r2 = idx[0][other], idx[1][other], idx[4][other], idx[5][other]
    x2 = P[i2]
    if shift is not None:
        x2 = x2 + cell[other] @ shift[0].T
    # The wall's (facet's, box's) side of the contact is the point of its surface nearest
    # the sphere's centre, x - (r - delta) n: the wall moves there (docs/law.md step 1, as
    # pyref and LIGGGHTS; YADE's contactPoint is midway in the overlap for facets and boxes).
    s1 = sphere[i1]
    surface = np.where(s1[:, None], P[i1] + (r1 - delta)[:, None] * n, x2 - (r2 - delta)[:, None] * n)
    half = 0.5 * delta  # a sphere's lever arm reaches midway into the overlap (docs/law.md)
    return {"broken": broken, "n": n, "delta": delta, "fn": A[:, 4],
            "a1": arm(s1, r1 - half, n, surface - P[i1]),
            "a2": arm(sphere[i2], -(r2 - half), n, surface - x2)}


def arm(sphere, r, n, to_point):
    """Lever arm: r*n for a sphere (r: its radius less half the overlap, docs/law.md step 1),
    else centre -> the point on the wall."""
    if not sphere.any():
        return to_point
    if sphere.all():
        return r[:, None] * n
    return np.where(sphere[:, None], r[:, None] * n, to_point)


def assemble(idx, d, dist, delta, other, g):
    """Per-contact geometry: sphere pairs from the recomputed distance (lever arms r - delta/2
    along the normal, docs/law.md step 1), the others from with_walls."""
    i1, i2, ss, _, r1, r2, _ = idx
    if len(other) and len(other) == len(i1):  # no sphere pair
        return {"i1": i1, "i2": i2, "ss": ss, "n": g["n"], "delta": g["delta"], "a1": g["a1"], "a2": g["a2"],
                "fn": g["fn"], "other": np.asarray(other, np.int64)}
    n = d / (dist if len(dist) and dist.min() > 0 else np.where(dist > 0, dist, 1.0))[:, None]
    fn = np.zeros(len(i1))
    a1 = a2 = None  # sphere pairs need no arrays of lever arms (c1 n, -c2 n: see velocities, law.apply)
    if len(other):
        a1, a2 = (r1 - 0.5 * delta)[:, None] * n, -(r2 - 0.5 * delta)[:, None] * n
        n[other], delta[other], fn[other] = g["n"], g["delta"], g["fn"]
        a1[other], a2[other] = g["a1"], g["a2"]
    return {"i1": i1, "i2": i2, "ss": ss, "n": n, "delta": delta, "a1": a1, "a2": a2, "fn": fn,
            "other": np.asarray(other, np.int64)}


def join(geo, new):
    """The geometry of two lists of contacts, one after the other."""
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


def velocities(geo, V, W, radius, rotation, cell, shift):
    """Relative velocity of id1's contact point w.r.t. id2's (docs/law.md step 1; across a
    periodic boundary id2's image also moves with the cell): (v_rel, v_n, V_s (eq. 6), the
    cell's shift velocity or None)."""
    i1, i2, n, delta, a1, a2 = (geo[k] for k in ("i1", "i2", "n", "delta", "a1", "a2"))
    other = geo["other"]
    v_rel = V[i1] - V[i2]
    if rotation and not len(other) == len(i1):  # w1 x a1 - w2 x a2 = (c1 w1 + c2 w2) x n for sphere pairs
        # lever arms c = r - delta/2 to the contact point midway in the overlap (docs/law.md)
        half = 0.5 * delta[:, None]
        v_rel += cross((radius[i1][:, None] - half) * W[i1] + (radius[i2][:, None] - half) * W[i2], n)
    if len(other):  # lever arms to the points that meet; walls and facets may turn
        o1, o2 = i1[other], i2[other]
        vo = V[o1] - V[o2]
        for w, a, sign in ((W[o1], a1, 1.0), (W[o2], a2, -1.0)):
            if w.any():
                vo += sign * cross(w, a[other])
        v_rel[other] = vo
    sv = None
    if shift is not None:
        sv = cell @ shift[1].T
        v_rel -= sv
    v_n = dot(v_rel, n)
    V_s = v_rel - v_n[:, None] * n
    return v_rel, v_n, V_s, sv


def sphere_pair_fn(geo, fn, kn, cn, v_n, sv):
    """Eq. 3 as YADE's native law computes it for the sphere pairs (kn, cn: each contact's,
    read from YADE when it was made), never tensile; the other contacts keep YADE's Fn."""
    ss, n, delta = geo["ss"], geo["n"], geo["delta"]
    v_fn = v_n
    if sv is not None:
        # YADE 2023.02a's Law2_ScGeom_ViscElPhys_Basic adds the cell's shift velocity
        # with the wrong sign (v1 - v2 + shiftVel): its normal dashpot sees
        # v_n + 2 n.shiftVel across a deforming periodic boundary. Fn is the force YADE
        # applies, so it is computed the same way here (the friction limit must hold for
        # the force applied); V_s uses the true relative velocity (measured: the
        # overlap grows at 1.99e-4 m/s where YADE's dashpot sees -1.80e-3 m/s).
        v_fn = v_n + 2.0 * dot(sv, n)
    if not len(geo["other"]):  # all sphere pairs (no masks: they copy)
        return np.maximum(0.0, kn * delta + cn * v_fn)
    fn[ss] = np.maximum(0.0, kn[ss] * delta[ss] + cn[ss] * v_fn[ss])
    return fn


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
