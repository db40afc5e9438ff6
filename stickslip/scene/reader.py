"""Reading and checking a scene file (docs/scene-format.md).

Every problem raises SceneError with one line that names the key and the allowed
range; overrides (command line, tests) are written into the file's data before it is
read, so they are checked by the same rules and named the same way.
"""
from __future__ import annotations

import json
import math
import re
import tomllib
from pathlib import Path

import numpy as np

from pyref.laws import LAWS, RESETS, SLIP_TIMINGS, LawParams

from .. import columns, kinds
from ..errors import SceneError
from .model import Contact, GravityRamp, Grain, Output, RampPhase, Scene, Wall, WallRotation, mass
from .stability import stability_limits

CASES_DIR = Path(__file__).resolve().parents[2] / "cases"
EFFECTS = ("gravity", "rotation", "normal_damping", "tangential_damping", "moving_walls")
# A scene name becomes a folder name (runs/NAME/...): letters, digits, _ . - only.
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")
# Grains may start overlapping a wall or each other by at most this share of the smaller
# radius: the linear law models small overlaps (a resting grain: ~1e-5 r), and a deep
# start is resolved differently by each engine (a centre behind a wall: pyref pushes the
# grain out, YADE pulls it through, LIGGGHTS ignores the wall), so it is refused.
MAX_START_OVERLAP = 0.1
# More steps than this is refused: at a microsecond per step it would run for 3 hours
# per grain, and it is almost always a mistyped dt or duration.
MAX_STEPS = 10**10
# More grains than this is refused before any is made: the reader holds ~0.9 kB per grain
# (measured: 870 MB for 10^6), so 10^7 grains need ~9 GB before an engine starts.
MAX_GRAINS = 10**7
# More grain-steps (steps x grains) than this is refused: LIGGGHTS, the fastest engine
# here, does ~6e6 grain-steps/s per core (liggghts_plugin/doc: 20 800 grains, 3.55 ms per
# step), so 10^13 is ~20 core-days (pyref, ~5e5/s: ~8 months).
MAX_GRAIN_STEPS = 10**13
# More recorded values (rows x columns of the time series) than this is refused: 8 GB
# as float64 in memory and ~20 GB of timeseries.csv. Raise output.every instead.
MAX_RECORDED = 10**9
# Numbers in a scene are at most this in magnitude. SI values of a DEM scene are far
# inside it, and it keeps sums and products of a few of them (masses, distances,
# stiffness over mass) inside double precision (1.8e308) instead of overflowing.
MAX_MAGNITUDE = 1e100
# A grain's mass (kg, or kg/m in 2D) must lie in this range: a nanometre grain weighs
# 1e-23 kg, so SI scenes are far inside, and the product of two masses (the pair's
# effective mass) and their ratios to a stiffness stay inside double precision.
MASS_RANGE = (1e-100, 1e100)

# A scene file larger than this is refused unread: TOML parses at ~2 MB/s here (10^5
# [[grain]] tables, 8.7 MB: 3.8 s), so 64 MB is half a minute; many grains go in a lattice.
MAX_SCENE_BYTES = 64 << 20

# output.every at most this: LIGGGHTS takes a dump interval as a 32-bit int (a larger
# one is misread there); more than the run's steps records only the start (allowed: a
# short trial of a scene keeps its interval).
MAX_EVERY = 2**31 - 1
# |gravity_rate| at most this, rad/s: a turn a second is far beyond any drum's avalanche
# regime (rad/s of ~1e-3 to 1e-1) and keeps g(t) sampled by many steps per turn.
MAX_GRAVITY_RATE = 2 * math.pi
# A fill's grains start on a hexagonal lattice this much wider than their largest
# diameter, jittered inside the slack, so that they do not touch at the start.
FILL_SLACK = 1.1

# Rolling resistance models (contact.rolling): LIGGGHTS' epsd2 only (no other engine here has one).
ROLLING_MODELS = ("epsd2",)
# gravity_ramp: a phase ends on one of these conditions (RampPhase.until).
RAMP_CONDITIONS = ("duration", "speed_above", "speed_below")
# [[base]]: at most this many spheres (the relaxation that spreads them is quadratic in them).
MAX_BASE_SPHERES = 5000
# [[base]]: spheres are pushed apart until no two overlap by more than this share of a diameter.
BASE_OVERLAP = 1e-6

