# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip calibrate`: mu_s and mu_k for what a user measured on their material, from the map
`stickslip study-3d` measured (docs/granular-3d/points.csv; docs/granular-3d.md).

The targets: two or more of theta_start, theta_stop (incline), theta_heap (heap), shear_peak,
shear_steady (the sheared layer's tau/sigma) and shear_dilation (its lid's rise, in grain
diameters), the last three once the map has them, each a value with its
standard error (--theta-start-se ...; none: exact), or a CSV of repeated measurements (a
column per target, one row per repeat, n >= 2: the mean and its standard error std/sqrt(n),
with n - 1 degrees of freedom). The map: calibrate_map.py (its points and the interpolation
that leave-one-out chooses, or --interpolation); the answer and its ranges: calibrate_fit.py.
The region can be drawn on the map (--region-png, calibrate_region.py).

What it prints: the answer first, each coefficient with as many digits as its range allows and
its range's ends that are edges (the map's, the law's bounds) said to be such; one line on what
the ranges mean; a line for an answer on an edge and for targets that disagree. --details adds
the statistics behind it, --json prints the whole answer (`answer`) for scripts instead.

theta_stop is taken at a fixed angle: the study's ramp measures it while the angle falls, and
the flow's lag puts it below the angle at which a flow held at a fixed angle stops (the angle
a user's experiment gives). The lag measured on stock history mu = 0.5, 10 d bed, is added to
the map's theta_stop, its standard error to the map's (calibrate_map.lag_of).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from .. import shipped
from ..errors import SceneError
from . import calibrate_fit, calibrate_map

AGREEMENT_P = 0.05  # the least chi2's tail probability below which the targets disagree
EDGE = {"map": "the map's edge", "mu_k = mu_s": "the law's bound mu_k = mu_s",
        "mu_k = mu_s / 2": "the law's bound mu_k = mu_s / 2"}
# What an answer on each edge means: the targets may ask for a pair beyond it.
BEYOND = {"map": "the map does not bracket it, and the pair the targets ask for may lie beyond the map",
          "mu_k = mu_s": "stock history, no stick-slip; the targets may ask for mu_k above mu_s, which the law "
                         "does not allow",
          "mu_k = mu_s / 2": "a slipping contact holds no force (2 mu_k - mu_s = 0); the targets may ask for mu_k "
                             "below mu_s / 2, which the law does not allow"}

DOCS = shipped.path("docs/granular-3d")
TARGETS = calibrate_map.TARGETS
OPTION = calibrate_fit.OPTION
UNIT = {"shear_peak": "", "shear_steady": "", "shear_dilation": " d"}  # the angles are in degrees


def read_measurements(path):
    """{target: Target} from a CSV of repeats: mean, standard error std/sqrt(n), n."""
    path = Path(path)
    try:
        df = pd.read_csv(path)
    except (OSError, ValueError, pd.errors.ParserError) as e:
        raise SceneError(f"--measurements {path}: cannot be read as CSV ({' '.join(str(e).split())[:120]})") from None
    unknown = [c for c in df.columns if c not in TARGETS]
    if unknown or not len(df.columns):
        raise SceneError(f"--measurements {path}: column {unknown[0] if unknown else '(none)'!r}: the columns must be "
                         f"among {', '.join(TARGETS)}")
    out = {}
    for c in df.columns:
        v = pd.to_numeric(df[c], errors="coerce")
        bad = df[c][v.isna() & df[c].notna()]
        if len(bad):
            raise SceneError(f"--measurements {path}: {c} = {bad.iloc[0]!r}: not a number")
        v = v.dropna().to_numpy(float)
        lo, hi, what = calibrate_fit.ALLOWED[c]
        if len(v) and not ((v > lo) & (v < hi)).all():
            raise SceneError(f"--measurements {path}: {c} = {v[~((v > lo) & (v < hi))][0]:g}: must be {what}, in "
                             f"({lo:g}, {hi:g})")
        if len(v) < 2:
            raise SceneError(f"--measurements {path}: {c} has {len(v)} value(s): needs n >= 2 repeats for a "
                             "standard error")
        out[c] = calibrate_fit.Target(float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))), len(v))
    return out


