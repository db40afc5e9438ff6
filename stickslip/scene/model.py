# SPDX-License-Identifier: GPL-2.0-or-later
"""The data a scene file describes: contact parameters, grains, walls, output, time."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pyref.laws import RESETS, SLIP_TIMINGS, LawParams

from . import stability


def mass(dim, radius, density) -> float:
    """Disk mass per unit thickness in 2D (the paper's convention), sphere mass in 3D.
    (The reader bounds radius and density to 1e100, so the powers cannot overflow; the
    product can reach inf or 0, which the reader refuses.)"""
    if dim == 2:
        return density * math.pi * radius**2
    return density * 4.0 / 3.0 * math.pi * radius**3


@dataclass
class Contact:
    law: str
    kn: float
    nu_n: float
    ks: float
    nu_s: float
    mu_s: float
    mu_k: float
    reset: str = RESETS[0]  # spring (eq. 8, the paper) | total (docs/law.md)
    slip_timing: str = SLIP_TIMINGS[0]  # step (the paper, literally) | exact (docs/law.md)
    # rolling resistance: "" (none) or "epsd2" (LIGGGHTS' elastic-plastic spring-dashpot
    # model: a torque opposing the relative rolling, capped at rolling_mu * R * Fn)
    rolling: str = ""
    rolling_mu: float = 0.0

    def law_params(self, effects) -> LawParams:
        """The kernel's parameters with the scene's effects applied (damping off = 0)."""
        return LawParams(self.law, self.kn, self.nu_n if effects["normal_damping"] else 0.0, self.ks,
                         self.nu_s if effects["tangential_damping"] else 0.0, self.mu_s, self.mu_k,
                         self.reset, self.slip_timing)


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
    # held where it starts: zero velocity and spin, whatever the forces (a drum's wall
    # grains, [[ring]]); it still exerts contact forces on the others
    fixed: bool = False


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
    # slip statistics of the grain-grain contacts at each row (columns.SLIP_STATS)
    slip_stats: bool = False
    energy: bool = False  # energy columns (docs/adapters.md); engines that cannot give them refuse
    # the moving grains' centre of mass and its velocity (columns.BULK)
    bulk: bool = False


@dataclass
class RampPhase:
    """One phase of a gravity ramp: gravity turns at `rate` (rad/s, signed) until `until`
    holds: "duration" (for `value` s), "speed_above" or "speed_below" (the moving grains'
    mean velocity along the ramp's downhill direction passes `value`, m/s)."""
    rate: float
    until: str
    value: float


@dataclass
class GravityRamp:
    """3D gravity turned about `axis` (unit) through phases (a tilting incline). The angle
    and the conditions change only at the recorded rows (every output.every steps): over
    each interval the angle is held, then it moves by rate * every * dt for the next one."""
    axis: np.ndarray
    phases: list
    max_angle: float  # rad: the run ends if the angle leaves [0, max_angle]


@dataclass
class Lid:
    """A rough lid on a bed in a box periodic in x and y ([lid], docs/scene-format.md): its
    grains move together as one body in translation (no spin), pressed along -z by `pressure`
    (Pa: N/m^2, beyond their own weight) over the box's `area`, and pulled along x by a spring
    of `stiffness` (N/m) whose far end moves at `velocity` (m/s) from `start` (s), at rest
    before: a shear cell driven through a spring."""
    names: tuple
    pressure: float
    stiffness: float
    velocity: float
    start: float
    area: float


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
    # gravity turns about +z at this rate, rad/s: g(t) = R_z(gravity_rate * t) gravity.
    # A still drum under turning gravity is a drum turning the other way under fixed
    # gravity, less the centrifugal and Coriolis terms (docs/drum.md).
    gravity_rate: float = 0.0
    # (rate, duration): gravity turns at this rate first, for this long, then at
    # gravity_rate (a drum brought quickly to its avalanche angle, then turned slowly)
    gravity_spinup: tuple = (0.0, 0.0)
    # 3D: axis -> (lo, hi) of the periodic box along x and/or y (grains leaving at hi come back at lo)
    periodic: dict = field(default_factory=dict)
    gravity_ramp: GravityRamp | None = None
    lid: Lid | None = None

    def gravity_angle(self, t) -> float:
        """The angle gravity has turned by at time t, rad."""
        rate0, t0 = self.gravity_spinup  # (LIGGGHTS' adapter writes the same arithmetic)
        return rate0 * t + (self.gravity_rate - rate0) * (t - t0) if t > t0 else rate0 * t

    def gravity_at(self, t) -> np.ndarray:
        """The gravity vector at time t (the scene's, turned by gravity_angle(t))."""
        if not (self.gravity_rate or self.gravity_spinup[1]):
            return self.gravity
        a = self.gravity_angle(t)
        c, s = math.cos(a), math.sin(a)
        g = self.gravity
        return np.array([c * g[0] - s * g[1], s * g[0] + c * g[1], g[2]])

    def downhill(self) -> np.ndarray:
        """The ramp's downhill direction: where gravity turns to, axis x initial gravity (unit)."""
        u = np.cross(self.gravity_ramp.axis, self.gravity)
        return u / np.linalg.norm(u)

    def gravity_tilted(self, angle) -> np.ndarray:
        """The scene's gravity turned by `angle` (rad) about the ramp's axis (Rodrigues)."""
        k, g = self.gravity_ramp.axis, self.gravity
        c, s = math.cos(angle), math.sin(angle)
        return g * c + np.cross(k, g) * s + k * float(k @ g) * (1 - c)

    def features(self) -> dict:
        """The features of this scene that not every engine has: {key: what it is, in words}."""
        out = {}
        if self.periodic:
            out["periodic"] = "periodic boundaries (periodic)"
        if self.gravity_ramp is not None:
            out["gravity_ramp"] = "gravity ramps (gravity_ramp)"
        if self.contact.rolling:
            out["rolling"] = "rolling resistance (contact.rolling)"
        if self.output.bulk:
            out["bulk"] = "the bulk columns (output.bulk)"
        if self.lid is not None:
            out["lid"] = "a driven lid (lid)"
        return out

    def refuse_unsupported(self, engine, supported=()):
        """One line (ValueError) if the scene needs a feature the engine lacks, never a silent run."""
        missing = [text for key, text in self.features().items() if key not in supported]
        if missing:
            raise ValueError(f"{engine} cannot run scene {self.name}: it does not support {', '.join(missing)}")

    def moving_grains(self) -> list:
        """The grains integrated one by one: neither fixed nor a driven lid's."""
        lid = set(self.lid.names) if self.lid is not None else ()
        return [g for g in self.grains if not g.fixed and g.name not in lid]

    def lid_grains(self) -> list:
        lid = set(self.lid.names) if self.lid is not None else ()
        return [g for g in self.grains if g.name in lid]

    @property
    def steps(self) -> int:
        return int(round(self.duration / self.dt))

    def grain_mass(self, g: Grain) -> float:
        return mass(self.dimension, g.radius, g.density)

    def grain_inertia(self, g: Grain) -> float:
        m = self.grain_mass(g)
        return 0.5 * m * g.radius**2 if self.dimension == 2 else 0.4 * m * g.radius**2

    def critical_dt(self) -> float:
        return stability.critical_dt(self)

    def rotation_steps(self, w: Wall) -> int:
        """Steps during which a rotating wall turns: it stops exactly at stop_angle."""
        r = w.rotation
        return max(1, int(round(r.stop_angle / (r.rate * self.dt))))

    def rotation_rate(self, w: Wall) -> float:
        """Rate actually applied so that the wall reaches stop_angle at the end of a step."""
        return w.rotation.stop_angle / (self.rotation_steps(w) * self.dt)