# Overrides by name -> (table, key) in the scene file.
_OVERRIDES = {"dt": ("time", "dt"), "duration": ("time", "duration"), "every": ("output", "every"),
              **{k: ("contact", k) for k in ("law", "kn", "nu_n", "ks", "nu_s", "mu_s", "mu_k", "reset",
                                             "slip_timing", "rolling", "rolling_mu")},
              **{f"effect_{e}": ("effects", e) for e in EFFECTS}}


def find(name_or_path) -> Path:
    """A scene given as a path, or as a name in cases/ (with or without .toml)."""
    p = Path(name_or_path)
    if p.is_file():
        return p
    for cand in (CASES_DIR / f"{name_or_path}.toml", CASES_DIR / str(name_or_path)):
        if cand.is_file():
            return cand
    known = ", ".join(sorted(q.stem for q in CASES_DIR.glob("*.toml")))
    raise SceneError(f"scene {name_or_path!r}: no such file and no such case (cases: {known})")


def load(name_or_path, **overrides) -> Scene:
    """Read and validate a scene. `overrides` replace values of the file before it is
    checked: dt, duration, every, law, reset, slip_timing, kn, ..., and effects as
    `effect_<name>=bool`."""
    path = find(name_or_path)
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_SCENE_BYTES + 1)  # no more: a scene path may name any file
    except OSError as e:
        raise SceneError(f"{path}: cannot be read ({e.strerror})") from None
    if len(raw) > MAX_SCENE_BYTES:
        raise SceneError(f"{path}: not a scene file (over {MAX_SCENE_BYTES >> 20} MB; many grains go in a "
                         f"[[lattice]])")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise SceneError(f"{path}: not a scene file (not UTF-8 text; scenes are TOML)") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{path}: not valid TOML ({e})") from None
    except RecursionError:
        raise SceneError(f"{path}: not a scene file (arrays or tables nested too deeply)") from None
    return parse(data, source=path, overrides=overrides)


def identity(name_or_path, **overrides) -> str:
    """The scene file's data with the overrides written in, as canonical text: two runs of
    equal identity on one engine are the same run (a precision ladder's step at the
    scene's own dt is the case's run)."""
    path = find(name_or_path)
    data = _apply_overrides(tomllib.loads(path.read_text()), overrides)
    return json.dumps(data, sort_keys=True, default=str)


