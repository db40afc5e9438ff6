# SPDX-License-Identifier: GPL-2.0-or-later
"""The tables, tests of the predictions and summary of `stickslip study-3d`
(docs/granular-3d.md), all from runs.csv: `write_runs` makes runs.csv from the finished
runs, `write_tables` the other tables from runs.csv alone, so that the committed CSVs
redraw every table and figure (`stickslip study-3d --from-csv`; granular3d_figures.py).

Means are over fills, with their spread: std (ddof 1) and standard error std/sqrt(n).
A prediction "X falls on the stock curve at mu" is tested by z = (X - curve(mu)) /
sqrt(se_X^2 + se_curve^2), the curve being stock history's mean at that mu (every mu the
predictions need is a measured one: granular3d.PAIRS; others are interpolated linearly,
with the standard errors of the two neighbours interpolated alike).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

ANGLES = ("theta_start", "theta_stop", "theta_heap")
KIND = {"theta_start": "incline", "theta_stop": "incline", "theta_heap": "heap"}  # the scene each angle is read on
# The sheared layer's figures (kind shear3d), in runs.csv, and in points.csv once a study ran it.
SHEAR = ("shear_peak", "shear_steady", "shear_dilation", "slip_drop")
# Weinhart et al. (2012, Granular Matter 14, 531), their fit of h_stop for a base of fixed
# spheres of the flowing ones' size: h_stop = A d (tan d2 - tan theta) / (tan theta - tan d1).
WEINHART = {"A": 3.836, "delta1": 17.561, "delta2": 32.257}
VALIDATION_TOLERANCE = 0.7  # degrees (issue 39)
DEEP_LAYERS, DEEP = 36, 20  # the deep bed: lattice layers (granular3d.DEEP_LAYERS), depth in d
KEYS = ["kind", "engine", "group", "material", "mu_s", "mu_k", "nu_s", "timing", "rolling", "layers",
        "rate_factor", "silbert"]
STATISTICS = ("mean", "std", "se", "n")  # of each measured figure over a point's fills, in points.csv
MEASURED = ANGLES + ("depth_at_stop", "grains_per_area") + SHEAR  # what points.csv may hold statistics of


def point_columns():
    """Every column points.csv may have (points() writes a figure's columns only where a run
    measured it): the keys, the statistics of each measured figure, the fills."""
    return KEYS + [f"{a}_{k}" for a in MEASURED for k in STATISTICS] + ["fills"]


def weinhart_theta_stop(depth):
    """The angle (deg) at which Weinhart et al.'s fit puts h_stop = depth (in d)."""
    a, t1, t2 = WEINHART["A"], math.tan(math.radians(WEINHART["delta1"])), math.tan(math.radians(WEINHART["delta2"]))
    return math.degrees(math.atan((a * t2 + depth * t1) / (a + depth)))


