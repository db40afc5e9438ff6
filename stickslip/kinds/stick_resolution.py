# SPDX-License-Identifier: GPL-2.0-or-later
"""How well a run resolved its stick phases, and the one warning when it did not.

With the step-mode law a slip is tested once per step, so once Ks*|V_s|*dt is a fair
share of the force drop 2(mu_s - mu_k)Fn the saw-tooth's rise is drawn with a few
steps and friction drifts to Fmin (docs/precision.md). The exact mode has no such
dependence, so it is not checked.
"""
from __future__ import annotations

import numpy as np

# A slip that follows fewer stick steps than this resolves the stick phase poorly:
# the saw-tooth's rise is then drawn with under 10 points (see docs/precision.md).
RESOLVED_STICK_STEPS = 10


def slip_rows(df, c):
    """Rows in which the contact slipped at least once."""
    return np.nonzero(df[f"{c}_slip"].to_numpy() > 0)[0]


def stick_steps(df, c, every):
    """How many stick steps preceded each slip event (needs every step recorded)."""
    if every != 1:
        return None
    idx = slip_rows(df, c)
    if len(idx) < 2:
        return None
    return np.diff(idx) - 1


def measure(df, c, every, dashpot=None):
    """With a row per step: the share of slips that followed fewer than
    RESOLVED_STICK_STEPS stick steps. With coarser rows: the share of rows with slips in
    which every step slipped (no stick step at all). Rows flagged in `dashpot` (the
    dashpot alone makes every step slip: physics, at any dt) are not counted."""
    slips = df[f"{c}_slip"].to_numpy()
    counted = np.ones(len(slips), bool) if dashpot is None else ~dashpot
    gaps = stick_steps(df, c, every)
    if gaps is not None:
        gaps = gaps[counted[np.nonzero(slips > 0)[0][1:]]]
        if not len(gaps):
            return {}
        poor = int(np.sum(gaps < RESOLVED_STICK_STEPS))
        return {"stick_steps_median": float(np.median(gaps)), "slips_underresolved_share": poor / len(gaps)}
    rows = (slips > 0) & counted
    if every > 1 and rows.sum() >= 2:
        return {"rows_all_slip_share": float(np.mean(slips[rows] >= every))}
    return {}


def warnings(scene, summary) -> list:
    """One clear warning, saying what to do, when the stick phases were under-resolved."""
    if scene.contact.slip_timing == "exact":
        return []
    share = summary.get("slips_underresolved_share")
    what = f"of slips followed fewer than {RESOLVED_STICK_STEPS} stick steps"
    if share is None:
        share = summary.get("rows_all_slip_share")
        what = f"of the recorded intervals with slips (every {scene.output.every} steps) slipped at every step"
    if share is not None and share > 0.1:
        return [f"{share:.0%} {what}: the time step (dt = {scene.dt:g} s) under-resolves the stick phase "
                f"there, so friction drifts from mu_k*Fn towards (2 mu_k - mu_s)*Fn (every step slips once "
                f"V*(Ks*dt + nu_s) >= 2(mu_s - mu_k)*Fn). Use a smaller dt, or [contact] slip_timing = \"exact\" "
                f"(--slip-timing exact), which places each slip at its time inside the step and does not "
                f"depend on dt (docs/precision.md)"]
    return []