def parse(data: dict, source=None, overrides=None) -> Scene:
    data = _apply_overrides(data, overrides or {})
    top = _Table(data, "")
    name = top.string("name", required=True)
    if not NAME_PATTERN.fullmatch(name):
        raise SceneError(f"name = {name!r}: must be letters, digits, '_', '.', '-' (it names the output "
                         "folder), at most 100 characters, starting with a letter or digit")
    description = top.string("description", default="")
    dim = top.get("dimension", required=True)
    if dim not in (2, 3) or not isinstance(dim, int) or isinstance(dim, bool):
        raise SceneError(f"dimension = {dim!r}: must be the integer 2 (disks per unit thickness) or 3 (spheres)")

    et = _Table(top.get("effects", {}), "effects")
    effects = {e: et.boolean(e, False) for e in EFFECTS}
    et.done()
    gravity = top.vector("gravity", dim, required=effects["gravity"])
    if gravity is None:
        gravity = np.zeros(3)
    gravity_rate = top.number("gravity_rate", 0.0, lo=-MAX_GRAVITY_RATE, hi=MAX_GRAVITY_RATE)
    if gravity_rate and not (effects["gravity"] and np.any(gravity)):
        raise SceneError(f"gravity_rate = {gravity_rate:g}: turning gravity needs effects.gravity = true and a "
                         "non-zero gravity")
    if gravity_rate and dim != 2:
        raise SceneError(f"gravity_rate = {gravity_rate:g}: gravity turns about z, in 2D scenes only (dimension = 2)")
    spinup = (0.0, 0.0)
    if "gravity_spinup" in top.data:
        st = _Table(top.get("gravity_spinup"), "gravity_spinup")
        spinup = (st.number("rate", required=True, lo=-MAX_GRAVITY_RATE, hi=MAX_GRAVITY_RATE),
                  st.number("duration", required=True, lo=0))
        st.done()
        if not gravity_rate:
            raise SceneError("gravity_spinup: goes with a turning gravity (set gravity_rate)")

    periodic = _periodic(top, dim)
    ramp = _gravity_ramp(top, dim, effects, gravity, gravity_rate)

    contact = _contact(_Table(top.get("contact", required=True), "contact"))

    tt = _Table(top.get("time", required=True), "time")
    dt = tt.number("dt", required=True, lo=0, lo_open=True)
    duration = tt.number("duration", required=True, lo=0, lo_open=True)
    tt.done()
    steps = duration / dt  # may be inf (a subnormal dt): refused below
    if steps > MAX_STEPS:
        raise SceneError(f"time.duration / time.dt = {steps:.3g} steps: must be <= {MAX_STEPS:.0e} "
                         f"(duration {duration:g} s at dt {dt:g} s; is one of them mistyped?)")

    # The size of the run is checked before any grain is made: a huge lattice is refused
    # at once instead of filling the memory first.
    grain_tables = [_Table(g, f"grain[{i}]") for i, g in enumerate(top.array("grain"))]
    lattices = [_Table(b, f"lattice[{i}]") for i, b in enumerate(top.array("lattice"))]
    counts = [_counts(bt, dim) for bt in lattices]
    rings = [_Table(b, f"ring[{i}]") for i, b in enumerate(top.array("ring"))]
    fills = [_Table(b, f"fill[{i}]") for i, b in enumerate(top.array("fill"))]
    if (rings or fills) and dim != 2:
        raise SceneError(f"{'ring' if rings else 'fill'}: rings and fills are made in 2D scenes only (dimension = 2)")
    bases = [_Table(b, f"base[{i}]") for i, b in enumerate(top.array("base"))]
    if bases and dim != 3:
        raise SceneError("base: a rough base of spheres is made in 3D scenes only (dimension = 3)")
    base_counts = [_base_count(t, periodic) for t in bases]
    n_grains = (len(grain_tables) + sum(math.prod(c) for c in counts)
                + sum(_count(t) for t in rings) + sum(_count(t) for t in fills) + sum(base_counts))
    if n_grains > MAX_GRAINS:
        raise SceneError(f"grain, lattice[].counts: {n_grains:.3g} grains; at most {MAX_GRAINS:.0e} per scene "
                         f"(the scene alone would need ~{n_grains * 0.9e3 / 1e9:.0f} GB)")
    if n_grains * steps > MAX_GRAIN_STEPS:
        raise SceneError(f"time.duration / time.dt x grains = {steps:.3g} steps x {n_grains} grains = "
                         f"{n_grains * steps:.3g} grain-steps; at most {MAX_GRAIN_STEPS:.0e} (~20 core-days on "
                         f"LIGGGHTS, the fastest engine here)")

    grains = []
    for i, gt in enumerate(grain_tables):
        grains.append(Grain(
            name=gt.string("name", f"g{i}"),
            radius=gt.number("radius", required=True, lo=0, lo_open=True),
            density=gt.number("density", required=True, lo=0, lo_open=True),
            position=gt.vector("position", dim, required=True),
            velocity=gt.vector("velocity", dim, default=[0.0] * dim),
            imposed=_axes(gt, "imposed", dim),
            angular_velocity=_spin(gt, dim, effects["rotation"]),
        ))
        _check_mass(gt.where, dim, grains[-1].radius, grains[-1].radius, grains[-1].density)
        gt.done()
    for bt, c in zip(lattices, counts):
        grains.extend(_lattice(bt, dim, len(grains), c))
    for rt in rings:
        grains.extend(_ring(rt))
    for ft in fills:
        grains.extend(_fill(ft))
    for bt, n in zip(bases, base_counts):
        grains.extend(_base(bt, n, periodic))
    if not grains:
        raise SceneError("grain: a scene needs at least one [[grain]] or [[lattice]]")
    _unique([g.name for g in grains], "grain.name")

    walls = []
    for i, w in enumerate(top.array("wall")):
        wt = _Table(w, f"wall[{i}]")
        normal = wt.vector("normal", dim, required=True)
        if np.linalg.norm(normal) == 0:
            raise SceneError(f"wall[{i}].normal: must not be the zero vector")
        wall = Wall(
            name=wt.string("name", f"w{i}"),
            point=wt.vector("point", dim, required=True),
            normal=normal / np.linalg.norm(normal),
            velocity=wt.vector("velocity", dim, default=[0.0] * dim),
            rotation=_rotation(wt, dim, i),
        )
        wt.done()
        moving = np.any(wall.velocity != 0) or wall.rotation is not None
        if moving and not effects["moving_walls"]:
            raise SceneError(f"wall[{i}] ({wall.name}) moves: set effects.moving_walls = true")
        walls.append(wall)
    for i, w in enumerate(walls):
        r = w.rotation
        if r is not None:  # the turn is counted in steps (Scene.rotation_steps): it must be a number of them
            turn = r.stop_angle / (r.rate * dt) if r.rate * dt > 0 else math.inf
            if not turn <= MAX_STEPS:
                raise SceneError(f"wall[{i}].rotation.rate = {r.rate:g} rad/s: at dt = {dt:g} s it reaches "
                                 f"stop_angle = {r.stop_angle:g} rad after {turn:.3g} steps; at most {MAX_STEPS:.0e}")
    _unique([g.name for g in grains] + [w.name for w in walls], "grain/wall name")
    _check_periodic(periodic, grains, walls)
    _check_start(grains, walls, dim, periodic)

    output = _output(_Table(top.get("output", {}), "output"), grains, walls)
    at = _Table(top.get("analysis", {"kind": "none"}), "analysis")
    kind = kinds.get(at.string("kind", "none", tuple(kinds.KINDS)))
    analysis = {"kind": kind.NAME, **kinds.read_names(at, kind, grains, walls, output, ramp)}
    at.done()
    top.done()

    scene = Scene(name, description, dim, effects, gravity, contact, dt, duration,
                  grains, walls, output, analysis, source, gravity_rate, spinup, periodic, ramp)
    if contact.rolling and not effects["rotation"]:
        raise SceneError(f"contact.rolling = {contact.rolling!r}: rolling resistance acts on spins; set "
                         "effects.rotation = true")
    if output.bulk and not scene.moving_grains():
        raise SceneError("output.bulk: the scene has no moving grain (every grain is fixed)")
    if ramp is not None and not scene.moving_grains():
        raise SceneError("gravity_ramp: its conditions follow the moving grains, and every grain is fixed")
    limits = stability_limits(scene)
    cause = min(limits, key=limits.get)
    if dt > limits[cause]:
        raise SceneError(f"time.dt = {dt:.3g} s: above the stability limit; must be <= {limits[cause]:.3g} s "
                         f"({cause} limit, from the masses, kn, ks and damping; see docs/scene-format.md)")
    if steps < 0.5:
        raise SceneError(f"time.duration = {duration:g} s: shorter than one step (dt = {dt:g} s)")
    recorded = (scene.steps // output.every + 1) * len(columns.names(scene))
    if recorded > MAX_RECORDED:
        raise SceneError(f"output.every = {output.every}: the time series would hold {recorded:.3g} values "
                         f"(rows x columns); at most {MAX_RECORDED:.0e} (~20 GB of CSV): record less often")
    return scene


def _apply_overrides(data, overrides):
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in data.items()}
    for k, v in overrides.items():
        if v is None:
            continue  # not given
        if k not in _OVERRIDES:
            raise SceneError(f"unknown override {k!r}: must be one of {', '.join(_OVERRIDES)}")
        table, key = _OVERRIDES[k]
        if not isinstance(data.get(table, {}), dict):
            continue  # the reader will say that the table is malformed
        data.setdefault(table, {})[key] = v
    return data


