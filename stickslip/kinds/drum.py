# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "drum": avalanches in a slowly turning drum (cases/drum.toml, docs/drum.md).

From the recorded grains at each row, two measures of the surface's slope (degrees,
positive on the side the turning steepens, in the frame of the row's gravity): theta,
a straight-line fit to the pile's top over the middle 60 % of its width (bins of one
mean diameter, the highest grain top in each), and theta_centroid, the angle between
gravity and the line from the drum's centre to the pile's centroid (a flat surface is
perpendicular to it). The fit reads the middle of the surface, as an experiment's
camera does, with ~1 deg of noise from which grain tops a bin; the centroid's angle
averages the whole surface and is free of that noise. From the
kinetic energy (output.stats): the avalanches (EKIN_QUIET, EKIN_AVALANCHE below), with
theta_start the slope just before one starts to move and theta_stop just after it is
quiet again. Their means, standard errors and the
list of avalanches go to summary.json, with the slip statistics of the grain-grain
contacts during avalanches (output.slip_stats, columns.SLIP_STATS).
"""
from __future__ import annotations

import math

import numpy as np

from .none import paper_statements, precision_figures  # noqa: F401 (the contract: neither, as kind none)
from .relative import angle_errors

NAME = "drum"
NAMES = {"settle": "seconds"}  # avalanches that start before this time are not measured
PRECISION_DURATION = None
errors = angle_errors("_mean_deg")  # stickslip precision: the angles' relative errors
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)

# Avalanches are found in the kinetic energy E (output.stats), in units of M g d (M the
# moving grains' mass, d their mean diameter). A pile turning rigidly with the drum at
# 0.03 rad/s has E ~ 1e-9 of it; precursor rearrangements reach 1e-7 to 1e-5, avalanches
# 1e-3 and more. An event is a run of rows with E above EKIN_QUIET (rows less than
# MERGE_GAP apart joined); it is an avalanche when its E exceeds EKIN_AVALANCHE.
# theta_start is theta at the last quiet row before it, theta_stop at the first quiet
# row after it (while grains flow, the surface fit reads the moving layer, not a slope).
EKIN_QUIET = 1e-6
EKIN_AVALANCHE = 1e-4
MERGE_GAP = 0.05  # s
# An event that lowers the centroid's angle by less than this (degrees) is a slide at the
# foot or the top of the pile (a precursor), not an avalanche of its surface: counted
# apart ("slides"). Between events the centroid's angle is a straight ramp to 1e-3 deg;
# the drops of the avalanches measured are 5-25 deg, of the slides below 0.5 deg.
MIN_DROP = 0.5
# The fit: bins of one mean diameter across the pile, the middle 60 % of its width.
FIT_MIDDLE = 0.6


def mobile(scene):
    """The recorded grains that move (not the drum's wall), with their radii."""
    fixed = {g.name for g in scene.grains if g.fixed}
    radius = {g.name: g.radius for g in scene.grains}
    names = [n for n in scene.output.grains if n not in fixed]
    return names, np.array([radius[n] for n in names])


def centre(scene):
    walls = np.array([g.position for g in scene.grains if g.fixed])
    return walls.mean(axis=0)[:2] if len(walls) else np.zeros(2)


def slope_angles(scene, df):
    """theta (degrees) of every row: the surface's slope in the frame of that row's gravity."""
    names, r = mobile(scene)
    x = df[[f"{n}_x" for n in names]].to_numpy(float) - centre(scene)[0]
    y = df[[f"{n}_y" for n in names]].to_numpy(float) - centre(scene)[1]
    sign = -1.0 if scene.gravity_rate > 0 else 1.0  # positive where the turning steepens
    width = 2.0 * r.mean()
    out = np.full(len(df), np.nan)
    for k, t in enumerate(df["t"].to_numpy(float)):
        g = scene.gravity_at(t)[:2]
        d = g / np.hypot(*g)  # down
        u = x[k] * -d[1] + y[k] * d[0]  # across: down turned by +90 degrees
        h = -(x[k] * d[0] + y[k] * d[1]) + r  # height of each grain's top
        b = np.floor((u - u.min()) / width).astype(int)
        top = np.full(b.max() + 1, -np.inf)
        np.maximum.at(top, b, h)
        have = np.isfinite(top)
        uc = u.min() + (np.arange(len(top)) + 0.5) * width
        lo, hi = uc[have].min(), uc[have].max()
        mid = have & (np.abs(uc - 0.5 * (lo + hi)) <= 0.5 * FIT_MIDDLE * (hi - lo))
        if mid.sum() >= 3:
            slope = np.polyfit(uc[mid], top[mid], 1)[0]
            out[k] = sign * math.degrees(math.atan(slope))
    return out


def energy_scale(scene):
    """M g d of the moving grains, J (J/m in 2D)."""
    names, r = mobile(scene)
    by_name = {g.name: g for g in scene.grains}
    m = float(sum(scene.grain_mass(by_name[n]) for n in names))
    return m * float(np.hypot(*scene.gravity[:2])) * 2.0 * r.mean()


def centroid_angles(scene, df):
    """A cross-check of theta: the angle (degrees) between gravity and the line from the
    drum's centre to the pile's centroid (area-weighted). A flat surface in a circular drum
    is perpendicular to that line, so this is its slope, averaged over the whole surface;
    it moves exactly with the pile, without the fit's dependence on which grain tops a bin."""
    names, r = mobile(scene)
    w = r**2 / np.sum(r**2)
    cx = df[[f"{n}_x" for n in names]].to_numpy(float) @ w - centre(scene)[0]
    cy = df[[f"{n}_y" for n in names]].to_numpy(float) @ w - centre(scene)[1]
    sign = -1.0 if scene.gravity_rate > 0 else 1.0
    out = np.empty(len(df))
    for k, t in enumerate(df["t"].to_numpy(float)):
        g = scene.gravity_at(t)[:2]
        # the centroid's angle from "down", counter-clockwise positive
        out[k] = math.degrees(math.atan2(g[0] * cy[k] - g[1] * cx[k], g[0] * cx[k] + g[1] * cy[k]))
    return sign * out


def avalanches(scene, df):
    """[(first row, last row)] of each avalanche that starts after `settle` and has ended."""
    scale = energy_scale(scene)
    t = df["t"].to_numpy(float)
    e = df["ekin"].to_numpy(float) / scale
    runs, k = [], 0
    while k < len(t):
        if e[k] > EKIN_QUIET:
            j = k
            while j + 1 < len(t) and e[j + 1] > EKIN_QUIET:
                j += 1
            if runs and t[k] - t[runs[-1][1]] < MERGE_GAP:
                runs[-1] = (runs[-1][0], j)
            else:
                runs.append((k, j))
            k = j + 1
        else:
            k += 1
    settle = scene.analysis.get("settle", 0.0)
    return [(a, b) for a, b in runs
            if a > 0 and t[a] >= settle and b + 1 < len(t) and e[a:b + 1].max() > EKIN_AVALANCHE]


def measure(scene, df, theta=None, theta_c=None):
    """The fit's and the centroid's angle series and the table of events (a dict each);
    `df` needs t, ekin (and the slip statistics), and the grains only when the angles are
    not given."""
    theta = slope_angles(scene, df) if theta is None else np.asarray(theta, float)
    theta_c = centroid_angles(scene, df) if theta_c is None else np.asarray(theta_c, float)
    t = df["t"].to_numpy(float)
    rows = []
    for a, b in avalanches(scene, df):
        row = {"t_onset": float(t[a]), "t_end": float(t[b + 1])}
        for key, series in (("", theta), ("_centroid", theta_c)):
            row[f"theta_start{key}"], row[f"theta_stop{key}"] = float(series[a - 1]), float(series[b + 1])
            row[f"delta_theta{key}"] = row[f"theta_start{key}"] - row[f"theta_stop{key}"]
        # an avalanche lowers the pile as a whole; a slide at its foot or top barely moves its centroid
        row["avalanche"] = row["delta_theta_centroid"] >= MIN_DROP
        if scene.output.slip_stats:
            seg = df.iloc[a:b + 1]
            n = float(seg["n_slipping"].sum())
            row["slipping_contacts"] = n
            row["share_above_vd"] = float(seg["n_slip_above_vd"].sum()) / n if n else math.nan
            row["share_above_vstar"] = float(seg["n_slip_above_vstar"].sum()) / n if n else math.nan
            row["slip_fs_fn"] = float(seg["slip_fs_fn_sum"].sum()) / n if n else math.nan
        rows.append(row)
    return theta, theta_c, rows


def mean_se(values):
    v = np.asarray([x for x in values if np.isfinite(x)], float)
    if len(v) == 0:
        return math.nan, math.nan
    if len(v) == 1:
        return float(v[0]), math.nan
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v)))


