# SPDX-License-Identifier: GPL-2.0-or-later
"""The inverse problem of `stickslip calibrate`: the (mu_s, mu_k) whose map values best give
the targets, each with its uncertainty, and ranges whose meaning is stated.

On a grid over the law's triangle (mu_s / 2 <= mu_k <= mu_s) within the map's hull,

    chi2(mu_s, mu_k) = sum over targets (map(mu) - target)^2 / (se_map^2 + se_interp^2 + se_target^2)

se_map: the map's prediction there (calibrate_map.predict: its points' fills), se_interp: the
interpolation's own error (calibrate_map.interp_error, from leave-one-out), se_target: the
user's (0: taken as exact). The answer is the grid point of least chi2.

Each coefficient's range is the extent of the region chi2 <= least + k^2 with the other
coefficient profiled (minimised over): with known errors k = 1, the 68.27 % interval of one
parameter (Wilks: delta chi2 is chi2 with 1 degree of freedom). But a standard error from 3
fills is itself uncertain by about half, so k is the coverage factor of the GUM (JCGM 100:2008,
annex G): Student's t quantile of 84.13 % at the Welch-Satterthwaite degrees of freedom of the
errors that coefficient comes from (each target's, weighted by how much of the coefficient's
variance it carries at the answer: the map's local slopes). The joint 68.27 % region of the
two is chi2 <= least + 2 F(0.6827; 2, nu) (2.30 for known errors, nu -> infinity), nu the
smaller of the two coefficients'. Both hold where the map is near linear over the region and
the errors Gaussian; a region that reaches the map's edge or the law's bounds is cut, and its
range there is a bound, not a standard error (`cut`), which calibrate says. Where they do not
hold, the ranges' threshold is widened by f^2, f measured by leaving the map's own points out
(calibrate_widen.py): `solve(..., widen=f)`.

An answer whose grid point touches the map's edge or one of the law's bounds is not bracketed:
the targets may ask for a pair beyond it (`Result.edge`), which calibrate says.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import SceneError
from . import calibrate_map

GRID = 0.0025  # grid step in mu
ORDER = ("map", "mu_k = mu_s", "mu_k = mu_s / 2")  # the edges a range or an answer can touch
COVER = calibrate_map.COVER
DELTA_PROFILE = 1.0  # one coefficient, the other profiled, known errors: chi2 quantile 0.6827 with 1 dof
DELTA_JOINT = 2.30  # the pair, known errors: chi2 quantile 0.6827 with 2 dof
JOINT_LIMIT = 9.0  # least chi2 above which the targets are not reachable together (3 standard errors)
OPTION = {"theta_start": "--theta-start", "theta_stop": "--theta-stop", "theta_heap": "--theta-heap",
          "shear_peak": "--shear-peak", "shear_steady": "--shear-steady", "shear_dilation": "--shear-dilation"}
# What a target may be, open bounds, and how the bound is said: the command's options and a file
# of repeats (calibrate.read_measurements) both check these.
ALLOWED = {"theta_start": (0.0, 90.0, "an angle in degrees"), "theta_stop": (0.0, 90.0, "an angle in degrees"),
           "theta_heap": (0.0, 90.0, "an angle in degrees"), "shear_peak": (0.0, 5.0, "a stress ratio"),
           "shear_steady": (0.0, 5.0, "a stress ratio"), "shear_dilation": (-5.0, 5.0, "in grain diameters")}


@dataclass
class Target:
    """A measured value, its standard error (0: exact) and the repeats it is the mean of
    (None: its error is known, not estimated)."""
    value: float
    se: float = 0.0
    n: int | None = None


@dataclass
class Surfaces:
    """The grid (mu_s along axis 0, mu_k along axis 1) and each target's prediction on it:
    {target: (mean, variance, degrees of freedom)}, NaN outside the triangle or the hull."""
    ms: np.ndarray
    mk: np.ndarray
    pred: dict
    method: str
    interp: dict = field(default_factory=dict)  # {target: se_interp}
    lag: tuple = (math.nan, math.nan, None)

    def triangle(self):
        s, k = np.meshgrid(self.ms, self.mk, indexing="ij")
        return (k <= s + 1e-9) & (k >= s / 2 - 1e-9)


def grid(m):
    """(mu_s values, mu_k values, the (mu_s, mu_k) of the grid's points in the law's triangle) over
    the extent of map m's points."""
    xy = np.vstack([p.xy for p in m.values() if len(p.xy)])
    ms = np.round(np.arange(xy[:, 0].min(), xy[:, 0].max() + GRID / 2, GRID) / GRID) * GRID
    mk = np.round(np.arange(xy[:, 1].min(), xy[:, 1].max() + GRID / 2, GRID) / GRID) * GRID
    tri = Surfaces(ms, mk, {}, "").triangle()
    gs, gk = np.meshgrid(ms, mk, indexing="ij")
    return ms, mk, np.column_stack([gs[tri], gk[tri]])


