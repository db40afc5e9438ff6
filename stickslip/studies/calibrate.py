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

theta_stop is taken at a fixed angle: the study's ramp measures it while the angle falls, and
the flow's lag puts it below the angle at which a flow held at a fixed angle stops (the angle
a user's experiment gives). The lag measured on stock history mu = 0.5, 10 d bed, is added to
the map's theta_stop, its standard error to the map's (calibrate_map.lag_of).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from .. import shipped
from ..errors import SceneError
from . import calibrate_fit, calibrate_map

AGREEMENT_P = 0.05  # the least chi2's tail probability below which the targets disagree

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


def _range_line(r, name, other):
    (lo, hi), value = r.ranges[name], getattr(r, name)
    text = f"{name} = {value:.3f} (one standard error, {other} profiled: {lo:.3f} to {hi:.3f}"
    for end, bound in (("lo", lo), ("hi", hi)):
        where = r.cut.get((name, end))
        if where == "map":
            text += f"; the range reaches the map's edge at {name} = {bound:.3f}: a bound, not a standard error"
        elif where:
            text += f"; the range reaches the law's bound {where} at {name} = {bound:.3f}: a bound, not a standard error"
    return text + ")"


def _k(r, name):
    dof = r.dof[name]
    return f"k {math.sqrt(r.delta[name]):.2f} ({'known errors' if not math.isfinite(dof) else f'{dof:.1f} dof'})"


def _agreement_line(chi2, dof):
    """With more targets than the two coefficients, the least chi2 tests whether the targets
    agree with each other on the map: its tail probability at (targets - 2) degrees of freedom,
    read as for known errors (errors from a few fills make the tail heavier: a p just below the
    line is weak evidence)."""
    from scipy.stats import chi2 as chi2_dist

    p = float(chi2_dist.sf(chi2, dof))
    text = f"agreement: least chi2 {chi2:.2f} at {dof} degree{'s' if dof > 1 else ''} of freedom (targets less 2), p = {p:.3f}"
    if p < AGREEMENT_P:
        text += (f"; below {AGREEMENT_P}: the targets do not agree with each other on the map (one may be off, or "
                 "its error too small), and the ranges are narrower than they should be")
    return text


def main(args):
    targets = targets_of(args)
    path = args.map or DOCS / "points.csv"
    pts = calibrate_map.read_points(path)
    lag = calibrate_map.lag_of(path, pts)
    surf, rows = prepare(pts, args.rolling, getattr(args, "interpolation", "auto") or "auto", lag, f"--map {path}")
    r = calibrate_fit.solve(targets, surf)
    print(_range_line(r, "mu_s", "mu_k"))
    print(_range_line(r, "mu_k", "mu_s"))
    if r.edge:
        print(f"edge: the least chi2 lies on the map's edge (mu_s {r.mu_s:.3f}, mu_k {r.mu_k:.3f}): the map does not "
              "bracket the answer, which may lie beyond it; read it as a bound and the region as what the targets allow")
    print(f"2 mu_k - mu_s = {2 * r.mu_k - r.mu_s:.3f} (the force a slipping contact holds, over Fn)")
    print(f"ranges: chi2 within k^2 of its least, the other coefficient profiled (each one's own 68 %: k = 1 for known "
          f"errors), k Student's t at the degrees of freedom of the errors it comes from: mu_s {_k(r, 'mu_s')}, mu_k "
          f"{_k(r, 'mu_k')}; the joint 68 % region of (mu_s, mu_k) is chi2 within {r.delta['joint']:.2f} of its least"
          + (" (drawn in --region-png)" if args.region_png else " (--region-png draws it)"))
    print("targets: " + ", ".join(f"{a} {t.value:.2f}" + (f" +- {t.se:.2f}" if t.se else "") + UNIT.get(a, " deg")
                                  + (f" (mean of {t.n})" if t.n else "" if t.se else " (exact)")
                                  for a, t in targets.items()))
    if len(targets) > 2:
        print(_agreement_line(r.chi2, len(targets) - 2))
    s = calibrate_map.scores(rows)
    score = "; ".join(f"{m} {v:.2f}" for m, (v, _) in s.items() if np.isfinite(v))
    n = max((v[1] for v in s.values()), default=0)
    print("the map there: " + ", ".join(f"{a} {v:.1f} +- {e:.1f}" + UNIT.get(a, " deg") for a, (v, e) in
                                          r.at_best.items())
          + f" (chi2 {r.chi2:.2f}); interpolation {surf.method}"
          + (f" (leave-one-out mean (residual/se)^2 on {n} points: {score})" if score else "")
          + f"; rolling resistance {args.rolling:g}, the paper's nu_s (0.8 nu_n), step mode; the scenes of "
            "docs/granular-3d.md")
    print("errors: the map's, its interpolation's own (leave-one-out: " + ", ".join(
        f"{t} {e:.2f}{UNIT.get(t, ' deg')}" for t, e in surf.interp.items()) + ") and the target's in quadrature")
    lag_value, lag_se, how = lag
    print({"fixed": f"theta_stop at a fixed angle: the ramp's value + {lag_value:.1f} +- {lag_se:.1f} deg (its lag to "
                    "beds held at fixed angles, measured)",
           "ramp": f"theta_stop at zero rate: the ramp's value + {lag_value:.1f} +- {lag_se:.1f} deg (its lag, from "
                   "half rates)",
           None: "theta_stop as the ramp measured it (the map has no measure of the ramp's lag)"}[how])
    if args.region_png:
        from . import calibrate_region

        print(f"wrote {calibrate_region.draw(r, targets, pts, args.rolling, args.region_png)}")
    return r