def _contact(ct) -> Contact:
    law = ct.string("law", "stick_slip", LAWS)
    spring = law in ("stick_slip", "visco_elastic")
    contact = Contact(
        law=law,
        kn=ct.number("kn", required=True),
        nu_n=ct.number("nu_n", 0.0),
        ks=ct.number("ks", 0.0, required=spring),
        nu_s=ct.number("nu_s", 0.0),
        mu_s=ct.number("mu_s", required=True),
        mu_k=ct.number("mu_k", required=True),
        reset=ct.string("reset", "spring", RESETS),
        slip_timing=ct.string("slip_timing", "step", SLIP_TIMINGS),
        rolling=ct.string("rolling", "", ("",) + ROLLING_MODELS),
        rolling_mu=ct.number("rolling_mu", 0.0, lo=0, hi=1),
    )
    ct.done()
    check_contact(contact)
    if contact.rolling and contact.rolling_mu <= 0:
        raise SceneError(f"contact.rolling_mu = {contact.rolling_mu:g}: must be > 0 with contact.rolling = "
                         f"{contact.rolling!r} (or leave contact.rolling out)")
    if contact.rolling_mu and not contact.rolling:
        raise SceneError(f"contact.rolling_mu = {contact.rolling_mu:g}: needs a rolling model "
                         f"(contact.rolling = {' or '.join(map(repr, ROLLING_MODELS))})")
    return contact