def write_runs(finished, out, kept=None, order=None):
    """runs.csv (one row per finished run) from [(job, scene, data, folder)] and the rows
    `kept` of an earlier runs.csv (granular3d.committed_rows), in the labels' `order`."""
    rows = []
    for job, sc, _, folder in finished:
        s = json.loads((folder / "summary.json").read_text())
        area = math.prod(hi - lo for lo, hi in sc.periodic.values()) if job.kind == "incline" else math.nan
        rows.append({"label": job.label, "kind": job.kind, "engine": job.engine, "group": job.group,
                     "material": job.material, "mu_s": job.mu_s, "mu_k": job.mu_k, "nu_s": job.nu_s,
                     "timing": job.timing, "rolling": job.rolling, "layers": job.layers or 0,
                     "rate_factor": job.rate_factor, "silbert": job.silbert, "fill": job.fill,
                     "grains": len(sc.grains), "dt": sc.dt, "steps": s["steps"], "wall_time_s": s["wall_time_s"],
                     "theta_start": s.get("theta_start_deg", math.nan), "theta_stop": s.get("theta_stop_deg", math.nan),
                     "theta_heap": s.get("theta_heap_deg", math.nan), "depth_at_stop": s.get("depth_at_stop", math.nan),
                     # Silbert et al.'s measure of a bed's depth: flowing grains per d^2 of the base
                     "grains_per_area": len(sc.moving_grains()) / area,
                     "heap_flank_half_difference": s.get("flank_half_difference_deg", math.nan),
                     "heap_ekin_per_grain_mgd": s.get("heap_ekin_per_grain_mgd", math.nan),
                     # the validation at fixed angles (kind hold3d): the held angle, did the bed stop, when
                     "hold_angle": s.get("theta_hold_deg", math.nan),  # as run: within one interval's turn
                     "stopped": s.get("stopped", math.nan), "time_to_stop": s.get("time_to_stop_s", math.nan),
                     "speed_at_end": s.get("speed_at_end", math.nan), "speed_trend": s.get("speed_trend", math.nan),
                     **{k: s.get(k, math.nan) for k in SHEAR + ("shear_steady_sd", "slip_count")}})
        if job.kind == "hold" and s.get("stopped") == 1.0:
            rows[-1]["depth_at_stop"] = s["depth_at_end"]
    out.mkdir(parents=True, exist_ok=True)
    runs = pd.DataFrame(rows)
    if kept is not None and len(kept):
        runs = pd.concat([kept, runs], ignore_index=True)
    if order is not None:
        rank = {label: k for k, label in enumerate(order)}
        runs = runs.sort_values("label", key=lambda c: c.map(rank), kind="stable", ignore_index=True)
    runs.to_csv(out / "runs.csv", index=False)
    return runs


def points(runs):
    """One row per point of the study: the mean, std, se and n of every angle over fills
    (the runs at fixed angles are holds' rows, not points)."""
    runs = runs[runs.kind != "hold"].copy()
    for k in ("layers", "rate_factor", "silbert"):
        runs[k] = runs[k].fillna(0)
    rows = []
    measured = ANGLES + ("depth_at_stop", "grains_per_area") + tuple(
        k for k in SHEAR if k in runs and runs[k].notna().any())  # (the committed tables: none)
    for key, grp in runs.groupby(KEYS, sort=False, dropna=False):
        row = dict(zip(KEYS, key))
        for a in measured:
            v = grp[a].to_numpy(float)
            v = v[np.isfinite(v)]
            row[f"{a}_mean"] = float(v.mean()) if len(v) else math.nan
            row[f"{a}_std"] = float(v.std(ddof=1)) if len(v) > 1 else math.nan
            row[f"{a}_se"] = row[f"{a}_std"] / math.sqrt(len(v)) if len(v) > 1 else math.nan
            row[f"{a}_n"] = len(v)
        row["fills"] = len(grp)
        rows.append(row)
    columns = KEYS + [f"{a}_{k}" for a in measured for k in STATISTICS] + ["fills"]
    return pd.DataFrame(rows, columns=columns)  # the columns even when only held beds ran


# The 10 d bed's lattice layers (cases/incline3d.toml): a run on the scene's own bed has
# layers 0 in runs.csv and points.csv (granular3d.Job.layers None).
SCENE_LAYERS = 18


def bed_layers(layers):
    """A row's bed as lattice layers: 0 stands for the scene's own, SCENE_LAYERS."""
    return int(layers) or SCENE_LAYERS


def _sweep(pts, kind, rolling):
    return pts[(pts.kind == kind) & (pts.engine == "liggghts") & (pts.group == "sweep") & (pts["rolling"] == rolling)]


def history(sweep):
    """Stock history's points (mu_k = mu_s) of a sweep's points, by mu."""
    return sweep[sweep.mu_s == sweep.mu_k].sort_values("mu_s")


def curve(pts, angle, rolling, mu):
    """Stock history's (mean, se) of `angle` at `mu` (interpolated between measured mus)."""
    h = history(_sweep(pts, KIND[angle], rolling))
    m, e = h[f"{angle}_mean"].to_numpy(float), h[f"{angle}_se"].to_numpy(float)
    x = h["mu_s"].to_numpy(float)
    if not len(x) or not x.min() - 1e-9 <= mu <= x.max() + 1e-9:
        return math.nan, math.nan
    return float(np.interp(mu, x, m)), float(np.interp(mu, x, e))


