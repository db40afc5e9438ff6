# SPDX-License-Identifier: GPL-2.0-or-later
"""The measured map that `stickslip calibrate` inverts (docs/granular-3d.md): the study's
points at one rolling resistance (`from_points`), and each target's surface over (mu_s, mu_k)
as a linear combination of the points' means, by one of two interpolations:

- linear: barycentric weights on the Delaunay triangulation of the points;
- quadratic: a + b mu_s + c mu_k + d mu_s^2 + e mu_s mu_k + f mu_k^2 fitted by least squares
  weighted by 1/se^2 (at least 7 points: one more than its terms); the fit's covariance is
  its prediction's uncertainty.

Both stop at the points' convex hull: a map is not extrapolated. A prediction is w . y (the
weights w over the points' means y), so its variance is sum w_i^2 se_i^2 (the points are
independent: each its own fills) and its degrees of freedom Welch-Satterthwaite's from each
point's fills - 1 (a point's se from 3 fills is itself uncertain; calibrate's coverage factor
uses them). For the quadratic sum w_i^2 se_i^2 is the fit's covariance x' C x.

Leave-one-out (`loo`) predicts each point from the others: its residuals measure the
interpolation's own error, which the fills' spread does not hold (the surface curves between
the points). `interp_error` is the part of the mean squared residual that the stated
variances do not explain, added to every prediction's variance; `choose` takes the
interpolation with the smaller leave-one-out error on the points both can predict.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import SceneError
from . import granular3d_tables

# What calibrate can take as a target: the column of points.csv ("<target>_mean", "_se",
# "_n") and the scene kind it is read on. The incline's and the heap's angles; the sheared
# layer's peak and steady tau/sigma and its dilation (kind shear3d) once the study has measured
# them on the map's points (its group "shear").
KIND = dict(granular3d_tables.KIND, shear_peak="shear", shear_steady="shear", shear_dilation="shear")
GROUPS = ("sweep", "shear")
TARGETS = tuple(KIND)
METHODS = ("linear", "quadratic")
SE_FLOOR = 0.05  # deg: a point measured once has no se
COVER = 0.6827  # one standard error of a Gaussian
QUADRATIC_TERMS = 6


@dataclass
class Points:
    """One target's measured points: (mu_s, mu_k), mean, se and fills of each."""
    xy: np.ndarray
    mean: np.ndarray
    se: np.ndarray
    n: np.ndarray

    def nu(self):
        """Each point's degrees of freedom: fills - 1 (inf where the fills are not known)."""
        return np.where(np.isfinite(self.n) & (self.n > 1), self.n - 1.0, np.inf)


# The columns a map must have (points.csv of `stickslip study-3d`): which rows are map points,
# and where they lie. A target's columns are "<target>_mean", "_se" and, optionally, "_n".
LABELS = ("kind", "engine", "group", "nu_s", "timing")
NUMBERS = ("mu_s", "mu_k", "rolling")