def targets_of(args):
    """{target: Target} from the command's options, or SceneError in one line."""
    out = read_measurements(args.measurements) if getattr(args, "measurements", None) else {}
    for a in TARGETS:
        v, se = getattr(args, a, None), getattr(args, f"{a}_se", None)
        if v is None:
            if se is not None:
                raise SceneError(f"{OPTION[a]}-se {se:g}: give {OPTION[a]} too")
            continue
        if a in out:
            raise SceneError(f"{OPTION[a]} {v:g}: {a} is also in --measurements {args.measurements}; give it once")
        out[a] = calibrate_fit.Target(v, se or 0.0)
    if len(out) < 2:
        raise SceneError("calibrate: give at least two of --theta-start, --theta-stop, --theta-heap, --shear-peak, "
                         "--shear-steady, --shear-dilation (or a --measurements file)")
    return out


def prepare(pts, rolling, method="auto", lag=(math.nan, math.nan, None), source="the map"):
    """The surfaces of the map at this rolling resistance, by `method` ("auto": the one of
    smaller leave-one-out error), the interpolation's own error added, and the leave-one-out
    rows they came from."""
    m = calibrate_map.from_points(pts, rolling, source=source)
    rows = calibrate_map.loo(m)
    chosen = calibrate_map.choose(rows) if method == "auto" else method
    err = calibrate_map.interp_error(rows)
    interp = {t: err.get((t, chosen), (0.0, 0))[0] for t in m}
    return calibrate_fit.surfaces(m, chosen, interp, lag), rows


def decimals(lo, hi):
    """The decimals a range of this width allows: its half-width to one significant digit (two
    where that digit is 1), from 1 to 3 (the grid's step is 0.0025)."""
    half = max((hi - lo) / 2, calibrate_fit.GRID)
    exp = math.floor(math.log10(half))
    return min(max(-exp + (half / 10 ** exp < 2), 1), 3)


def _finite(x):
    """x for JSON: NaN and infinities as None, numpy's numbers as Python's."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    return x.item() if isinstance(x, np.generic) else x


def answer(r, targets, surf, rows, lag, path, rolling, widening):
    """The whole answer as a dict (what --json prints; the text is made from it): each
    coefficient's value, range and the edges that cut it, the answer's own edges, what the
    ranges are, the targets, the map at the answer (for the targets given), its interpolation and
    the theta_stop lag taken."""
    from scipy.stats import chi2 as chi2_dist

    coefficients = {}
    for name in ("mu_s", "mu_k"):
        lo, hi = r.ranges[name]
        values = r.surf.ms if name == "mu_s" else r.surf.mk
        coefficients[name] = {"value": getattr(r, name), "range": [lo, hi],
                              "cut": {"low": r.cut.get((name, "lo")), "high": r.cut.get((name, "hi"))},
                              "extent": [float(values.min()), float(values.max())],
                              "k": math.sqrt(r.delta[name]) / r.widen, "dof": r.dof[name]}
    dof = len(targets) - 2
    s = calibrate_map.scores(rows)
    return _finite({
        **coefficients, "fmin_over_fn": 2 * r.mu_k - r.mu_s, "edge": list(r.edge),
        "ranges": {"confidence": calibrate_fit.COVER, "widened_by": r.widen, "widening_from_ranges": widening[1],
                   "joint_delta_chi2": r.delta["joint"], "note": widening[2]},
        "chi2": r.chi2,
        "agreement": {"dof": dof, "p": float(chi2_dist.sf(r.chi2, dof))} if dof > 0 else None,
        "targets": {a: {"value": t.value, "se": t.se, "n": t.n} for a, t in targets.items()},
        "map_at_answer": {a: {"mean": r.at_best[a][0], "se": r.at_best[a][1]} for a in targets if a in r.at_best},
        "interpolation": {"method": surf.method, "own_error": {a: surf.interp.get(a, 0.0) for a in targets},
                          "leave_one_out": {m: v for m, (v, _) in s.items()},
                          "leave_one_out_points": max((v[1] for v in s.values()), default=0)},
        "theta_stop_lag": {"value": lag[0], "se": lag[1], "measured_as": lag[2]},
        "map": str(path), "rolling": rolling})


def _number(value, d):
    return f"{value:.{d}f}"


def _exact(value, d):
    """`value` (a point of the grid: a multiple of its step) with at least d decimals and as
    many more as it needs, up to the grid's 4."""
    return next(_number(value, k) for k in range(d, 5) if abs(round(value, k) - value) < 1e-9 or k == 4)


