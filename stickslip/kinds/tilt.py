# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "tilt" (paper §3.3, Figs. 13-15): a grain on a plate tilted until tan(beta) = mu_s.

First slip at tan(beta) = mu_s, then stick-slip, then steady sliding at Fmin.
"""
from __future__ import annotations

import math

import numpy as np

from pyref.laws import every_step_slips_speed

from .. import plotstyle
from . import stick_resolution
from .paper import Statement, near

NAME = "tilt"
NAMES = {"grain": "grain", "contact": "contact", "wall": "turning wall"}
PRECISION_DURATION = None
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step", "exact")  # §3.3 is judged in both (the paper ties its speed effect to dt)


def _prefix(scene):
    a, b = scene.analysis["contact"]
    return f"{a}-{b}"


def speed_down_plate(scene, df):
    """Speed down the plate: its direction is (cos b, sin b) in the plane of motion; down
    the slope is minus that."""
    g, w = scene.analysis["grain"], scene.analysis["wall"]
    beta = df[f"{w}_angle"].to_numpy()
    return -(df[f"{g}_vx"].to_numpy() * np.cos(beta) + df[f"{g}_vy"].to_numpy() * np.sin(beta))


def _stop_angle(scene):
    return next(w.rotation.stop_angle for w in scene.walls if w.name == scene.analysis["wall"])


def summarise(scene, df):
    c = _prefix(scene)
    every = scene.output.every
    t = df["t"].to_numpy()
    beta = df[f"{scene.analysis['wall']}_angle"].to_numpy()
    u = speed_down_plate(scene, df)
    slips = df[f"{c}_slip"].to_numpy()
    rows = np.nonzero(slips > 0)[0]
    p = scene.contact
    b_stop = _stop_angle(scene)
    gmag = float(np.linalg.norm(scene.gravity))
    out = {
        "tan_beta_stop": math.tan(b_stop),
        "accel_steady_expected_mps2": gmag * (math.sin(b_stop) - (2 * p.mu_k - p.mu_s) * math.cos(b_stop)),
        "accel_mean_friction_mu_k_mps2": gmag * (math.sin(b_stop) - p.mu_k * math.cos(b_stop)),
        "tan_beta_first_slip": None, "t_first_slip_s": None,
        "accel_stick_slip_mps2": None, "accel_steady_mps2": None, "t_steady_s": None,
        "final_speed_mps": float(u[-1]),
    }
    if not len(rows):
        return out
    first = rows[0]
    out["tan_beta_first_slip"] = float(np.tan(beta[first]))
    out["t_first_slip_s"] = float(t[first])
    # Steady sliding: from the first row after which the friction stays at Fmin (in the
    # step timing every step then slips; in the exact one several slips a step can still
    # average mu_k*Fn, so "every step slipped" would start it too early).
    fn, fs = df[f"{c}_fn"].to_numpy(), df[f"{c}_fs"].to_numpy()
    at_fmin = (np.abs(fs - (2 * p.mu_k - p.mu_s) * fn) <= 1e-9 * fn) & (slips > 0)
    not_full = np.nonzero(~at_fmin)[0]
    start = not_full[-1] + 1 if len(not_full) else 0
    if start < len(t) - 2 and start > first:
        out["t_steady_s"] = float(t[start])
        out["accel_steady_mps2"] = float(np.polyfit(t[start:], u[start:], 1)[0])
    end = start if out["t_steady_s"] is not None else len(t) - 1
    if end > first:
        out["accel_stick_slip_mps2"] = float((u[end] - u[first]) / (t[end] - t[first]))
        out["stick_slip_duration_s"] = float(t[end] - t[first])
        # mean friction over the first and the second half of the stick-slip phase, each
        # over whole saw-tooth periods (slip to slip: a part of a period would weigh its
        # rise or its drop, and the engines place slips a few steps apart)
        cuts = rows[(rows >= first) & (rows <= end)]
        if len(cuts) >= 3:
            mid = cuts[np.argmin(np.abs(t[cuts] - 0.5 * (t[first] + t[end])))]
            if first < mid < cuts[-1]:
                ratio = fs / np.where(fn > 0, fn, np.inf)
                out["stick_slip_friction_early"] = float(np.mean(ratio[first + 1:mid + 1]))
                out["stick_slip_friction_late"] = float(np.mean(ratio[mid + 1:cuts[-1] + 1]))
    # Before the first slip the friction holds the weight's component along the plate.
    g = next(q for q in scene.grains if q.name == scene.analysis["grain"])
    weight = scene.grain_mass(g) * gmag
    tilting = (t < t[first]) & (beta > 0)
    if tilting.any():
        out["friction_vs_weight_dev"] = float(np.max(np.abs(fs[tilting] - weight * np.sin(beta[tilting])))
                                              / (weight * math.sin(b_stop)))
    # The plate's stop jolts the grain: the least normal force in the 30 ms after it.
    stop = int(np.argmax(beta >= b_stop * (1 - 1e-12)))
    after = (t >= t[stop]) & (t <= t[stop] + 0.03)
    out["fn_min_after_stop_ratio"] = float(fn[after].min() / (weight * math.cos(b_stop)))
    # Where the dashpot alone covers the force drop, nu_s*V >= 2(mu_s - mu_k)*Fn, every
    # step slips at any dt: physics, not a time-step artefact (docs/precision.md).
    nu_s = p.nu_s if scene.effects["tangential_damping"] else 0.0
    dashpot = nu_s * np.abs(u) >= 2 * (p.mu_s - p.mu_k) * df[f"{c}_fn"].to_numpy()
    out.update(stick_resolution.measure(df, c, every, dashpot))
    return out


def errors(scene, summary, df, ref_summary, ref_df):
    """RMS difference of the speed down the plate after the reference's first slip,
    relative to the reference's final speed."""
    t0 = ref_summary["t_first_slip_s"]
    tr = ref_df["t"].to_numpy()
    sel = tr >= t0
    u_ref = speed_down_plate(scene, ref_df)[sel]
    u = np.interp(tr[sel], df["t"].to_numpy(), speed_down_plate(scene, df))
    return {"velocity_history": float(np.sqrt(np.mean((u - u_ref) ** 2)) / max(abs(u_ref[-1]), 1e-30))}