def read_points(path):
    """The map's points from a CSV, or SceneError in one line naming the file, the column (and
    the line where there is one) and what was expected: only the columns study-3d writes, the
    columns LABELS and NUMBERS, a standard error beside every mean (a mean beside every other
    statistic: a renamed mean), finite numbers where numbers are (a "nan" or "inf" written in a
    cell is refused; only an empty cell is "not measured"), no empty cell in NUMBERS, a mean in
    every map row of its target's kind, and no row or map point twice."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(f"--map {path}: not found (stickslip study-3d writes it)")
    where = f"--map {path}"
    try:
        # keep_default_na=False: "nan", "NA", "null" stay text (refused below), an empty cell is NaN
        pts = pd.read_csv(path, dtype={c: str for c in LABELS}, keep_default_na=False, na_values=[""])
    except (OSError, ValueError, pd.errors.ParserError) as e:  # (UnicodeDecodeError is a ValueError)
        raise SceneError(f"{where}: cannot be read as CSV ({' '.join(str(e).split())[:120]})") from None
    known = granular3d_tables.point_columns()
    unknown = [c for c in pts if c not in known]
    if unknown:
        raise SceneError(f"{where}: column {unknown[0]!r} is not a column of a map (points.csv of stickslip "
                         f"study-3d: {', '.join(LABELS + NUMBERS)}, each figure's "
                         f"{'/'.join(granular3d_tables.STATISTICS)}, fills)")
    missing = [c for c in (*LABELS, *NUMBERS) if c not in pts]
    if missing:
        raise SceneError(f"{where}: no column {missing[0]!r}: a map has the columns {', '.join(LABELS + NUMBERS)} "
                         "(points.csv of stickslip study-3d)")
    means = [t for t in TARGETS if f"{t}_mean" in pts]
    if not means:
        raise SceneError(f"{where}: no column of a target's mean: expected one of "
                         f"{', '.join(t + '_mean' for t in TARGETS)}")
    for figure in granular3d_tables.MEASURED:
        beside = [f"{figure}_{k}" for k in granular3d_tables.STATISTICS[1:] if f"{figure}_{k}" in pts]
        if beside and f"{figure}_mean" not in pts:
            raise SceneError(f"{where}: column {beside[0]} has no {figure}_mean beside it: expected each statistic "
                             "beside its mean")
    for t in means:
        if f"{t}_se" not in pts:
            raise SceneError(f"{where}: column {t}_mean has no {t}_se beside it: expected each mean's standard "
                             "error")
    for c in (*NUMBERS, *(f"{t}_{s}" for t in means for s in ("mean", "se", "n") if f"{t}_{s}" in pts)):
        v = pd.to_numeric(pts[c], errors="coerce")
        bad = pts[c].notna() & ~np.isfinite(v) | (pts[c].isna() & (c in NUMBERS))
        if c.endswith("_se"):
            bad |= pts[c].isna() & pts[c.replace("_se", "_mean")].notna()
        if bad.any():
            i = int(np.argmax(bad.to_numpy()))
            cell = "empty" if pd.isna(pts[c].iloc[i]) else repr(str(pts[c].iloc[i]))
            raise SceneError(f"{where}: column {c}, line {i + 2}: {cell}: expected a finite number"
                             + (" (the standard error of the mean beside it)" if c.endswith("_se") else ""))
        pts[c] = v
    _check_rows(pts, where)
    return pts


def _check_rows(pts, where):
    """SceneError in one line for a row written twice, a map point of one kind measured twice
    (two rows at one (mu_s, mu_k) and rolling resistance), or a map row without the mean of a
    target its kind measures (a point the map would otherwise drop without a word). Lines are
    the file's (the header is line 1)."""
    later = np.flatnonzero(pts.duplicated().to_numpy())
    if len(later):
        i = later[0]
        j = next(k for k in range(i) if pts.iloc[k].equals(pts.iloc[i]))
        raise SceneError(f"{where}: line {i + 2} repeats line {j + 2}: each row once")
    on = on_map(pts)
    key = ["kind", "mu_s", "mu_k", "rolling", "nu_s", "timing"]
    points = pts[on]
    later = np.flatnonzero(points.duplicated(key).to_numpy())
    if len(later):
        i = points.index[later[0]]
        a = points.loc[i]
        j = next(k for k in points.index if k != i and all(points.loc[k, c] == a[c] for c in key))
        raise SceneError(f"{where}: lines {j + 2} and {i + 2}: two map points of kind {a.kind} at mu_s {a.mu_s:g}, "
                         f"mu_k {a.mu_k:g}, rolling {a['rolling']:g}: each point once")
    for t, kind in KIND.items():
        if f"{t}_mean" not in pts:
            continue
        empty = on & (pts.kind == kind) & pts[f"{t}_mean"].isna()
        if empty.any():
            i = int(np.argmax(empty.to_numpy()))
            raise SceneError(f"{where}: column {t}_mean, line {i + 2}: empty: expected a finite number (a map row of "
                             f"kind {kind} measures {t})")


def on_map(pts):
    """Where pts's rows are the map's points (map_rows, any rolling resistance)."""
    return ((pts["engine"] == "liggghts") & pts["group"].isin(GROUPS)
            & ((pts.mu_s == pts.mu_k) | ((pts.nu_s == "paper") & (pts.timing == "step"))))


