# SPDX-License-Identifier: GPL-2.0-or-later
"""pyref's performance figures for `stickslip bench`: cost per grain-step over packing sizes,
what each effect costs, both slip timings. Every figure is a median over repetitions.
"""
from __future__ import annotations

import statistics
import time
import tracemalloc

import numpy as np

from .. import scene as scene_mod

# The pyref figures' sizes: packings for the scaling fit, each timed over about
# STEP_BUDGET grain-steps; the ~10 000-contact packing (also the effects' and slip timings'
# one), timed over TIMED_STEPS steps. (The test suite runs the command on small ones.)
PYREF_SIZES = (1000, 5000, 20000)
STEP_BUDGET = 200_000
CONTACT_TARGET_GRAINS = 3400
TIMED_STEPS = 60

PACKING = """
name = "packing"
dimension = 3
gravity = [0.0, 0.0, -9.81]
[effects]
gravity = true
rotation = true
normal_damping = true
tangential_damping = true
[contact]
kn = 10.0
nu_n = 1e-5
ks = 8.0
nu_s = 1e-5
mu_s = 0.5
mu_k = 0.45
[time]
dt = 1e-5
duration = 1.0
[[lattice]]
origin = [0.0, 0.0, 0.001]
counts = [{nx}, {ny}, {nz}]
radius = 0.001
spacing = 0.002
density = 2600
[[wall]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""


def packing(n_grains, **overrides):
    """A cubic lattice of spheres pressed 0.01 % together (six contacts per inner grain).
    Soft springs (kn = 10 N/m) keep the boundary grains from flying off during the
    timed steps, so the number of contacts stays steady; the code path is the same
    as in any packing."""
    import tomllib

    side = max(2, round(n_grains ** (1 / 3)))
    nz = max(2, round(n_grains / side**2))
    sc = scene_mod.parse(tomllib.loads(PACKING.format(nx=side, ny=side, nz=nz)), overrides=overrides)
    for g in sc.grains:
        g.position = g.position * 0.9999
    return sc


def time_steps(sc, steps, reps, warm=5):
    """Median seconds per step and the mean number of contacts."""
    from pyref import Simulation

    times, contacts = [], []
    for _ in range(reps):
        sim = Simulation(sc, record=False)
        for _ in range(warm):
            sim.step()
        t0 = time.perf_counter()
        n = 0
        for _ in range(steps):
            sim.step()
            n += len(sim.contacts.key)
        times.append((time.perf_counter() - t0) / steps)
        contacts.append(n / steps)
    return statistics.median(times), float(np.mean(contacts))


def memory(sc):
    """Persistent bytes per grain (state arrays) and per contact (history + key), and the
    transient peak of one step per contact (tracemalloc)."""
    from pyref import Simulation

    sim = Simulation(sc, record=False)
    sim.step()
    per_grain = sum(a.nbytes for a in (sim.x, sim.v, sim.w, sim.r, sim.m, sim.inertia, sim.imposed,
                                       sim.v_imposed, sim.f)) / sim.N
    k = len(sim.keys)
    per_contact = (sim.keys.nbytes + sim.D.nbytes) / max(k, 1)
    tracemalloc.start()
    sim.step()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return per_grain, per_contact, peak / max(k, 1)


def pyref_rows(reps):
    rows = []
    per_step = []
    for n in PYREF_SIZES:
        sc = packing(n)
        steps = max(10, STEP_BUDGET // n)
        t, c = time_steps(sc, steps, reps)
        per_step.append((len(sc.grains), t))
        rows.append({"benchmark": "pyref", "case": f"{len(sc.grains)} grains", "contacts": round(c),
                     "seconds_per_step": t, "contact_steps_per_s": c / t})
    # Cost growth: slope of log(time per step) against log(grains).
    x, y = np.log([p[0] for p in per_step]), np.log([p[1] for p in per_step])
    rows.append({"benchmark": "pyref", "case": "scaling exponent (time/step ~ N^p)", "value": float(np.polyfit(x, y, 1)[0])})
    # The 10 000-contact point the target names: a packing of ~3 400 grains.
    sc = packing(CONTACT_TARGET_GRAINS)
    t, c = time_steps(sc, TIMED_STEPS, reps)
    rows.append({"benchmark": "pyref", "case": "~10 000 contacts (target >= 2e6 contact-steps/s)",
                 "contacts": round(c), "seconds_per_step": t, "contact_steps_per_s": c / t})
    rows += timing_rows(reps)
    g, k, peak = memory(sc)
    rows.append({"benchmark": "pyref", "case": "memory: bytes per grain (state)", "value": g})
    rows.append({"benchmark": "pyref", "case": "memory: bytes per contact (history + key)", "value": k})
    rows.append({"benchmark": "pyref", "case": "memory: peak transient bytes per contact in a step", "value": peak})
    return rows


def timing_rows(reps, n=None):
    """Cost of the exact slip timing against the step timing, per contact-step, on the
    packing at rest (contacts stick: the exact mode only adds a threshold test) and set
    sliding (every grain with a random velocity of 0.05 m/s: contacts slip, several times
    a step, and the exact mode follows each slip). Same process, one after the other."""
    n = n or CONTACT_TARGET_GRAINS
    rows = []
    for state, extra in (("at rest", {}), ("sliding", {"jitter": 0.05})):
        costs = {}
        for timing in ("step", "exact"):
            sc = packing(n, slip_timing=timing)
            for g in sc.grains:  # seeded, the same for both modes
                g.velocity = np.random.default_rng(hash(g.name) % 2**32).uniform(-1, 1, 3) * extra.get("jitter", 0.0)
            t, c = time_steps(sc, TIMED_STEPS, reps)
            costs[timing] = t / c
            rows.append({"benchmark": "pyref", "case": f"slip timing {timing}, packing {state}, s per contact-step",
                         "contacts": round(c), "value": t / c})
        rows.append({"benchmark": "pyref", "case": f"exact / step timing cost, packing {state}",
                     "value": costs["exact"] / costs["step"]})
    return rows


def effect_rows(reps):
    """The same packing with each effect switched off in turn, against all on."""
    n = CONTACT_TARGET_GRAINS
    base_t, c = time_steps(packing(n), TIMED_STEPS, reps)
    rows = [{"benchmark": "effects", "case": "all on", "contacts": round(c), "seconds_per_step": base_t,
             "ratio_to_all_on": 1.0}]
    for effect in ("gravity", "rotation", "normal_damping", "tangential_damping"):
        t, c = time_steps(packing(n, **{f"effect_{effect}": False}), TIMED_STEPS, reps)
        rows.append({"benchmark": "effects", "case": f"{effect} off", "contacts": round(c), "seconds_per_step": t,
                     "ratio_to_all_on": t / base_t})
    off = {f"effect_{e}": False for e in ("gravity", "rotation", "normal_damping", "tangential_damping")}
    t, c = time_steps(packing(n, **off), TIMED_STEPS, reps)
    rows.append({"benchmark": "effects", "case": "all off", "contacts": round(c), "seconds_per_step": t,
                 "ratio_to_all_on": t / base_t})
    return rows
