"""`stickslip calibrate`: mu_s and mu_k for the angles a user measured on their material,
from the map `stickslip study-3d` measured (docs/granular-3d/points.csv; docs/granular-3d.md).

The map: at each measured (mu_s, mu_k) of the sweep (stock history on the diagonal, the
stick-slip pairs below it; LIGGGHTS, the chosen rolling resistance and nu_s variant), the
mean and standard error over fills of theta_start, theta_stop (incline) and theta_heap
(heap). Between the points each angle is interpolated linearly on their triangulation (so
the map reaches exactly the convex hull of the measured points, no further). Given two or
three target angles, every (mu_s, mu_k) of a fine grid over that hull gets
chi2 = sum ((angle(mu_s, mu_k) - target) / se(mu_s, mu_k))^2, se interpolated alike; the
answer is the grid point of least chi2, its uncertainty the extent of the region where
chi2 <= min + 1 (one standard error, the map's spread over fills). A target outside the
angles the map reaches, or targets no point of the map gives together within 3 standard
errors, is refused in one line naming what is reachable (exit status 2).

theta_stop is taken at a fixed angle: the study's ramp measures it while the angle falls,
and the flow's lag puts it below the angle at which a flow held at a fixed angle stops (the
angle a user's experiment gives). The lag measured on stock history mu = 0.5, 10 d bed, is
added to every point's theta_stop, its standard error to theirs: from beds held at fixed
angles (validation.csv beside the map: fixed_lag, granular3d_tables.holds), else from the
ramp at half its rates (granular3d_tables.ramp_lag, a lag linear in the rate), else none.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import SceneError
from . import granular3d_tables

DOCS = Path(__file__).resolve().parents[2] / "docs" / "granular-3d"
ANGLES = granular3d_tables.ANGLES
OPTION = {"theta_start": "--theta-start", "theta_stop": "--theta-stop", "theta_heap": "--theta-heap"}
GRID = 0.0025  # grid step in mu
JOINT_LIMIT = 9.0  # chi2 above which targets are not reachable together (3 standard errors)


def load_map(path, rolling, nu_s="paper"):
    """({angle: (points (n, 2), means, ses)}, (lag, its se, "fixed" | "ramp" | None)): the
    sweep at this rolling resistance, history (mu_s = mu_k) and the stick-slip pairs with the
    chosen nu_s in the step mode, theta_stop with the ramp's lag added (the module's docstring)."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(f"--map {path}: not found (stickslip study-3d writes it)")
    pts = pd.read_csv(path, dtype={"nu_s": str})
    lag, lag_se = (granular3d_tables.ramp_lag(pts) if {"material", "layers", "rate_factor", "silbert"} <= set(pts)
                   else (math.nan, math.nan))
    how = "ramp" if math.isfinite(lag) else None
    val = path.with_name("validation.csv")
    if val.is_file():  # the lag to beds held at fixed angles: measured, not extrapolated
        v = pd.read_csv(val)
        if "fixed_lag" in v:
            v = v[(v.engine == "liggghts") & (v.layers == granular3d_tables.SCENE_LAYERS)]
            if len(v) and math.isfinite(v.fixed_lag.iloc[0]):
                lag, lag_se, how = float(v.fixed_lag.iloc[0]), float(v.fixed_lag_se.iloc[0]), "fixed"
    pts = pts[(pts["engine"] == "liggghts") & (pts["group"] == "sweep")]
    rolls = sorted(pts["rolling"].unique())
    if not any(math.isclose(rolling, r, abs_tol=1e-9) for r in rolls):
        raise SceneError(f"--rolling {rolling:g}: the map was measured at rolling resistance "
                         f"{' and '.join(f'{r:g}' for r in rolls)} only")
    pts = pts[np.isclose(pts["rolling"], rolling)]
    pts = pts[(pts.mu_s == pts.mu_k) | ((pts.nu_s == nu_s) & (pts.timing == "step"))]
    out = {}
    for angle in ANGLES:
        p = pts[(pts.kind == granular3d_tables.KIND[angle]) & np.isfinite(pts[f"{angle}_mean"])]
        mean, se = p[f"{angle}_mean"].to_numpy(float), p[f"{angle}_se"].fillna(0.0).to_numpy(float)
        if angle == "theta_stop" and np.isfinite(lag):
            mean, se = mean + lag, np.hypot(se, lag_se)
        out[angle] = (p[["mu_s", "mu_k"]].to_numpy(float), mean, se)
    return out, (lag, lag_se, how)