def effective_mu(pts, angle, rolling, value):
    """The mu at which stock history's curve of `angle` reaches `value` (linear between the
    measured mus), or nan where the curve reaches it more than once (it levels off above mu ~
    0.5, where the fills' spread can make it dip) or not at all."""
    h = history(_sweep(pts, KIND[angle], rolling))
    y, x = h[f"{angle}_mean"].to_numpy(float), h["mu_s"].to_numpy(float)
    hits = [i for i in range(len(y) - 1) if min(y[i], y[i + 1]) <= value <= max(y[i], y[i + 1]) and y[i] != y[i + 1]]
    if len(hits) != 1:
        return math.nan
    i = hits[0]
    return float(x[i] + (value - y[i]) / (y[i + 1] - y[i]) * (x[i + 1] - x[i]))


def _z(a, sa, b, sb):
    s = math.sqrt(sa**2 + sb**2) if np.isfinite(sa) and np.isfinite(sb) else math.nan
    return (a - b) / s if s and np.isfinite(s) else math.nan


def predictions(pts):
    """Each prediction of issue 39 tested on each stick-slip point: the measured angle, the
    stock curve's at the predicted mu (and at mu_k, the naive reading), z of each, and the
    mu at which stock history gives the measured angle (effective_mu)."""
    rows = []
    ss = pts[(pts.engine == "liggghts") & (pts.group == "sweep") & (pts.mu_s != pts.mu_k)]
    tests = (("theta_stop", "2mu_k-mu_s"), ("theta_heap", "2mu_k-mu_s"), ("theta_start", "mu_s"))
    for _, p in ss.iterrows():
        for angle, predicted in tests:
            if p.kind != KIND[angle]:
                continue
            mu = 2 * p.mu_k - p.mu_s if predicted == "2mu_k-mu_s" else p.mu_s
            c, ce = curve(pts, angle, p["rolling"], mu)
            k, ke = curve(pts, angle, p["rolling"], p.mu_k)
            m, e = p[f"{angle}_mean"], p[f"{angle}_se"]
            rows.append({"angle": angle, "material": p.material, "mu_s": p.mu_s, "mu_k": p.mu_k, "nu_s": p.nu_s,
                         "timing": p.timing, "rolling": p["rolling"], "measured": m, "se": e, "predicted_at": predicted,
                         "mu_predicted": mu, "stock_at_predicted": c, "stock_se": ce, "z_predicted": _z(m, e, c, ce),
                         "stock_at_mu_k": k, "z_mu_k": _z(m, e, k, ke),
                         "mu_effective": effective_mu(pts, angle, p["rolling"], m)})
    return pd.DataFrame(rows)


def hysteresis(pts):
    """theta_start - theta_stop against mu_s - mu_k (history at 0), per rolling and variant:
    the weighted least-squares slope, its standard error and z = slope / se."""
    inc = pts[(pts.kind == "incline") & (pts.engine == "liggghts") & (pts.group == "sweep")]
    rows = []
    for rolling in sorted(inc["rolling"].unique()):
        for variant in (("paper", "step"), ("0", "exact")):
            sel = inc[(inc["rolling"] == rolling) & ((inc.mu_s == inc.mu_k) | ((inc.nu_s == variant[0]) &
                                                                          (inc.timing == variant[1])))]
            line = weighted_line((sel.mu_s - sel.mu_k).to_numpy(float),
                                 (sel.theta_start_mean - sel.theta_stop_mean).to_numpy(float),
                                 np.hypot(sel.theta_start_se, sel.theta_stop_se).to_numpy(float))
            if line is None:
                continue
            intercept, slope, slope_se, n = line
            rows.append({"rolling": rolling, "nu_s": variant[0], "timing": variant[1], "points": n,
                         "slope_deg_per_unit_mu": slope, "slope_se": slope_se, "z": slope / slope_se,
                         "intercept_deg": intercept})
    return pd.DataFrame(rows)