def claims(scene):
    p = scene.contact
    return [("tan_beta_first_slip", f"tan β at the first slip (paper: μs = {p.mu_s:g})"),
            ("accel_stick_slip_mps2", "mean acceleration, stick-slip phase"),
            ("accel_mean_friction_mu_k_mps2", "… if friction averaged μk·Fn"),
            ("accel_steady_mps2", "acceleration, steady sliding"),
            ("accel_steady_expected_mps2", "… expected with friction (2μk−μs)·Fn"),
            ("t_steady_s", "steady sliding from t (s)"), ("final_speed_mps", "speed at the end (m/s)"),
            ("wall_time_s", "wall time (s)")]


def figures(out, runs):
    plt = plotstyle.pyplot()
    # Fig. 14: friction force and tan(beta) (a), zoom after the stop (b).
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 7))
    for (law, timing, eng), (sc, s, df) in runs.items():
        c, angle = _prefix(sc), df[f"{sc.analysis['wall']}_angle"]
        a.plot(df["t"], df[f"{c}_fs"], **plotstyle.line(eng, timing), label=f"|Fs|: {plotstyle.label(eng, timing)}")
        t_stop = df["t"][np.argmax(angle.to_numpy())]
        z = df["t"] >= t_stop - 0.005
        b.plot(df["t"][z], df[f"{c}_fs"][z], **plotstyle.line(eng, timing), lw=0.7, label=plotstyle.label(eng, timing))
    ax2 = a.twinx()
    ax2.plot(df["t"], np.tan(angle), "k-", lw=0.8)  # (black: the timings' colours are the runs')
    ax2.set_ylabel("tan β (black)")
    a.set_xlabel("t (s)")
    a.set_ylabel("friction force (N/m)")
    a.legend(loc="upper left")
    b.set_xlabel("t (s)")
    b.set_ylabel("friction force (N/m)")
    b.legend()
    a.set_title("Fig. 14 — tilt: (a) friction and tan β, (b) after the plate stops (colour: slip timing)")
    names = [plotstyle.save(fig, out, "fig14_tilt_friction.png")]
    # Fig. 15: speed along the plate after the first slip.
    fig, ax = plt.subplots(figsize=(7, 4))
    for (law, timing, eng), (sc, s, df) in runs.items():
        z = df["t"] >= (s["t_first_slip_s"] or 0) - 0.002
        ax.plot(df["t"][z], speed_down_plate(sc, df)[z] * 1e3, **plotstyle.line(eng, timing),
                label=plotstyle.label(eng, timing))
        if s.get("t_steady_s"):
            ax.axvline(s["t_steady_s"], color=plotstyle.TIMING_COLOURS[timing], lw=0.5, alpha=0.5)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("speed down the plate (mm/s)")
    ax.set_title("Fig. 15 — tilt: stick-slip, then steady sliding (thin lines: its start)")
    ax.legend()
    names.append(plotstyle.save(fig, out, "fig15_tilt_velocity.png"))
    return names


