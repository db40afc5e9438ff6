# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "hold3d": does a flowing bed of spheres stop at a held angle? (cases/incline3d_hold.toml,
docs/granular-3d.md: theta_stop without a ramp's lag, as Weinhart et al. 2012 measured it).

The scene's gravity ramp makes the bed flow, brings it to the held angle and holds it there
in phase `hold_phase`, which ends (and the run with it) when the bed's mean speed along the
slope falls below the phase's threshold. From the time series (columns.RAMP, columns.BULK):
- theta_hold_deg: the held angle;
- stopped: 1 when the hold ended on its condition, 0 when the run ended first (the bed
  still flowed after the scene's time.duration);
- time_to_stop_s: from the hold's first row to the stop (NaN when not stopped);
- depth_at_end: the bed's depth at the last row, measured as incline3d measures it;
- speed_at_end: the mean speed along the slope at the last row;
- speed_trend: for a bed still flowing, its mean speed over the hold's last quarter over
  that over its third quarter: near 1 it flows steadily; well below 1 it was still slowing
  down and might have stopped in a longer hold (NaN for a bed that stopped).
"""
from __future__ import annotations

import math

import numpy as np

from . import incline3d
from .none import paper_statements, precision_figures  # noqa: F401 (the contract: neither, as kind none)

NAME = "hold3d"
NAMES = {"hold_phase": "phase"}
PRECISION_DURATION = None
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)


def summarise(scene, df):
    phase = scene.analysis["hold_phase"]
    rows = np.flatnonzero(df["phase"].to_numpy(int) == phase)
    if not len(rows):  # the run ended before the hold (time.duration or the angle guard)
        return {"theta_hold_deg": math.nan, "stopped": math.nan, "time_to_stop_s": math.nan, "depth_at_end": math.nan,
                "speed_at_end": math.nan, "speed_trend": math.nan, "duration_run_s": float(df["t"].iat[-1])}
    end = incline3d.phase_end(scene, df, phase)
    v = incline3d.downhill_speed(scene, df)
    return {"theta_hold_deg": math.degrees(df["tilt"].iat[rows[0]]),
            "stopped": float(end is not None),
            # the hold's first row closes its first interval: the hold began one interval earlier
            "time_to_stop_s": (float(df["t"].iat[end] - df["t"].iat[rows[0]]) + scene.output.every * scene.dt
                               if end is not None else math.nan),
            "depth_at_end": incline3d.depth(scene, df, -1),
            "speed_at_end": float(v[-1]),
            "speed_trend": _trend(v[rows]) if end is None else math.nan,
            "duration_run_s": float(df["t"].iat[-1])}


def _trend(v):
    """Mean of the last quarter of v over the mean of its third quarter."""
    q = len(v) // 4
    return float(np.mean(v[3 * q:]) / np.mean(v[2 * q:3 * q])) if q and np.mean(v[2 * q:3 * q]) else math.nan


def errors(scene, summary, df, ref_summary, ref_df):
    return {"theta_hold": abs(summary["theta_hold_deg"] - ref_summary["theta_hold_deg"])}


def claims(scene):
    return [("theta_hold_deg", "held angle (deg)"), ("stopped", "stopped (1) or still flowing (0)"),
            ("time_to_stop_s", "time to stop"), ("depth_at_end", "bed depth at the end (d)")]


def figures(out, runs):
    """Mean speed along the slope against time, one figure per run."""
    return incline3d.speed_figures(out, runs, NAME, lambda df: df["t"], "time")