def weighted_line(x, y, e):
    """(intercept, slope, the slope's standard error, points used) of the weighted least-squares
    line through the points with finite y and e > 0 (weights 1 / e^2), or None with fewer than
    three of them or one value of x (a slope needs two)."""
    ok = np.isfinite(y) & np.isfinite(e) & (e > 0)
    if ok.sum() < 3 or len(np.unique(x[ok])) < 2:
        return None
    w = 1 / e[ok] ** 2
    a = np.column_stack([np.ones(ok.sum()), x[ok]])
    cov = np.linalg.inv(a.T @ (a * w[:, None]))
    coef = cov @ (a.T @ (w * y[ok]))
    return coef[0], coef[1], math.sqrt(cov[1, 1]), int(ok.sum())


def rolling_effect(pts):
    """Does rolling resistance shrink what the law changes? For each pair and variant, the
    difference from stock history at mu_s, d = X(pair) - stock(mu_s), without and with
    rolling resistance; z = (|d_0| - |d_r|) / combined se (> 0: shrinks)."""
    rows = []
    ss = pts[(pts.engine == "liggghts") & (pts.group == "sweep") & (pts.mu_s != pts.mu_k)]
    rolls = sorted(ss["rolling"].unique())
    if len(rolls) < 2:
        return pd.DataFrame(rows)
    for angle in ANGLES:
        for (mat, nu_s, timing), grp in ss[ss.kind == KIND[angle]].groupby(["material", "nu_s", "timing"]):
            d = {}
            for _, p in grp.iterrows():
                c, ce = curve(pts, angle, p["rolling"], p.mu_s)
                d[p["rolling"]] = (p[f"{angle}_mean"] - c, math.hypot(p[f"{angle}_se"], ce))
            if rolls[0] in d and rolls[-1] in d:
                (d0, e0), (d1, e1) = d[rolls[0]], d[rolls[-1]]
                rows.append({"angle": angle, "material": mat, "nu_s": nu_s, "timing": timing,
                             f"d_roll{rolls[0]:g}": d0, f"se_roll{rolls[0]:g}": e0,
                             f"d_roll{rolls[-1]:g}": d1, f"se_roll{rolls[-1]:g}": e1,
                             "z_shrinks": _z(abs(d0), e0, abs(d1), e1)})
    return pd.DataFrame(rows)


def stock_ramps(pts, layers, engine="liggghts"):
    """The points of the validation's ramps on a bed (layers; 0: the 10 d bed): stock history
    mu = 0.5, no rolling resistance, the scene's contact (not Silbert's), every rate."""
    return pts[(pts.kind == "incline") & (pts.engine == engine) & (pts.material == "history_0.50") &
               (pts["rolling"] == 0) & (pts.layers == layers) & (~pts.silbert.astype(bool))]


def ramp_lag(pts, layers=0):
    """How far the ramp's theta_stop lags its zero-rate limit on a bed of stock history
    (mu = 0.5, LIGGGHTS; layers 0: the 10 d bed) measured at the ramp's rates and at half of
    them: a lag linear in the rate, theta(r) = theta_0 - c r, gives theta_0 - theta(1) =
    2 (theta(1/2) - theta(1)). (lag, se), or (nan, nan) where the half-rate runs are not on
    disk."""
    inc = stock_ramps(pts, layers)
    full, half = inc[inc.rate_factor == 1], inc[inc.rate_factor == 0.5]
    if not len(full) or not len(half):
        return math.nan, math.nan
    f, h = full.iloc[0], half.iloc[0]
    return (2 * (h.theta_stop_mean - f.theta_stop_mean),
            2 * math.hypot(h.theta_stop_se, f.theta_stop_se))


# The held angles are at most 0.5 deg apart: a fill's theta_stop is the middle of the step
# between the highest angle at which its bed stopped and the lowest at which it still flowed,
# within half the step. The fills share the grid, so the grid's error does not average out
# over fills: it is added to their standard error as a uniform spread's, step / sqrt(12).
HOLD_STEP = 0.5