def lag_of(path, pts):
    """(lag, se, "fixed" | "ramp" | None): how far the ramp's theta_stop lies below a bed
    held at a fixed angle (validation.csv beside the map), else below its zero-rate limit
    (half rates in the map: granular3d_tables.ramp_lag), else unknown."""
    lag, lag_se = (granular3d_tables.ramp_lag(pts) if {"material", "layers", "rate_factor", "silbert"} <= set(pts)
                   else (math.nan, math.nan))
    how = "ramp" if math.isfinite(lag) else None
    val = Path(path).with_name("validation.csv") if path is not None else None
    if val is not None and val.is_file():
        try:
            v = pd.read_csv(val)
        except (OSError, ValueError, pd.errors.ParserError) as e:
            raise SceneError(f"{val} (beside --map): cannot be read as CSV "
                             f"({' '.join(str(e).split())[:120]})") from None
        if "fixed_lag" in v:
            need = [c for c in ("engine", "layers", "fixed_lag_se") if c not in v]
            if need:
                raise SceneError(f"{val} (beside --map): column fixed_lag without {need[0]!r}: expected "
                                 "validation.csv of stickslip study-3d")
            v = v[(v.engine == "liggghts") & (v.layers == granular3d_tables.SCENE_LAYERS)]
            if len(v) and math.isfinite(v.fixed_lag.iloc[0]):
                lag, lag_se, how = float(v.fixed_lag.iloc[0]), float(v.fixed_lag_se.iloc[0]), "fixed"
    return lag, lag_se, how


def blank(column):
    """Where a text column of a table read back is empty (a column with no text reads as NaN)."""
    return column.isna() | column.astype(str).eq("")


def widening(rows, rolling):
    """(f, ranges): the factor by which calibrate's ranges are widened at this rolling
    resistance, from leave_pair_out.csv's rows (granular3d_calibration.leave_pair_out): the
    square root of the 68.27 % quantile of the profiled delta chi2 at the true value over the
    range's threshold, over the ranges not cut by an edge (1 where they hold the truth at least
    that often already, or where there are none), and how many ranges it comes from. A true
    value off the map that is left (a corner of the map left out: an infinite ratio) cannot be
    answered by any range and is left out."""
    g = rows[np.isclose(rows["rolling"], rolling) & blank(rows.refused)]
    ratios = np.concatenate([g.loc[blank(g[f"{c}_cut"]), f"{c}_ratio"].to_numpy(float)
                             for c in ("mu_s", "mu_k")])
    ratios = ratios[np.isfinite(ratios)]
    if not len(ratios):
        return 1.0, 0
    return math.sqrt(max(float(np.quantile(ratios, COVER)), 1.0)), len(ratios)


# leave_pair_out.csv's columns that widening() reads, and which of them hold numbers
WIDENING_COLUMNS = ("rolling", "refused", "mu_s_cut", "mu_k_cut", "mu_s_ratio", "mu_k_ratio")
WIDENING_NUMBERS = ("rolling", "mu_s_ratio", "mu_k_ratio")


def widening_of(path, rolling):
    """(f, ranges, note): widening() from leave_pair_out.csv beside the map; where there is no
    such file, or it has no ranges at this rolling resistance, f = 1 and `note` says so in one
    line (calibrate prints it first: the ranges are then as stated, not widened). A file that is
    not a leave_pair_out.csv is SceneError in one line naming it, the column and the line."""
    lpo = Path(path).with_name("leave_pair_out.csv")
    if not lpo.is_file():
        return 1.0, 0, (f"note: no leave_pair_out.csv beside --map {path}: the ranges are not widened by the map's "
                        "own measure (f = 1), so they may hold the truth less often than 68 % (stickslip study-3d "
                        "writes it beside points.csv)")
    where = f"{lpo} (beside --map)"
    try:
        rows = pd.read_csv(lpo, keep_default_na=False, na_values=[""])
    except (OSError, ValueError, pd.errors.ParserError) as e:
        raise SceneError(f"{where}: cannot be read as CSV ({' '.join(str(e).split())[:120]})") from None
    missing = [c for c in WIDENING_COLUMNS if c not in rows]
    if missing:
        raise SceneError(f"{where}: no column {missing[0]!r}: expected leave_pair_out.csv of stickslip study-3d "
                         f"({', '.join(WIDENING_COLUMNS)})")
    answered = blank(rows.refused)
    for c in WIDENING_NUMBERS:
        v = pd.to_numeric(rows[c], errors="coerce")
        # a ratio may be infinite (a truth off the map that is left: widening() leaves it out)
        bad = (rows[c].isna() | v.isna() | (np.isinf(v) & (c == "rolling"))) & (answered | (c == "rolling"))
        if bad.any():
            i = int(np.argmax(bad.to_numpy()))
            cell = "empty" if pd.isna(rows[c].iloc[i]) else repr(str(rows[c].iloc[i]))
            raise SceneError(f"{where}: column {c}, line {i + 2}: {cell}: expected a number")
        rows[c] = v
    f, ranges = widening(rows, rolling)
    if not ranges:
        return 1.0, 0, (f"note: {lpo.name} beside --map {path} has no ranges uncut by an edge at --rolling {rolling:g}: "
                        "the ranges are not widened by the map's own measure (f = 1), so they may hold the truth less often than "
                        "68 %")
    return f, ranges, None


