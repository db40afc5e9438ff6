"""The drum study's figures (stickslip/drum_study.py): the calibration map, the
distributions of the avalanche angles, and slope traces."""
from __future__ import annotations

import numpy as np
import pandas as pd

from .plotstyle import pyplot, save


def effective_mu(study, column):
    """For each stick-slip run: the history mu whose mean `column` is the same (linear
    interpolation of the history runs at the study's rate and dt; NaN outside them)."""
    hist = _history(study)
    x, y = hist["mu_s"].to_numpy(), hist[column].to_numpy()
    order = np.argsort(y)
    out = {}
    for _, r in study[study.label.str.startswith("ss_")].iterrows():
        v = r[column]
        out[r.label] = float(np.interp(v, y[order], x[order])) if y.min() <= v <= y.max() else np.nan
    return out


def _history(study):
    h = study[study.label.str.startswith("history_mu") & ~study.label.str.contains("half")]
    return h.sort_values("mu_s")


def draw(out, study, events, folders):
    plt = pyplot()
    names = []
    hist = _history(study)
    ss = study[study.label.str.startswith("ss_") & ~study.label.str.contains("half")]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharey=True)
    for ax, suffix, title in ((axes[0], "", "fit to the middle of the surface"),
                              (axes[1], "_centroid", "centroid's angle")):
        for col, mark, name in (("theta_start", "o", "θ_start"), ("theta_stop", "s", "θ_stop")):
            ax.errorbar(hist.mu_s, hist[f"{col}{suffix}_mean_deg"], yerr=hist[f"{col}{suffix}_se_deg"], marker=mark,
                        capsize=3, color="k", ls="-" if col == "theta_start" else "--", label=f"history: {name}")
        for k, (_, r) in enumerate(ss.iterrows()):
            c = f"C{k}"
            ax.axhline(r[f"theta_start{suffix}_mean_deg"], color=c, ls="-", lw=0.8)
            ax.axhline(r[f"theta_stop{suffix}_mean_deg"], color=c, ls="--", lw=0.8, label=f"{r.label} (— start, -- stop)")
        ax.set_xlabel("history friction coefficient μ")
        ax.set_title(f"θ: {title}", fontsize=10)
    axes[0].set_ylabel("angle (deg)")
    axes[1].legend(fontsize=7)
    names.append(save(fig, out, "drum_calibration.png"))

    if len(events):
        shown = [lab for lab in ("history_mu0.50", "history_mu0.20", "ss_0.50_0.45_step", "ss_0.50_0.35_step")
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

    traces = [lab for lab in ("history_mu0.50", "ss_0.50_0.35_step") if lab in folders]
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