def holds(runs):
    """theta_stop at fixed angles, one row per engine, bed (lattice layers) and fill: the highest held
    angle at which the bed stopped, the lowest at which it still flowed, their middle
    (theta_stop), whether every stop lies below every flow (ordered), the bed's depth at its
    stops and the longest time a stop took (against the hold's length: a bed slower to stop
    than the hold counts as flowing, so the beds that flowed to the end say whether they were
    still slowing down: hold3d's speed_trend)."""
    rows = []
    h = runs[runs.kind == "hold"]
    for (engine, layers, fill), grp in h.groupby(["engine", "layers", "fill"]):
        stopped, flowing = grp[grp.stopped == 1], grp[grp.stopped == 0]
        lo = float(stopped.hold_angle.max()) if len(stopped) else math.nan
        hi = float(flowing.hold_angle.min()) if len(flowing) else math.nan
        ordered = bool(np.isfinite(lo) and np.isfinite(hi) and lo < hi)
        rows.append({"engine": engine, "layers": bed_layers(layers), "fill": int(fill), "angles": len(grp),
                     "highest_stopped": lo, "lowest_flowing": hi, "ordered": ordered,
                     "theta_stop": (lo + hi) / 2 if ordered and hi - lo < 1.5 * HOLD_STEP else math.nan,  # next angles
                     "depth_d": float(stopped.depth_at_stop.mean()) if len(stopped) else math.nan,
                     "longest_stop": float(stopped.time_to_stop.max()) if len(stopped) else math.nan,
                     # the flowing beds' least speed_trend: near 1, none was still slowing down
                     "flowing_least_trend": float(flowing.speed_trend.min()) if len(flowing) else math.nan})
    return pd.DataFrame(rows, columns=HOLD_COLUMNS)  # the columns even when no bed was held


HOLD_COLUMNS = ["engine", "layers", "fill", "angles", "highest_stopped", "lowest_flowing", "ordered", "theta_stop",
                "depth_d", "longest_stop", "flowing_least_trend"]


def fixed_angle(hold_rows, layers, engine="liggghts"):
    """(theta_stop, se, fills, depth) at fixed angles for a bed on an engine: the mean over its
    fills, se their spread's with the grid's step / sqrt(12) added (the fills' mean step,
    HOLD_STEP); nans when not run."""
    if hold_rows is None or not len(hold_rows):
        return math.nan, math.nan, 0, math.nan
    sel = hold_rows[(hold_rows.engine == engine) & (hold_rows.layers == layers) & np.isfinite(hold_rows.theta_stop)]
    v = sel.theta_stop.to_numpy(float)
    if not len(v):
        return math.nan, math.nan, 0, math.nan
    spread = v.std(ddof=1) / math.sqrt(len(v)) if len(v) > 1 else math.nan
    step = float((sel.lowest_flowing - sel.highest_stopped).mean())
    return float(v.mean()), math.hypot(spread, step / math.sqrt(12)), len(v), float(sel.depth_d.mean())


