# SPDX-License-Identifier: GPL-2.0-or-later
"""Reading and checking a scene file (docs/scene-format.md).

Every problem raises SceneError with one line that names the key and the allowed
range; overrides (command line, tests) are written into the file's data before it is
read, so they are checked by the same rules and named the same way.
"""
from __future__ import annotations

import dataclasses
import json
import math
import re
import tomllib
from pathlib import Path

import numpy as np

from pyref.laws import LAWS, RESETS, SLIP_TIMINGS, SPRING_LAWS, LawParams

from .. import columns, kinds, shipped
from ..errors import SceneError
from .grains import (MAX_GRAINS, base, base_count, block_count, check_mass, check_periodic, check_start, fill,
                     initial_spin, lattice, lattice_counts,
                     ring)
from .model import Contact, GravityRamp, Grain, Lid, Output, RampPhase, Scene, Wall, WallRotation
from .stability import stability_limits
from .table import Table, finite, shown, unique

CASES_DIR = shipped.path("cases")
EFFECTS = ("gravity", "rotation", "normal_damping", "tangential_damping", "moving_walls")
# A scene name becomes a folder name (runs/NAME/...): letters, digits, _ . - only.
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")
# More steps than this is refused: at a microsecond per step it would run for 3 hours
# per grain, and it is almost always a mistyped dt or duration.
MAX_STEPS = 10**10
# More grain-steps (steps x grains) than this is refused: LIGGGHTS, the fastest engine
# here, does ~6e6 grain-steps/s per core (liggghts_plugin/doc: 20 800 grains, 3.55 ms per
# step), so 10^13 is ~20 core-days (pyref, ~5e5/s: ~8 months).
MAX_GRAIN_STEPS = 10**13
# More recorded values (rows x columns of the time series) than this is refused: 8 GB
# as float64 in memory and ~20 GB of timeseries.csv. Raise output.every instead.
MAX_RECORDED = 10**9

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