def surfaces(m, method, interp=None, lag=(math.nan, math.nan, None), weights=None, on=None):
    """Each target's (mean, variance, dof) on the grid, from map m (calibrate_map.from_points)
    by `method`; interp {target: se} added to every prediction's variance (infinite dof); the
    lag (value, se, how) added to theta_stop (common to every point: its whole variance).
    weights {target: (w, Points)} on grid `on` (grid(m) of a larger map) stand in for the
    map's own (calibrate_widen: the map less one of its points)."""
    ms, mk, at = on or grid(m)
    s = Surfaces(ms, mk, {}, method, dict(interp or {}), lag)
    tri = s.triangle()
    for target, p in m.items():
        w, p = (weights or {}).get(target) or (None, p)
        if len(p.mean) < 3:
            continue
        mean, var, nu = calibrate_map.predict(calibrate_map.weights(method, p, at) if w is None else w, p)
        extra = s.interp.get(target, 0.0) ** 2
        if target == "theta_stop" and math.isfinite(lag[0]):
            mean, extra = mean + lag[0], extra + lag[1] ** 2
        with np.errstate(invalid="ignore", divide="ignore"):
            nu = np.where(var > 0, (var + extra) ** 2 / (var ** 2 / nu), np.inf)
        full = [np.full(tri.shape, np.nan) for _ in range(3)]
        for f, v in zip(full, (mean, var + extra, nu)):
            f[tri] = v
        s.pred[target] = tuple(full)
    return s


_NU = np.geomspace(0.5, 1e5, 600)
_K = []


def coverage_factor(nu):
    """Student's t quantile of (1 + 0.6827) / 2 at nu degrees of freedom (1 at infinity):
    interpolated in log nu on a table of scipy's (within 1e-5; a grid's worth at once)."""
    if not _K:
        from scipy.stats import t

        _K.append(t.ppf(0.5 + COVER / 2, _NU) / t.ppf(0.5 + COVER / 2, np.inf))
    nu = np.asarray(nu, float)
    k = np.interp(np.log(np.where(np.isfinite(nu), np.clip(nu, _NU[0], _NU[-1]), _NU[-1])), np.log(_NU), _K[0])
    return np.where(np.isfinite(nu) & (nu < _NU[-1]), k, 1.0)


@dataclass
class Result:
    mu_s: float
    mu_k: float
    chi2: float  # least chi2
    field: np.ndarray  # chi2 on the grid (inf outside)
    surf: Surfaces
    ranges: dict  # {"mu_s": (lo, hi), "mu_k": (lo, hi)}
    cut: dict  # {("mu_s", "lo" | "hi"): the edges that cut it, of ORDER ("map"; the law's bounds)}
    at_best: dict  # {target: (mean, se)} of the map at the answer
    delta: dict  # {"mu_s" | "mu_k" | "joint": delta chi2 of its 68.27 %; the ranges' widened by widen^2}
    dof: dict  # {"mu_s" | "mu_k": Welch-Satterthwaite degrees of freedom}
    edge: tuple = ()  # where the answer itself lies on an edge: "map", "mu_k = mu_s", "mu_k = mu_s / 2"
    widen: float = 1.0  # the factor the ranges were widened by (calibrate_widen)

    def delta_at(self, mu_s, mu_k):
        """chi2 - least chi2 at the grid point nearest (mu_s, mu_k) (inf off the map)."""
        i, j = np.abs(self.surf.ms - mu_s).argmin(), np.abs(self.surf.mk - mu_k).argmin()
        return float(self.field[i, j] - self.chi2)

    def profile_at(self, name, value):
        """chi2 - least chi2 with coefficient `name` at the grid value nearest `value`, the other
        profiled (its least along that line; inf where the line misses the map): within
        delta[name], `value` lies in the range."""
        if name == "mu_s":
            line = self.field[np.abs(self.surf.ms - value).argmin(), :]
        else:
            line = self.field[:, np.abs(self.surf.mk - value).argmin()]
        return float(line.min() - self.chi2)


