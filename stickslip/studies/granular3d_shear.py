# SPDX-License-Identifier: GPL-2.0-or-later
"""The sheared layer's tables (kind shear3d, docs/granular-3d.md "A measurement that tells μs
from μk"), written by `stickslip study-3d` beside its others once the study ran the layer:

- sensitivity.csv: each observable of the layer (shear_peak, shear_steady, shear_dilation) against
  mu_s - mu_k on each line of fixed mu_k (granular3d.SHEAR_LINES, no rolling resistance): the
  weighted least-squares slope per unit of mu_s - mu_k, its standard error and z = slope / se,
  and the resolution: the median standard error of one point (its fills) over |slope|, the
  mu_s - mu_k that one measurement tells apart; beside them the incline's hysteresis theta_start -
  theta_stop over the map's pairs (granular3d_tables.hysteresis), in the same terms;
- shear_engines.csv: LAMMPS against LIGGGHTS on the point both ran.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from . import granular3d_tables

OBSERVABLES = ("shear_peak", "shear_steady", "shear_dilation")


def _fit(x, y, e):
    """(slope, se) of the weighted least-squares line (granular3d_tables.weighted_line), or
    (nan, nan) where it has none."""
    line = granular3d_tables.weighted_line(x, y, e)
    return (float(line[1]), line[2]) if line is not None else (math.nan, math.nan)


def sensitivity(pts):
    rows = []
    sh = pts[(pts.kind == "shear") & (pts.engine == "liggghts") & (pts.group == "shear") & (pts["rolling"] == 0)]
    for mu_k in sorted(sh.mu_k.unique()):
        line = sh[np.isclose(sh.mu_k, mu_k)]
        if len(line) < 3:
            continue
        x = (line.mu_s - line.mu_k).to_numpy(float)
        for obs in OBSERVABLES:
            if f"{obs}_mean" not in line:
                continue
            e = line[f"{obs}_se"].to_numpy(float)
            slope, se = _fit(x, line[f"{obs}_mean"].to_numpy(float), e)
            point_se = float(np.median(e[np.isfinite(e)])) if np.isfinite(e).any() else math.nan
            rows.append({"measurement": f"shear3d {obs}", "mu_k": mu_k, "points": len(line),
                         "mu_s_minus_mu_k": f"{x.min():g}-{x.max():g}", "slope_per_unit": slope, "slope_se": se,
                         "z": slope / se if se else math.nan, "point_se": point_se,
                         "resolution": point_se / abs(slope) if slope else math.nan})
    hyst = granular3d_tables.hysteresis(pts)
    if not len(hyst):
        return pd.DataFrame(rows)
    inc = pts[(pts.kind == "incline") & (pts.engine == "liggghts") & (pts.group == "sweep") & (pts["rolling"] == 0)]
    e = np.hypot(inc.theta_start_se, inc.theta_stop_se).to_numpy(float)
    e = float(np.median(e[np.isfinite(e)])) if np.isfinite(e).any() else math.nan
    for _, h in hyst[(hyst["rolling"] == 0) & (hyst.nu_s == "paper")].iterrows():
        rows.append({"measurement": "incline theta_start - theta_stop (deg)", "mu_k": math.nan, "points": h.points,
                     "mu_s_minus_mu_k": "map", "slope_per_unit": h.slope_deg_per_unit_mu, "slope_se": h.slope_se,
                     "z": h.z, "point_se": e, "resolution": e / abs(h.slope_deg_per_unit_mu)})
    return pd.DataFrame(rows)


def engines(pts):
    """LAMMPS against LIGGGHTS on the sheared layer's points both ran: difference and z."""
    rows = []
    sh = pts[pts.kind == "shear"]
    for _, p in sh[sh.engine == "lammps"].iterrows():
        q = sh[(sh.engine == "liggghts") & (sh.material == p.material) & (sh.nu_s == p.nu_s) &
               (sh.timing == p.timing) & (sh["rolling"] == p["rolling"])]
        if not len(q):
            continue
        q = q.iloc[0]
        for obs in OBSERVABLES:
            if f"{obs}_mean" in p:
                rows.append({"material": p.material, "observable": obs, "liggghts": q[f"{obs}_mean"],
                             "lammps": p[f"{obs}_mean"], "difference": p[f"{obs}_mean"] - q[f"{obs}_mean"],
                             "z": granular3d_tables._z(p[f"{obs}_mean"], p[f"{obs}_se"], q[f"{obs}_mean"],
                                                      q[f"{obs}_se"])})
    return pd.DataFrame(rows)


def write(out, pts):
    """sensitivity.csv and shear_engines.csv when the study ran the sheared layer; {name: table}."""
    if not (pts.kind == "shear").any():
        return {}
    tables = {"sensitivity.csv": sensitivity(pts), "shear_engines.csv": engines(pts)}
    for name, t in tables.items():
        t.to_csv(out / name, index=False)
    return tables


def markdown(tables):
    from .granular3d_tables import _md

    if "sensitivity.csv" not in tables:
        return ""
    return "\n".join(["## The sheared layer against mu_s - mu_k", "",
                      "Slopes per unit of μs − μk at fixed μk ([sensitivity.csv](sensitivity.csv)); resolution: one "
                      "point's standard error over |slope|.", "", _md(tables["sensitivity.csv"],
                                                                          list(tables["sensitivity.csv"].columns),
                                                                          ".3g"),
                      "LAMMPS against LIGGGHTS:", "", _md(tables["shear_engines.csv"],
                                                            ["material", "observable", "liggghts", "lammps",
                                                             "difference", "z"], ".3f")])
