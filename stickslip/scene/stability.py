"""The largest time step a scene may use, by cause (docs/scene-format.md)."""
from __future__ import annotations

import math

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
              "impact": _ratio(math.pi, math.sqrt(c.kn / m_eff) * IMPACT_STEPS)}
    if c.law in ("stick_slip", "visco_elastic"):
        limits["tangential"] = _oscillator_limit(c.ks, nu_s, m_eff / turn)
    elif nu_s > 0:
        # A pure dashpot (visco-plastic, Coulomb's regularisation) is explicitly stable for dt < 2 m / nu_s.
        limits["tangential"] = _ratio(2.0 * m_eff, turn * nu_s)
    return limits


def critical_dt(scene) -> float:
    """Largest time step a scene may use: the smallest of `stability_limits`."""
    return min(stability_limits(scene).values())


def _oscillator_limit(k, nu, m):
    """(2/w)(sqrt(1 + zeta^2) - zeta), written so that extreme (finite, positive) inputs
    give 0 or inf instead of raising: sqrt(1 + z^2) - z = 1/(sqrt(1 + z^2) + z)."""
    w = math.sqrt(k / m)
    zeta = _ratio(nu, 2.0 * math.sqrt(k) * math.sqrt(m))
    return _ratio(2.0, w) / (math.sqrt(1.0 + zeta * zeta) + zeta)


def _ratio(a, b):
    """a / b for a >= 0, b >= 0, with a / 0 = inf (0 / 0 = 0): a limit that does not bind."""
    if b == 0:
        return math.inf if a > 0 else 0.0
    return a / b
