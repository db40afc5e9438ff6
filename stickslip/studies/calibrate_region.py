# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip calibrate --region-png FILE`: the answer's region on the map's (mu_s, mu_k) plane.

The map's domain (the law's triangle within the measured hull) shaded, the measured points,
the contours chi2 = least + k^2 (whose extent along each axis is that coefficient's range:
calibrate_fit.thresholds) and the joint 68 % region, and the answer. Where the contours meet the
domain's edge the region is cut: its range there is a bound, which the figure shows.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotstyle import pyplot, save


def draw(r, targets, pts, rolling, path):
    """Write the figure to `path` (PNG); returns the path."""
    plt = pyplot()
    path = Path(path)
    fig, ax = plt.subplots(figsize=(6, 5))
    s, k = np.meshgrid(r.surf.ms, r.surf.mk, indexing="ij")
    inside = np.isfinite(r.field)
    ax.contourf(s, k, inside.astype(float), levels=[0.5, 1.5], colors=["0.92"])
    delta = np.where(inside, r.field - r.chi2, 1e9)
    levels = {r.delta["mu_s"]: "μs's range", r.delta["mu_k"]: "μk's range", r.delta["joint"]: "joint 68 %"}
    if abs(r.delta["mu_s"] - r.delta["mu_k"]) < 1e-6:
        levels = {r.delta["mu_s"]: "ranges", r.delta["joint"]: "joint 68 %"}
    order = sorted(levels)
    cs = ax.contour(s, k, delta, levels=order, colors=[f"C{i}" for i in range(len(order))],
                    linestyles=["-"] * (len(order) - 1) + ["--"])
    ax.clabel(cs, fmt={v: f"Δχ² = {v:.2f} ({levels[v]})" for v in order}, fontsize=7)
    sweep = pts[(pts.engine == "liggghts") & (pts.group == "sweep") & np.isclose(pts["rolling"], rolling)]
    sweep = sweep.drop_duplicates(["mu_s", "mu_k"])
    ax.plot(sweep.mu_s, sweep.mu_k, "k.", ms=6, label="measured points")
    ax.plot(r.mu_s, r.mu_k, "r*", ms=12, label=f"answer ({r.mu_s:.3f}, {r.mu_k:.3f})")
    for name, (lo, hi) in r.ranges.items():
        line = ax.axvline if name == "mu_s" else ax.axhline
        for end, v in (("lo", lo), ("hi", hi)):
            line(v, color="C0", lw=0.6, ls=":" if (name, end) in r.cut else "-", alpha=0.7)
    x = np.array([r.surf.ms.min() - 0.05, r.surf.ms.max() + 0.05])  # the law's bounds across the map
    ax.plot(x, x, color="0.5", lw=0.6)
    ax.plot(x, x / 2, color="0.5", lw=0.6)
    ax.set_xlabel("μs")
    ax.set_ylabel("μk")
    ax.set_title("calibrate: " + ", ".join(f"{a} {t.value:.2f}" + (f" ± {t.se:.2f}" if t.se else "")
                                           for a, t in targets.items()) + f"; rolling {rolling:g}", fontsize=8)
    ax.legend(fontsize=7, loc="upper left")
    fig.text(0.01, 0.01, "thin lines: each coefficient's range (dotted: cut by the domain's edge, a bound); "
             "grey: the map's domain", fontsize=6)
    save(fig, path.parent, path.name)
    return path
