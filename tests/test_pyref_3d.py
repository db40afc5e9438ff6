# SPDX-License-Identifier: GPL-2.0-or-later
"""3D form of the law: history kept in the tangent plane, objectivity."""
import tomllib

import numpy as np

from stickslip import scene as scene_mod
from pyref import Simulation

# A sphere held still (x, y imposed) on a turntable: the plate slides under it along
# a circle, so the sliding direction turns by 90 degrees during the run. Softer 3D
# parameters (N/m): the paper's 2D stiffnesses on a 3D sphere need dt ~ 1e-7 s.
TURNTABLE = """
name = "turntable"
dimension = 3
gravity = [0.0, 0.0, -9.81]
[effects]
gravity = true
normal_damping = true
tangential_damping = true
moving_walls = true
[contact]
kn = 1e5
nu_n = 1.0
ks = 8e4
nu_s = 0.5
mu_s = 0.5
mu_k = 0.45
[time]
dt = 1e-5
duration = 0.0157
[[grain]]
name = "ball"
radius = 0.005
density = 2600
position = [0.01, 0.0, 0.0049998665]  # static overlap m*g/Kn
imposed = ["x", "y"]
[[wall]]
name = "table"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
rotation = { pivot = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], rate = 100.0, stop_angle = 1.5707963 }
"""


def steps(sim, n):
    for _ in range(n):
        sim.step()
        yield sim


def test_turntable_force_in_tangent_plane_and_against_sliding():
    sc = scene_mod.parse(tomllib.loads(TURNTABLE))
    sim = Simulation(sc, record=False)
    p = sc.contact
    omega = sc.rotation_rate(sc.walls[0])
    worst = 0.0
    slips = 0
    for s in steps(sim, sc.steps - 1):
        i, j, key, n, fn, F_s, slipped, delta = s.contacts
        assert len(key) == 1
        f = F_s[0]
        assert abs(f @ n[0]) <= 1e-12 * np.linalg.norm(f)  # in the tangent plane
        if not slipped[0]:
            continue
        slips += 1
        # The ball is still, so V_s = -v_wall: friction must point along the wall's velocity.
        cp = s.x[0] + s.r[0] * n[0]
        v_wall = omega * np.cross([0, 0, 1.0], cp)
        cosang = f @ v_wall / (np.linalg.norm(f) * np.linalg.norm(v_wall))
        worst = max(worst, np.arccos(min(1.0, cosang)))
    assert slips > 0.9 * sc.steps  # sliding at 1 m/s: the dashpot alone exceeds the force drop
    # After a slip the spring keeps the previous direction; the new trial force mixes it
    # (weight Fmin) with the new sliding direction (weight (Ks*dt + nu_s)*V), while the
    # direction turns by omega*dt per step. The lag is at most omega*dt*Fmin/((Ks dt + nu_s) V)
    # per step, accumulated geometrically: bound = omega*dt*(1 + Fmin/((Ks dt + nu_s) V)).
    fn = sim.m[0] * 9.81
    v = omega * 0.01
    bound = omega * sc.dt * (1 + (2 * p.mu_k - p.mu_s) * fn / ((p.ks * sc.dt + p.nu_s) * v))
    assert worst <= bound


def test_history_turns_with_the_normal_over_a_sphere():
    # A sphere pushed at constant velocity over a fixed one: the normal turns through
    # the whole contact; the force must stay in the tangent plane at every step.
    text = """
name = "pass"
dimension = 3
[contact]
kn = 1e5
ks = 8e4
nu_s = 0.0
mu_s = 0.5
mu_k = 0.45
[time]
dt = 1e-6
duration = 0.002
[[grain]]
name = "fixed"
radius = 0.005
density = 2600
position = [0.0, 0.0, 0.0]
imposed = ["x", "y", "z"]
[[grain]]
name = "mover"
radius = 0.005
density = 2600
position = [-0.003, 0.0, 0.0098]
velocity = [3.0, 0.0, 0.0]
imposed = ["x", "y", "z"]
"""
    sc = scene_mod.parse(tomllib.loads(text))
    sim = Simulation(sc, record=False)
    seen = 0
    turned = []
    for s in steps(sim, sc.steps):
        i, j, key, n, fn, F_s, slipped, delta = s.contacts
        if len(key):
            seen += 1
            turned.append(n[0].copy())
            assert abs(F_s[0] @ n[0]) <= 1e-12 * max(np.linalg.norm(F_s[0]), 1e-300)
            assert abs(s.D[0] @ n[0]) <= 1e-12 * max(np.linalg.norm(s.D[0]), 1e-300)
    assert seen > 100
    assert np.degrees(np.arccos(turned[0] @ turned[-1])) > 20  # the frame really turned


def _rotated(sc, Q):
    """The same scene seen in a frame turned by Q (all vectors rotated)."""
    import copy

    r = copy.deepcopy(sc)
    r.gravity = Q @ sc.gravity
    for g in r.grains:
        g.position, g.velocity = Q @ g.position, Q @ g.velocity
    for w in r.walls:
        w.point, w.normal, w.velocity = Q @ w.point, Q @ w.normal, Q @ w.velocity
    return r


def test_objectivity_rotating_the_scene_rotates_the_result():
    # Free spheres with spin thrown onto a plane and into each other; nothing imposed,
    # so the scene can be turned by any rotation.
    text = """
name = "throw"
dimension = 3
gravity = [0.0, 0.0, -9.81]
[effects]
gravity = true
rotation = true
normal_damping = true
tangential_damping = true
[contact]
kn = 1e5
nu_n = 0.5
ks = 8e4
nu_s = 0.2
mu_s = 0.5
mu_k = 0.4
[time]
dt = 5e-6
duration = 0.02
[[grain]]
name = "a"
radius = 0.005
density = 2600
position = [0.0, 0.0, 0.0052]
velocity = [0.3, 0.1, -0.2]
[[grain]]
name = "b"
radius = 0.004
density = 2600
position = [0.011, 0.002, 0.0041]
velocity = [-0.1, 0.0, -0.1]
[[wall]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""
    sc = scene_mod.parse(tomllib.loads(text))
    angle, axis = 0.7, np.array([1.0, 2.0, 3.0]) / np.sqrt(14)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    Q = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    a, b = Simulation(sc, record=False), Simulation(_rotated(sc, Q), record=False)
    a.w[0] = [0.0, 50.0, 20.0]  # spin, so rotation and torques take part
    b.w[0] = Q @ a.w[0]
    a.f, a.torque = a._forces(elapsed=0.0)
    b.f, b.torque = b._forces(elapsed=0.0)
    slips = 0
    for _ in range(sc.steps):
        a.step()
        b.step()
        slips += int(a.contacts.slipped.sum())
    assert slips > 0 and a.slip_steps == b.slip_steps
    # Round-off only: positions agree to 1e-9 of a radius, velocities to 1e-9 of 0.3 m/s.
    assert np.allclose(b.x, a.x @ Q.T, atol=5e-12, rtol=0)
    assert np.allclose(b.v, a.v @ Q.T, atol=3e-10, rtol=0)
    assert np.allclose(b.w, a.w @ Q.T, atol=5e-8, rtol=0)