def reachable(surf, names):
    """What the map reaches of the targets `names` (and of theta_start - theta_stop where both are
    among them), for a refusal."""
    parts = [f"{a} {np.nanmin(s[0]):.1f}-{np.nanmax(s[0]):.1f}" for a, s in surf.pred.items() if a in names]
    if {"theta_start", "theta_stop"} <= set(names):
        d = surf.pred["theta_start"][0] - surf.pred["theta_stop"][0]
        parts.append(f"theta_start - theta_stop {np.nanmin(d):.1f}-{np.nanmax(d):.1f}")
    return "reachable: " + ", ".join(parts) + " deg"


def _chi2(targets, surf):
    """chi2 on the grid, and each target's total variance and its degrees of freedom there."""
    chi2, var_nu = 0.0, {}
    for a, t in targets.items():
        mean, var, nu = surf.pred[a]
        nu_t = (t.n - 1.0) if t.n else math.inf
        tot = var + t.se ** 2
        with np.errstate(invalid="ignore", divide="ignore"):
            nu_all = tot ** 2 / (np.where(np.isfinite(nu), var ** 2 / nu, 0.0) + t.se ** 4 / nu_t)
        var_nu[a] = (tot, np.where(np.isfinite(nu_all), nu_all, np.inf))
        chi2 = chi2 + (mean - t.value) ** 2 / tot
    return np.where(np.isfinite(chi2), chi2, np.inf), var_nu


def _slopes(surf, a, best):
    """d(target)/d(mu_s), d/d(mu_k) at the grid point `best`: central differences, one-sided at
    the domain's edge (0 where neither neighbour is on the map)."""
    mean = surf.pred[a][0]
    c = mean[tuple(best)]
    out = []
    for axis in (0, 1):
        vals = []
        for step in (-1, 1):
            j = list(best)
            j[axis] += step
            ok = 0 <= j[axis] < mean.shape[axis] and np.isfinite(mean[tuple(j)])
            vals.append(mean[tuple(j)] if ok else None)
        lo, hi = vals
        out.append((hi - lo) / (2 * GRID) if lo is not None and hi is not None else
                   (hi - c) / GRID if hi is not None else (c - lo) / GRID if lo is not None else 0.0)
    return out


def thresholds(targets, surf, var_nu, best):
    """({"mu_s", "mu_k", "joint": delta chi2}, {"mu_s", "mu_k": dof}): each coefficient's
    variance at the answer is sum over targets c_a^2 var_a, c = (J' W J)^-1 J' W (J the map's
    slopes, W = 1 / var): Welch-Satterthwaite's dof over those terms, and k^2 from it."""
    from scipy.stats import f

    names = list(targets)
    jac = np.array([_slopes(surf, a, best) for a in names])
    var = np.array([var_nu[a][0][best] for a in names])
    nu = np.array([var_nu[a][1][best] for a in names])
    try:
        w = jac.T / var
        c = np.linalg.solve(w @ jac, w)  # 2 x targets
    except np.linalg.LinAlgError:
        c = None
    dof = {}
    for i, p in enumerate(("mu_s", "mu_k")):
        u = c[i] ** 2 * var if c is not None else np.zeros(len(names))
        denom = float(np.sum(np.where(np.isfinite(nu), u ** 2 / nu, 0.0)))
        dof[p] = float(u.sum() ** 2 / denom) if denom > 0 else math.inf
    delta = {p: float(coverage_factor(dof[p])) ** 2 * DELTA_PROFILE for p in dof}
    joint = min(dof.values())
    delta["joint"] = float(2 * f.ppf(COVER, 2, joint)) if math.isfinite(joint) else DELTA_JOINT
    return delta, dof


