"""Headline figures of a run, computed from the standard time series alone.

The same code reads every engine's output, so engines are compared on equal
terms. `summarise(scene, df)` returns the dict written to summary.json.
"""
from __future__ import annotations

import math

import numpy as np

# A slip that follows fewer stick steps than this resolves the stick phase poorly:
# the saw-tooth's rise is then drawn with under 10 points (see docs/precision.md).
RESOLVED_STICK_STEPS = 10


def summarise(scene, df) -> dict:
    kind = scene.analysis["kind"]
    out = {}
    if kind == "drag":
        out = drag(scene, df)
    elif kind == "tray":
        out = tray(scene, df)
    elif kind == "tilt":
        out = tilt(scene, df)
    return out


def _prefix(pair):
    return f"{pair[0]}-{pair[1]}"


def _grain(scene, name):
    return next(g for g in scene.grains if g.name == name)


def slip_rows(df, c):
    """Rows in which the contact slipped at least once."""
    return np.nonzero(df[f"{c}_slip"].to_numpy() > 0)[0]


def stick_resolution(df, c, every):
    """How many stick steps preceded each slip event (needs every step recorded)."""
    if every != 1:
        return None
    slip = df[f"{c}_slip"].to_numpy() > 0
    idx = np.nonzero(slip)[0]
    if len(idx) < 2:
        return None
    return np.diff(idx) - 1


def drag(scene, df):
    """Case 1: saw-tooth between mu_s*Fn and (2 mu_k - mu_s)*Fn (Fig. 9)."""
    c = _prefix(scene.analysis["contact"])
    g = _grain(scene, scene.analysis["grain"])
    fn = df[f"{c}_fn"].to_numpy()
    ratio = np.divide(df[f"{c}_fs"].to_numpy(), fn, out=np.zeros_like(fn), where=fn > 0)
    t = df["t"].to_numpy()
    rows = slip_rows(df, c)
    p = scene.contact
    speed = float(np.linalg.norm(g.velocity))
    fn_mean = float(fn[fn > 0].mean())
    nu_s = p.nu_s if scene.effects["tangential_damping"] else 0.0
    drop = 2 * (p.mu_s - p.mu_k) * fn_mean  # the force the spring must regain after a slip
    out = {
        "fs_fn_max": float(ratio.max()),
        "slip_count": int(df[f"{c}_slip"].sum()),
        "fn_mean_N": fn_mean,
        "drag_speed_mps": speed,
        # Paper's period (section 3.1), and the same less the dashpot's jump nu_s*V at the
        # start of each stick phase, which shortens the spring's travel.
        "slip_period_paper_s": drop / (p.ks * speed) if speed else None,
        "slip_period_expected_s": (drop - nu_s * speed) / (p.ks * speed) if speed else None,
    }
    if len(rows) >= 2:
        # Whole saw-tooth periods: from just after the first slip to the last slip.
        window = slice(rows[0] + 1, rows[-1] + 1)
        out["fs_fn_min"] = float(ratio[window].min())
        out["fs_fn_mean"] = float(ratio[window].mean())
        out["slip_period_s"] = float((t[rows[-1]] - t[rows[0]]) / (len(rows) - 1))
        out["first_slip_s"] = float(t[rows[0]])
    else:
        out.update(fs_fn_min=None, fs_fn_mean=None, slip_period_s=None, first_slip_s=None)
    out.update(_resolution(df, c, scene.output.every))
    return out


def tray(scene, df):
    """Case 2: does grain 1 stay up (Fig. 11)?"""
    name = scene.analysis["grain"]
    g = _grain(scene, name)
    floor = next(w for w in scene.walls if w.name == scene.analysis["floor"])
    y = (df[[f"{name}_x", f"{name}_y"]].to_numpy() - floor.point[:2]) @ floor.normal[:2]
    v = np.hypot(df[f"{name}_vx"].to_numpy(), df[f"{name}_vy"].to_numpy())
    t = df["t"].to_numpy()
    # At rest: speed below 1 um/s from then on (1 um/s is 1e-5 of the 0.03 m/s impact speed).
    moving = np.nonzero(v > 1e-6)[0]
    rest = float(t[moving[-1] + 1]) if len(moving) and moving[-1] + 1 < len(t) else (
        0.0 if not len(moving) else None)
    return {
        "y1_final_m": float(y[-1]),
        "y1_min_m": float(y.min()),
        "radius_m": g.radius,
        # Touching the floor: centre closer to it than one radius.
        "reached_bottom": bool(y[-1] < g.radius),
        "time_to_rest_s": rest,
    }


