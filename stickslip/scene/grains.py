"""A scene's grains: single grains' spins and masses, and the blocks that make many at once
(lattice, ring, fill), each checked as it is read; and the starting overlaps every engine
must agree on (docs/scene-format.md)."""
from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from .model import Grain, mass
from .table import Table, shown

# Grains may start overlapping a wall or each other by at most this share of the smaller
# radius: the linear law models small overlaps (a resting grain: ~1e-5 r), and a deep
# start is resolved differently by each engine (a centre behind a wall: pyref pushes the
# grain out, YADE pulls it through, LIGGGHTS ignores the wall), so it is refused.
MAX_START_OVERLAP = 0.1

# More grains than this is refused before any is made: the reader holds ~0.9 kB per grain
# (measured: 870 MB for 10^6), so 10^7 grains need ~9 GB before an engine starts.
MAX_GRAINS = 10**7

# A grain's mass (kg, or kg/m in 2D) must lie in this range: a nanometre grain weighs
# 1e-23 kg, so SI scenes are far inside, and the product of two masses (the pair's
# effective mass) and their ratios to a stiffness stay inside double precision.
MASS_RANGE = (1e-100, 1e100)

# A fill's grains start on a hexagonal lattice this much wider than their largest
# diameter, jittered inside the slack, so that they do not touch at the start.
FILL_SLACK = 1.1


def initial_spin(gt, dim, rotation):
    """A grain's initial angular velocity: a number (about z) in 2D, 3 numbers in 3D."""
    if dim == 2:
        w = np.zeros(3)
        w[2] = gt.number("angular_velocity", 0.0)
    else:
        w = gt.vector("angular_velocity", 3, default=[0.0, 0.0, 0.0])
    if np.any(w) and not rotation:
        raise SceneError(f"{gt.key('angular_velocity')}: a spinning grain needs effects.rotation = true")
    return w


def lattice_counts(bt: Table, dim):
    """A lattice's grain counts per axis, read before any grain is made (the size check)."""
    counts = bt.get("counts", required=True)
    if (not isinstance(counts, list) or len(counts) != dim
            or not all(isinstance(n, int) and not isinstance(n, bool) and n >= 1 for n in counts)):
        raise SceneError(f"{bt.key('counts')}: expected {dim} positive integers, got {shown(counts)}")
    if math.prod(counts) > MAX_GRAINS:
        raise SceneError(f"{bt.key('counts')}: {math.prod(counts):.3g} grains; at most {MAX_GRAINS:.0e} per scene")
    return counts


def lattice(bt: Table, dim, start, counts):
    """A block of grains on a square/cubic lattice, radii spread uniformly (seeded)."""
    origin = bt.vector("origin", dim, required=True)
    radius = bt.number("radius", required=True, lo=0, lo_open=True)
    spread = bt.number("radius_spread", 0.0, lo=0, hi=0.5)
    spacing = bt.number("spacing", 2.0 * radius * (1 + spread) * 1.05, lo=2.0 * radius * (1 + spread))
    density = bt.number("density", required=True, lo=0, lo_open=True)
    velocity = bt.vector("velocity", dim, default=[0.0] * dim)
    jitter = bt.number("velocity_jitter", 0.0, lo=0)
    seed = bt.integer("seed", 0, lo=0)
    prefix = bt.string("prefix", "p")
    bt.done()
    check_mass(bt.where, dim, radius * (1 - spread), radius * (1 + spread), density)
    n = math.prod(counts)
    # One draw per grain of `dim` jitter components then one radius factor, in grain
    # order: the same numbers as drawing them grain by grain (the scenes stay the same).
    u = np.random.default_rng(seed).uniform(-1, 1, (n, dim + 1))
    pos = np.zeros((n, 3))
    pos[:, :dim] = origin[:dim] + np.indices(counts).reshape(dim, n).T * spacing
    vel = np.zeros((n, 3))
    vel[:, :dim] = velocity[:dim] + jitter * u[:, :dim]
    radii = radius * (1 + spread * u[:, dim])
    return [Grain(f"{prefix}{start + k}", float(radii[k]), density, pos[k], vel[k]) for k in range(n)]


