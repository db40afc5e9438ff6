# SPDX-License-Identifier: GPL-2.0-or-later
"""The contact laws of Khellaf & Mansouri (2024), vectorised over contacts.

This is the one numpy kernel of the law: pyref and the YADE law both call it
(yade_law/stickslip_yade/kernel.py imports this file). It follows docs/law.md line by
line. Arrays have one row per contact; vectors are (K, 3). It needs numpy only.
Sign convention: forces are those acting on grain i; `V_s` is the tangential
velocity of i's contact point relative to j's, so friction opposes it.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

LAWS = ("stick_slip", "visco_elastic", "visco_plastic", "coulomb", "static_dynamic")
SPRING_LAWS = ("stick_slip", "visco_elastic", "static_dynamic")  # those with a tangential spring Ks
# The law's options (docs/law.md), as the scene file, pyref, the YADE law and DEM-Engine's
# model name them: each option's values, the law's default first. Each engine's spelling of
# them, and of the options only an engine has, is stickslip/law_options.py's table.
OPTIONS = {"reset": ("spring", "total"), "slip_timing": ("step", "exact")}
RESETS, SLIP_TIMINGS = OPTIONS["reset"], OPTIONS["slip_timing"]

# Exact slip timing (docs/law.md, "Exact slip timing"): slips are followed one by one
# until the force direction has settled along -V_s (its part across -V_s below
# SETTLED times mu_s*Fn, so that it changes the slip level by less than round-off,
# SETTLED^2/2 < 1e-16) or MAX_EXPLICIT_SLIPS slips have been followed in the step;
# the remaining slips of the step then have a closed form.
SETTLED = 1e-8
MAX_EXPLICIT_SLIPS = 100

# numpy's C einsum and count_nonzero themselves. np.einsum without `optimize` is exactly
# c_einsum behind a Python wrapper and the array-function dispatch; on a few rows those
# layers cost as much again as the work (np.count_nonzero's ten times as much), and a small
# scene's step is numpy's per-call overhead: same arithmetic, called directly.
try:  # numpy 2 (the project's venv)
    from numpy._core.multiarray import c_einsum as _einsum, count_nonzero as _count_nonzero
except ImportError:
    try:  # numpy 1 (Debian's python3-numpy, which YADE runs the law with)
        from numpy.core.multiarray import c_einsum as _einsum, count_nonzero as _count_nonzero
    except ImportError:
        _einsum, _count_nonzero = np.einsum, np.count_nonzero


@dataclass
class LawParams:
    law: str  # stick_slip | visco_elastic | visco_plastic | coulomb | static_dynamic
    kn: float | None  # None: a caller with its own normal law (the YADE law) does not use it
    nu_n: float | None  # 0 when normal damping is switched off
    ks: float
    nu_s: float  # 0 when tangential damping is switched off
    mu_s: float
    mu_k: float
    reset: str = RESETS[0]  # spring (eq. 8 read literally) | total
    slip_timing: str = SLIP_TIMINGS[0]  # step (the paper: slip tested at the end of the step) | exact

    def __post_init__(self):
        self.check()

    @property
    def has_spring(self) -> bool:
        """Laws that keep a tangential history (a spring elongation D per contact)."""
        return self.law in SPRING_LAWS

    @property
    def has_state(self) -> bool:
        """Laws that keep a state per contact beside the spring (static or sliding)."""
        return self.law == "static_dynamic"

    def check(self) -> None:
        """The parameter rules of docs/law.md (check_parameters, all of them)."""
        check_parameters(**{k: getattr(self, k) for k in self.__dataclass_fields__ if getattr(self, k) is not None})


def check_parameters(law="stick_slip", **given) -> dict:
    """The parameter rules of docs/law.md for the parameters given (kn, nu_n, ks, nu_s,
    mu_s, mu_k, reset, slip_timing; mu_k needs mu_s): ValueError naming the parameter and
    its allowed range. The one checker of the Python engines (scenes prefix "contact.",
    the YADE law calls it with its arguments). Returns them, numbers as floats."""
    unknown = set(given) - {"kn", "nu_n", "ks", "nu_s", "mu_s", "mu_k"} - set(OPTIONS)
    if unknown:
        raise TypeError(f"check_parameters: unknown parameter {sorted(unknown)[0]!r}")
    if law not in LAWS:
        raise ValueError(f"law = {law!r}: must be one of {', '.join(LAWS)}")
    out = {}
    for name, allowed in OPTIONS.items():
        if name in given and given[name] not in allowed:
            raise ValueError(f"{name} = {given[name]!r}: must be one of {', '.join(allowed)}")
        if name in given:
            out[name] = given[name]
    positive = ("kn", "mu_s") + (("ks",) if law in SPRING_LAWS else ())
    for name in ("kn", "ks", "mu_s", "nu_n", "nu_s", "mu_k"):
        if name not in given:
            continue
        v = given[name]
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            raise ValueError(f"{name} = {v!r}: must be a finite number")
        v = out[name] = float(v)
        if name in positive and not v > 0:
            raise ValueError(f"{name} = {v:g}: must be > 0")
        if v < 0:
            raise ValueError(f"{name} = {v:g}: must be >= 0")
    if "mu_k" in out and law == "stick_slip":
        if "mu_s" not in out:
            raise ValueError("mu_k needs mu_s: the allowed range is [mu_s/2, mu_s]")
        mu_s, mu_k = out["mu_s"], out["mu_k"]
        if not mu_s / 2 <= mu_k <= mu_s:
            raise ValueError(f"mu_k = {mu_k:g}: must be in [mu_s/2, mu_s] = [{mu_s / 2:g}, {mu_s:g}] "
                             f"so that 0 <= Fmin = (2 mu_k - mu_s) Fn <= mu_k Fn")
    if "mu_k" in out and law == "static_dynamic":
        if "mu_s" not in out:
            raise ValueError("mu_k needs mu_s: the allowed range is [0, mu_s]")
        if not out["mu_k"] <= out["mu_s"]:
            raise ValueError(f"mu_k = {out['mu_k']:g}: must be in [0, mu_s] = [0, {out['mu_s']:g}] "
                             f"(the dynamic limit is at most the static one)")
    return out


class TangentialStep(NamedTuple):
    """One step of the tangential law for K contacts."""
    force: np.ndarray  # (K, 3) force on i applied over the step
    spring: np.ndarray  # (K, 3) spring elongation D at the end of the step
    slipped: np.ndarray  # (K,) bool: at least one slip during the step
    dissipated_dashpot: np.ndarray | None  # (K,) energy the dashpot took (energy=True)
    dissipated_slip: np.ndarray | None  # (K,) energy the slips took (energy=True)


def every_step_slips_speed(p: LawParams, fn, dt):
    """Step timing: the sliding speed above which every step slips. After a slip the
    spring holds Fmin (eq. 8); one step later the trial force is Fmin + (Ks*dt + nu_s)*V,
    so every step slips once V >= 2(mu_s - mu_k)Fn/(Ks*dt + nu_s) (docs/precision.md)."""
    return 2 * (p.mu_s - p.mu_k) * fn / (p.ks * dt + p.nu_s)


def normal_force(delta, v_n, p: LawParams):
    """Eq. 3: Fn = Kn*D_n + nu_n*V_n, never tensile (grains do not glue)."""
    fn = p.kn * delta
    if p.nu_n:
        fn = fn + p.nu_n * v_n
    return np.maximum(fn, 0.0)


def rotate_history(D, n):
    """Turn the spring elongation into the current tangent plane, keeping its length
    (the 3D form; when D already lies in the plane, as in 2D on a fixed wall, nothing moves)."""
    dn = _einsum("ij,ij->i", D, n)
    if not _any(dn):
        return D
    old = _einsum("ij,ij->i", D, D)
    D = D - dn[:, None] * n
    new = _einsum("ij,ij->i", D, D)
    scale = np.sqrt(old / np.maximum(new, 1e-300))
    return D * np.where(new > 0, scale, 1.0)[:, None]


def tangential_force(D, V_s, fn, dt, p: LawParams, energy=False, sliding=None) -> TangentialStep:
    """One step of the tangential law for all contacts.

    D: spring elongation from the previous step, already in the tangent plane.
    energy: also return what the dashpot and the slips dissipated (docs/law.md, Energy).
    sliding: static_dynamic's state of each contact from the previous step (None: all static);
    its state after the step is `slipped` (a contact whose force was cut is sliding).
    """
    if p.law == "static_dynamic":
        return _static_dynamic(D, V_s, fn, dt, p, energy, np.zeros(len(fn), bool) if sliding is None else sliding)
    if p.law in ("coulomb", "visco_plastic"):
        F = _coulomb(V_s, fn, p) if p.law == "coulomb" else _visco_plastic(V_s, fn, p)
        e = -_dot(F, V_s) * dt if energy else None
        zero = np.zeros(len(fn)) if energy else None
        return TangentialStep(F, D, np.zeros(len(fn), bool), zero if p.law == "coulomb" else e,
                              e if p.law == "coulomb" else zero)

    if p.law == "visco_elastic":
        mu_s = mu_k = p.mu_k  # Table 1 uses one coefficient, mu = mu_k, for the classic laws
    else:
        mu_s, mu_k = p.mu_s, p.mu_k

    D_start = D
    D = D + V_s * dt  # eq. 7: the spring follows the relative tangential displacement
    F_t = -p.ks * D  # eq. 5 (stick): elastic ...
    if p.nu_s:
        F_t = F_t - p.nu_s * V_s  # ... plus viscous part
    mag = np.sqrt(_dot(F_t, F_t))
    limit = mu_s * fn
    slip = mag >= limit  # Coulomb's static threshold reached (Fn = 0 always slips)
    stick_share = None
    if p.slip_timing == "exact":
        # The force moves along a straight line during the step; |F| is convex in time,
        # so no slip happened inside the step iff it was below the threshold at both ends.
        F_0 = -p.ks * D_start - p.nu_s * V_s
        slip = slip | (_dot(F_0, F_0) >= limit * limit)
        F_s, stick_share = F_t, np.ones(len(fn))
        k = slip.nonzero()[0]  # (np.flatnonzero's Python layer costs more on a few rows)
        if len(k):
            F_s, D = F_t.copy(), D.copy()
            F_s[k], D[k], stick_share[k] = _exact_slips(D_start[k], V_s[k], fn[k], dt, p, mu_s, mu_k)
    elif not _any(slip):
        F_s = F_t
    else:
        # Slip (kinematic phase): the force drops to Fmin = (2 mu_k - mu_s) Fn along the
        # trial direction, so that a slow saw-tooth averages mu_k*Fn (section 2.3).
        # (Fn = 0 and |F_t| = 0 gives Fmin = 0 and scale 0.)
        f_min = (2.0 * mu_k - mu_s) * fn
        scale = np.where(slip, f_min / np.maximum(mag, 1e-300), 1.0)
        F_s = F_t * scale[:, None]
        if p.reset == "spring":
            D_slip = -F_s / p.ks  # eq. 8: Ks*|D_s| = Fmin, along the force
        else:  # "total": spring + dashpot equal Fmin, so a saw-tooth survives a strong dashpot
            D_slip = -(F_s + p.nu_s * V_s) / p.ks
        D = np.where(slip[:, None], D_slip, D)
    if not energy:
        return TangentialStep(F_s, D, slip, None, None)
    if stick_share is None:
        stick_share = (~slip).astype(float)
    # Work the contact received this step, less what its spring stored; the dashpot's
    # share is nu_s |V_s|^2 over the time the contact stuck (docs/law.md, Energy).
    total = -_dot(F_s, V_s) * dt - 0.5 * p.ks * (_dot(D, D) - _dot(D_start, D_start))
    dashpot = p.nu_s * _dot(V_s, V_s) * dt * stick_share
    return TangentialStep(F_s, D, slip, dashpot, total - dashpot)


def _exact_slips(D0, V_s, fn, dt, p, mu_s, mu_k):
    """Steps in which at least one slip happens, with every slip at its exact time.

    V_s and Fn are constant over the step, so the trial force F = -Ks*D - nu_s*V_s
    moves along u = -V_s/|V_s| at `rate` = Ks|V_s|dt per unit of step fraction theta.
    Returns the force at the end of the step (the one applied, as in a step without
    slip), the spring at the end, and the share of the step spent sticking
    (docs/law.md, "Exact slip timing", steps E1-E7).
    """
    K = len(fn)
    T = mu_s * fn  # static threshold
    f_min = (2.0 * mu_k - mu_s) * fn
    r = (2.0 * mu_k - mu_s) / mu_s  # Fmin/T, a parameter: exactly 1 iff mu_k = mu_s
    speed = np.sqrt(_dot(V_s, V_s))
    u = np.divide(-V_s, speed[:, None], out=np.zeros(V_s.shape, V_s.dtype), where=speed[:, None] > 0)
    rate = p.ks * speed * dt
    # After a slip the trial force restarts from Fmin*t + kept*u (E3): the spring holds
    # Fmin and the dashpot adds nu_s|V_s| (reset "spring"), or both hold Fmin ("total").
    kept = p.nu_s * speed if p.reset == "spring" else np.zeros(K)
    flow_law = r == 1.0 and (p.reset == "total" or p.nu_s == 0)  # E6 applies

    F = -p.ks * D0 - p.nu_s * V_s  # trial force at theta = 0
    theta = np.zeros(K)
    stick = np.zeros(K)  # share of the step spent sticking
    trial_end = np.zeros((K, 3))  # trial force (spring + dashpot) at the end of the step
    applied = np.zeros((K, 3))  # force at the end of the step
    slips = np.zeros(K, np.int64)
    active = T > 0
    # E1. No normal force: no friction; the spring keeps what the reset leaves.
    trial_end[~active] = kept[~active, None] * u[~active]

    def finish(i, trial, force, stuck):
        trial_end[i], applied[i] = trial, force
        stick[i] += stuck
        active[i] = False

    while _any(active):
        a = active.nonzero()[0]
        # E2. Next slip: the first theta at which |F| reaches T. Before the step's first
        # slip the force may already be at or above T (Fn fell, or V_s jumped): slip now.
        f = _dot(F[a], u[a])
        F2 = _dot(F[a], F[a])
        gap = np.maximum(np.sqrt(np.maximum(T[a] ** 2 - (F2 - f * f), 0.0)) - f, 0.0)
        dtheta = np.divide(gap, rate[a], out=np.full(len(a), np.inf), where=rate[a] > 0)
        dtheta[(slips[a] == 0) & (F2 >= T[a] ** 2)] = 0.0
        hit = theta[a] + dtheta <= 1.0
        s = a[~hit]  # no slip before the end of the step: stick, the force keeps loading
        if len(s):
            rest = 1.0 - theta[s]
            F_end = F[s] + (rate[s] * rest)[:, None] * u[s]
            finish(s, F_end, F_end, rest)
        h = a[hit]
        if not len(h):
            break
        dth = dtheta[hit]
        F_hit = F[h] + (rate[h] * dth)[:, None] * u[h]
        stick[h] += dth
        theta[h] += dth
        # E3. The slip: the force drops to Fmin along its direction t (eq. 8).
        t = F_hit / np.sqrt(_dot(F_hit, F_hit))[:, None]
        slips[h] += 1
        F[h] = f_min[h, None] * t + kept[h, None] * u[h]
        rest = 1.0 - theta[h]
        # E4. Sliding: the restarted force is at or above T again, so slips follow without
        # end and turn t onto u: the contact slides at Fmin*u for the rest of the step.
        slide = (kept[h] > 0) & (_dot(F[h], F[h]) >= T[h] ** 2)
        # E5. Not moving: the force stays where the slip left it.
        frozen = ~slide & (rate[h] == 0)
        # E6. mu_k = mu_s and nothing added at the reset: plastic flow on |F| = T.
        along = _dot(t, u[h])
        # (t.u = 0 too: |F + rate theta u| = T sqrt(1 + (rate theta/T)^2) rises at once: it
        # flows from phi = 90 degrees; only t.u < 0 unloads into the cone and sticks again)
        flow = (~slide & ~frozen & (along >= 0)) if flow_law else np.zeros(len(h), bool)
        if _any(slide):
            i = h[slide]
            finish(i, (f_min[i] + kept[i])[:, None] * u[i], f_min[i, None] * u[i], 0.0)
        if _any(frozen):
            i = h[frozen]
            finish(i, F[i], F[i], rest[frozen])
        if _any(flow):
            i = h[flow]
            F_end = _plastic_flow(F[i], u[i], rate[i] * rest[flow] / T[i], T[i])
            finish(i, F_end, F_end, 0.0)
        # E7. Settled along u (or followed MAX_EXPLICIT_SLIPS times): the remaining slips
        # of the step repeat one cycle, (Fmin + kept)*u -> T*u, in closed form.
        go = ~slide & ~frozen & ~flow
        if _any(go):
            i = h[go]
            q = F[i] - _dot(F[i], u[i])[:, None] * u[i]
            settled = (((np.sqrt(_dot(q, q)) <= SETTLED * T[i]) & (along[go] > 0))
                       | (slips[i] >= MAX_EXPLICIT_SLIPS))
            c = i[settled]
            if len(c):
                trial, force, slid = _periodic_slips(q[settled], u[c], rate[c], T[c], r, kept[c], f_min[c],
                                                     rest[go][settled])
                finish(c, trial, force, np.where(slid, 0.0, rest[go][settled]))
    # The spring at the end holds the trial force less the dashpot (eq. 5).
    D_end = -(trial_end + p.nu_s * V_s) / p.ks
    return applied, D_end, stick


def _periodic_slips(q, u, rate, T, r, kept, f_min, rest):
    """E7: from just after a slip, n whole cycles (Fmin + kept)*u -> T*u, each of length
    L in theta, then part of one. The part q of the force across u shrinks by r at each
    slip. Returns the trial and applied force at the end, and which contacts slide."""
    low = f_min + kept  # the force along u just after a slip
    L = (T - low) / rate  # rate > 0 here (E5 took the others)
    # a contact followed MAX_EXPLICIT_SLIPS times whose restart is already at T slides
    slid = ~(L > 0)
    L = np.where(slid, 1.0, L)
    n = np.floor(rest / L)
    part = rest - n * L
    trial = np.where(slid[:, None], low[:, None] * u, (low + rate * part)[:, None] * u + (r ** n)[:, None] * q)
    force = np.where(slid[:, None], f_min[:, None] * u, trial)
    return trial, force, slid


def _plastic_flow(F, u, k_rest, T):
    """E6: mu_k = mu_s, the force stays on |F| = T and turns towards u. With phi the angle
    between F and u, d(phi)/d(theta) = -(rate/T) sin(phi), so tan(phi/2) falls as
    exp(-rate*theta/T): over the rest of the step by the factor exp(-k_rest)."""
    f = _dot(F, u)
    q = F - f[:, None] * u
    qn = np.sqrt(_dot(q, q))
    s = qn / (T + f) * np.exp(-k_rest)  # tan(phi/2) at the end (f >= 0 here)
    cos, sin = (1.0 - s * s) / (1.0 + s * s), 2.0 * s / (1.0 + s * s)
    p_hat = np.divide(q, qn[:, None], out=np.zeros_like(q), where=qn[:, None] > 0)
    return (T * cos)[:, None] * u + (T * sin)[:, None] * p_hat


def _static_dynamic(D, V_s, fn, dt, p, energy, sliding):
    """The two-state static/dynamic law (docs/law.md, "Other tangential laws"; LAMMPS'
    linear_history/static): steps 3-4 of the stick-slip law, then a Coulomb limit of
    mu_s*Fn for a static contact and mu_k*Fn for a sliding one. A trial force above the
    limit is cut to it, spring and dashpot together carrying it, and the contact is sliding
    after the step (`slipped`); a trial force at or below it sticks, and the contact is static
    again."""
    D_start = D
    D = D + V_s * dt  # eq. 7
    F_t = -p.ks * D - p.nu_s * V_s  # eq. 5
    mag = np.sqrt(_dot(F_t, F_t))
    limit = np.where(sliding, p.mu_k, p.mu_s) * fn
    over = mag > limit
    F_s = F_t * np.where(over, limit / np.maximum(mag, 1e-300), 1.0)[:, None]
    D = np.where(over[:, None], -(F_s + p.nu_s * V_s) / p.ks, D)
    if not energy:
        return TangentialStep(F_s, D, over, None, None)
    total = -_dot(F_s, V_s) * dt - 0.5 * p.ks * (_dot(D, D) - _dot(D_start, D_start))
    dashpot = p.nu_s * _dot(V_s, V_s) * dt * ~over
    return TangentialStep(F_s, D, over, dashpot, total - dashpot)


def _dot(a, b):
    return _einsum("ij,ij->i", a, b)


def _any(a):
    """a.any(), faster on the few rows of a small scene (where the step's cost is numpy's
    per-call overhead)."""
    return _count_nonzero(a) > 0


def _unit(V):
    mag = np.sqrt(_dot(V, V))
    # (np.zeros: np.zeros_like costs five times as much on a few rows)
    return np.divide(V, mag[:, None], out=np.zeros(V.shape, V.dtype), where=mag[:, None] > 0), mag


def _coulomb(V_s, fn, p):
    """Table 1, Coulomb: F_s = -mu_k*Fn*sign(V_s); undefined (here 0) at V_s = 0."""
    u, _ = _unit(V_s)
    return -(p.mu_k * fn)[:, None] * u


def _visco_plastic(V_s, fn, p):
    """Table 1, visco-plastic: F_s = -min(nu_s*|V_s|, mu_k*Fn)*sign(V_s)."""
    u, mag = _unit(V_s)
    return -np.minimum(p.nu_s * mag, p.mu_k * fn)[:, None] * u