def tilt(scene, df):
    """Case 3: first slip at tan(beta) = mu_s, then stick-slip, then steady sliding (Figs. 14-15)."""
    name = scene.analysis["grain"]
    c = _prefix(scene.analysis["contact"])
    wall = scene.analysis["wall"]
    every = scene.output.every
    t = df["t"].to_numpy()
    beta = df[f"{wall}_angle"].to_numpy()
    # Speed down the plate: the plate's direction is (cos b, sin b); down-slope is minus that.
    u = -(df[f"{name}_vx"].to_numpy() * np.cos(beta) + df[f"{name}_vy"].to_numpy() * np.sin(beta))
    slips = df[f"{c}_slip"].to_numpy()
    rows = np.nonzero(slips > 0)[0]
    p = scene.contact
    b_stop = max(w.rotation.stop_angle for w in scene.walls if w.name == wall)
    gmag = float(np.linalg.norm(scene.gravity))
    out = {
        "tan_beta_stop": math.tan(b_stop),
        "accel_steady_expected_mps2": gmag * (math.sin(b_stop) - (2 * p.mu_k - p.mu_s) * math.cos(b_stop)),
        "accel_mean_friction_mu_k_mps2": gmag * (math.sin(b_stop) - p.mu_k * math.cos(b_stop)),
        "tan_beta_first_slip": None, "t_first_slip_s": None,
        "accel_stick_slip_mps2": None, "accel_steady_mps2": None, "t_steady_s": None,
        "final_speed_mps": float(u[-1]),
    }
    if not len(rows):
        return out
    first = rows[0]
    out["tan_beta_first_slip"] = float(np.tan(beta[first]))
    out["t_first_slip_s"] = float(t[first])
    # Steady sliding: from the first row after which every step slipped.
    full = slips >= every
    not_full = np.nonzero(~full)[0]
    start = not_full[-1] + 1 if len(not_full) else 0
    if start < len(t) - 2 and start > first:
        out["t_steady_s"] = float(t[start])
        out["accel_steady_mps2"] = float(np.polyfit(t[start:], u[start:], 1)[0])
    end = start if out["t_steady_s"] is not None else len(t) - 1
    if end > first:
        out["accel_stick_slip_mps2"] = float((u[end] - u[first]) / (t[end] - t[first]))
        out["stick_slip_duration_s"] = float(t[end] - t[first])
    # Where the dashpot alone covers the force drop, nu_s*V >= 2(mu_s - mu_k)*Fn, every
    # step slips at any dt: physics, not a time-step artefact (docs/precision.md).
    nu_s = p.nu_s if scene.effects["tangential_damping"] else 0.0
    dashpot = nu_s * np.abs(u) >= 2 * (p.mu_s - p.mu_k) * df[f"{c}_fn"].to_numpy()
    out.update(_resolution(df, c, every, dashpot))
    return out


def _resolution(df, c, every, dashpot=None):
    """How well the run resolved its stick phases. With a row per step: the share of slips
    that followed fewer than RESOLVED_STICK_STEPS stick steps. With coarser rows: the
    share of rows with slips in which every step slipped (no stick step at all). Rows
    flagged in `dashpot` (the dashpot alone makes every step slip) are not counted."""
    slips = df[f"{c}_slip"].to_numpy()
    counted = np.ones(len(slips), bool) if dashpot is None else ~dashpot
    gaps = stick_resolution(df, c, every)
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
    """One clear warning when the stick phases were not resolved by the time step."""
    share = summary.get("slips_underresolved_share")
    what = f"of slips followed fewer than {RESOLVED_STICK_STEPS} stick steps"
    if share is None:
        share = summary.get("rows_all_slip_share")
        what = f"of the recorded intervals with slips (every {scene.output.every} steps) slipped at every step"
    if share is not None and share > 0.1:
        return [f"{share:.0%} {what}: the time step (dt = {scene.dt:g} s) under-resolves the stick phase "
                f"there, so friction sits at (2 mu_k - mu_s)*Fn instead of averaging mu_k*Fn; every step "
                f"slips once V*(Ks*dt + nu_s) >= 2(mu_s - mu_k)*Fn (see docs/precision.md; where nu_s*V alone "
                f"reaches it, that is physics and not counted)"]
    return []
