# SPDX-License-Identifier: GPL-2.0-or-later
"""The sliding speed above which every step slips, measured against the formula.

After a slip the spring holds Fmin = (2 mu_k - mu_s)Fn (eq. 8); one step later the
trial force is Fmin + (Ks*dt + nu_s)*V. So every step slips as soon as
    V >= V* = 2 (mu_s - mu_k) Fn / (Ks*dt + nu_s),
which contains both limits of the physics notes: the dashpot's (nu_s*V, physical)
and one step's spring increment (Ks*V*dt, numerical). Above V* the friction sits
at Fmin instead of averaging mu_k*Fn: the paper's "friction falls with speed"
(Fig. 15) is partly this time-step artefact.
"""
from __future__ import annotations

import copy
import csv
from pathlib import Path

import numpy as np

from pyref.laws import every_step_slips_speed

from .. import parallel, plotstyle, runner
from .. import scene as scene_mod

DTS = (1e-6, 4e-6, 1.6e-5)
NU_S = (0.0, 33.10, 100.0)


def formula(sc, dt, nu_s, fn):
    """V* for the scene's law with tangential damping nu_s (pyref.laws.every_step_slips_speed)."""
    p = sc.contact.law_params(dict(sc.effects, tangential_damping=True))
    p.nu_s = nu_s
    return every_step_slips_speed(p, fn, dt)


def every_step_slips(base, dt, nu_s, speed, after_first=40):
    """Drag at `speed`: does every step after the first slip slip again?"""
    from pyref import Simulation

    sc = copy.deepcopy(base)
    sc.dt = dt
    sc.contact.nu_s = nu_s
    sc.effects = dict(sc.effects, tangential_damping=nu_s > 0)
    sc.grains[0].velocity = np.array([speed, 0.0, 0.0])
    sim = Simulation(sc, record=False)
    p = sc.contact
    fn = sim.m[0] * 9.81
    static = max(0.0, p.mu_s * fn - nu_s * speed) / (p.ks * speed)  # time to the first slip
    for _ in range(int(static / dt) + 5):
        sim.step()
        if sim.slip_steps:
            break
    if not sim.slip_steps:
        raise RuntimeError("no slip where the static phase should have ended")
    start = sim.slip_steps
    for _ in range(after_first):
        sim.step()
    return sim.slip_steps - start == after_first


def measure(base, dt, nu_s, rel_tol=1e-3):
    """Bisection (in log speed) for the smallest speed at which every step slips."""
    m = base.grain_mass(base.grains[0])
    guess = formula(base, dt, nu_s, m * 9.81)
    lo, hi = guess / 4, guess * 4
    assert not every_step_slips(base, dt, nu_s, lo) and every_step_slips(base, dt, nu_s, hi)
    while hi / lo > 1 + rel_tol:
        mid = (lo * hi) ** 0.5
        if every_step_slips(base, dt, nu_s, mid):
            hi = mid
        else:
            lo = mid
    return (lo * hi) ** 0.5, guess


def run_thresholds(out: Path, dts=DTS, nus=NU_S, progress=True):
    tasks, finish = plan(out, dts, nus)
    return finish(parallel.run_all(tasks, "thresholds", progress))


def plan(out: Path, dts=DTS, nus=NU_S):
    """Tasks for parallel.run_all (one bisection each) and the function that writes the
    CSV and the figure from their results."""
    keys = [(nu, dt) for nu in nus for dt in dts]
    drag = scene_mod.load("drag")
    tasks = [(runner.cost(drag, "pyref", _steps(drag, dt, nu)), _measure_drag, (dt, nu)) for nu, dt in keys]

    def finish(results):
        rows = []
        for (nu, dt), got in zip(keys, results):
            if isinstance(got, Exception):
                raise got
            measured, predicted = got
            rows.append({"dt_s": dt, "nu_s": nu, "v_star_measured_mps": measured,
                         "v_star_formula_mps": predicted, "rel_diff": measured / predicted - 1})
        out_dir = Path(out)
        out_dir.mkdir(parents=True, exist_ok=True)
        with open(out_dir / "thresholds.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        _plot(rows, out_dir / "thresholds.png")
        return rows

    return tasks, finish


def _steps(base, dt, nu_s, tries=14):
    """About how many steps `measure` takes: `tries` drags (a bisection over a factor 16 to
    rel_tol = 1e-3 takes 12, and two to check its ends), each through its static phase at
    about V* and `after_first` steps more."""
    p = base.contact
    static_steps = p.mu_s * (p.ks * dt + nu_s) / (2 * (p.mu_s - p.mu_k) * p.ks * dt)
    return tries * int(static_steps + 45)


def _measure_drag(dt, nu_s):
    return measure(scene_mod.load("drag"), dt, nu_s)


def _plot(rows, path):
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for nu, mark in zip(sorted({r["nu_s"] for r in rows}), "os^"):
        rr = [r for r in rows if r["nu_s"] == nu]
        dts = [r["dt_s"] for r in rr]
        ax.loglog(dts, [r["v_star_formula_mps"] for r in rr], "-", color="gray")
        ax.loglog(dts, [r["v_star_measured_mps"] for r in rr], mark,
                  label=f"{plotstyle.label('pyref', 'step')}: measured, nu_s = {nu:g} kg/s")
    ax.set_xlabel("time step dt (s)")
    ax.set_ylabel("speed above which every step slips (m/s)")
    ax.set_title("V* = 2(mu_s - mu_k)Fn / (Ks dt + nu_s)  (grey: formula)")
    ax.legend(fontsize=8)
    plotstyle.save(fig, path.parent, path.name, dpi=110)