def check_mass(where, dim, r_min, r_max, density):
    """A grain's mass must lie within MASS_RANGE (radius and density each within range can
    still multiply far beyond it)."""
    lo, hi = MASS_RANGE
    for r in (r_min, r_max):
        m = mass(dim, r, density)
        if not lo <= m <= hi:
            raise SceneError(f"{where}.radius = {r:g} m with density = {density:g}: mass {m:g}; must be in "
                             f"[{lo:g}, {hi:g}] (SI units)")


def block_count(t: Table):
    """A ring's or fill's grain count, read before any grain is made (the size check)."""
    n = t.get("count", required=True)
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_GRAINS:
        raise SceneError(f"{t.key('count')}: expected a whole number in [1, {MAX_GRAINS:.0e}], got {shown(n)}")
    return n


def ring(rt: Table):
    """A drum's wall: `count` fixed disks evenly spaced on a circle of centres `radius`
    about `center`; grains inside touch the bumps between them (the drum's roughness)."""
    center = rt.vector("center", 2, required=True)
    radius = rt.number("radius", required=True, lo=0, lo_open=True)
    grain_radius = rt.number("grain_radius", required=True, lo=0, lo_open=True)
    density = rt.number("density", required=True, lo=0, lo_open=True)
    n = block_count(rt)
    prefix = rt.string("prefix", "ring")
    rt.done()
    if n < 3:
        raise SceneError(f"{rt.key('count')} = {n}: a ring needs at least 3 grains")
    if grain_radius >= radius:
        raise SceneError(f"{rt.key('grain_radius')} = {grain_radius:g}: must be < ring radius {radius:g}")
    # neighbours may overlap at most as much as any starting grains (MAX_START_OVERLAP)
    chord = 2 * radius * math.sin(math.pi / n)
    if chord < 2 * grain_radius * (1 - MAX_START_OVERLAP):
        most = int(math.pi / math.asin(min(1.0, grain_radius * (1 - MAX_START_OVERLAP) / radius)))
        raise SceneError(f"{rt.key('count')} = {n}: neighbours would overlap by more than {MAX_START_OVERLAP:g} "
                         f"of their radius; at most {most} grains fit on this ring")
    check_mass(rt.where, 2, grain_radius, grain_radius, density)
    a = 2 * math.pi * np.arange(n) / n
    pos = np.zeros((n, 3))
    pos[:, 0], pos[:, 1] = center[0] + radius * np.cos(a), center[1] + radius * np.sin(a)
    return [Grain(f"{prefix}{k}", grain_radius, density, pos[k], np.zeros(3), fixed=True) for k in range(n)]


def fill(ft: Table):
    """`count` disks of radii uniform in radius*(1 +- spread) in the lower part of a circle
    (`center`, `radius`: the room inside a drum), on a hexagonal lattice FILL_SLACK wider
    than the largest diameter, each jittered inside its slack: the sites lowest under a
    surface line `slope` degrees steep (rising to +x), so a drum can start from a slope
    above its avalanche angle and its first avalanche comes at once."""
    center = ft.vector("center", 2, required=True)
    room = ft.number("radius", required=True, lo=0, lo_open=True)
    r = ft.number("grain_radius", required=True, lo=0, lo_open=True)
    spread = ft.number("radius_spread", 0.0, lo=0, hi=0.5)
    density = ft.number("density", required=True, lo=0, lo_open=True)
    n = block_count(ft)
    slope = ft.number("slope", 0.0, lo=-60.0, hi=60.0)
    seed = ft.integer("seed", 0, lo=0)
    prefix = ft.string("prefix", "p")
    ft.done()
    check_mass(ft.where, 2, r * (1 - spread), r * (1 + spread), density)
    rmax = r * (1 + spread)
    s = 2 * rmax * FILL_SLACK
    inner = room - rmax - 0.5 * (s - 2 * rmax)  # a site's grain stays clear of the circle
    sites = int(2 * inner / s) + 2 if inner > 0 else 0
    if sites * sites * 2 > MAX_GRAINS * 4:
        raise SceneError(f"{ft.key('radius')} = {room:g}: {room / r:.3g} grain radii; too many lattice sites")
    k = np.arange(-sites, sites + 1)
    iy, ix = np.meshgrid(k, k, indexing="ij")
    xy = np.stack(((ix + 0.5 * (iy % 2)) * s, iy * s * math.sqrt(3) / 2), axis=-1).reshape(-1, 2)
    xy = xy[np.hypot(xy[:, 0], xy[:, 1]) <= inner] if inner > 0 else xy[:0]
    if len(xy) < n:
        raise SceneError(f"{ft.key('count')} = {n}: at most {len(xy)} grains of radius up to {rmax:g} m fit in a "
                         f"circle of radius {room:g} m (hexagonal sites {s:.3g} m apart)")
    # lowest sites first below a line at `slope` degrees (the pile's starting surface)
    a = math.radians(slope)
    order = np.lexsort((xy[:, 0], xy[:, 1] * math.cos(a) - xy[:, 0] * math.sin(a)))[:n]
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, (n, 3))
    pos = np.zeros((n, 3))
    pos[:, :2] = center[:2] + xy[order] + 0.5 * (s - 2 * rmax) * u[:, :2] / math.sqrt(2)
    radii = r * (1 + spread * u[:, 2])
    return [Grain(f"{prefix}{k}", float(radii[k]), density, pos[k], np.zeros(3)) for k in range(n)]


