# SPDX-License-Identifier: GPL-2.0-or-later
"""A scene's grains: single grains' spins and masses, and the blocks that make many at once
(lattice, ring, fill), each checked as it is read; and the starting overlaps every engine
must agree on (docs/scene-format.md)."""
from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from .model import Grain, mass
from .table import Table, finite, shown

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

# [[base]]: at most this many spheres (each relaxation pass searches all their pairs).
MAX_BASE_SPHERES = 5000
# [[base]]: spheres are pushed apart until no two overlap by more than this share of a diameter.
BASE_OVERLAP = 1e-6


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


def check_start(grains, walls, dim, periodic=None):
    """Refuse starting states the engines cannot agree on (MAX_START_OVERLAP); across a
    periodic boundary too."""
    x = np.array([g.position for g in grains])
    r = np.array([g.radius for g in grains])
    for w in walls:
        dist = (x - w.point) @ w.normal
        for i in np.flatnonzero(dist <= (1 - MAX_START_OVERLAP) * r):
            where = "behind" if dist[i] <= 0 else "deep inside"
            raise SceneError(f"grain {grains[i].name!r} starts {where} wall {w.name!r} (centre {dist[i]:.3g} m "
                             f"from it, radius {r[i]:.3g} m): a grain may start overlapping a wall by at most "
                             f"{MAX_START_OVERLAP:g} of its radius")
    if periodic:
        a, b, dist = near_pairs_periodic(x, r, periodic)
    else:
        a, b = near_pairs(x[:, :dim], r)
        dist = np.linalg.norm(x[a] - x[b], axis=1)
    gap = dist - (r[a] + r[b])
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


def near_pairs_periodic(x, r, periodic):
    """(a, b, distance) of every pair of grains closer than twice the largest radius, the
    distance to the nearest periodic image (x, y periodic as the scene says)."""
    from scipy.spatial import cKDTree

    span = np.ptp(x, axis=0) + 4 * r.max() + 1.0
    box, y = np.empty(3), np.array(x, float)
    for k, axis in enumerate("xyz"):
        if axis in periodic:
            lo, hi = periodic[axis]
            box[k], y[:, k] = hi - lo, (x[:, k] - lo) % (hi - lo)
        else:  # not periodic: a box far wider than the grains' spread never wraps
            box[k], y[:, k] = 2 * span[k], x[:, k] - x[:, k].min()
    p = cKDTree(y, boxsize=box).query_pairs(2 * r.max(), output_type="ndarray")
    d = y[p[:, 0]] - y[p[:, 1]]
    d -= box * np.round(d / box)
    return p[:, 0], p[:, 1], np.linalg.norm(d, axis=1)


def check_periodic(periodic, grains, walls):
    """Grains inside the periodic box, no wall across a periodic axis, and a box wide enough
    that no grain touches its own image."""
    if not periodic:
        return
    x = np.array([g.position for g in grains])
    r = np.array([g.radius for g in grains])
    for axis, (lo, hi) in periodic.items():
        k = "xyz".index(axis)
        if hi - lo <= 4 * r.max():
            raise SceneError(f"periodic.{axis} = [{lo:g}, {hi:g}]: must be longer than two largest diameters "
                             f"({4 * r.max():.3g} m): a grain would touch its own image")
        out = np.flatnonzero((x[:, k] < lo) | (x[:, k] >= hi))
        if len(out):
            g = grains[out[0]]
            raise SceneError(f"grain {g.name!r} starts at {axis} = {g.position[k]:.6g}, outside the periodic box "
                             f"periodic.{axis} = [{lo:g}, {hi:g})")
        for w in walls:
            if abs(w.normal[k]) > 1e-12:
                raise SceneError(f"wall {w.name!r}: its normal has a part along the periodic axis {axis} (a plane "
                                 "across a periodic box would cut it)")


def base_extent(bt: Table, periodic):
    """A base's lower corner and its x, y size: the periodic box along a periodic axis
    unless given."""
    origin = bt.vector("origin", 3, required=True)
    size = bt.get("size")
    if size is None:
        if set(periodic) != {"x", "y"}:
            raise SceneError(f"{bt.key('size')}: missing (required unless the scene is periodic in x and y)")
        size = [periodic["x"][1] - periodic["x"][0], periodic["y"][1] - periodic["y"][0]]
    if (not isinstance(size, list) or len(size) != 2
            or not all(isinstance(a, (int, float)) and not isinstance(a, bool) and finite(a) and a > 0 for a in size)):
        raise SceneError(f"{bt.key('size')}: expected 2 positive numbers (x and y extent), got {shown(size)}")
    return origin, [float(a) for a in size]


