# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "incline3d": the start and stop angles of a bed of spheres on a rough incline
(cases/incline3d.toml, docs/granular-3d.md).

The scene's gravity ramp does the protocol; this module reads its outcome from the time
series (columns.RAMP: the angle and phase of each row; columns.BULK: the moving grains'
centre of mass and velocity):
- theta_stop: the angle at the last row of phase `stop_phase` (a ramp down that ends when
  the bed's mean speed along the slope falls below its threshold: the bed stopped);
- theta_start: the angle at the last row of phase `start_phase` (a ramp up from that
  deposit that ends when the mean speed passes its threshold: the bed started);
- the bed's depth h at the stop: twice the height of the moving grains' centre of mass
  above the base's surface, taken as the mean top of the base's spheres (a uniform bed
  from there to its surface has its centre of mass half way up).
A phase that did not end (the run hit time.duration or the angle guard first) gives NaN.
"""
from __future__ import annotations

import math

import numpy as np

from .none import paper_statements, precision_figures  # noqa: F401 (the contract: neither, as kind none)
from .relative import angle_errors

NAME = "incline3d"
NAMES = {"stop_phase": "phase", "start_phase": "phase"}
PRECISION_DURATION = None
errors = angle_errors("_deg")  # stickslip precision: the angles' relative errors
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)


def downhill_speed(scene, df):
    """The moving grains' mean velocity along the ramp's downhill direction, per row."""
    u = scene.downhill()
    return df[["vcm_x", "vcm_y", "vcm_z"]].to_numpy(float) @ u


def base_surface(scene):
    """Height of the base's surface along -gravity at the start: the mean top of the fixed
    spheres (NaN without any)."""
    up = -scene.gravity / np.linalg.norm(scene.gravity)
    tops = [float(g.position @ up) + g.radius for g in scene.grains if g.fixed]
    return float(np.mean(tops)) if tops else math.nan


def depth(scene, df, row):
    """The bed's depth at `row` of the series: twice the height of its centre of mass above
    the base's surface (base_surface; a uniform bed has its centre of mass half way up)."""
    up = -scene.gravity / np.linalg.norm(scene.gravity)
    com = df[["com_x", "com_y", "com_z"]].to_numpy(float)[row]
    return 2.0 * (float(com @ up) - base_surface(scene))


def phase_end(scene, df, phase):
    """The row index at which `phase` ended on its condition, or None (it never ended)."""
    ph = df["phase"].to_numpy(int)
    rows = np.flatnonzero(ph == phase)
    if not len(rows):
        return None
    last = int(rows[-1])
    if last + 1 < len(df):  # a later row belongs to a later phase: the condition held here
        return last
    cond = scene.gravity_ramp.phases[phase]
    v = downhill_speed(scene, df.iloc[[last]])[0]
    held = v > cond.value if cond.until == "speed_above" else v < cond.value if cond.until == "speed_below" else False
    return last if held else None  # the last phase ends the run when it holds


def summarise(scene, df):
    out = {}
    for key in ("stop", "start"):
        phase = scene.analysis[f"{key}_phase"]
        row = phase_end(scene, df, phase)
        out[f"theta_{key}_deg"] = math.degrees(df["tilt"].iat[row]) if row is not None else math.nan
        out[f"t_{key}_s"] = float(df["t"].iat[row]) if row is not None else math.nan
        out[f"ramp_{key}_deg_per_s"] = math.degrees(scene.gravity_ramp.phases[phase].rate)
        if key == "stop":
            out["depth_at_stop"] = depth(scene, df, row) if row is not None else math.nan
    v = downhill_speed(scene, df)
    out["max_speed"] = float(np.max(v)) if len(v) else math.nan
    out["duration_run_s"] = float(df["t"].iat[-1])
    out["hysteresis_deg"] = out["theta_start_deg"] - out["theta_stop_deg"]
    return out


def claims(scene):
    return [("theta_stop_deg", "theta_stop (deg)"), ("theta_start_deg", "theta_start (deg)"),
            ("depth_at_stop", "bed depth at the stop (d)")]


def figures(out, runs):
    """Mean speed along the slope against the angle, one figure per run, theta_stop and
    theta_start marked."""
    def marks(summary):
        return [summary[f"theta_{k}_deg"] for k in ("stop", "start")
                if np.isfinite(summary.get(f"theta_{k}_deg", math.nan))]
    return speed_figures(out, runs, NAME, lambda df: np.degrees(df["tilt"]), "tilt (deg)", marks)


def speed_figures(out, runs, prefix, x, xlabel, marks=lambda summary: ()):
    """The bed's mean speed along the slope (log scale) against x(df), one figure per run
    (prefix_KEY.png), a dashed line at each of marks(summary); for this kind and hold3d."""
    from ..plotstyle import pyplot, save

    plt, names = pyplot(), []
    for key, (scene, summary, df) in runs.items():
        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.semilogy(x(df), np.maximum(np.abs(downhill_speed(scene, df)), 1e-7), lw=0.6)
        for m in marks(summary):
            ax.axvline(m, ls="--", color="0.4")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("mean speed along the slope")
        names.append(save(fig, out, f"{prefix}_{'_'.join(str(k) for k in key)}.png"))
    return names
