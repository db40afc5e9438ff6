# SPDX-License-Identifier: GPL-2.0-or-later
"""The figures of `stickslip study-3d` (docs/granular-3d.md), from its tables alone
(granular3d_tables.write_tables passes them): the stock curves with the stick-slip points
on them, the map (mu_s, mu_k) -> angles, and the validation against Weinhart et al."""
from __future__ import annotations

import numpy as np

from ..plotstyle import pyplot, save
from . import granular3d_tables as tables

LABEL = {"theta_start": "θ_start", "theta_stop": "θ_stop", "theta_heap": "θ_heap"}
VARIANTS = {("paper", "step"): ("C0", "paper's ν_s, step"), ("0", "exact"): ("C1", "ν_s = 0, exact"),
            ("paper", "exact"): ("C2", "paper's ν_s, exact")}


def draw(out, t):
    pts = t["points.csv"]
    names = []
    if (pts.group == "sweep").any():  # a study of checks alone has no curves to draw
        names.append(curves(out, pts))
        names.append(calibration_map(out, pts))
    if len(t["validation.csv"]):
        names.append(validation(out, t["validation.csv"]))
    return names


def _panels(pts, height):
    """A figure of one row per rolling resistance and one panel per angle, and its panels:
    (row, column, axes, rolling, angle, the sweep's points of that angle's kind)."""
    rolls = sorted(pts[pts.group == "sweep"]["rolling"].unique())
    fig, axes = pyplot().subplots(len(rolls), 3, figsize=(12, height * len(rolls)), squeeze=False)
    panels = [(i, j, axes[i, j], r, angle, tables._sweep(pts, tables.KIND[angle], r))
              for i, r in enumerate(rolls) for j, angle in enumerate(tables.ANGLES)]
    return fig, panels


def curves(out, pts):
    """Stock history's angles against mu (black, ± se) and each stick-slip point drawn at its
    mu_s (up triangle), its mu_k (circle) and 2 mu_k - mu_s (down triangle); a coefficient
    "sets" an angle where its marker falls on the black curve. One row per rolling resistance."""
    fig, panels = _panels(pts, 3.6)
    for i, j, ax, r, angle, sw in panels:
        h = tables.history(sw)
        ax.errorbar(h.mu_s, h[f"{angle}_mean"], yerr=h[f"{angle}_se"], color="k", marker="s", ms=4,
                    label="stock history at μ")
        for (nu_s, timing), (color, text) in VARIANTS.items():
            ss = sw[(sw.mu_s != sw.mu_k) & (sw.nu_s == nu_s) & (sw.timing == timing)]
            for k, (_, p) in enumerate(ss.iterrows()):
                y, e = p[f"{angle}_mean"], p[f"{angle}_se"]
                for x, m in ((p.mu_s, "^"), (p.mu_k, "o"), (2 * p.mu_k - p.mu_s, "v")):
                    ax.errorbar(x, y, yerr=e, color=color, marker=m, ms=5, ls="none", alpha=0.8,
                                label=text if (k == 0 and m == "^") else None)
                ax.plot([2 * p.mu_k - p.mu_s, p.mu_s], [y, y], color=color, lw=0.5, alpha=0.5)
        ax.set_xlabel("μ (history) / μs ▲, μk ●, 2μk − μs ▼ (stick-slip)")
        ax.set_ylabel(f"{LABEL[angle]} (deg)")
        ax.set_title(f"{LABEL[angle]}, rolling resistance {r:g}")
        if i == 0 and j == 0:
            ax.legend(fontsize=7)
    return save(fig, out, "granular3d_curves.png")


def calibration_map(out, pts):
    """The measured map: each point of the (mu_s, mu_k) plane (history on the diagonal)
    labelled with its angle, paper's nu_s; one panel per angle and rolling resistance."""
    fig, panels = _panels(pts, 3.8)
    for _, _, ax, r, angle, sw in panels:
        sel = sw[(sw.mu_s == sw.mu_k) | ((sw.nu_s == "paper") & (sw.timing == "step"))]
        v = sel[f"{angle}_mean"].to_numpy(float)
        sc = ax.scatter(sel.mu_s, sel.mu_k, c=v, cmap="viridis", s=120, edgecolor="k")
        for _, p in sel.iterrows():
            if np.isfinite(p[f"{angle}_mean"]):
                ax.annotate(f"{p[f'{angle}_mean']:.1f}", (p.mu_s, p.mu_k), textcoords="offset points",
                            xytext=(6, -10), fontsize=8)
        x = np.array([sel.mu_s.min() - 0.05, sel.mu_s.max() + 0.05])
        ax.plot(x, x, color="0.7", lw=0.5)
        ax.plot(x, x / 2, color="0.85", lw=0.5)  # mu_k = mu_s / 2, the law's lower bound
        ax.set_xlim(x[0], x[1] + 0.1)  # room for the labels of the last row
        ax.set_xlabel("μs")
        ax.set_ylabel("μk")
        ax.set_title(f"{LABEL[angle]} (deg), rolling {r:g}, paper's ν_s")
        fig.colorbar(sc, ax=ax)
    return save(fig, out, "granular3d_map.png")


def validation(out, val):
    """theta_stop of stock history (mu = 0.5) against the bed's depth: Weinhart et al.'s
    fit (line, ± 0.7 deg band) and each engine's mean ± std over fills at the ramp's rates
    (open), at zero rate (filled circles: granular3d_tables.ramp_lag) and held at fixed angles
    (squares: granular3d_tables.holds)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    h = np.linspace(5, 30, 100)
    w = np.array([tables.weinhart_theta_stop(x) for x in h])
    ax.plot(h, w, color="k", label="Weinhart et al. 2012 fit")
    ax.fill_between(h, w - tables.VALIDATION_TOLERANCE, w + tables.VALIDATION_TOLERANCE, color="0.9")
    for engine, color, dx in (("liggghts", "C0", -0.2), ("lammps", "C3", 0.2)):
        e = val[val.engine == engine]
        if "theta_stop" in e:  # the ramps (a study of held beds alone has none)
            ax.errorbar(e.depth_d + dx, e.theta_stop, yerr=e["std"], color=color, marker="o", mfc="none", ls="none",
                        label=f"{engine}, at the ramp's rates (mean ± std over fills)")
            ax.errorbar(e.depth_d + dx, e.theta_stop_zero_rate, yerr=e.se_zero_rate, color=color, marker="o",
                        ls="none", label=f"{engine}, at zero rate (± se)")
        if "theta_stop_fixed" in e and np.isfinite(e.theta_stop_fixed).any():
            ax.errorbar(e.fixed_depth_d + dx, e.theta_stop_fixed, yerr=e.se_fixed, color=color, marker="s",
                        ls="none", label=f"{engine}, held at fixed angles (± se)")
    ax.set_xlabel("bed depth at the stop, h (d)")
    ax.set_ylabel("θ_stop (deg)")
    ax.legend(fontsize=8)
    return save(fig, out, "granular3d_validation.png")