def _outward(value, d, side, extent):
    """An uncut end rounded outwards (down for the low end, up for the high one) to d decimals,
    or to more where that would reach the map's extent: a printed end that is the map's edge
    must be one (only a cut end is, and it is printed as it is)."""
    for k in range(d, 5):
        shown = (math.floor(value * 10 ** k + 1e-6) if side == "low" else math.ceil(value * 10 ** k - 1e-6)) / 10 ** k
        if extent[0] + 1e-9 < shown < extent[1] - 1e-9:
            return _number(shown, k)
    return _exact(value, d)


def _coefficient_line(name, c):
    """"mu_s = 0.6 (0.3475 to 0.93; 0.3475 is the law's bound mu_k = mu_s, not an uncertainty)":
    the value to the digits its range allows; an end that an edge cuts printed as it is (the
    edge's value there), the others rounded outwards without reaching the map's extent, so that
    the printed range holds the computed one and each end named an edge is that edge."""
    (lo, hi), d = c["range"], decimals(*c["range"])
    ends = [(_exact(v, d) if c["cut"][side] else _outward(v, d, side, c["extent"]), side)
            for v, side in ((lo, "low"), (hi, "high"))]
    text = f"{name} = {_number(c['value'], d)} ({ends[0][0]} to {ends[1][0]}"
    for end, side in ends:
        if c["cut"][side]:
            text += f"; {end} is {' and '.join(EDGE[e] for e in c['cut'][side])}, not an uncertainty"
    return text + ")"


def _ranges_line(a):
    widened, cover = a["ranges"]["widened_by"], f"{a['ranges']['confidence'] * 100:.0f} %"
    how = (f", widened by {widened:.2f} as measured on the map's own points" if widened > 1 else
           "" if a["ranges"]["widening_from_ranges"] else "; not widened (first line)")
    return (f"each range: where its coefficient lies with {cover} confidence, the other left free (the map's spread, "
            f"its interpolation's error and the targets' errors{how}); --details: the statistics")


def _agreement_text(a):
    """The agreement line of --details, and the warning of the plain answer where the targets
    disagree (None where they agree or are only two). With more targets than the two
    coefficients the least chi2 tests whether they agree with each other on the map: its tail
    probability at (targets - 2) degrees of freedom, read as for known errors (errors from a few
    fills make the tail heavier: a p just below the line is weak evidence)."""
    g = a["agreement"]
    if not g:
        return None, None
    line = (f"agreement: least chi2 {a['chi2']:.2f} at {g['dof']} degree{'s' if g['dof'] > 1 else ''} of freedom "
            f"(targets less 2), p = {g['p']:.3f}")
    if g["p"] >= AGREEMENT_P:
        return line, None
    return line, (f"warning: the targets do not agree with each other on the map (p = {g['p']:.3f}, below "
                  f"{AGREEMENT_P}): one may be off, or its error too small, and the ranges are then too narrow")


def plain(a):
    """The answer in plain words: the lines calibrate prints without --details."""
    note = a["ranges"]["note"]
    lines = [note] if note else []
    lines += [_coefficient_line(n, a[n]) for n in ("mu_s", "mu_k")] + [_ranges_line(a)]
    lines += [f"edge: the answer lies on {EDGE[e]} (mu_s {a['mu_s']['value']:.3f}, mu_k {a['mu_k']['value']:.3f}): "
              f"{BEYOND[e]}; read it as a bound" for e in a["edge"]]
    warning = _agreement_text(a)[1]
    return lines + ([warning] if warning else [])