# Overrides by name -> (table, key) in the scene file.
# Rolling resistance models (contact.rolling): LIGGGHTS' epsd2 only (no other engine here has one).
ROLLING_MODELS = ("epsd2",)
# gravity_ramp: a phase ends on one of these conditions (RampPhase.until).
RAMP_CONDITIONS = ("duration", "speed_above", "speed_below")

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
    top = Table(data, "")
    name = top.string("name", required=True)
    if not NAME_PATTERN.fullmatch(name):
        raise SceneError(f"name = {name!r}: must be letters, digits, '_', '.', '-' (it names the output "
                         "folder), at most 100 characters, starting with a letter or digit")
    description = top.string("description", default="")
    dim = top.get("dimension", required=True)
    if dim not in (2, 3) or not isinstance(dim, int) or isinstance(dim, bool):
        raise SceneError(f"dimension = {dim!r}: must be the integer 2 (disks per unit thickness) or 3 (spheres)")

    et = Table(top.get("effects", {}), "effects")
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
        st = Table(top.get("gravity_spinup"), "gravity_spinup")
        spinup = (st.number("rate", required=True, lo=-MAX_GRAVITY_RATE, hi=MAX_GRAVITY_RATE),
                  st.number("duration", required=True, lo=0))
        st.done()
        if not gravity_rate:
            raise SceneError("gravity_spinup: goes with a turning gravity (set gravity_rate)")

    periodic = _periodic(top, dim)
    ramp = _gravity_ramp(top, dim, effects, gravity, gravity_rate)

    contact = _contact(Table(top.get("contact", required=True), "contact"))

    tt = Table(top.get("time", required=True), "time")
    dt = tt.number("dt", required=True, lo=0, lo_open=True)
    duration = tt.number("duration", required=True, lo=0, lo_open=True)
    tt.done()
    steps = duration / dt  # may be inf (a subnormal dt): refused below
    if steps > MAX_STEPS:
        raise SceneError(f"time.duration / time.dt = {steps:.3g} steps: must be <= {MAX_STEPS:.0e} "
                         f"(duration {duration:g} s at dt {dt:g} s; is one of them mistyped?)")

    # The size of the run is checked before any grain is made: a huge lattice is refused
    # at once instead of filling the memory first.
    grain_tables = [Table(g, f"grain[{i}]") for i, g in enumerate(top.array("grain"))]
    lattices = [Table(b, f"lattice[{i}]") for i, b in enumerate(top.array("lattice"))]
    counts = [lattice_counts(bt, dim) for bt in lattices]
    rings = [Table(b, f"ring[{i}]") for i, b in enumerate(top.array("ring"))]
    fills = [Table(b, f"fill[{i}]") for i, b in enumerate(top.array("fill"))]
    if (rings or fills) and dim != 2:
        raise SceneError(f"{'ring' if rings else 'fill'}: rings and fills are made in 2D scenes only (dimension = 2)")
    bases = [Table(b, f"base[{i}]") for i, b in enumerate(top.array("base"))]
    if bases and dim != 3:
        raise SceneError("base: a rough base of spheres is made in 3D scenes only (dimension = 3)")
    base_counts = [base_count(t, periodic) for t in bases]
    lid_slab, drive = _lid(top, dim, periodic)
    lid_count = base_count(lid_slab, periodic) if lid_slab is not None else 0
    n_grains = (len(grain_tables) + sum(math.prod(c) for c in counts) + lid_count
                + sum(block_count(t) for t in rings) + sum(block_count(t) for t in fills) + sum(base_counts))
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
            angular_velocity=initial_spin(gt, dim, effects["rotation"]),
        ))
        check_mass(gt.where, dim, grains[-1].radius, grains[-1].radius, grains[-1].density)
        gt.done()
    for bt, c in zip(lattices, counts):
        grains.extend(lattice(bt, dim, len(grains), c))
    for rt in rings:
        grains.extend(ring(rt))
    for ft in fills:
        grains.extend(fill(ft))
    for bt, n in zip(bases, base_counts):
        grains.extend(base(bt, n, periodic))
    lid = None
    if lid_slab is not None:  # a base's slab, its grains free to move (together: the adapters)
        lid_grains = [dataclasses.replace(g, fixed=False) for g in base(lid_slab, lid_count, periodic)]
        grains.extend(lid_grains)
        area = (periodic["x"][1] - periodic["x"][0]) * (periodic["y"][1] - periodic["y"][0])
        lid = Lid(tuple(g.name for g in lid_grains), *drive, area)
    if not grains:
        raise SceneError("grain: a scene needs at least one [[grain]] or [[lattice]]")
    unique([g.name for g in grains], "grain.name")

    walls = []
    for i, w in enumerate(top.array("wall")):
        wt = Table(w, f"wall[{i}]")
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
    unique([g.name for g in grains] + [w.name for w in walls], "grain/wall name")
    check_periodic(periodic, grains, walls)
    check_start(grains, walls, dim, periodic)

    output = _output(Table(top.get("output", {}), "output"), grains, walls)
    at = Table(top.get("analysis", {"kind": "none"}), "analysis")
    kind = kinds.get(at.string("kind", "none", tuple(kinds.KINDS)))
    analysis = {"kind": kind.NAME, **kinds.read_names(at, kind, grains, walls, output, ramp)}
    at.done()
    top.done()

    scene = Scene(name, description, dim, effects, gravity, contact, dt, duration,
                  grains, walls, output, analysis, source, gravity_rate, spinup, periodic, ramp, lid)
    if contact.rolling and not effects["rotation"]:
        raise SceneError(f"contact.rolling = {contact.rolling!r}: rolling resistance acts on spins; set "
                         "effects.rotation = true")
    if (output.bulk or ramp is not None) and not scene.moving_grains():
        raise SceneError(f"{'output.bulk' if output.bulk else 'gravity_ramp'}: follows the moving grains, and "
                         "every grain is fixed")
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
    spring = law in SPRING_LAWS
    contact = Contact(
        law=law,
        kn=ct.number("kn", required=True),
        nu_n=ct.number("nu_n", 0.0),
        ks=ct.number("ks", 0.0, required=spring),
        nu_s=ct.number("nu_s", 0.0),
        mu_s=ct.number("mu_s", required=True),
        mu_k=ct.number("mu_k", required=True),
        reset=ct.string("reset", RESETS[0], RESETS),
        slip_timing=ct.string("slip_timing", SLIP_TIMINGS[0], SLIP_TIMINGS),
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
            raise SceneError(f"output.contacts: {shown(pair)} must be [grain, other grain or wall]")
        if frozenset(pair) in seen:  # [a, b] and [b, a] are one contact
            raise SceneError(f"output.contacts: {pair!r} is recorded twice (each contact once)")
        seen.add(frozenset(pair))
    return output


def _axes(t: Table, k, dim):
    v = t.get(k, [])
    allowed = "xyz"[:dim]
    if not isinstance(v, list) or any(not isinstance(a, str) or a not in allowed for a in v):
        raise SceneError(f"{t.key(k)}: expected a list of axes from {list(allowed)}, got {shown(v)}")
    return tuple(v)


def _rotation(wt: Table, dim, i):
    r = wt.get("rotation")
    if r is None:
        return None
    rt = Table(r, f"wall[{i}].rotation")
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


def _grain_names(ot: Table, names):
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
            raise SceneError(f"output.grains: {shown(x)} is not a grain name (or a prefix ending in '*')")
        else:
            out.append(x)
    unique(out, "output.grains")
    return out


def _periodic(top: Table, dim):
    """[periodic]: axis -> (lo, hi), x and/or y, 3D only."""
    if "periodic" not in top.data:
        return {}
    pt = Table(top.get("periodic"), "periodic")
    if dim != 3:
        raise SceneError("periodic: periodic boundaries are for 3D scenes (dimension = 3)")
    out = {}
    for axis in ("x", "y"):
        v = pt.get(axis)
        if v is None:
            continue
        if (not isinstance(v, list) or len(v) != 2 or not all(isinstance(a, (int, float)) and not isinstance(a, bool)
                                                              and finite(a) for a in v) or not v[0] < v[1]):
            raise SceneError(f"{pt.key(axis)}: expected [lo, hi] with lo < hi (the periodic box along {axis}), "
                             f"got {shown(v)}")
        out[axis] = (float(v[0]), float(v[1]))
    pt.done()
    if not out:
        raise SceneError("periodic: give x = [lo, hi] and/or y = [lo, hi]")
    return out


LID_DRIVE = ("pressure", "stiffness", "velocity", "start")


def _lid(top: Table, dim, periodic):
    """[lid]: (a Table of its slab for grains.base: origin, thickness, number_density, radius,
    density, seed, prefix "lid"; (pressure, stiffness, velocity, start)), or (None, None)."""
    if "lid" not in top.data:
        return None, None
    raw = top.get("lid")
    lt = Table(raw, "lid")
    if dim != 3 or set(periodic) != {"x", "y"}:
        raise SceneError("lid: a driven lid spans a box periodic in x and y (dimension = 3, [periodic] x and y)")
    drive = (lt.number("pressure", required=True, lo=0), lt.number("stiffness", required=True, lo=0, lo_open=True),
             lt.number("velocity", required=True), lt.number("start", 0.0, lo=0))
    if "size" in raw:
        raise SceneError("lid.size: a lid spans the periodic box (leave size out)")
    return Table({"prefix": "lid", **{k: v for k, v in raw.items() if k not in LID_DRIVE}}, "lid"), drive


def _gravity_ramp(top: Table, dim, effects, gravity, gravity_rate):
    """[gravity_ramp]: 3D gravity turned about an axis through phases (docs/scene-format.md)."""
    if "gravity_ramp" not in top.data:
        return None
    rt = Table(top.get("gravity_ramp"), "gravity_ramp")
    if dim != 3:
        raise SceneError("gravity_ramp: for 3D scenes (dimension = 3); 2D scenes turn gravity with gravity_rate")
    if not (effects["gravity"] and np.any(gravity)):
        raise SceneError("gravity_ramp: needs effects.gravity = true and a non-zero gravity")
    if gravity_rate:
        raise SceneError("gravity_ramp: not with gravity_rate (one way of turning gravity per scene)")
    axis = rt.vector("axis", 3, required=True)
    g = gravity / np.linalg.norm(gravity)
    if np.linalg.norm(axis) == 0 or abs(float(axis @ g)) > 1e-9 * np.linalg.norm(axis):
        raise SceneError(f"gravity_ramp.axis = {shown([float(a) for a in axis])}: must be a non-zero vector "
                         "perpendicular to gravity (gravity turns about it)")
    max_angle = rt.number("max_angle", 90.0, lo=0, lo_open=True, hi=180.0)
    phases = []
    for i, ph in enumerate(rt.array("phase")):
        pt = Table(ph, f"gravity_ramp.phase[{i}]")
        most = math.degrees(MAX_GRAVITY_RATE)
        rate = pt.number("rate", required=True, lo=-most, hi=most)
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