def solve(targets, surf, widen=1.0):
    """Result for {target name: Target} on the surfaces, each coefficient's range widened by
    `widen` (its delta chi2 by widen^2), or SceneError in one line: a target the map does not
    measure, one outside what it reaches (by more than 3 of its standard errors), or targets no
    point gives together within 3 standard errors."""
    missing = [a for a in targets if a not in surf.pred]
    if missing:
        what = ("shear3d measurements (stickslip study-3d --groups shear measures them)"
                if missing[0].startswith("shear") else f"{missing[0]} measurements")
        raise SceneError(f"{OPTION[missing[0]]}: the map has no {what}")
    for a, t in targets.items():
        lo, hi = np.nanmin(surf.pred[a][0]), np.nanmax(surf.pred[a][0])
        if not lo - 3 * t.se <= t.value <= hi + 3 * t.se:
            raise SceneError(f"{OPTION[a]} {t.value:g}: outside the measured map, which reaches {a} from {lo:.1f} to "
                             f"{hi:.1f} deg ({reachable(surf, targets)})")
    field, var_nu = _chi2(targets, surf)
    best = np.unravel_index(np.argmin(field), field.shape)
    chi2 = float(field[best])
    ms, mk = float(surf.ms[best[0]]), float(surf.mk[best[1]])
    if chi2 > JOINT_LIMIT:
        got = ", ".join(f"{a} {surf.pred[a][0][best]:.1f}" for a in targets)
        raise SceneError(f"{' '.join(f'{OPTION[a]} {t.value:g}' for a, t in targets.items())}: no (mu_s, mu_k) of "
                         f"the map gives these together within 3 standard errors (closest: mu_s {ms:.3f}, mu_k "
                         f"{mk:.3f}: {got} deg); {reachable(surf, targets)}")
    delta, dof = thresholds(targets, surf, var_nu, best)
    delta.update({p: delta[p] * widen ** 2 for p in ("mu_s", "mu_k")})
    inside = np.isfinite(field)
    ranges, cut = {}, {}
    for axis, name, values in ((0, "mu_s", surf.ms), (1, "mu_k", surf.mk)):
        region = field <= chi2 + delta[name]
        idx = np.nonzero(region.any(axis=1 - axis))[0]
        ranges[name] = (float(values[idx.min()]), float(values[idx.max()]))
        for end, i, step in (("lo", idx.min(), -1), ("hi", idx.max(), 1)):
            where = _edge(surf, region, inside, axis, i, step)
            if where:
                cut[name, end] = where
    at_best = {a: (float(mean[best]), math.sqrt(var[best])) for a, (mean, var, _) in surf.pred.items()
               if np.isfinite(mean[best])}
    return Result(ms, mk, chi2, field, surf, ranges, cut, at_best, delta, dof, _answer_edge(surf, inside, best),
                  widen)


def _answer_edge(surf, inside, best):
    """What the answer's grid point touches, as a tuple: "map" where a neighbour along mu_s or
    mu_k is off the map (its extent or hull), the law's bound where one is beyond it; the least
    chi2 is then where the map or the law stops, and the targets may ask for a pair beyond it.
    () inside."""
    found = set()
    for axis in (0, 1):
        for step in (-1, 1):
            j = list(best)
            j[axis] += step
            found.add(_beyond(surf, inside, *j))
    return tuple(e for e in ORDER if e in found)


def _edge(surf, region, inside, axis, i, step):
    """What cuts the region's extreme row/column i along `axis`: the edges beyond it there, in
    ORDER ("map": the map's hull or extent; the law's bounds "mu_k = mu_s", "mu_k = mu_s / 2"),
    each once; () where the region closes inside."""
    line = region[i] if axis == 0 else region[:, i]
    found = {_beyond(surf, inside, *((i + step, j) if axis == 0 else (j, i + step))) for j in np.nonzero(line)[0]}
    return tuple(e for e in ORDER if e in found)


def _beyond(surf, inside, s_i, k_i):
    """What lies at grid point (s_i, k_i), a neighbour of a point on the map: None (the map),
    "map" (off the grid, or outside the map's hull within the law's triangle), or the law's
    bound it is beyond ("mu_k = mu_s", "mu_k = mu_s / 2")."""
    if not (0 <= s_i < len(surf.ms) and 0 <= k_i < len(surf.mk)):
        return "map"
    if inside[s_i, k_i]:
        return None
    s, k = surf.ms[s_i], surf.mk[k_i]
    return "mu_k = mu_s" if k > s + 1e-9 else "mu_k = mu_s / 2" if k < s / 2 - 1e-9 else "map"