def validation(pts, hold_rows=None):
    """theta_stop of stock history mu = 0.5, no rolling resistance, at both depths and on
    both engines, against Weinhart et al.'s fit at the measured depth, as measured at the
    ramp's rates and at zero rate (the lag measured at that depth on LIGGGHTS added:
    ramp_lag; Weinhart et al. ran at fixed angles), and at fixed angles (holds: LIGGGHTS,
    the lag it shows, theta_fixed - theta_ramp, taken by LAMMPS, which runs the same scene at
    the same rates, as it takes the zero-rate lag)."""
    rows = []
    h = pts[(pts.kind == "incline") & (pts.material == "history_0.50") & (pts["rolling"] == 0) &
            (pts.rate_factor == 1) & (~pts.silbert.astype(bool)) & pts.group.isin(["sweep", "validation"])]
    for _, p in h.iterrows():
        lag, lag_se = ramp_lag(pts, p.layers)
        w = weinhart_theta_stop(p.depth_at_stop_mean)
        wn = weinhart_theta_stop(p.grains_per_area_mean)
        zero, zero_se = p.theta_stop_mean + lag, math.hypot(p.theta_stop_se, lag_se)
        rows.append({"engine": p.engine, "layers": bed_layers(p.layers), "depth_d": p.depth_at_stop_mean,
                     "theta_stop": p.theta_stop_mean, "std": p.theta_stop_std, "se": p.theta_stop_se,
                     "fills": p.fills, "weinhart_at_depth": w, "difference": p.theta_stop_mean - w,
                     "z": _z(p.theta_stop_mean, p.theta_stop_se, w, 0.0),
                     "within_0.7": abs(p.theta_stop_mean - w) <= VALIDATION_TOLERANCE,
                     "ramp_lag": lag, "ramp_lag_se": lag_se, "theta_stop_zero_rate": zero, "se_zero_rate": zero_se,
                     "difference_zero_rate": zero - w, "z_zero_rate": _z(zero, zero_se, w, 0.0),
                     "within_0.7_zero_rate": abs(zero - w) <= VALIDATION_TOLERANCE,
                     "grains_per_area": p.grains_per_area_mean, "weinhart_at_grains_per_area": wn,
                     "difference_grains_per_area": p.theta_stop_mean - wn,
                     "within_0.7_grains_per_area": abs(p.theta_stop_mean - wn) <= VALIDATION_TOLERANCE})
        rows[-1].update(_fixed_columns(pts, hold_rows, p))
    # a bed an engine held at fixed angles and did not ramp (LAMMPS' 20 d bed): its own row
    ramped = {(r["engine"], r["layers"]) for r in rows}
    for engine, layers in ([] if hold_rows is None else
                           sorted(set(zip(hold_rows.engine, hold_rows.layers)) - ramped)):
        fixed, fixed_se, n, depth = fixed_angle(hold_rows, layers, engine)
        rows.append({"engine": engine, "layers": int(layers), "fixed_fills": n,
                     **_fixed_against_weinhart(fixed, fixed_se, depth)})
    return pd.DataFrame(rows)


def _fixed_against_weinhart(fixed, fixed_se, depth):
    """theta_stop at fixed angles (its se, the bed's depth) against Weinhart et al.'s fit there."""
    w = weinhart_theta_stop(depth) if np.isfinite(depth) else math.nan
    return {"fixed_depth_d": depth, "theta_stop_fixed": fixed, "se_fixed": fixed_se, "weinhart_at_fixed_depth": w,
            "difference_fixed": fixed - w, "z_fixed": _z(fixed, fixed_se, w, 0.0),
            "within_0.7_fixed": bool(abs(fixed - w) <= VALIDATION_TOLERANCE)}


def _fixed_columns(pts, hold_rows, p):
    """The validation's columns at fixed angles for point p (a ramp's row): the engine's own
    holds and the lag they show (fixed - ramp); an engine that held no bed there (but LIGGGHTS
    did) takes its ramp plus LIGGGHTS' lag on that bed."""
    layers = bed_layers(p.layers)
    fixed, fixed_se, n, depth = fixed_angle(hold_rows, layers, p.engine)
    if n or p.engine == "liggghts":
        lag, lag_se = fixed - p.theta_stop_mean, math.hypot(fixed_se, p.theta_stop_se)
    else:
        lig_fixed, lig_se, _, _ = fixed_angle(hold_rows, layers)
        ramp = stock_ramps(pts, p.layers)
        ramp = ramp[ramp.rate_factor == 1]
        lag, lag_se = ((lig_fixed - ramp.iloc[0].theta_stop_mean, math.hypot(lig_se, ramp.iloc[0].theta_stop_se))
                       if len(ramp) else (math.nan, math.nan))
        fixed, fixed_se, depth = p.theta_stop_mean + lag, math.hypot(p.theta_stop_se, lag_se), p.depth_at_stop_mean
    return {"fixed_fills": n, "fixed_depth_d": depth, "fixed_lag": lag, "fixed_lag_se": lag_se,  # the columns' order
            **_fixed_against_weinhart(fixed, fixed_se, depth)}