ANGLES = ("theta_start", "theta_stop", "delta_theta")


def summarise(scene, df, theta=None, theta_c=None):
    _, _, events = measure(scene, df, theta, theta_c)
    rows = [r for r in events if r["avalanche"]]
    out = {"avalanches": len(rows), "slides": len(events) - len(rows), "energy_scale_J": energy_scale(scene)}
    for key in ANGLES + tuple(f"{k}_centroid" for k in ANGLES):
        m, se = mean_se([r[key] for r in rows])
        out[f"{key}_mean_deg"], out[f"{key}_se_deg"] = m, se
    if scene.output.slip_stats and rows:
        n = sum(r["slipping_contacts"] for r in rows)
        for key in ("share_above_vd", "share_above_vstar", "slip_fs_fn"):
            total = sum(r[key] * r["slipping_contacts"] for r in rows if r["slipping_contacts"])
            out[f"avalanche_{key}"] = total / n if n else math.nan
    out["avalanche_list"] = events  # slides too ("avalanche": false)
    return out


def claims(scene):
    return [("avalanches", "avalanches measured"), ("theta_start_mean_deg", "mean theta_start (deg)"),
            ("theta_stop_mean_deg", "mean theta_stop (deg)")]


def figures(out, runs):
    """theta against time, avalanches shaded, one figure per run."""
    from ..plotstyle import pyplot, save

    plt, names = pyplot(), []
    for key, (scene, summary, df) in runs.items():
        theta, theta_c, rows = measure(scene, df)
        fig, ax = plt.subplots(figsize=(8, 3))
        ax.plot(df["t"], theta, lw=0.8, label="fit")
        ax.plot(df["t"], theta_c, lw=0.8, label="centroid")
        ax.legend()
        for r in rows:
            ax.axvspan(r["t_onset"], r["t_end"], color="0.85" if r["avalanche"] else "0.95")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("surface slope (deg)")
        ax.set_title(" ".join(str(k) for k in key))
        names.append(save(fig, out, f"drum_theta_{'_'.join(str(k) for k in key)}.png"))
    return names