def check_contact(c: Contact) -> None:
    """The law's parameter rules (docs/law.md), checked by the kernel's own checker."""
    try:
        LawParams(c.law, c.kn, c.nu_n, c.ks, c.nu_s, c.mu_s, c.mu_k, c.reset, c.slip_timing)
    except ValueError as e:
        raise SceneError(f"contact.{e}") from None


def _output(ot, grains, walls) -> Output:
    gnames = {g.name for g in grains}
    wnames = {w.name for w in walls}
    output = Output(
        every=ot.integer("every", 1, lo=1, hi=MAX_EVERY),
        grains=_grain_names(ot, [g.name for g in grains]),
        contacts=ot.array("contacts"),
        walls=ot.names("walls", wnames, "a wall name"),
        stats=ot.boolean("stats", False),
        slip_stats=ot.boolean("slip_stats", False),
        energy=ot.boolean("energy", False),
        bulk=ot.boolean("bulk", False),
    )
    ot.done()
    seen = set()
    for pair in output.contacts:
        if (not isinstance(pair, list) or len(pair) != 2 or pair[0] not in gnames
                or pair[1] not in gnames | wnames or pair[0] == pair[1]):
            raise SceneError(f"output.contacts: {_shown(pair)} must be [grain, other grain or wall]")
        if frozenset(pair) in seen:  # [a, b] and [b, a] are one contact
            raise SceneError(f"output.contacts: {pair!r} is recorded twice (each contact once)")
        seen.add(frozenset(pair))
    return output


def _check_start(grains, walls, dim, periodic=None):
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
        a, b, dist = _near_pairs_periodic(x, r, periodic)
    else:
        a, b = _near_pairs(x[:, :dim], r)
        dist = np.linalg.norm(x[a] - x[b], axis=1)
    gap = dist - (r[a] + r[b])
    bad = np.flatnonzero(gap < -MAX_START_OVERLAP * np.minimum(r[a], r[b]))
    if len(bad):
        i, j = a[bad[0]], b[bad[0]]
        raise SceneError(f"grains {grains[i].name!r} and {grains[j].name!r} start overlapping by "
                         f"{-gap[bad[0]]:.3g} m: at most {MAX_START_OVERLAP:g} of the smaller radius")


def _near_pairs_periodic(x, r, periodic):
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


def _near_pairs(x, r):
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