def precision_figures(out, runs):
    """Fig. 15 at each time step and slip timing (runs[(engine, timing, dt)]): which parts
    of the curve are physics, which are the time step."""
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for k, ((eng, timing, dt), (sc, s, df)) in enumerate(sorted(runs.items(), key=lambda kv: (kv[0][1], kv[0][2]))):
        if s["t_first_slip_s"] is None:
            continue
        sel = df["t"].to_numpy() >= s["t_first_slip_s"] - 0.002
        label = f"{plotstyle.label(eng, timing)}, dt = {dt:.1e} s"
        if timing == "step":
            g = next(q for q in sc.grains if q.name == sc.analysis["grain"])
            fn = sc.grain_mass(g) * float(np.linalg.norm(sc.gravity)) / math.sqrt(1 + s["tan_beta_stop"] ** 2)
            v_star = every_step_slips_speed(sc.contact.law_params(sc.effects), fn, dt)
            label += f" (every step slips above {v_star * 1e3:.2f} mm/s)"
        ax.plot(df["t"][sel], speed_down_plate(sc, df)[sel] * 1e3, ls="--" if timing == "step" else "-",
                lw=0.9, label=label)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("speed down the plate (mm/s)")
    ax.set_title("tilt: velocity after the first slip, by time step (dashed: step timing, solid: exact)")
    ax.legend(fontsize=6)
    return [plotstyle.save(fig, out, "precision_tilt_velocity.png", dpi=110)]


def paper_statements(scene):
    """Paper §3.3 beside the runs' figures (kinds/paper.py)."""
    p = scene.contact
    exact_why = ("with each slip at its time the stick stage is resolved at any dt: the mean friction rises with "
                 "speed (μk + νs·V/(2Fn)) until the dashpot alone covers the drop, then falls to 2μk−μs within "
                 "the normal force's ringing after the stop; the paper's gradual fall is its time step's "
                 "(docs/precision.md)")
    return [
        Statement("§3.3", "Before the slip the friction follows P·sin β (the reaction to the weight along the plate)",
                  lambda s: s.get("friction_vs_weight_dev"), lambda v: v < 0.01,
                  how="largest |Fs − P·sin β| under 1 % of P·sin β at the stop (the spring follows within "
                      "its period, 1000x shorter than the tilt)"),
        Statement("§3.3", "When tan β = μs the friction reaches the static threshold and the grain starts to slide",
                  lambda s: s["tan_beta_first_slip"], near(p.mu_s, 0.005),
                  how="tan β at the first slip within 0.5 % of μs"),
        Statement("§3.3", "Stopping the plate makes the normal force drop sharply (transition phase)",
                  lambda s: s.get("fn_min_after_stop_ratio"), lambda v: v < 0.95,
                  how="least Fn in the 30 ms after the stop below 95 % of P·cos β"),
        Statement("§3.3", "Then stick-slip: the friction switches between the two thresholds",
                  lambda s: s.get("stick_slip_duration_s"), lambda v: v > 0,
                  how="a stretch of slips with stick steps between them (its length, s)"),
        Statement("§3.3", "At the start of stick-slip the average friction is close to μk·Fn",
                  lambda s: s.get("stick_slip_friction_early"), near(p.mu_k, 0.02),
                  how="mean |Fs|/Fn over the whole saw-tooth periods of the first half of the stick-slip "
                      "stretch within 2 % of μk",
                  why={"exact": "the mean carries the dashpot's share νs·V/(2Fn), which grows with the speed to 11 % "
                                "of μk at the dashpot threshold (2.6 % over the first half here); in the step timing "
                                "the under-resolved stick stage pulls the mean down about as much"}),
        Statement("§3.3", "As the grain speeds up the stick stage is poorly resolved and the average friction falls",
                  lambda s: (s["stick_slip_friction_late"] - s["stick_slip_friction_early"])
                  if s.get("stick_slip_friction_late") is not None else None, lambda v: v < 0,
                  how="second-half minus first-half mean |Fs|/Fn of the stick-slip stretch (whole periods) "
                      "below zero",
                  why={"exact": exact_why}),
        Statement("§3.3", "Steady sliding: constant friction (2μk−μs)·Fn and constant acceleration",
                  lambda s: (s["accel_steady_mps2"] / s["accel_steady_expected_mps2"])
                  if s.get("accel_steady_mps2") else None, near(1.0, 0.01),
                  how="measured over expected steady acceleration within 1 %"),
        Statement("§3.3", "The grain accelerates more in steady sliding than in stick-slip (Fig. 15)",
                  lambda s: (s["accel_steady_mps2"] - s["accel_stick_slip_mps2"])
                  if s.get("accel_steady_mps2") and s.get("accel_stick_slip_mps2") else None, lambda v: v > 0,
                  how="steady minus stick-slip acceleration (m/s²) above zero"),
    ]