def map_rows(pts, rolling, nu_s="paper", source="the map"):
    """The rows of pts that are the map's points on LIGGGHTS at this rolling resistance:
    history (mu_s = mu_k) and the stick-slip pairs with the chosen nu_s in the step mode.
    `source` names the map in a refusal."""
    pts = pts[(pts["engine"] == "liggghts") & pts["group"].isin(GROUPS)]
    if not len(pts):
        raise SceneError(f"{source}: no rows with engine 'liggghts' and group {' or '.join(map(repr, GROUPS))}: "
                         "expected the map's points (points.csv of stickslip study-3d)")
    rolls = sorted(pts["rolling"].unique())
    if not any(math.isclose(rolling, r, abs_tol=1e-9) for r in rolls):
        raise SceneError(f"{source}: column rolling has no map rows at --rolling {rolling:g}: it was measured at "
                         f"{' and '.join(f'{r:g}' for r in rolls)} only")
    pts = pts[np.isclose(pts["rolling"], rolling)]
    return pts[(pts.mu_s == pts.mu_k) | ((pts.nu_s == nu_s) & (pts.timing == "step"))]


def from_points(pts, rolling, nu_s="paper", source="the map"):
    """{target: Points}: each target's map points (map_rows) as the ramp measured them (the
    lag to a fixed angle, common to every point, is added to the predictions:
    calibrate_fit.surfaces)."""
    pts = map_rows(pts, rolling, nu_s, source)
    out = {}
    for target, kind in KIND.items():
        if f"{target}_mean" not in pts or f"{target}_se" not in pts:
            continue
        p = pts[(pts.kind == kind) & np.isfinite(pts[f"{target}_mean"])]
        mean = p[f"{target}_mean"].to_numpy(float)
        se = np.maximum(p[f"{target}_se"].fillna(0.0).to_numpy(float), SE_FLOOR)
        n = p[f"{target}_n"].to_numpy(float) if f"{target}_n" in p else np.full(len(p), np.nan)
        out[target] = Points(p[["mu_s", "mu_k"]].to_numpy(float), mean, se, n)
    return out


def _design(xy):
    s, k = xy[:, 0], xy[:, 1]
    return np.column_stack([np.ones(len(xy)), s, k, s * s, s * k, k * k])


def _hull(xy):
    """The Delaunay triangulation of the points, or None (fewer than 3, or all on a line)."""
    from scipy.spatial import Delaunay, QhullError

    if len(xy) < 3:
        return None
    try:
        return Delaunay(xy)
    except QhullError:
        return None


def _locate(tri, at):
    """(simplex, barycentric coordinates): for each of `at`, the first triangle of the
    triangulation that holds it (-1: none), within Qhull's 100 ulps, and its coordinates there
    (one per vertex, in tri.simplices' order). Plain arithmetic: scipy's find_simplex and
    transform call LAPACK for each triangle, whose threads cost far more than a map's few
    triangles."""
    v = tri.points[tri.simplices]  # (triangles, 3 vertices, 2)
    (ax, ay), (bx, by), (cx, cy) = (v[:, i].T for i in range(3))
    det = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
    px, py = at[:, :1] - cx, at[:, 1:] - cy  # (points, triangles)
    with np.errstate(invalid="ignore", divide="ignore"):
        la = ((by - cy) * px + (cx - bx) * py) / det
        lb = ((cy - ay) * px + (ax - cx) * py) / det
    coords = np.stack([la, lb, 1.0 - la - lb], axis=2)
    eps = 100 * np.finfo(float).eps
    held = ((coords >= -eps) & (coords <= 1 + eps)).all(axis=2)
    simplex = np.where(held.any(axis=1), held.argmax(axis=1), -1)
    return simplex, coords[np.arange(len(at)), np.maximum(simplex, 0)]


