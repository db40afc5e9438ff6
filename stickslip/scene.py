"""Scene files: one TOML file describes a case once, for every engine.

`load(path_or_name)` reads and validates a scene and returns a `Scene`.
Any problem raises `SceneError` with a one-line message that names the key
and the allowed range; no engine ever sees an invalid scene.
The format is documented in docs/scene-format.md.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

CASES_DIR = Path(__file__).resolve().parent.parent / "cases"
LAWS = ("stick_slip", "visco_elastic", "visco_plastic", "coulomb")
RESETS = ("spring", "total")
SLIP_TIMINGS = ("step", "exact")
EFFECTS = ("gravity", "rotation", "normal_damping", "tangential_damping", "moving_walls")
ANALYSES = ("none", "drag", "tray", "tilt")


class SceneError(ValueError):
    """A scene that cannot be run; the message names the key and the allowed range."""


@dataclass
class Contact:
    law: str
    kn: float
    nu_n: float
    ks: float
    nu_s: float
    mu_s: float
    mu_k: float
    reset: str = "spring"
    slip_timing: str = "step"  # step (the paper, literally) | exact (docs/law.md)


@dataclass
class Grain:
    name: str
    radius: float
    density: float
    position: np.ndarray  # always 3 components; z = 0 in 2D
    velocity: np.ndarray
    imposed: tuple = ()  # velocity components held at their initial value: "x", "y", "z"
    # initial spin, rad/s, always 3 components (2D: about z only); needs effects.rotation
    angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))


@dataclass
class WallRotation:
    pivot: np.ndarray
    axis: np.ndarray  # unit vector; +z in 2D
    rate: float  # rad/s
    stop_angle: float  # rad; the wall is held there afterwards


@dataclass
class Wall:
    name: str
    point: np.ndarray
    normal: np.ndarray  # unit, pointing to the side where grains are
    velocity: np.ndarray
    rotation: WallRotation | None = None


@dataclass
class Output:
    every: int = 1
    grains: list = field(default_factory=list)
    contacts: list = field(default_factory=list)  # [grain, grain-or-wall] pairs
    walls: list = field(default_factory=list)
    stats: bool = False


@dataclass
class Scene:
    name: str
    description: str
    dimension: int
    effects: dict
    gravity: np.ndarray
    contact: Contact
    dt: float
    duration: float
    grains: list
    walls: list
    output: Output
    analysis: dict
    source: Path | None = None

    @property
    def steps(self) -> int:
        return int(round(self.duration / self.dt))

    def grain_mass(self, g: Grain) -> float:
        """Disk mass per unit thickness in 2D (the paper's convention), sphere mass in 3D."""
        if self.dimension == 2:
            return g.density * math.pi * g.radius**2
        return g.density * 4.0 / 3.0 * math.pi * g.radius**3

    def grain_inertia(self, g: Grain) -> float:
        m = self.grain_mass(g)
        return 0.5 * m * g.radius**2 if self.dimension == 2 else 0.4 * m * g.radius**2

    def critical_dt(self) -> float:
        return critical_dt(self)

    def rotation_steps(self, w: Wall) -> int:
        """Steps during which a rotating wall turns: it stops exactly at stop_angle."""
        r = w.rotation
        return max(1, int(round(r.stop_angle / (r.rate * self.dt))))

    def rotation_rate(self, w: Wall) -> float:
        """Rate actually applied so that the wall reaches stop_angle at the end of a step."""
        return w.rotation.stop_angle / (self.rotation_steps(w) * self.dt)


# ---------------------------------------------------------------- stability limit
# An impact must last at least this many steps (T_c = pi/w >= 5 dt). With fewer, an
# explicit step can give back more energy than the contact took: measured for an
# undamped grain-wall impact over 40 entry phases, the restitution reaches 1.02 at
# w*dt = 0.5, 1.11 at 0.9 and 1.25 at 1.2, so bouncing grains gain energy well below
# the oscillator's limit w*dt = 2 (see tests/test_stability.py).
IMPACT_STEPS = 5


def stability_limits(scene) -> dict:
    """The time-step limits of a scene, by cause (all single-contact estimates).

    - normal, tangential: a damped oscillator x'' + 2 zeta w x' + w^2 x = 0 integrated by
      leapfrog is stable for dt < (2/w)(sqrt(1 + zeta^2) - zeta), w^2 = k/m_eff;
    - impact: T_c = pi/w_n >= IMPACT_STEPS*dt (contacts open and close).
    m_eff is the lightest grain (on a wall) or the lightest pair (in series); the
    tangential spring also turns the grain when rotation is on, which lowers its
    effective mass to m/(1 + m r^2/I) (disk: m/3, sphere: m/3.5). A dense packing
    should run well below these (dt ~ T_c/50 is usual).
    """
    c, eff = scene.contact, scene.effects
    masses = sorted(scene.grain_mass(g) for g in scene.grains)
    candidates = []
    if scene.walls:
        candidates.append(masses[0])  # lightest grain on a wall
    if len(masses) >= 2:
        candidates.append(masses[0] * masses[1] / (masses[0] + masses[1]))  # lightest pair
    m_eff = min(candidates) if candidates else masses[0]
    turn = (3.0 if scene.dimension == 2 else 3.5) if eff["rotation"] else 1.0
    nu_n = c.nu_n if eff["normal_damping"] else 0.0
    nu_s = c.nu_s if eff["tangential_damping"] else 0.0
    limits = {"normal": _oscillator_limit(c.kn, nu_n, m_eff),
              "impact": math.pi / math.sqrt(c.kn / m_eff) / IMPACT_STEPS}
    if c.law in ("stick_slip", "visco_elastic"):
        limits["tangential"] = _oscillator_limit(c.ks, nu_s, m_eff / turn)
    elif nu_s > 0:
        # A pure dashpot (visco-plastic, Coulomb's regularisation) is explicitly stable for dt < 2 m / nu_s.
        limits["tangential"] = 2.0 * m_eff / (turn * nu_s)
    return limits


def critical_dt(scene) -> float:
    """Largest time step a scene may use: the smallest of `stability_limits`."""
    return min(stability_limits(scene).values())


def _oscillator_limit(k, nu, m):
    w = math.sqrt(k / m)
    zeta = nu / (2.0 * math.sqrt(k * m))
    return 2.0 / w * (math.sqrt(1.0 + zeta**2) - zeta)


# ---------------------------------------------------------------- parsing
class _Table:
    """A TOML table that remembers which keys were read, so unknown keys are errors."""

    def __init__(self, data, where):
        if not isinstance(data, dict):
            raise SceneError(f"{where}: expected a table, got {type(data).__name__}")
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
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SceneError(f"{self.key(k)}: expected a finite number, got {v!r}")
        v = float(v)
        if lo is not None and (v < lo or (lo_open and v == lo)):
            rng = f"> {lo:g}" if lo_open else f">= {lo:g}"
            if hi is not None:
                rng += f" and <= {hi:g}"
            raise SceneError(f"{self.key(k)} = {v:g}: must be {rng}")
        if hi is not None and v > hi:
            raise SceneError(f"{self.key(k)} = {v:g}: must be <= {hi:g}")
        return v

    def boolean(self, k, default):
        v = self.get(k, default)
        if not isinstance(v, bool):
            raise SceneError(f"{self.key(k)}: expected true or false, got {v!r}")
        return v

    def string(self, k, default=None, choices=None, required=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if not isinstance(v, str):
            raise SceneError(f"{self.key(k)}: expected a string, got {v!r}")
        if choices and v not in choices:
            raise SceneError(f"{self.key(k)} = {v!r}: must be one of {', '.join(choices)}")
        return v

    def vector(self, k, dim, default=None, required=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if (not isinstance(v, list) or len(v) != dim
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)):
            raise SceneError(f"{self.key(k)}: expected {dim} finite numbers (dimension = {dim}), got {v!r}")
        out = np.zeros(3)
        out[:dim] = v
        return out

    def done(self):
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise SceneError(f"{self.key(unknown[0])}: unknown key")


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
    """Read and validate a scene. `overrides` replace values after reading:
    dt, duration, law, reset, mu_k, mu_s, nu_s, ... and effects as `effect_<name>=bool`."""
    path = find(name_or_path)
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{path.name}: not valid TOML ({e})") from None
    scene = parse(data, source=path, overrides=overrides)
    return scene


def parse(data: dict, source=None, overrides=None) -> Scene:
    overrides = dict(overrides or {})
    top = _Table(data, "")
    name = top.string("name", required=True)
    description = top.string("description", default="")
    dim = top.get("dimension", required=True)
    if dim not in (2, 3) or isinstance(dim, bool):
        raise SceneError(f"dimension = {dim!r}: must be 2 (disks per unit thickness) or 3 (spheres)")

    et = _Table(top.get("effects", {}), "effects")
    effects = {e: et.boolean(e, False) for e in EFFECTS}
    et.done()
    for e in EFFECTS:
        if f"effect_{e}" in overrides:
            effects[e] = bool(overrides.pop(f"effect_{e}"))

    gravity = top.vector("gravity", dim, required=effects["gravity"])
    if gravity is None:
        gravity = np.zeros(3)

    ct = _Table(top.get("contact", required=True), "contact")
    law = ct.string("law", "stick_slip", LAWS)
    law = overrides.pop("law", None) or law
    if law not in LAWS:
        raise SceneError(f"law = {law!r}: must be one of {', '.join(LAWS)}")
    contact = Contact(
        law=law,
        kn=ct.number("kn", required=True, lo=0, lo_open=True),
        nu_n=ct.number("nu_n", 0.0, lo=0),
        ks=ct.number("ks", required=law in ("stick_slip", "visco_elastic"), lo=0, lo_open=True) or 0.0,
        nu_s=ct.number("nu_s", 0.0, lo=0),
        mu_s=ct.number("mu_s", required=True, lo=0, lo_open=True),
        mu_k=ct.number("mu_k", required=True, lo=0),
        reset=ct.string("reset", "spring", RESETS),
        slip_timing=ct.string("slip_timing", "step", SLIP_TIMINGS),
    )
    ct.done()
    for k in ("kn", "nu_n", "ks", "nu_s", "mu_s", "mu_k", "reset", "slip_timing"):
        if k in overrides:
            setattr(contact, k, overrides.pop(k))
    check_contact(contact)

    tt = _Table(top.get("time", required=True), "time")
    dt = tt.number("dt", required=True, lo=0, lo_open=True)
    duration = tt.number("duration", required=True, lo=0, lo_open=True)
    tt.done()
    dt = float(overrides.pop("dt", None) or dt)
    duration = float(overrides.pop("duration", None) or duration)
    if not dt > 0:
        raise SceneError(f"dt = {dt:g}: must be > 0")

    grains = []
    for i, g in enumerate(top.get("grain", [])):
        gt = _Table(g, f"grain[{i}]")
        grains.append(Grain(
            name=gt.string("name", f"g{i}"),
            radius=gt.number("radius", required=True, lo=0, lo_open=True),
            density=gt.number("density", required=True, lo=0, lo_open=True),
            position=gt.vector("position", dim, required=True),
            velocity=gt.vector("velocity", dim, default=[0.0] * dim),
            imposed=_axes(gt, "imposed", dim),
            angular_velocity=_spin(gt, dim, effects["rotation"]),
        ))
        gt.done()
    for i, b in enumerate(top.get("lattice", [])):
        grains.extend(_lattice(_Table(b, f"lattice[{i}]"), dim, len(grains)))
    if not grains:
        raise SceneError("grain: a scene needs at least one [[grain]] or [[lattice]]")
    _unique([g.name for g in grains], "grain.name")

    walls = []
    for i, w in enumerate(top.get("wall", [])):
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
    _unique([g.name for g in grains] + [w.name for w in walls], "grain/wall name")

    ot = _Table(top.get("output", {}), "output")
    output = Output(
        every=int(ot.number("every", 1, lo=1)),
        grains=ot.get("grains", []),
        contacts=ot.get("contacts", []),
        walls=ot.get("walls", []),
        stats=ot.boolean("stats", False),
    )
    ot.done()
    if "every" in overrides:
        output.every = int(overrides.pop("every"))
    gnames = {g.name for g in grains}
    wnames = {w.name for w in walls}
    for gname in output.grains:
        if gname not in gnames:
            raise SceneError(f"output.grains: {gname!r} is not a grain name")
    for pair in output.contacts:
        if (not isinstance(pair, list) or len(pair) != 2 or pair[0] not in gnames
                or pair[1] not in gnames | wnames or pair[0] == pair[1]):
            raise SceneError(f"output.contacts: {pair!r} must be [grain, other grain or wall]")
    for wname in output.walls:
        if wname not in wnames:
            raise SceneError(f"output.walls: {wname!r} is not a wall name")

    at = _Table(top.get("analysis", {"kind": "none"}), "analysis")
    analysis = {"kind": at.string("kind", "none", ANALYSES)}
    for k in list(at.data):
        if k != "kind":
            analysis[k] = at.get(k)
    top.done()
    if overrides:
        raise SceneError(f"unknown override {sorted(overrides)[0]!r}")

    scene = Scene(name, description, dim, effects, gravity, contact, dt, duration,
                  grains, walls, output, analysis, source)
    limits = stability_limits(scene)
    cause = min(limits, key=limits.get)
    if dt > limits[cause]:
        raise SceneError(f"time.dt = {dt:.3g} s: above the stability limit; must be <= {limits[cause]:.3g} s "
                         f"({cause} limit, from the masses, kn, ks and damping; see docs/scene-format.md)")
    if scene.steps < 1:
        raise SceneError(f"time.duration = {duration:g} s: shorter than one step (dt = {dt:g} s)")
    return scene


def check_contact(c: Contact) -> None:
    """Parameter ranges of the law (docs/law.md)."""
    for k in ("kn", "nu_n", "ks", "nu_s", "mu_s", "mu_k"):
        v = getattr(c, k)
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SceneError(f"contact.{k} = {v!r}: must be a finite number")
    if c.kn <= 0:
        raise SceneError(f"contact.kn = {c.kn:g}: must be > 0")
    if c.law in ("stick_slip", "visco_elastic") and c.ks <= 0:
        raise SceneError(f"contact.ks = {c.ks:g}: must be > 0")
    for k in ("nu_n", "nu_s", "ks"):
        if getattr(c, k) < 0:
            raise SceneError(f"contact.{k} = {getattr(c, k):g}: must be >= 0")
    if c.mu_s <= 0:
        raise SceneError(f"contact.mu_s = {c.mu_s:g}: must be > 0")
    if c.law == "stick_slip" and not (c.mu_s / 2 <= c.mu_k <= c.mu_s):
        raise SceneError(f"contact.mu_k = {c.mu_k:g}: must be in [mu_s/2, mu_s] = "
                         f"[{c.mu_s / 2:g}, {c.mu_s:g}] so that 0 <= Fmin = (2 mu_k - mu_s) Fn <= mu_k Fn")
    if c.mu_k < 0:
        raise SceneError(f"contact.mu_k = {c.mu_k:g}: must be >= 0")
    if c.reset not in RESETS:
        raise SceneError(f"contact.reset = {c.reset!r}: must be one of {', '.join(RESETS)}")
    if c.slip_timing not in SLIP_TIMINGS:
        raise SceneError(f"contact.slip_timing = {c.slip_timing!r}: must be one of {', '.join(SLIP_TIMINGS)}")


def _axes(t: _Table, k, dim):
    v = t.get(k, [])
    allowed = "xyz"[:dim]
    if not isinstance(v, list) or any(a not in allowed for a in v):
        raise SceneError(f"{t.key(k)}: expected a list of axes from {list(allowed)}, got {v!r}")
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


def _lattice(bt: _Table, dim, start):
    """A block of grains on a square/cubic lattice, radii spread uniformly (seeded)."""
    counts = bt.get("counts", required=True)
    if (not isinstance(counts, list) or len(counts) != dim
            or not all(isinstance(n, int) and n >= 1 for n in counts)):
        raise SceneError(f"{bt.key('counts')}: expected {dim} positive integers, got {counts!r}")
    origin = bt.vector("origin", dim, required=True)
    radius = bt.number("radius", required=True, lo=0, lo_open=True)
    spread = bt.number("radius_spread", 0.0, lo=0, hi=0.5)
    spacing = bt.number("spacing", 2.0 * radius * (1 + spread) * 1.05, lo=2.0 * radius * (1 + spread))
    density = bt.number("density", required=True, lo=0, lo_open=True)
    velocity = bt.vector("velocity", dim, default=[0.0] * dim)
    jitter = bt.number("velocity_jitter", 0.0, lo=0)
    seed = int(bt.number("seed", 0, lo=0))
    prefix = bt.string("prefix", "p")
    bt.done()
    rng = np.random.default_rng(seed)
    grains = []
    for idx in np.ndindex(*counts):
        pos = origin.copy()
        pos[:dim] += np.array(idx) * spacing
        vel = velocity.copy()
        vel[:dim] += jitter * rng.uniform(-1, 1, dim)
        r = radius * (1 + spread * rng.uniform(-1, 1))
        grains.append(Grain(f"{prefix}{start + len(grains)}", r, density, pos, vel))
    return grains


def _unique(names, what):
    seen = set()
    for n in names:
        if n in seen:
            raise SceneError(f"{what}: {n!r} is used twice")
        seen.add(n)
