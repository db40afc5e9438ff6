# SPDX-License-Identifier: GPL-2.0-or-later
"""Two engines that do the same arithmetic in another order, row by row: the round-off bound.

At each step an engine may round a coordinate differently, by u L (L: the largest coordinate
a contact is computed from), and an overlap by up to 4 u L more (a wall that turns a
grain's offset into its own frame and back); the dynamics is stable and dissipative, so
such errors add up without growing (a perturbed oscillator keeps its perturbation's
amplitude): after k steps positions differ by at most dx = (k + 4) u L and velocities by
dv = w dx, w = sqrt((Kn + Ks)/m_eff) the fastest contact frequency (m_eff: half the
lightest grain); normal forces by Kn dx + nu_n dv, tangential ones by Ks dx + nu_s dv, and
slips fall in the same steps (a slip moves only if the trial force ends a step within ~Ks dx
of mu_s Fn; it changes by Ks |V_s| dt, 1e5 times more, per step). Wall angles and times come
from the same formula on both: equal.
"""
import math

import numpy as np

U = np.finfo(float).eps / 2  # unit round-off, 1.1e-16


def assert_round_off_apart(sc, de, dp, min_length=0.0, slips_where_pressed=False):
    """Engine `de` against pyref's `dp`, every column of every row, within the bound above.
    min_length: a floor for L (a turning wall built as a box of that half thickness).
    slips_where_pressed: compare slip flags only over rows that begin and end with a normal
    force on both engines (an engine whose wall contact begins at zero overlap, where it
    slips with zero force, and pyref has no contact)."""
    assert list(de.columns) == list(dp.columns) and len(de) == len(dp)
    c = sc.contact
    k = (dp["t"].to_numpy() / sc.dt).round()  # steps made by each row
    L = max(np.abs(dp[[col for col in dp.columns if col.endswith(("_x", "_y", "_z"))]].to_numpy()).max(), min_length)
    m_eff = min(sc.grain_mass(g) for g in sc.grains) / 2
    dx = (k + 4) * U * L
    dv = math.sqrt((c.kn + c.ks) / m_eff) * dx
    nu_n = c.nu_n if sc.effects["normal_damping"] else 0.0
    nu_s = c.nu_s if sc.effects["tangential_damping"] else 0.0
    for col in dp.columns:
        y, p = de[col].to_numpy(), dp[col].to_numpy()
        if col.endswith("_slip") and slips_where_pressed:
            fn = col[:-len("_slip")] + "_fn"
            pressed = (de[fn].to_numpy() > 0) & (dp[fn].to_numpy() > 0)
            whole = pressed & np.concatenate(([False], pressed[:-1]))  # at the row and the one before
            y, p, bound = y[whole], p[whole], np.zeros(whole.sum())
        elif col == "t" or col.endswith(("_slip", "_angle")):
            bound = np.zeros_like(k)
        elif col.endswith(("_x", "_y", "_z")):
            bound = dx
        elif col.endswith(("_vx", "_vy", "_vz")):
            bound = dv
        elif col.endswith("_fn"):
            bound = c.kn * dx + nu_n * dv
        elif col.endswith(("_fs", "_ftx", "_fty", "_ftz")):
            bound = c.ks * dx + nu_s * dv
        else:
            raise AssertionError(f"no bound for column {col}")
        worst = int(np.argmax(np.abs(y - p) - bound))
        assert np.all(np.abs(y - p) <= bound), (col, worst, y[worst], p[worst], bound[worst])