def surfaces(m):
    """The grid over the measured hull and each angle's (mean, se) on it (NaN outside)."""
    from scipy.interpolate import LinearNDInterpolator

    xy = np.vstack([v[0] for v in m.values() if len(v[0])])
    g = np.arange(xy[:, 0].min(), xy[:, 0].max() + GRID / 2, GRID)
    ms, mk = np.meshgrid(g, np.arange(xy[:, 1].min(), xy[:, 1].max() + GRID / 2, GRID), indexing="ij")
    grid = np.column_stack([ms.ravel(), mk.ravel()])
    grid = grid[grid[:, 1] <= grid[:, 0] + 1e-12]
    out = {}
    for angle, (p, mean, se) in m.items():
        if len(p) < 3:
            continue
        out[angle] = (LinearNDInterpolator(p, mean)(grid), LinearNDInterpolator(p, se)(grid))
    return grid, out


def solve(targets, m):
    """(mu_s, mu_k, their one-se ranges, the angles at the answer) for {angle: target}."""
    grid, surf = surfaces(m)
    missing = [a for a in targets if a not in surf]
    if missing:
        raise SceneError(f"{OPTION[missing[0]]}: the map has no {missing[0]} measurements")
    inside = np.all([np.isfinite(surf[a][0]) for a in targets], axis=0)
    for a, v in targets.items():
        lo, hi = np.nanmin(surf[a][0]), np.nanmax(surf[a][0])
        if not lo <= v <= hi:
            raise SceneError(f"{OPTION[a]} {v:g}: outside the measured map, which reaches {a} from {lo:.1f} to "
                             f"{hi:.1f} deg ({reachable(surf)})")
    chi2 = np.zeros(len(grid))
    for a, v in targets.items():
        mean, se = surf[a]
        chi2 += ((mean - v) / np.maximum(se, 0.05)) ** 2  # (0.05 deg: a point measured once has no se)
    chi2[~inside] = np.inf
    best = int(np.argmin(chi2))
    if chi2[best] > JOINT_LIMIT:
        got = ", ".join(f"{a} {surf[a][0][best]:.1f}" for a in targets)
        raise SceneError(f"{' '.join(f'{OPTION[a]} {v:g}' for a, v in targets.items())}: no (mu_s, mu_k) of the map "
                         f"gives these together within 3 standard errors (closest: mu_s {grid[best, 0]:.3f}, mu_k "
                         f"{grid[best, 1]:.3f}: {got} deg); {reachable(surf)}")
    region = grid[chi2 <= chi2[best] + 1.0]
    return {"mu_s": grid[best, 0], "mu_k": grid[best, 1], "mu_s_range": (region[:, 0].min(), region[:, 0].max()),
            "mu_k_range": (region[:, 1].min(), region[:, 1].max()), "chi2": float(chi2[best]),
            "angles": {a: (float(surf[a][0][best]), float(surf[a][1][best])) for a in surf}}


def reachable(surf):
    parts = [f"{a} {np.nanmin(s[0]):.1f}-{np.nanmax(s[0]):.1f}" for a, s in surf.items()]
    if "theta_start" in surf and "theta_stop" in surf:
        d = surf["theta_start"][0] - surf["theta_stop"][0]
        parts.append(f"theta_start - theta_stop {np.nanmin(d):.1f}-{np.nanmax(d):.1f}")
    return "reachable: " + ", ".join(parts) + " deg"


def main(args):
    targets = {a: getattr(args, a) for a in ANGLES if getattr(args, a) is not None}
    if len(targets) < 2:
        raise SceneError("calibrate: give at least two of --theta-start, --theta-stop, --theta-heap (degrees)")
    m, (lag, lag_se, how) = load_map(args.map or DOCS / "points.csv", args.rolling)
    r = solve(targets, m)
    (s0, s1), (k0, k1) = r["mu_s_range"], r["mu_k_range"]
    print(f"mu_s = {r['mu_s']:.3f} (one standard error: {s0:.3f} to {s1:.3f})")
    print(f"mu_k = {r['mu_k']:.3f} (one standard error: {k0:.3f} to {k1:.3f})")
    print(f"2 mu_k - mu_s = {2 * r['mu_k'] - r['mu_s']:.3f} (the force a slipping contact holds, over Fn)")
    print("the map there: " + ", ".join(f"{a} {v:.1f} +- {e:.1f} deg" for a, (v, e) in r["angles"].items())
          + f" (chi2 {r['chi2']:.2f}); rolling resistance {args.rolling:g}, the paper's nu_s (0.8 nu_n), step mode;"
          " the scenes of docs/granular-3d.md")
    print({"fixed": f"theta_stop at a fixed angle: the ramp's value + {lag:.1f} +- {lag_se:.1f} deg (its lag to beds "
                    "held at fixed angles, measured)",
           "ramp": f"theta_stop at zero rate: the ramp's value + {lag:.1f} +- {lag_se:.1f} deg (its lag, from half "
                   "rates)",
           None: "theta_stop as the ramp measured it (the map has no measure of the ramp's lag)"}[how])
    return r
