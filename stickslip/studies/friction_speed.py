# SPDX-License-Identifier: GPL-2.0-or-later
"""Mean friction against imposed sliding speed (drag scene), step and exact slip timing: a
study of `stickslip report` (report_plan.py), not a command of its own.

The paper's Fig. 4/15 message is that friction falls with sliding speed. With the
law stepped as the paper does, part of that fall is the time step: every step slips
once V*(Ks*dt + nu_s) >= 2(mu_s - mu_k)Fn. With exact slip timing only the dashpot's
share remains (nu_s*V >= 2(mu_s - mu_k)Fn: physics), so its curves must not move
with dt. Measured on pyref (the engines agree with it at equal dt).
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from pyref import Simulation
from pyref.laws import every_step_slips_speed

from .. import plotstyle, runner
from .. import scene as scene_mod

SPEEDS = np.logspace(-6, -2, 17)  # m/s: 4 decades, past the dashpot threshold (~1e-3 m/s)
DT_FACTORS = (4.0, 1.0, 0.25)  # x the drag scene's dt
PERIODS = 6  # saw-tooth periods averaged after the first slip (at least MIN_STEPS steps)
MIN_STEPS = 400


def steps_needed(sc, speed, dt):
    """Steps of a drag at `speed`: the static phase, PERIODS + 1 saw-tooth periods, and
    MIN_STEPS more."""
    p = sc.contact
    fn = sc.grain_mass(sc.grains[0]) * float(np.linalg.norm(sc.gravity))
    period = 2 * (p.mu_s - p.mu_k) * fn / (p.ks * speed)
    static = p.mu_s * fn / (p.ks * speed)
    return int((static + (PERIODS + 1) * period) / dt) + MIN_STEPS


def mean_friction(base, speed, dt, timing):
    """Mean |Fs|/Fn of a drag at `speed` over whole saw-tooth periods after the first slip
    (over MIN_STEPS steps where every step slips)."""
    sc = scene_mod.load(base, dt=dt, slip_timing=timing)
    sc.grains[0].velocity = np.array([speed, 0.0, 0.0])
    sim = Simulation(sc, record=False)
    steps = steps_needed(sc, speed, dt)
    ratio, slipped = np.zeros(steps), np.zeros(steps, bool)
    for k in range(steps):
        sim.step()
        c = sim.contacts
        ratio[k] = np.linalg.norm(c.force[0]) / c.fn[0]
        slipped[k] = c.slipped[0]
    slips = np.flatnonzero(slipped)
    if len(slips) < 2:
        return float("nan")
    # whole periods: from just after the first slip to the last one
    return float(ratio[slips[0] + 1: slips[-1] + 1].mean())


def plan(out: Path, scene="drag", speeds=SPEEDS, dt_factors=DT_FACTORS):
    """Tasks for parallel.run_all (one drag run each), and the function that writes the
    CSV and the figure from their results."""
    base = scene_mod.load(scene)
    keys = [(timing, base.dt * f, float(v)) for timing in ("step", "exact") for f in dt_factors for v in speeds]
    tasks = [(runner.cost(base, "pyref", steps_needed(base, v, dt)), mean_friction, (scene, v, dt, timing))
             for timing, dt, v in keys]

    def finish(results):
        rows = []
        for (timing, dt, v), got in zip(keys, results):
            if isinstance(got, Exception):
                raise got
            rows.append({"slip_timing": timing, "dt_s": dt, "speed_mps": v, "mean_fs_fn": got})
        Path(out).mkdir(parents=True, exist_ok=True)
        with open(Path(out) / "friction_speed.csv", "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        _plot(base, rows, Path(out) / "friction_speed.png")
        return rows

    return tasks, finish


def spread(rows, timing):
    """Largest difference between the time steps' mean friction at one speed."""
    by_speed = {}
    for r in rows:
        if r["slip_timing"] == timing:
            by_speed.setdefault(r["speed_mps"], []).append(r["mean_fs_fn"])
    return max(np.nanmax(v) - np.nanmin(v) for v in by_speed.values())


def _plot(base, rows, path):
    plt = plotstyle.pyplot()
    p = base.contact
    law = p.law_params(base.effects)
    fn = base.grain_mass(base.grains[0]) * float(np.linalg.norm(base.gravity))
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    dts = sorted({r["dt_s"] for r in rows})
    for k, dt in enumerate(dts):
        for timing, ls in (("step", "--"), ("exact", "-")):
            rr = [r for r in rows if r["dt_s"] == dt and r["slip_timing"] == timing]
            ax.semilogx([r["speed_mps"] for r in rr], [r["mean_fs_fn"] for r in rr], ls, marker=".",
                        color=f"C{k}", label=f"{plotstyle.label('pyref', timing)}, dt = {dt:.1e} s")
        ax.axvline(every_step_slips_speed(law, fn, dt), color=f"C{k}", lw=0.5, ls=":")
    ax.axvline(2 * (p.mu_s - p.mu_k) * fn / law.nu_s, color="k", lw=0.8, ls=":") if law.nu_s else None
    ax.axhline(p.mu_k, color="gray", lw=0.5)
    ax.axhline(2 * p.mu_k - p.mu_s, color="gray", lw=0.5)
    ax.set_xlabel("imposed sliding speed V (m/s)")
    ax.set_ylabel("mean |Fs|/Fn")
    ax.set_title("drag: friction vs speed (dotted: every step slips, step timing; black: dashpot threshold)",
                 fontsize=8)
    ax.legend(fontsize=7)
    plotstyle.save(fig, path.parent, path.name, dpi=110)
