# SPDX-License-Identifier: GPL-2.0-or-later
"""How far `stickslip calibrate` holds, measured on the study's own runs (docs/granular-3d.md,
"When the map holds"): written by `stickslip study-3d` beside its other tables.

- loo.csv: the map's leave-one-out, each point predicted from the others by each interpolation
  (calibrate_map.loo), per rolling resistance, and interpolation.csv: each method's score and
  which one calibrate takes (calibrate_map.choose);
- coverage.csv: the round trip. Each pair of granular3d.COVERAGE_PAIRS (not map points, run on
  fills the map never used) gives its mean angles and their standard errors over its fills (n
  fills: n - 1 degrees of freedom), as a user's measurement; calibrate answers from the map
  (no leave-out needed: the pairs are not map points) and the row says whether the stated
  ranges hold the true mu_s, mu_k, and whether the true pair lies in the joint 68 % region.
  theta_stop is the ramp's on both sides: the lag to a fixed angle, common to both, cancels and
  is left out. One row per pair and set of targets (TARGET_SETS: the incline's two angles,
  with the heap's, with the sheared layer's peak and steady tau/sigma and dilation);
- leave_pair_out.csv: the map answering its own points. Each point of the map (a pair with its
  incline, heap and sheared-layer measurements), left out in turn, is answered by the map less
  that point, its means and standard errors over its fills taken as a user's; the row keeps, for
  each coefficient, the profiled delta chi2 at the true value over the range's threshold (<= 1:
  the range holds it) and whether an edge cuts the range. calibrate_map.widening makes of it
  the factor calibrate widens its ranges by. Leaving a point out doubles the map's spacing
  around it, so the factor is if anything too large; the round trip checks it;
- coverage_summary.csv: per set of targets, how many ranges held the truth, against 68.27 %
  and its binomial spread sqrt(p (1 - p) / n), z = (held - n p) / sqrt(n p (1 - p)); ranges cut
  by the map's edge or the law's bound (bounds, not standard errors) apart from those that are
  not; before and after the widening (coverage.csv's rows, one per pair, set of targets and
  widening); and how many answers lie on the map's edge or on a law's bound (answer_edge).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..errors import SceneError
from . import calibrate, calibrate_fit, calibrate_map

TARGET_SETS = (("theta_start", "theta_stop"), ("theta_start", "theta_stop", "theta_heap"),
               ("theta_start", "theta_stop", "shear_peak", "shear_steady", "shear_dilation"))
P = calibrate_fit.COVER
COLUMNS = ["targets", "widening", "mu_s", "mu_k", "fills", "theta_start", "theta_start_se", "theta_stop",
           "theta_stop_se", "theta_heap", "theta_heap_se", "shear_peak", "shear_peak_se", "shear_steady",
           "shear_steady_se", "shear_dilation", "shear_dilation_se", "answer_mu_s", "mu_s_lo", "mu_s_hi", "answer_mu_k", "mu_k_lo", "mu_k_hi",
           "mu_s_held", "mu_k_held", "mu_s_cut", "mu_k_cut", "answer_edge", "delta_chi2_true", "joint_held", "chi2",
           "interpolation", "refused"]


def loo_table(pts):
    """(loo rows with their rolling resistance, one row per rolling and method: score, points,
    the interpolation's own error per target and whether calibrate takes it)."""
    rows, choice = [], []
    sweep = pts[(pts.engine == "liggghts") & (pts.group == "sweep")]
    for rolling in sorted(sweep["rolling"].unique()):
        r = calibrate_map.loo(calibrate_map.from_points(pts, rolling)).assign(rolling=rolling)
        rows.append(r)
        chosen, err = calibrate_map.choose(r), calibrate_map.interp_error(r)
        for method, (score, n) in calibrate_map.scores(r).items():
            choice.append({"rolling": rolling, "method": method, "score": score, "common_points": n,
                           "chosen": method == chosen,
                           **{f"{t}_interp_error": err.get((t, method), (math.nan, 0))[0] for t in r.target.unique()}})
    return (pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(), pd.DataFrame(choice))


def measured(cov):
    """{(mu_s, mu_k): ({target: Target}, fills)} of the points of `cov` (incline, heap, shear rows):
    the round trip's pairs, or the map's own (leave_pair_out); fills 0 where not known."""
    out = {}
    for (mu_s, mu_k), grp in cov.groupby(["mu_s", "mu_k"]):
        t = {}
        for target, kind in calibrate_map.KIND.items():
            row = grp[grp.kind == kind]
            if f"{target}_mean" in row and len(row) and np.isfinite(row[f"{target}_mean"].iloc[0]):
                r = row.iloc[0]
                n = int(r[f"{target}_n"]) if f"{target}_n" in r and np.isfinite(r[f"{target}_n"]) else None
                t[target] = calibrate_fit.Target(float(r[f"{target}_mean"]), float(r[f"{target}_se"]), n)
        fills = grp.fills.max() if "fills" in grp else math.nan
        out[float(mu_s), float(mu_k)] = (t, int(fills) if np.isfinite(fills) else 0)
    return out


def _cuts(r, name):
    return " ".join(f"{e}: {' and '.join(w)}" for (n, e), w in r.cut.items() if n == name)


def coverage(pts, method="auto", surf=None, widenings=(1.0,)):
    """coverage.csv's rows: the coverage pairs of pts calibrated on its sweep (rolling 0), with
    the ranges widened by each of `widenings`."""
    cov = pts[(pts.group == "coverage") & (pts.engine == "liggghts")]
    if not len(cov):
        return pd.DataFrame(columns=COLUMNS)
    surf = surf or calibrate.prepare(pts, 0.0, method)[0]
    rows = []
    for widen in widenings:
        for (mu_s, mu_k), (got, fills) in measured(cov).items():
            for names in TARGET_SETS:
                row = {"targets": "+".join(names), "widening": widen, "mu_s": mu_s, "mu_k": mu_k, "fills": fills,
                       "interpolation": surf.method}
                for a, t in got.items():
                    row[a], row[f"{a}_se"] = t.value, t.se
                if not set(names) <= set(got):
                    continue
                try:
                    r = calibrate_fit.solve({a: got[a] for a in names}, surf, widen)
                except SceneError as e:
                    rows.append({**row, "refused": str(e)})
                    continue
                (s0, s1), (k0, k1) = r.ranges["mu_s"], r.ranges["mu_k"]
                tol = calibrate_fit.GRID / 2
                delta = r.delta_at(mu_s, mu_k)
                rows.append({**row, "answer_mu_s": r.mu_s, "mu_s_lo": s0, "mu_s_hi": s1, "answer_mu_k": r.mu_k,
                             "mu_k_lo": k0, "mu_k_hi": k1, "mu_s_held": s0 - tol <= mu_s <= s1 + tol,
                             "mu_k_held": k0 - tol <= mu_k <= k1 + tol, "mu_s_cut": _cuts(r, "mu_s"),
                             "mu_k_cut": _cuts(r, "mu_k"), "answer_edge": "; ".join(r.edge),
                             "delta_chi2_true": delta, "joint_held": delta <= r.delta["joint"], "chi2": r.chi2,
                             "refused": ""})
    return pd.DataFrame(rows, columns=COLUMNS)


LPO_COLUMNS = ["rolling", "targets", "mu_s", "mu_k", "fills", "answer_mu_s", "mu_s_lo", "mu_s_hi", "answer_mu_k",
               "mu_k_lo", "mu_k_hi", "mu_s_ratio", "mu_k_ratio", "mu_s_cut", "mu_k_cut", "answer_edge", "refused"]


def leave_pair_out(pts, rolling):
    """leave_pair_out.csv's rows at one rolling resistance: each point of the map left out and
    answered by the rest, with the interpolation calibrate takes on the whole map and its own
    error (theta_stop as the ramp measured it on both sides, as in the round trip)."""
    m = calibrate_map.from_points(pts, rolling)
    loo = calibrate_map.loo(m)
    method, err = calibrate_map.choose(loo), calibrate_map.interp_error(loo)
    interp = {t: err.get((t, method), (0.0, 0))[0] for t in m}
    on = calibrate_fit.grid(m)
    full = {t: calibrate_map.weights(method, p, on[2]) for t, p in m.items()}
    rows = []
    for (mu_s, mu_k), (got, fills) in measured(calibrate_map.map_rows(pts, rolling)).items():
        weights = {}
        for t, p in m.items():
            i = np.flatnonzero(np.isclose(p.xy, (mu_s, mu_k)).all(axis=1))
            weights[t] = calibrate_map.without(method, p, on[2], full[t], i[0]) if len(i) else (full[t], p)
        surf = calibrate_fit.surfaces(m, method, interp, weights=weights, on=on)
        for names in TARGET_SETS:
            if not set(names) <= set(got):
                continue
            row = {"rolling": rolling, "targets": "+".join(names), "mu_s": mu_s, "mu_k": mu_k, "fills": fills}
            try:
                r = calibrate_fit.solve({a: got[a] for a in names}, surf)
            except SceneError as e:
                rows.append({**row, "refused": str(e)})
                continue
            rows.append({**row, "answer_mu_s": r.mu_s, "mu_s_lo": r.ranges["mu_s"][0], "mu_s_hi": r.ranges["mu_s"][1],
                         "answer_mu_k": r.mu_k, "mu_k_lo": r.ranges["mu_k"][0], "mu_k_hi": r.ranges["mu_k"][1],
                         **{f"{c}_ratio": r.profile_at(c, v) / r.delta[c] for c, v in (("mu_s", mu_s), ("mu_k", mu_k))},
                         "mu_s_cut": _cuts(r, "mu_s"), "mu_k_cut": _cuts(r, "mu_k"), "answer_edge": "; ".join(r.edge),
                         "refused": ""})
    return pd.DataFrame(rows, columns=LPO_COLUMNS)


def summary(cov):
    """Per set of targets, widening and statement (mu_s's range, mu_k's, the joint region): how
    many held the truth of how many, against P and its binomial spread; ranges cut by an edge
    and uncut ones apart."""
    rows = []
    for (targets, widen), g in cov.groupby(["targets", "widening"], sort=False):
        answered = g[calibrate_map.blank(g.refused)]
        edges = answered.answer_edge.astype(object).fillna("").astype(str)
        for what, held, cut in (("mu_s range", "mu_s_held", "mu_s_cut"), ("mu_k range", "mu_k_held", "mu_k_cut"),
                                ("joint region", "joint_held", None)):
            uncut = calibrate_map.blank(answered[cut]) if cut else pd.Series(True, index=answered.index)
            for which, sel in (("all", answered), ("cut", answered[~uncut]), ("uncut", answered[uncut])):
                if which == "cut" and not cut:
                    continue
                n = len(sel)
                k = int(sel[held].astype(bool).sum()) if n else 0
                sd = math.sqrt(P * (1 - P) / n) if n else math.nan
                rows.append({"targets": targets, "widening": widen, "statement": what, "ranges": which, "pairs": n,
                             "held": k, "share": k / n if n else math.nan, "expected": P, "binomial_sd": sd,
                             "z": (k / n - P) / sd if n else math.nan, "refused": len(g) - len(answered),
                             "answers_on_map_edge": int(edges.str.contains("map").sum()),
                             "answers_on_law_bound": int(edges.str.contains("mu_k").sum())})
    return pd.DataFrame(rows)


def write(out, pts):
    """loo.csv, interpolation.csv, leave_pair_out.csv and, when the study ran coverage pairs,
    coverage.csv and coverage_summary.csv (before and after the widening); returns {name:
    DataFrame}."""
    tables = {}
    if ((pts.group == "sweep") & (pts.engine == "liggghts")).any():
        tables["loo.csv"], tables["interpolation.csv"] = loo_table(pts)
        rolls = sorted(pts[(pts.group == "sweep") & (pts.engine == "liggghts")]["rolling"].unique())
        tables["leave_pair_out.csv"] = pd.concat([leave_pair_out(pts, r) for r in rolls], ignore_index=True)
    if (pts.group == "coverage").any():
        f = calibrate_map.widening(tables["leave_pair_out.csv"], 0.0)[0] if "leave_pair_out.csv" in tables else 1.0
        cov = coverage(pts, widenings=sorted({1.0, f}))
        tables["coverage.csv"], tables["coverage_summary.csv"] = cov, summary(cov)
    for name, t in tables.items():
        t.to_csv(out / name, index=False)
    return tables


def markdown(tables):
    """summary.md's sections of these tables (none when the study has not made them)."""
    from .granular3d_tables import _md

    lines = []
    if "interpolation.csv" in tables:
        t = tables["interpolation.csv"]
        lines += ["## The map's interpolation, chosen by leave-one-out", "",
                  "Each map point predicted from the others ([loo.csv](loo.csv)); score: mean (residual / se)² over the "
                  "points both interpolations predict; the interpolation's own error: the residuals' part that the "
                  "stated errors do not explain, which calibrate adds.", "",
                  _md(t, list(t.columns), ".3g")]
    if "leave_pair_out.csv" in tables:
        lpo = tables["leave_pair_out.csv"]
        f = {r: calibrate_map.widening(lpo, r) for r in sorted(lpo["rolling"].unique())}
        lines += ["## The ranges' widening, by leaving each map point out", "",
                  "Each map point answered by the others ([leave_pair_out.csv](leave_pair_out.csv)); ratio: the "
                  "profiled Δχ² at the true value over the range's threshold (≤ 1: held). The widening f makes "
                  "68.27 % of the uncut ranges hold: " + "; ".join(f"rolling {r:g}: f = {v:.3f} from {n} ranges"
                                                   for r, (v, n) in f.items()) + ".", "",
                  _md(lpo, ["rolling", "targets", "mu_s", "mu_k", "answer_mu_s", "mu_s_lo", "mu_s_hi", "answer_mu_k",
                            "mu_k_lo", "mu_k_hi", "mu_s_ratio", "mu_k_ratio", "mu_s_cut", "mu_k_cut", "answer_edge"],
                      ".3f")]
    if "coverage_summary.csv" in tables:
        lines += ["## Calibrate's round trip: how often its ranges hold the truth", "",
                  f"Pairs off the map, on fills it never used ([coverage.csv](coverage.csv)); expected {P:.1%} ± the "
                  "binomial spread; ranges cut by an edge and uncut ones apart, as stated (widening 1) and "
                  "widened.", "",
                  _md(tables["coverage_summary.csv"], ["targets", "widening", "statement", "ranges", "pairs", "held",
                                                       "share", "expected", "binomial_sd", "z", "refused",
                                                       "answers_on_map_edge", "answers_on_law_bound"]),
                  _md(tables["coverage.csv"], ["targets", "widening", "mu_s", "mu_k", "answer_mu_s", "mu_s_lo",
                                               "mu_s_hi", "answer_mu_k", "mu_k_lo", "mu_k_hi", "mu_s_held", "mu_k_held",
                                               "delta_chi2_true", "joint_held", "mu_s_cut", "mu_k_cut", "answer_edge"],
                      ".3f")]
    return "\n".join(lines)