def checks(pts):
    """The set-up's checks against the stock run they vary: half rates (10 d and 20 d beds),
    Silbert's kn."""
    rows = []
    every = pts[(pts.kind == "incline") & (pts.engine == "liggghts") & (pts.material == "history_0.50") &
                (pts["rolling"] == 0)]
    for what, layers, check in (("rates halved", 0, "rate"), ("Silbert's kn = 2e5, dt = 1e-4", 0, "silbert"),
                                (f"rates halved, {DEEP} d bed", DEEP_LAYERS, "rate")):
        inc = every[every.layers == layers]
        ref = inc[(inc.rate_factor == 1) & (~inc.silbert.astype(bool))]
        sel = inc.rate_factor == 0.5 if check == "rate" else inc.silbert.astype(bool)
        if not len(ref):
            continue
        ref = ref.iloc[0]
        for _, p in inc[sel].iterrows():
            for a in ("theta_stop", "theta_start"):
                rows.append({"check": what, "angle": a, "reference": ref[f"{a}_mean"], "reference_se": ref[f"{a}_se"],
                             "checked": p[f"{a}_mean"], "checked_se": p[f"{a}_se"],
                             "difference": p[f"{a}_mean"] - ref[f"{a}_mean"],
                             "z": _z(p[f"{a}_mean"], p[f"{a}_se"], ref[f"{a}_mean"], ref[f"{a}_se"])})
    return pd.DataFrame(rows)


def engines(pts):
    """LAMMPS against LIGGGHTS on the points both ran: difference and z."""
    rows = []
    lam = pts[pts.engine == "lammps"]
    lig = pts[pts.engine == "liggghts"]
    for _, p in lam.iterrows():
        q = lig[(lig.kind == p.kind) & (lig.material == p.material) & (lig.nu_s == p.nu_s) & (lig.timing == p.timing)
                & (lig["rolling"] == p["rolling"]) & (lig.layers == p.layers) & (lig.rate_factor == 1)
                & (~lig.silbert.astype(bool))]
        if not len(q):
            continue
        q = q.iloc[0]
        for a in ("theta_stop", "theta_start"):
            rows.append({"material": p.material, "nu_s": p.nu_s, "layers": bed_layers(p.layers), "angle": a,
                         "liggghts": q[f"{a}_mean"], "liggghts_std": q[f"{a}_std"], "lammps": p[f"{a}_mean"],
                         "lammps_std": p[f"{a}_std"], "difference": p[f"{a}_mean"] - q[f"{a}_mean"],
                         "z": _z(p[f"{a}_mean"], p[f"{a}_se"], q[f"{a}_mean"], q[f"{a}_se"])})
    return pd.DataFrame(rows)


def cost(runs):
    """CPU seconds per grain-step of each engine and kind, measured on the study's runs
    (the engine's own loop time; 2 runs at once on the 2-core machine)."""
    rows = []
    for (engine, kind), grp in runs.groupby(["engine", "kind"]):
        gs = (grp.grains * grp.steps).to_numpy(float)
        rows.append({"engine": engine, "kind": kind, "runs": len(grp), "wall_s_total": grp.wall_time_s.sum(),
                     "seconds_per_grain_step": grp.wall_time_s.sum() / gs.sum(),
                     "mean_simulated_time": float((grp.steps * grp.dt).mean())})
    return pd.DataFrame(rows)


TABLES = {"points.csv": points}


def write_tables(out):
    """Every table from out/runs.csv: {file name: DataFrame}, written beside it."""
    out = Path(out)
    runs = pd.read_csv(out / "runs.csv")
    pts = points(runs)
    hold_rows = holds(runs) if "hold_angle" in runs else None
    tables = {"points.csv": pts, "predictions.csv": predictions(pts), "hysteresis.csv": hysteresis(pts),
              "rolling.csv": rolling_effect(pts), "validation.csv": validation(pts, hold_rows),
              "checks.csv": checks(pts),
              "engines.csv": engines(pts), "cost.csv": cost(runs)}
    if hold_rows is not None:
        tables["holds.csv"] = hold_rows
    for name, t in tables.items():
        t.to_csv(out / name, index=False)
    return tables