def weights(method, p, at):
    """(len(at), len(points)) weights w: the prediction at each of `at` is w . mean; rows of
    NaN outside the points' hull or where the method cannot fit these points."""
    w = np.full((len(at), len(p.mean)), np.nan)
    tri = _hull(p.xy)
    if tri is None:
        return w
    simplex, bary = _locate(tri, at)
    inside = simplex >= 0
    if method == "linear":
        bary = bary[inside]
        rows = np.zeros((inside.sum(), len(p.mean)))
        np.put_along_axis(rows, tri.simplices[simplex[inside]], bary, axis=1)
        w[inside] = rows
        return w
    a = _design(p.xy)
    if len(p.mean) <= QUADRATIC_TERMS or np.linalg.matrix_rank(a) < QUADRATIC_TERMS:
        return w
    wt = 1.0 / p.se ** 2
    cov = np.linalg.inv(a.T @ (a * wt[:, None]))
    w[inside] = _design(at[inside]) @ cov @ (a * wt[:, None]).T
    return w


def without(method, p, at, w, i):
    """(weights at `at` of the map's points less point i, those points) from w = weights(method,
    p, at): the linear interpolation changes only where point i had a weight (removing a point
    re-triangulates only the triangles around it), so only those rows are recomputed; the
    quadratic surface is fitted again."""
    keep = np.arange(len(p.mean)) != i
    rest = Points(p.xy[keep], p.mean[keep], p.se[keep], p.n[keep])
    if method != "linear":
        return weights(method, rest, at), rest
    out = w[:, keep].copy()
    redo = np.nan_to_num(w[:, i]) != 0
    out[redo] = weights(method, rest, at[redo])
    return out, rest


def predict(w, p):
    """(mean, variance, degrees of freedom) of the predictions w . mean (NaN where w is)."""
    c = w ** 2 * p.se ** 2
    var = c.sum(axis=1)
    nu_i = p.nu()
    with np.errstate(invalid="ignore", divide="ignore"):
        denom = (c ** 2 / nu_i).sum(axis=1)
        nu = np.where(denom > 0, var ** 2 / denom, np.inf)
    return w @ p.mean, var, np.where(np.isfinite(var), nu, np.nan)


def loo(m, methods=METHODS):
    """One row per target, method and point: the point predicted from the others, its
    residual (measured - predicted), the prediction's se and z = residual / sqrt(se_point^2 +
    se_predicted^2); NaN where the others cannot predict it (outside their hull, too few)."""
    rows = []
    for target, p in m.items():
        for method in methods:
            for i in range(len(p.mean)):
                keep = np.arange(len(p.mean)) != i
                others = Points(p.xy[keep], p.mean[keep], p.se[keep], p.n[keep])
                mean, var, _ = predict(weights(method, others, p.xy[i:i + 1]), others)
                r = p.mean[i] - mean[0]
                rows.append({"target": target, "method": method, "mu_s": p.xy[i, 0], "mu_k": p.xy[i, 1],
                             "measured": p.mean[i], "se": p.se[i], "predicted": mean[0],
                             "predicted_se": math.sqrt(var[0]) if np.isfinite(var[0]) else math.nan,
                             "residual": r, "z": r / math.sqrt(p.se[i] ** 2 + var[0])})
    return pd.DataFrame(rows, columns=["target", "method", "mu_s", "mu_k", "measured", "se", "predicted",
                                       "predicted_se", "residual", "z"])


def interp_error(rows):
    """{(target, method): (sd, points)}: the interpolation's own error, the part of the
    leave-one-out mean squared residual its stated variances do not explain (0 when they do)."""
    out = {}
    for (target, method), g in rows.groupby(["target", "method"]):
        g = g[np.isfinite(g.residual)]
        excess = float(np.mean(g.residual ** 2 - g.se ** 2 - g.predicted_se ** 2)) if len(g) else 0.0
        out[target, method] = (math.sqrt(max(excess, 0.0)), len(g))
    return out


def scores(rows):
    """{method: (score, points)}: mean of (residual / se_point)^2 over the points every method
    predicts (the same points for each, the same yardstick: the points' own se)."""
    ok = rows.pivot_table(index=["target", "mu_s", "mu_k"], columns="method", values="residual", aggfunc="first")
    common = ok.dropna()
    se = rows.drop_duplicates(["target", "mu_s", "mu_k"]).set_index(["target", "mu_s", "mu_k"]).se
    return {m: (float(np.mean((common[m] / se.loc[common.index]) ** 2)) if len(common) else math.nan, len(common))
            for m in ok.columns}


def choose(rows):
    """The interpolation of smaller leave-one-out score (linear where none can be compared)."""
    s = scores(rows)
    usable = {m: v for m, v in s.items() if np.isfinite(v[0])}
    return min(usable, key=lambda m: usable[m][0]) if usable else "linear"
