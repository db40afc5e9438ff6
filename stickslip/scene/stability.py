# SPDX-License-Identifier: GPL-2.0-or-later
"""The largest time step a scene may use, by cause, and the step below which its
collisions are accurate (docs/scene-format.md)."""
from __future__ import annotations

import math

from pyref.laws import SPRING_LAWS

# An impact must last at least this many steps (T_c = pi/w >= 5 dt). With fewer, an
# explicit step can give back more energy than the contact took: measured for an
# undamped grain-wall impact over 40 entry phases, the restitution reaches 1.02 at
# w*dt = 0.5, 1.11 at 0.9 and 1.25 at 1.2, so bouncing grains gain energy well below
# the oscillator's limit w*dt = 2 (see tests/test_stability.py).
IMPACT_STEPS = 5

# Stable is not accurate: a contact resolved by few steps loses or keeps the wrong share
# of its energy. Measured on pyref (tests/test_collision_accuracy.py, whose __main__ prints
# this table): head-on impacts of disk pairs with Table 2's kn and nu_n (equal 5 mm disks,
# zeta = 0.02, and 100:1 radius pairs, zeta = 0.3 to 8), 64 entry phases per step, against
# the same impact at T/3000. With T = min(pi*sqrt(m/kn), 4*pi*m/nu_n) (the spring's
# half-period, or the dashpot's time when that is shorter: zeta > 2), the worst error of
# the restitution, as a share of the impact speed, depends on the steps per contact
# n = T/dt alone once n >= 14, ~0.7/n:
#     n        5     6    10     14     18     20     22     24     25     50
#     error  1.9   1.3   0.31  0.053  0.041  0.036  0.033  0.030  0.029  0.015
# (worst over the pairs: zeta ~ 0.7-1 from n = 14 on; below, zeta >= 2, near or past its
# stability limit; the equal disks: 0.005 at n = 20). The damped half-period
# pi/sqrt(kn/m - (nu_n/2m)^2) is no measure of it: it grows without bound as zeta -> 1
# while the error does not shrink (zeta = 0.95: 20 such steps, error 0.12).
# Below CONTACT_STEPS a run warns; the paper's cases use 51 (tilt) to 82 (drag) steps.
CONTACT_STEPS = 25
RESTITUTION_ERROR = 0.03  # the worst error at CONTACT_STEPS, share of the impact speed


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
    m_eff = lightest_contact_mass(scene)
    turn = (3.0 if scene.dimension == 2 else 3.5) if eff["rotation"] else 1.0
    nu_n = c.nu_n if eff["normal_damping"] else 0.0
    nu_s = c.nu_s if eff["tangential_damping"] else 0.0
    limits = {"normal": _oscillator_limit(c.kn, nu_n, m_eff),
              "impact": _ratio(math.pi, math.sqrt(c.kn / m_eff) * IMPACT_STEPS)}
    if c.law in SPRING_LAWS:
        limits["tangential"] = _oscillator_limit(c.ks, nu_s, m_eff / turn)
    elif nu_s > 0:
        # A pure dashpot (visco-plastic, Coulomb's regularisation) is explicitly stable for dt < 2 m / nu_s.
        limits["tangential"] = _ratio(2.0 * m_eff, turn * nu_s)
    return limits


def lightest_contact_mass(scene) -> float:
    """The effective mass of the lightest contact: the lightest grain on a wall, or the
    two lightest grains in series (the fastest contact of the scene)."""
    masses = sorted(scene.grain_mass(g) for g in scene.grains)
    candidates = []
    if scene.walls:
        candidates.append(masses[0])  # lightest grain on a wall
    if len(masses) >= 2:
        candidates.append(masses[0] * masses[1] / (masses[0] + masses[1]))  # lightest pair
    return min(candidates) if candidates else masses[0]


def contact_time(scene) -> float:
    """The time scale an accurate collision must resolve (see CONTACT_STEPS): the spring's
    half-period pi*sqrt(m/kn), or the dashpot's 4*pi*m/nu_n when that is shorter, for the
    lightest contact."""
    m = lightest_contact_mass(scene)
    nu_n = scene.contact.nu_n if scene.effects["normal_damping"] else 0.0
    return min(math.pi * math.sqrt(m / scene.contact.kn), _ratio(4.0 * math.pi * m, nu_n))


def contact_steps(scene) -> float:
    """Steps per contact: contact_time / dt."""
    return contact_time(scene) / scene.dt


def accuracy_warnings(scene) -> list:
    """One warning when the scene's fastest contact spans fewer than CONTACT_STEPS steps."""
    n = contact_steps(scene)
    if n >= CONTACT_STEPS:
        return []
    t = contact_time(scene)
    text = (f"contacts are resolved by {n:.3g} steps (dt = {scene.dt:g} s; contact time {t:.3g} s = "
            f"min(pi*sqrt(m/kn), 4*pi*m/nu_n) of the lightest contact, m = {lightest_contact_mass(scene):.3g}): "
            f"with fewer than {CONTACT_STEPS} steps per contact the restitution of an impact can be off by more "
            f"than {RESTITUTION_ERROR:g} of the impact speed (measured on pyref), although the run is stable. "
            f"For accurate collisions use dt <= {t / CONTACT_STEPS:.3g} s (docs/scene-format.md)")
    return [text]


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
