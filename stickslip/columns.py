# SPDX-License-Identifier: GPL-2.0-or-later
"""The time-series columns every engine writes (docs/adapters.md): the names live here only.

`names(scene)` is the full header, in order; it needs nothing but the standard library,
so YADE's runner (system Python) uses it too. `frame(scene, rec)` turns recorded arrays
(pyref's Recording, or an adapter's arrays with the same fields) into the DataFrame.
"""
from __future__ import annotations

# Energy books with output.energy: kinetic, elastic (springs), dissipated by contacts
# (of which the tangential law's slips and dashpot), work of gravity and of the drive.
ENERGY = ("e_kin", "e_elastic", "e_dissipated", "e_slip", "e_dashpot", "w_gravity", "w_drive")
STATS = ("n_contacts", "ekin")
# Slip statistics with output.slip_stats, over the grain-grain contacts pressed together
# at the row (Fn > 0; wall contacts are not counted): how many slipped in the row's step, how many of those
# slide (|V_s|) at or above the dashpot threshold V_d = 2(mu_s - mu_k) Fn / nu_s and above
# V* = 2(mu_s - mu_k) Fn / (nu_s + Ks dt) (docs/law.md: above them every step slips; nu_s
# = 0: V_d is infinite), and the sum of |Fs|/Fn over those (its mean: / n_slipping).
SLIP_STATS = ("n_slipping", "n_slip_above_vd", "n_slip_above_vstar", "slip_fs_fn_sum")
# output.bulk: the moving grains' centre of mass and its velocity (m, m/s).
BULK = ("com_x", "com_y", "com_z", "vcm_x", "vcm_y", "vcm_z")
# With a gravity_ramp: the angle gravity has turned by over the interval that ends at the
# row (rad) and the index of that interval's phase.
RAMP = ("tilt", "phase")
# With a [lid]: its displacement along x since the start (m), its centre's height (m), its
# velocity along x (m/s) and the spring's pull on it along x (N).
LID = ("lid_x", "lid_z", "lid_vx", "lid_force")


def grain(name, dim, rotation):
    axes = "xyz"[:dim]
    spin = (["wz"] if dim == 2 else [f"w{a}" for a in axes]) if rotation else []
    return [f"{name}_{a}" for a in axes] + [f"{name}_v{a}" for a in axes] + [f"{name}_{w}" for w in spin]


def contact(a, b, dim):
    c = f"{a}-{b}"
    return [f"{c}_fn", f"{c}_fs"] + [f"{c}_ft{x}" for x in "xyz"[:dim]] + [f"{c}_slip"]


def wall(name):
    return [f"{name}_angle"]


def names(scene):
    """Every column of a scene's time series, in order."""
    out, d = scene.output, scene.dimension
    cols = ["t"]
    for g in out.grains:
        cols += grain(g, d, scene.effects["rotation"])
    for a, b in out.contacts:
        cols += contact(a, b, d)
    for w in out.walls:
        cols += wall(w)
    if out.stats:
        cols += STATS
    if out.slip_stats:
        cols += SLIP_STATS
    if out.energy:
        cols += ENERGY
    if out.bulk:
        cols += BULK
    if getattr(scene, "lid", None) is not None:
        cols += LID
    if scene.gravity_ramp is not None:
        cols += RAMP
    return cols


def frame(scene, rec):
    """The DataFrame of a run from recorded arrays (fields as pyref.Recording's)."""
    import numpy as np
    import pandas as pd

    out, d = scene.output, scene.dimension
    cols = {"t": rec.t}
    for k, g in enumerate(out.grains):
        parts = [rec.x[:, k], rec.v[:, k]] + ([rec.w[:, k]] if scene.effects["rotation"] else [])
        cols.update(zip(grain(g, d, scene.effects["rotation"]), np.hstack(parts).T))
    for k, (a, b) in enumerate(out.contacts):
        ft = rec.ft[:, k]
        values = [rec.fn[:, k], np.linalg.norm(ft, axis=1), *ft.T, rec.slips[:, k]]
        cols.update(zip(contact(a, b, d), values))
    for k, w in enumerate(out.walls):
        cols[wall(w)[0]] = rec.angle[:, k]
    if out.stats:
        cols.update(n_contacts=rec.n_contacts, ekin=rec.ekin)
    if out.slip_stats:
        cols.update(zip(SLIP_STATS, rec.slip_stats.T))
    if out.energy:
        cols.update({e: rec.energy[e] for e in ENERGY})
    df = pd.DataFrame(cols)
    assert list(df.columns) == names(scene), "column order differs from columns.names"
    return df