def _md(df, cols, fmt=".2f"):
    cols = [c for c in cols if df is not None and c in df]  # a partial study has fewer
    if df is None or not len(df) or not cols:
        return "(none measured yet)\n"
    head = "| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n"
    body = ""
    for _, r in df.iterrows():
        cells = []
        for c in cols:
            v = r[c]
            cells.append(f"{v:{fmt}}" if isinstance(v, (float, np.floating)) and np.isfinite(v) else
                         "—" if isinstance(v, (float, np.floating)) else str(v))
        body += "| " + " | ".join(cells) + " |\n"
    return head + body


def summary(t, figs):
    pts = t["points.csv"]
    lines = ["# Granular scale in 3D: the study's tables", "",
             "Written by `stickslip study-3d` (stickslip/studies/granular3d.py, granular3d_tables.py) from "
             "[runs.csv](runs.csv); the findings: [../granular-3d.md](../granular-3d.md). Angles in degrees, "
             "means over fills ± their standard error (std/√n); z = difference / combined standard error.", "",
             "## Points", ""]
    view = pts.copy()
    for a in ANGLES:
        view[a] = [f"{m:.2f} ± {e:.2f}" if np.isfinite(m) and np.isfinite(e)
                   else (f"{m:.2f}" if np.isfinite(m) else "—") for m, e in zip(view[f"{a}_mean"], view[f"{a}_se"])]
    lines.append(_md(view, ["kind", "engine", "group", "material", "nu_s", "timing", "rolling", "layers",
                            "rate_factor", "silbert", "fills", "theta_start", "theta_stop", "theta_heap"]))
    lines += ["## Validation (stock history, μ = 0.5, no rolling resistance) against Weinhart et al. 2012", "",
              _md(t["validation.csv"], ["engine", "layers", "depth_d", "theta_stop", "std", "fills",
                                        "weinhart_at_depth", "difference", "z", "within_0.7", "ramp_lag",
                                        "theta_stop_zero_rate", "difference_zero_rate", "z_zero_rate",
                                        "within_0.7_zero_rate", "grains_per_area", "difference_grains_per_area"]),
              "### At fixed angles (a flowing bed held at each angle: did it stop?)", "",
              _md(t["validation.csv"], ["engine", "layers", "fixed_fills", "fixed_depth_d", "theta_stop_fixed",
                                        "se_fixed", "weinhart_at_fixed_depth", "difference_fixed", "z_fixed",
                                        "within_0.7_fixed", "fixed_lag", "fixed_lag_se"]
                  if "theta_stop_fixed" in t["validation.csv"] else ["engine"]),
              _md(t.get("holds.csv"), HOLD_COLUMNS),
              "## Checks of the set-up", "",
              _md(t["checks.csv"], ["check", "angle", "reference", "checked", "difference", "z"]),
              "## Predictions", "",
              _md(t["predictions.csv"], ["angle", "material", "nu_s", "timing", "rolling", "measured", "se",
                                         "predicted_at", "mu_predicted", "stock_at_predicted", "z_predicted",
                                         "stock_at_mu_k", "z_mu_k", "mu_effective"]),
              "## Hysteresis θ_start − θ_stop against μs − μk", "",
              _md(t["hysteresis.csv"], ["rolling", "nu_s", "timing", "points", "slope_deg_per_unit_mu", "slope_se",
                                        "z"]),
              "## Rolling resistance and the law's effect (d = angle − stock at μs)", "",
              _md(t["rolling.csv"], list(t["rolling.csv"].columns) if len(t["rolling.csv"]) else ["angle"]),
              "## LAMMPS against LIGGGHTS", "",
              _md(t["engines.csv"], ["material", "nu_s", "layers", "angle", "liggghts", "liggghts_std", "lammps",
                                     "lammps_std", "difference", "z"]),
              "## Cost", "",
              _md(t["cost.csv"], ["engine", "kind", "runs", "wall_s_total", "seconds_per_grain_step",
                                  "mean_simulated_time"], ".3g"),
              ""] + [f"![{f}]({f})" for f in figs] + [""]
    return "\n".join(lines)