def _k(c):
    dof = "known errors" if c["dof"] is None else f"{c['dof']:.1f} dof"
    return f"k {c['k']:.2f} ({dof})"


def details(a):
    """The statistics behind the answer: the lines --details adds."""
    unit = lambda name: UNIT.get(name, " deg")  # noqa: E731
    ranges = a["ranges"]
    lines = [f"2 mu_k - mu_s = {a['fmin_over_fn']:.3f} (the force a slipping contact holds, over Fn)",
             "ranges: chi2 within (k f)^2 of its least, the other coefficient profiled; k Student's t at the degrees "
             f"of freedom of the errors the coefficient comes from (1 for known errors): mu_s {_k(a['mu_s'])}, mu_k "
             f"{_k(a['mu_k'])}; "
             + ("f = 1, not widened (first line)" if ranges["note"] else
                f"f = {ranges['widened_by']:.2f}, the widening that makes 68 % of the ranges hold the truth when each "
                "of the map's points is left out and answered by the others "
                f"({ranges['widening_from_ranges']} ranges, leave_pair_out.csv)")
             + "; the joint 68 % region of (mu_s, mu_k) is chi2 within "
             f"{ranges['joint_delta_chi2']:.2f} of its least (--region-png draws it)",
             "targets: " + ", ".join(f"{n} {t['value']:.2f}" + (f" +- {t['se']:.2f}" if t["se"] else "") + unit(n)
                                     + (f" (mean of {t['n']})" if t["n"] else "" if t["se"] else " (exact)")
                                     for n, t in a["targets"].items())]
    agreement = _agreement_text(a)[0]
    lines += [agreement] if agreement else []
    i = a["interpolation"]
    scores = "; ".join(f"{m} {v:.2f}" for m, v in i["leave_one_out"].items() if v is not None)
    lines += ["the map at the answer: " + ", ".join(f"{n} {v['mean']:.1f} +- {v['se']:.1f}{unit(n)}"
                                                  for n, v in a["map_at_answer"].items()) + f" (chi2 {a['chi2']:.2f})",
              f"interpolation: {i['method']}" + (f" (leave-one-out mean (residual/se)^2 on {i['leave_one_out_points']} "
                                                 f"points: {scores})" if scores else "")
              + "; its own error, added to the map's and the target's in quadrature: "
              + ", ".join(f"{n} {e:.2f}{unit(n)}" for n, e in i["own_error"].items()),
              f"the map: {a['map']}, rolling resistance {a['rolling']:g}, the paper's nu_s (0.8 nu_n), step mode; the "
              "scenes of docs/granular-3d.md"]
    lag = a["theta_stop_lag"]
    if lag["measured_as"] is None:
        return lines + ["theta_stop as the ramp measured it (the map has no measure of the ramp's lag)"]
    return lines + [f"theta_stop at {'a fixed angle' if lag['measured_as'] == 'fixed' else 'zero rate'}: the ramp's "
                    f"value + {lag['value']:.1f} +- {lag['se']:.1f} deg ("
                    + ("its lag to beds held at fixed angles, measured)" if lag["measured_as"] == "fixed" else
                       "its lag, from half rates)")]


def main(args):
    targets = targets_of(args)
    path = args.map or DOCS / "points.csv"
    pts = calibrate_map.read_points(path)
    lag = calibrate_map.lag_of(path, pts)
    surf, rows = prepare(pts, args.rolling, getattr(args, "interpolation", "auto") or "auto", lag, f"--map {path}")
    widening = calibrate_map.widening_of(path, args.rolling)
    r = calibrate_fit.solve(targets, surf, widening[0])
    a = answer(r, targets, surf, rows, lag, args.map or "docs/granular-3d/points.csv", args.rolling, widening)
    if args.region_png:
        from . import calibrate_region

        a["region_png"] = str(calibrate_region.draw(r, targets, pts, args.rolling, args.region_png))
    if getattr(args, "json", False):
        print(json.dumps(a, indent=2))
        return r
    print("\n".join(plain(a) + (details(a) if getattr(args, "details", False) else [])))
    if args.region_png:
        print(f"wrote {a['region_png']}")
    return r