class _Table:
    """A TOML table that remembers which keys were read, so unknown keys are errors."""

    def __init__(self, data, where):
        if not isinstance(data, dict):
            raise SceneError(f"{where}: expected a table, got {_shown(data)}")
        self.data, self.where, self.used = data, where, set()

    def key(self, k):
        return f"{self.where}.{k}" if self.where else k

    def get(self, k, default=None, required=False):
        self.used.add(k)
        if k not in self.data:
            if required:
                raise SceneError(f"{self.key(k)}: missing (required)")
            return default
        return self.data[k]

    def number(self, k, default=None, required=False, lo=None, hi=None, lo_open=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not _finite(v):
            raise SceneError(f"{self.key(k)}: expected a finite number (|x| <= {MAX_MAGNITUDE:g}), got {_shown(v)}")
        v = float(v)
        if lo is not None and (v < lo or (lo_open and v == lo)):
            rng = f"> {lo:g}" if lo_open else f">= {lo:g}"
            if hi is not None:
                rng += f" and <= {hi:g}"
            raise SceneError(f"{self.key(k)} = {v:g}: must be {rng}")
        if hi is not None and v > hi:
            raise SceneError(f"{self.key(k)} = {v:g}: must be <= {hi:g}")
        return v

    def integer(self, k, default=None, lo=None, hi=None):
        v = self.get(k, default)
        if isinstance(v, bool) or not isinstance(v, int):
            raise SceneError(f"{self.key(k)}: expected a whole number, got {_shown(v)}")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise SceneError(f"{self.key(k)} = {v}: must be in [{lo if lo is not None else '-inf'}, "
                             f"{hi if hi is not None else 'inf'}]")
        return v

    def boolean(self, k, default):
        v = self.get(k, default)
        if not isinstance(v, bool):
            raise SceneError(f"{self.key(k)}: expected true or false, got {_shown(v)}")
        return v

    def string(self, k, default=None, choices=None, required=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if not isinstance(v, str):
            raise SceneError(f"{self.key(k)}: expected a string, got {_shown(v)}")
        if choices and v not in choices:
            raise SceneError(f"{self.key(k)} = {v!r}: must be one of {', '.join(choices)}")
        return v

    def vector(self, k, dim, default=None, required=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if (not isinstance(v, list) or len(v) != dim
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and _finite(x) for x in v)):
            raise SceneError(f"{self.key(k)}: expected {dim} finite numbers (|x| <= {MAX_MAGNITUDE:g}, "
                             f"dimension = {dim}), got {_shown(v)}")
        out = np.zeros(3)
        out[:dim] = v
        return out

    def array(self, k):
        """A list (of tables or values); absent = empty."""
        v = self.get(k, [])
        if not isinstance(v, list):
            raise SceneError(f"{self.key(k)}: expected a list, got {_shown(v)}")
        return v

    def names(self, k, known, what):
        """A list of names, each one of `known`, each once (a name twice would give its
        columns twice)."""
        v = self.array(k)
        for x in v:
            if not isinstance(x, str) or x not in known:
                raise SceneError(f"{self.key(k)}: {_shown(x)} is not {what}")
        _unique(v, self.key(k))
        return list(v)

    def done(self):
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise SceneError(f"{self.key(unknown[0])}: unknown key")


def _finite(v):
    """A number within MAX_MAGNITUDE (an int too large for a float is not)."""
    try:
        return math.isfinite(v) and abs(v) <= MAX_MAGNITUDE
    except OverflowError:
        return False


def _shown(v):
    """A value in an error message, cut short (a whole table would not fit on one line)."""
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _spin(gt, dim, rotation):
    """A grain's initial angular velocity: a number (about z) in 2D, 3 numbers in 3D."""
    if dim == 2:
        w = np.zeros(3)
        w[2] = gt.number("angular_velocity", 0.0)
    else:
        w = gt.vector("angular_velocity", 3, default=[0.0, 0.0, 0.0])
    if np.any(w) and not rotation:
        raise SceneError(f"{gt.key('angular_velocity')}: a spinning grain needs effects.rotation = true")
    return w


def _axes(t: _Table, k, dim):
    v = t.get(k, [])
    allowed = "xyz"[:dim]
    if not isinstance(v, list) or any(not isinstance(a, str) or a not in allowed for a in v):
        raise SceneError(f"{t.key(k)}: expected a list of axes from {list(allowed)}, got {_shown(v)}")
    return tuple(v)


def _rotation(wt: _Table, dim, i):
    r = wt.get("rotation")
    if r is None:
        return None
    rt = _Table(r, f"wall[{i}].rotation")
    axis = rt.vector("axis", 3, default=[0.0, 0.0, 1.0]) if dim == 3 else np.array([0.0, 0.0, 1.0])
    if np.linalg.norm(axis) == 0:
        raise SceneError(f"wall[{i}].rotation.axis: must not be the zero vector")
    rot = WallRotation(
        pivot=rt.vector("pivot", dim, required=True),
        axis=axis / np.linalg.norm(axis),
        rate=rt.number("rate", required=True, lo=0, lo_open=True),
        stop_angle=rt.number("stop_angle", required=True, lo=0, lo_open=True, hi=math.pi / 2),
    )
    rt.done()
    return rot


def _counts(bt: _Table, dim):
    """A lattice's grain counts per axis, read before any grain is made (the size check)."""
    counts = bt.get("counts", required=True)
    if (not isinstance(counts, list) or len(counts) != dim
            or not all(isinstance(n, int) and not isinstance(n, bool) and n >= 1 for n in counts)):
        raise SceneError(f"{bt.key('counts')}: expected {dim} positive integers, got {_shown(counts)}")
    if math.prod(counts) > MAX_GRAINS:
        raise SceneError(f"{bt.key('counts')}: {math.prod(counts):.3g} grains; at most {MAX_GRAINS:.0e} per scene")
    return counts


def _lattice(bt: _Table, dim, start, counts):
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
    _check_mass(bt.where, dim, radius * (1 - spread), radius * (1 + spread), density)
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


def _check_mass(where, dim, r_min, r_max, density):
    """A grain's mass must lie within MASS_RANGE (radius and density each within range can
    still multiply far beyond it)."""
    lo, hi = MASS_RANGE
    for r in (r_min, r_max):
        m = mass(dim, r, density)
        if not lo <= m <= hi:
            raise SceneError(f"{where}.radius = {r:g} m with density = {density:g}: mass {m:g}; must be in "
                             f"[{lo:g}, {hi:g}] (SI units)")


def _unique(names, what):
    seen = set()
    for n in names:
        if n in seen:
            raise SceneError(f"{what}: {n!r} is used twice")
        seen.add(n)


def _grain_names(ot: _Table, names):
    """output.grains: grain names, each once; a name ending in '*' stands for every grain
    whose name starts with what precedes it, in the scene's order (a fill's grains)."""
    v = ot.array("grains")
    out = []
    for x in v:
        if isinstance(x, str) and x.endswith("*"):
            hit = [n for n in names if n.startswith(x[:-1])]
            if not hit:
                raise SceneError(f"output.grains: {x!r} matches no grain name")
            out.extend(hit)
        elif not isinstance(x, str) or x not in names:
            raise SceneError(f"output.grains: {_shown(x)} is not a grain name (or a prefix ending in '*')")
        else:
            out.append(x)
    _unique(out, "output.grains")
    return out


def _count(t: _Table):
    """A ring's or fill's grain count, read before any grain is made (the size check)."""
    n = t.get("count", required=True)
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_GRAINS:
        raise SceneError(f"{t.key('count')}: expected a whole number in [1, {MAX_GRAINS:.0e}], got {_shown(n)}")
    return n


def _ring(rt: _Table):
    """A drum's wall: `count` fixed disks evenly spaced on a circle of centres `radius`
    about `center`; grains inside touch the bumps between them (the drum's roughness)."""
    center = rt.vector("center", 2, required=True)
    radius = rt.number("radius", required=True, lo=0, lo_open=True)
    grain_radius = rt.number("grain_radius", required=True, lo=0, lo_open=True)
    density = rt.number("density", required=True, lo=0, lo_open=True)
    n = _count(rt)
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
    _check_mass(rt.where, 2, grain_radius, grain_radius, density)
    a = 2 * math.pi * np.arange(n) / n
    pos = np.zeros((n, 3))
    pos[:, 0], pos[:, 1] = center[0] + radius * np.cos(a), center[1] + radius * np.sin(a)
    return [Grain(f"{prefix}{k}", grain_radius, density, pos[k], np.zeros(3), fixed=True) for k in range(n)]


def _fill(ft: _Table):
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
    n = _count(ft)
    slope = ft.number("slope", 0.0, lo=-60.0, hi=60.0)
    seed = ft.integer("seed", 0, lo=0)
    prefix = ft.string("prefix", "p")
    ft.done()
    _check_mass(ft.where, 2, r * (1 - spread), r * (1 + spread), density)
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


def _periodic(top: _Table, dim):
    """[periodic]: axis -> (lo, hi), x and/or y, 3D only."""
    if "periodic" not in top.data:
        return {}
    pt = _Table(top.get("periodic"), "periodic")
    if dim != 3:
        raise SceneError("periodic: periodic boundaries are for 3D scenes (dimension = 3)")
    out = {}
    for axis in ("x", "y"):
        v = pt.get(axis)
        if v is None:
            continue
        if (not isinstance(v, list) or len(v) != 2 or not all(isinstance(a, (int, float)) and not isinstance(a, bool)
                                                              and _finite(a) for a in v) or not v[0] < v[1]):
            raise SceneError(f"{pt.key(axis)}: expected [lo, hi] with lo < hi (the periodic box along {axis}), "
                             f"got {_shown(v)}")
        out[axis] = (float(v[0]), float(v[1]))
    pt.done()
    if not out:
        raise SceneError("periodic: give x = [lo, hi] and/or y = [lo, hi]")
    return out


def _check_periodic(periodic, grains, walls):
    """Grains inside the periodic box, no wall across a periodic axis, and a box wide enough
    that no grain touches its own image."""
    if not periodic:
        return
    x = np.array([g.position for g in grains])
    r = np.array([g.radius for g in grains])
    for axis, (lo, hi) in periodic.items():
        k = "xyz".index(axis)
        out = np.flatnonzero((x[:, k] < lo) | (x[:, k] >= hi))
        if len(out):
            g = grains[out[0]]
            raise SceneError(f"grain {g.name!r} starts at {axis} = {g.position[k]:.6g}, outside the periodic box "
                             f"periodic.{axis} = [{lo:g}, {hi:g})")
        if hi - lo <= 4 * r.max():
            raise SceneError(f"periodic.{axis} = [{lo:g}, {hi:g}]: must be longer than two largest diameters "
                             f"({4 * r.max():.3g} m): a grain would touch its own image")
        for w in walls:
            if abs(w.normal[k]) > 1e-12:
                raise SceneError(f"wall {w.name!r}: its normal has a part along the periodic axis {axis} (a plane "
                                 "across a periodic box would cut it)")


def _gravity_ramp(top: _Table, dim, effects, gravity, gravity_rate):
    """[gravity_ramp]: 3D gravity turned about an axis through phases (docs/scene-format.md)."""
    if "gravity_ramp" not in top.data:
        return None
    rt = _Table(top.get("gravity_ramp"), "gravity_ramp")
    if dim != 3:
        raise SceneError("gravity_ramp: for 3D scenes (dimension = 3); 2D scenes turn gravity with gravity_rate")
    if not (effects["gravity"] and np.any(gravity)):
        raise SceneError("gravity_ramp: needs effects.gravity = true and a non-zero gravity")
    if gravity_rate:
        raise SceneError("gravity_ramp: not with gravity_rate (one way of turning gravity per scene)")
    axis = rt.vector("axis", 3, required=True)
    g = gravity / np.linalg.norm(gravity)
    if np.linalg.norm(axis) == 0 or abs(float(axis @ g)) > 1e-9 * np.linalg.norm(axis):
        raise SceneError(f"gravity_ramp.axis = {_shown(list(axis))}: must be a non-zero vector perpendicular to "
                         "gravity (gravity turns about it)")
    max_angle = rt.number("max_angle", 90.0, lo=0, lo_open=True, hi=180.0)
    phases = []
    for i, ph in enumerate(rt.array("phase")):
        pt = _Table(ph, f"gravity_ramp.phase[{i}]")
        rate = pt.number("rate", required=True, lo=-MAX_GRAVITY_RATE * 180 / math.pi, hi=MAX_GRAVITY_RATE * 180 / math.pi)
        given = [c for c in RAMP_CONDITIONS if c in pt.data]
        if len(given) != 1:
            raise SceneError(f"gravity_ramp.phase[{i}]: give exactly one of {', '.join(RAMP_CONDITIONS)} (how the "
                             f"phase ends), got {', '.join(given) or 'none'}")
        value = pt.number(given[0], required=True, lo=0, lo_open=True)
        pt.done()
        phases.append(RampPhase(math.radians(rate), given[0], value))
    rt.done()
    if not phases:
        raise SceneError("gravity_ramp.phase: at least one [[gravity_ramp.phase]]")
    return GravityRamp(axis / np.linalg.norm(axis), phases, math.radians(max_angle))


def _base_extent(bt: _Table, periodic):
    """A base's lower corner and its x, y size: the periodic box along a periodic axis
    unless given."""
    origin = bt.vector("origin", 3, required=True)
    size = bt.get("size")
    if size is None:
        if set(periodic) != {"x", "y"}:
            raise SceneError(f"{bt.key('size')}: missing (required unless the scene is periodic in x and y)")
        size = [periodic["x"][1] - periodic["x"][0], periodic["y"][1] - periodic["y"][0]]
    if (not isinstance(size, list) or len(size) != 2
            or not all(isinstance(a, (int, float)) and not isinstance(a, bool) and _finite(a) and a > 0 for a in size)):
        raise SceneError(f"{bt.key('size')}: expected 2 positive numbers (x and y extent), got {_shown(size)}")
    return origin, [float(a) for a in size]


def _base_count(bt: _Table, periodic):
    """How many spheres a base holds, read before any grain is made (the size check)."""
    origin, size = _base_extent(bt, periodic)
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


def _base(bt: _Table, n, periodic):
    """A rough base: n fixed spheres at random in the slab origin + [0, size] x [0, thickness]
    (z), pushed apart until none overlap (a slice of a random packing, as the rough base of
    Silbert et al. 2001); across the box's periodic boundaries where the base spans them."""
    origin, size = _base_extent(bt, periodic)
    radius = bt.number("radius", required=True, lo=0, lo_open=True)
    thickness = bt.number("thickness", 0.0, lo=0)
    density = bt.number("density", required=True, lo=0, lo_open=True)
    seed = bt.integer("seed", 0, lo=0)
    prefix = bt.string("prefix", "base")
    bt.number("number_density", required=True)
    bt.done()
    _check_mass(bt.where, 3, radius, radius, density)
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
