# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "drag" (paper §3.1, Fig. 9): a grain dragged at constant speed over a wall.

Friction saw-tooth between mu_s*Fn and (2 mu_k - mu_s)*Fn, mean mu_k*Fn, period
2(mu_s - mu_k)Fn/(Ks V) less the dashpot's share.
"""
from __future__ import annotations

import numpy as np

from .. import plotstyle
from . import stick_resolution
from .paper import Statement, near

NAME = "drag"
NAMES = {"contact": "contact", "grain": "grain"}
PRECISION_DURATION = None
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)


def prefix(scene):
    a, b = scene.analysis["contact"]
    return f"{a}-{b}"


def grain(scene):
    return next(g for g in scene.grains if g.name == scene.analysis["grain"])


def friction_ratio(df, c):
    """|Fs|/Fn per row (0 where the grain does not touch)."""
    fn = df[f"{c}_fn"].to_numpy()
    return np.divide(df[f"{c}_fs"].to_numpy(), fn, out=np.zeros_like(fn), where=fn > 0)


def summarise(scene, df):
    c = prefix(scene)
    fn = df[f"{c}_fn"].to_numpy()
    ratio = friction_ratio(df, c)
    t = df["t"].to_numpy()
    rows = stick_resolution.slip_rows(df, c)
    p = scene.contact
    speed = float(np.linalg.norm(grain(scene).velocity))
    fn_mean = float(fn[fn > 0].mean())
    nu_s = p.nu_s if scene.effects["tangential_damping"] else 0.0
    drop = 2 * (p.mu_s - p.mu_k) * fn_mean  # the force the spring must regain after a slip
    out = {
        "fs_fn_max": float(ratio.max()),
        "slip_count": int(df[f"{c}_slip"].sum()),
        "fn_mean_N": fn_mean,
        "drag_speed_mps": speed,
        # Paper's period (section 3.1), and the same less the dashpot's jump nu_s*V at the
        # start of each stick phase, which shortens the spring's travel.
        "slip_period_paper_s": drop / (p.ks * speed) if speed else None,
        "slip_period_expected_s": (drop - nu_s * speed) / (p.ks * speed) if speed else None,
    }
    if len(rows) >= 2:
        # Whole saw-tooth periods: from just after the first slip to the last slip.
        window = slice(rows[0] + 1, rows[-1] + 1)
        out["fs_fn_min"] = float(ratio[window].min())
        out["fs_fn_mean"] = float(ratio[window].mean())
        out["slip_period_s"] = float((t[rows[-1]] - t[rows[0]]) / (len(rows) - 1))
        out["first_slip_s"] = float(t[rows[0]])
    else:
        out.update(fs_fn_min=None, fs_fn_mean=None, slip_period_s=None, first_slip_s=None)
    out.update(stick_resolution.measure(df, c, scene.output.every))
    return out


def errors(scene, summary, df, ref_summary, ref_df):
    return {"mean_friction": _rel(summary["fs_fn_mean"], ref_summary["fs_fn_mean"]),
            "slip_period": _rel(summary["slip_period_s"], ref_summary["slip_period_s"])}


def _rel(a, b):
    if a is None or b is None or b == 0:
        return float("nan")
    return abs(a - b) / abs(b)


def claims(scene):
    p = scene.contact
    return [("fs_fn_max", f"max |Fs|/Fn = μs = {p.mu_s:g}"),
            ("fs_fn_min", f"min |Fs|/Fn = 2μk − μs = {2 * p.mu_k - p.mu_s:g}"),
            ("fs_fn_mean", f"mean over whole periods = μk = {p.mu_k:g}"),
            ("slip_period_s", "measured slip period (s)"), ("slip_period_paper_s", "paper: 2(μs−μk)Fn/(Ks·V)"),
            ("slip_period_expected_s", "same, less the dashpot's jump ν_s·V"), ("slip_count", "slips"),
            ("wall_time_s", "wall time (s)")]


def figures(out, runs):
    """Fig. 9: friction force and sliding against the imposed displacement."""
    plt = plotstyle.pyplot()
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    fn = None
    for (law, timing, eng), (sc, s, df) in runs.items():
        c, g = prefix(sc), sc.analysis["grain"]
        disp = (df[f"{g}_x"] - df[f"{g}_x"].iloc[0]) * 1e6
        a.plot(disp, df[f"{c}_fs"], **plotstyle.line(eng), label=plotstyle.label(eng, timing))
        b.plot(disp, disp - df[f"{c}_fs"] / sc.contact.ks * 1e6, **plotstyle.line(eng), label=plotstyle.label(eng, timing))
        fn, p = s["fn_mean_N"], sc.contact
    if fn is None:
        plt.close(fig)
        return []
    a.axhline(p.mu_s * fn, color="k", lw=0.5)
    a.axhline((2 * p.mu_k - p.mu_s) * fn, color="k", lw=0.5)
    a.axhline(p.mu_k * fn, color="gray", lw=0.5, ls="--")
    a.set_ylabel("friction force |Fs| (N/m)")
    a.legend()
    b.set_ylabel("sliding ≈ disp. − |Fs|/Ks (µm)")
    b.set_xlabel("imposed displacement (µm)")
    a.set_title("Fig. 9 — drag: saw-tooth between μs·Fn and (2μk−μs)·Fn")
    return [plotstyle.save(fig, out, "fig09_drag.png")]


def precision_figures(out, runs):
    return []


def paper_statements(scene):
    """Paper §3.1 beside the runs' figures (kinds/paper.py)."""
    p = scene.contact
    return [
        Statement("§3.1", "In the static phase the friction rises linearly to the static threshold μs·Fn",
                  lambda s: s["fs_fn_max"], near(p.mu_s, 0.005),
                  how="largest |Fs|/Fn within 0.5 % of μs (one step's loading is 0.12 % of it at the scene's dt)"),
        Statement("§3.1", "In the dynamic phase it switches between μs·Fn and the dynamic limit (2μk−μs)·Fn",
                  lambda s: s["fs_fn_min"], near(2 * p.mu_k - p.mu_s, 0.005),
                  how="least |Fs|/Fn over whole periods within 0.5 % of 2μk−μs"),
        Statement("§3.1", "The lower limit is chosen so that the average tangential force is μk·Fn",
                  lambda s: s["fs_fn_mean"], near(p.mu_k, 0.005),
                  how="mean |Fs|/Fn over whole periods within 0.5 % of μk (the dashpot adds νs·V/(2Fn) = 0.05 %)"),
        Statement("§3.1", "During the stick periods there is no sliding: the force rises with the displacement",
                  lambda s: s["slip_period_s"] / s["slip_period_expected_s"] if s.get("slip_period_s") else None,
                  near(1.0, 0.01),
                  how="slip period over (2(μs−μk)Fn − νs·V)/(Ks·V), the period of a spring that follows the "
                      "imposed displacement while sticking, within 1 % (one step is 0.6 %)"),
    ]
