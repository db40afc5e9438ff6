# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "shear3d": a layer of spheres sheared under a rough lid that a spring drives along x
(cases/shear3d.toml, docs/granular-3d.md): the shear cell of a powder lab (a ring or Jenike
shear tester: a sample consolidated under a normal stress, then sheared, its peak and its
steady shear stress read), and with a soft spring the stick-slip of a sheared layer of glass
beads (Nasuno et al. 1998, Phys. Rev. E 58, 2161).

From the time series (columns.LID), after the drive starts (the lid's start; its travel
s = velocity (t - start)): the stress ratio tau/sigma = lid_force / (sigma A), sigma the lid's
pressure plus its weight over the box's area A:
- shear_peak: the largest tau/sigma until `peak_until` s of drive (the first yield of the
  layer at rest: its static strength);
- shear_steady, shear_steady_sd: the mean and the spread of tau/sigma after `steady_after` s
  of drive (its dynamic strength);
- shear_dilation: how far the lid rose from the drive's start to the steady part (its mean), m;
- slip_count, slip_drop: the lid's slips after steady_after, runs of rows where it moves
  faster than SLIP_SPEED times the drive, and the mean fall of tau/sigma over one (from the
  row before the run to its last row + 1); NaN drop without slips.
"""
from __future__ import annotations

import math

import numpy as np

from .none import paper_statements, precision_figures  # noqa: F401 (the contract: neither, as kind none)

NAME = "shear3d"
NAMES = {"peak_until": "seconds", "steady_after": "seconds"}
PRECISION_DURATION = None
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)
SLIP_SPEED = 3.0  # a slip: the lid faster than this many times the drive's velocity


def normal_stress(scene):
    """sigma: the lid's pressure plus its grains' weight over the box's area (Pa)."""
    weight = sum(scene.grain_mass(g) for g in scene.lid_grains()) * float(np.linalg.norm(scene.gravity))
    return scene.lid.pressure + weight / scene.lid.area


def stress_ratio(scene, df):
    """(time since the drive started, tau/sigma) of the rows after it started."""
    t = df["t"].to_numpy(float) - scene.lid.start
    on = t > 0
    return t[on], df["lid_force"].to_numpy(float)[on] / (normal_stress(scene) * scene.lid.area)


def slips(scene, df, after):
    """[(first row, last row)] of the runs of rows after `after` s of drive in which the lid moves
    faster than SLIP_SPEED x the drive's velocity."""
    t = df["t"].to_numpy(float) - scene.lid.start
    fast = (df["lid_vx"].to_numpy(float) > SLIP_SPEED * abs(scene.lid.velocity)) & (t > after)
    edges = np.diff(np.concatenate([[0], fast.astype(int), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1))


def summarise(scene, df):
    sigma = normal_stress(scene)
    t = df["t"].to_numpy(float) - scene.lid.start  # time since the drive started, every row
    full = df["lid_force"].to_numpy(float) / (sigma * scene.lid.area)  # tau/sigma, every row
    on = t > 0  # the rows after the drive started (stress_ratio's)
    after = t >= scene.analysis["steady_after"]
    peak, steady = on & (t <= scene.analysis["peak_until"]), on & after
    z = df["lid_z"].to_numpy(float)
    first = int(np.searchsorted(t, 0.0))  # the drive's first row
    z0 = z[first] if first < len(z) else math.nan  # (a run that ends before the drive: none)
    events = [(a, b) for a, b in slips(scene, df, scene.analysis["steady_after"]) if a > 0 and b + 1 < len(df)]
    drops = [full[a - 1] - full[b + 1] for a, b in events]
    return {"shear_peak": float(full[peak].max()) if peak.any() else math.nan,
            "shear_steady": float(full[steady].mean()) if steady.any() else math.nan,
            "shear_steady_sd": float(full[steady].std()) if steady.any() else math.nan,
            "shear_dilation": float(z[after].mean() - z0) if after.any() else math.nan,
            "slip_count": len(events), "slip_drop": float(np.mean(drops)) if drops else math.nan,
            "normal_stress": sigma,
            "drive_travel": float(scene.lid.velocity * t[on][-1]) if on.any() else 0.0}


def errors(scene, summary, df, ref_summary, ref_df):
    return {k: abs(summary[k] - ref_summary[k]) / abs(ref_summary[k]) for k in ("shear_peak", "shear_steady")}


def claims(scene):
    return [("shear_peak", "peak tau/sigma"), ("shear_steady", "steady tau/sigma"), ("shear_dilation", "dilation (m)"),
            ("slip_count", "slips")]


def figures(out, runs):
    """tau/sigma against the drive's travel, one figure per run, the peak's and the steady part's
    windows marked."""
    from ..plotstyle import pyplot, save

    plt, names = pyplot(), []
    for key, (scene, summary, df) in runs.items():
        t, ratio = stress_ratio(scene, df)
        v = abs(scene.lid.velocity)
        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.plot(v * t, ratio, lw=0.6)
        for x in (scene.analysis["peak_until"], scene.analysis["steady_after"]):
            ax.axvline(v * x, ls="--", color="0.4")
        ax.set_xlabel("drive's travel (m)")
        ax.set_ylabel("τ/σ")
        names.append(save(fig, out, f"{NAME}_{'_'.join(str(k) for k in key)}.png"))
    return names
