# SPDX-License-Identifier: GPL-2.0-or-later
"""The drum study's figures (stickslip/studies/drum_study.py): the calibration map, the
distributions of the avalanche angles, and slope traces."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..plotstyle import pyplot, save


def history(study):
    """The history runs at the study's rate and dt, by mu."""
    h = study[study.label.str.startswith("history_mu") & ~study.label.str.contains("half")]
    return h.sort_values("mu_s")


def stick_slip(study):
    return study[study.label.str.startswith("ss_") & ~study.label.str.contains("half")]


def consistent_mu(study, key, z=2.0):
    """For each stick-slip run: the history friction coefficients whose angle `key` (e.g.
    'theta_stop_centroid') agrees with the run's within z combined standard errors, as
    [(lo, hi)] intervals of mu (the history means and errors interpolated linearly between
    the measured mu; an empty list: no history run agrees). The calibration map inverted:
    which mu of stock history gives the angle this stick-slip pair gives."""
    h = history(study)
    mu = np.linspace(h.mu_s.min(), h.mu_s.max(), 1001)
    m = np.interp(mu, h.mu_s, h[f"{key}_mean_deg"])
    se = np.interp(mu, h.mu_s, h[f"{key}_se_deg"])
    out = {}
    for _, r in stick_slip(study).iterrows():
        ok = np.abs(m - r[f"{key}_mean_deg"]) <= z * np.hypot(se, r[f"{key}_se_deg"])
        edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(int), 0]))
        out[r.label] = [(float(mu[a]), float(mu[b - 1])) for a, b in zip(edges[::2], edges[1::2])]
    return out


def draw(out, study, events, folders):
    plt = pyplot()
    names = []
    hist, ss = history(study), stick_slip(study)
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), sharex=True)
    for col, (ax_row, what) in zip(("theta_start", "theta_stop"), zip(axes, ("θ_start", "θ_stop"))):
        for ax, suffix, title in ((ax_row[0], "", "fit to the middle of the surface"),
                                  (ax_row[1], "_centroid", "centroid's angle")):
            key = f"{col}{suffix}"
            ax.errorbar(hist.mu_s, hist[f"{key}_mean_deg"], yerr=hist[f"{key}_se_deg"], marker="o", capsize=3,
                        color="k", label="stock history (μ)")
            for k, (_, r) in enumerate(ss.iterrows()):
                # the run's angle drawn at each of its three coefficients: the marker that sits on
                # the history curve names the coefficient that sets this angle
                x = [r.mu_s, r.mu_k, 2 * r.mu_k - r.mu_s]
                y = [r[f"{key}_mean_deg"]] * 3
                ax.plot(x, y, color=f"C{k}", lw=0.6)
                for xi, mk in zip(x, ("^", "o", "v")):
                    ax.errorbar(xi, y[0], yerr=r[f"{key}_se_deg"], color=f"C{k}", marker=mk, ms=6, capsize=2,
                                mfc="none" if mk == "o" else f"C{k}")
                ax.plot([], [], color=f"C{k}", lw=1, label=r.label)
            ax.set_title(f"{what}: {title}", fontsize=10)
            ax.set_ylabel(f"{what} (deg)")
    for ax in axes[1]:
        ax.set_xlabel("friction coefficient μ (stick-slip: ▲ μs, ○ μk, ▼ 2μk − μs)")
    axes[0, 1].legend(fontsize=7)
    names.append(save(fig, out, "drum_calibration.png"))

    if len(events):
        shown = [lab for lab in ("history_mu0.50", "history_mu0.10", "ss_0.50_0.30_step", "ss_0.50_0.30_nus0_exact",
                                 "ss_0.50_0.35_step")
                 if lab in set(events.label)]
        fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
        av = events[events.avalanche.astype(bool)]
        for lab in shown:
            e = av[av.label == lab]
            for ax, col in zip(axes, ("theta_start_centroid", "theta_stop_centroid", "delta_theta_centroid")):
                ax.hist(e[col], bins=np.arange(0, 45, 1.0), histtype="step", label=f"{lab} ({len(e)})")
        for ax, col in zip(axes, ("θ_start", "θ_stop", "δθ")):
            ax.set_xlabel(f"{col}, centroid's angle (deg)")
        axes[0].set_ylabel("avalanches")
        axes[2].legend(fontsize=7)
        names.append(save(fig, out, "drum_distributions.png"))

    traces = [lab for lab in ("history_mu0.50", "ss_0.50_0.30_step", "ss_0.50_0.35_step") if lab in folders][:2]
    if traces:
        fig, axes = plt.subplots(len(traces), 1, figsize=(10, 2.6 * len(traces)), squeeze=False)
        for ax, lab in zip(axes[:, 0], traces):
            s = pd.read_csv(folders[lab] / "slope.csv")
            ax.plot(s.t, s.theta_deg, lw=0.6, label="fit")
            if "theta_centroid_deg" in s:
                ax.plot(s.t, s.theta_centroid_deg, lw=0.8, label="centroid")
            ax.legend(fontsize=7, loc="lower right")
            e = events[(events.label == lab)] if len(events) else events
            for _, r in e.iterrows():
                ax.axvspan(r.t_onset, r.t_end, color="0.8" if r.avalanche else "0.93")
            ax.set_ylabel("slope (deg)")
            ax.set_title(lab, fontsize=9)
            ax.set_ylim(0, 45)
        axes[-1, 0].set_xlabel("t (s)")
        names.append(save(fig, out, "drum_traces.png"))
    return names