def check_start(grains, walls, dim):
    """Refuse starting states the engines cannot agree on (MAX_START_OVERLAP)."""
    x = np.array([g.position for g in grains])
    r = np.array([g.radius for g in grains])
    for w in walls:
        dist = (x - w.point) @ w.normal
        for i in np.flatnonzero(dist <= (1 - MAX_START_OVERLAP) * r):
            where = "behind" if dist[i] <= 0 else "deep inside"
            raise SceneError(f"grain {grains[i].name!r} starts {where} wall {w.name!r} (centre {dist[i]:.3g} m "
                             f"from it, radius {r[i]:.3g} m): a grain may start overlapping a wall by at most "
                             f"{MAX_START_OVERLAP:g} of its radius")
    a, b = near_pairs(x[:, :dim], r)
    gap = np.linalg.norm(x[a] - x[b], axis=1) - (r[a] + r[b])
    bad = np.flatnonzero(gap < -MAX_START_OVERLAP * np.minimum(r[a], r[b]))
    if len(bad):
        i, j = a[bad[0]], b[bad[0]]
        raise SceneError(f"grains {grains[i].name!r} and {grains[j].name!r} start overlapping by "
                         f"{-gap[bad[0]]:.3g} m: at most {MAX_START_OVERLAP:g} of the smaller radius")


def near_pairs(x, r):
    """Index arrays (a, b) of every pair of grains whose centres are closer than the sum of
    their radii (and some more). A search radius set by the largest grain for all of them
    would make one big grain among many small ones quadratic (9e4 grains of 0.1 mm and
    one of 2 mm: 4 GB and 25 s), so the
    grains are binned by radius in factors of 2 and each bin is searched with its own
    largest radius, against itself and against the bins of larger grains."""
    n = len(r)
    if n <= 64:
        a, b = np.triu_indices(n, 1)
        return a, b
    from scipy.spatial import cKDTree

    level = np.floor(np.log2(r / r.min())).astype(int)
    bins = [np.flatnonzero(level == k) for k in np.unique(level)]
    trees = [cKDTree(x[i]) for i in bins]
    a, b = [], []
    for k, (ik, tk) in enumerate(zip(bins, trees)):
        rk = r[ik].max()
        p = tk.query_pairs(2 * rk, output_type="ndarray")
        a.append(ik[p[:, 0]])
        b.append(ik[p[:, 1]])
        for il, tl in zip(bins[k + 1:], trees[k + 1:]):
            m = tl.sparse_distance_matrix(tk, r[il].max() + rk, output_type="ndarray")
            a.append(ik[m["j"]])
            b.append(il[m["i"]])
    return np.concatenate(a), np.concatenate(b)