def base_count(bt: Table, periodic):
    """How many spheres a base holds, read before any grain is made (the size check)."""
    origin, size = base_extent(bt, periodic)
    per_area = bt.number("number_density", required=True, lo=0, lo_open=True)
    radius = bt.number("radius", required=True, lo=0, lo_open=True)
    n = int(round(per_area * size[0] * size[1]))
    most = 1.0 / (2 * math.sqrt(3) * radius**2)  # hexagonal close packing of the plane
    thickness = bt.number("thickness", 0.0, lo=0)
    layers = 1 + thickness / (2 * radius)
    if per_area > 0.7 * most * layers:
        raise SceneError(f"{bt.key('number_density')} = {per_area:g}: at most {0.7 * most * layers:.3g} spheres per "
                         f"unit area fit loosely in a layer {thickness:g} m thick (radius {radius:g} m)")
    if not 1 <= n <= MAX_BASE_SPHERES:
        raise SceneError(f"{bt.key('number_density')} = {per_area:g}: {n} spheres on {size[0]:g} x {size[1]:g} m; "
                         f"must be 1 to {MAX_BASE_SPHERES}")
    return n


def base(bt: Table, n, periodic):
    """A rough base: n fixed spheres at random in the slab origin + [0, size] x [0, thickness]
    (z), pushed apart until none overlap (a slice of a random packing, as the rough base of
    Silbert et al. 2001); across the box's periodic boundaries where the base spans them."""
    origin, size = base_extent(bt, periodic)
    radius = bt.number("radius", required=True, lo=0, lo_open=True)
    thickness = bt.number("thickness", 0.0, lo=0)
    density = bt.number("density", required=True, lo=0, lo_open=True)
    seed = bt.integer("seed", 0, lo=0)
    prefix = bt.string("prefix", "base")
    bt.number("number_density", required=True)
    bt.done()
    check_mass(bt.where, 3, radius, radius, density)
    wrap = np.array([axis in periodic and math.isclose(size[k], periodic[axis][1] - periodic[axis][0])
                     and math.isclose(origin[k], periodic[axis][0]) for k, axis in enumerate("xy")])
    pos = relaxed_slab(n, np.array(size), thickness, 2 * radius, wrap, np.random.default_rng(seed))
    pos += origin
    return [Grain(f"{prefix}{k}", radius, density, pos[k], np.zeros(3), fixed=True) for k in range(n)]


def relaxed_slab(n, size, thickness, diameter, wrap, rng, iterations=20000):
    """n points uniform in [0, size] x [0, thickness], then each overlapping pair (closer
    than `diameter`) pushed apart by half its overlap each, until none overlaps by more than
    BASE_OVERLAP of a diameter; x, y wrap where `wrap` says (periodic), else stay in range."""
    from scipy.spatial import cKDTree

    p = np.column_stack([rng.uniform(0, size[0], n), rng.uniform(0, size[1], n), rng.uniform(0, thickness, n)])
    # cKDTree wraps every axis of its box: an axis that must not wrap gets a box twice its range
    box = np.array([size[0] if wrap[0] else 2 * size[0] + 2 * diameter,
                    size[1] if wrap[1] else 2 * size[1] + 2 * diameter, 2 * thickness + 2 * diameter])
    for _ in range(iterations):
        pairs = cKDTree(p, boxsize=box).query_pairs(diameter * (1 - BASE_OVERLAP), output_type="ndarray")
        if not len(pairs):
            return p
        a, b = pairs[:, 0], pairs[:, 1]
        d = p[a] - p[b]
        d -= box * np.round(d / box)
        dist = np.linalg.norm(d, axis=1)
        push = (0.5 * (diameter - dist) / np.maximum(dist, 1e-300))[:, None] * d
        move = np.zeros_like(p)
        np.add.at(move, a, push)
        np.add.at(move, b, -push)
        p += move
        for k in range(2):
            p[:, k] = p[:, k] % size[k] if wrap[k] else np.clip(p[:, k], 0, size[k])
        p[:, 2] = np.clip(p[:, 2], 0, thickness)
    raise SceneError(f"base: {n} spheres could not be spread without overlaps in {size[0]:g} x {size[1]:g} x "
                     f"{thickness:g} m; lower number_density")
