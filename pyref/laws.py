"""The contact laws of Khellaf & Mansouri (2024), vectorised over contacts.

This file is the only place where pyref computes contact forces; it follows
docs/law.md line by line. Arrays have one row per contact; vectors are (K, 3).
Sign convention: forces are those acting on grain i; `V_s` is the tangential
velocity of i's contact point relative to j's, so friction opposes it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class LawParams:
    law: str  # stick_slip | visco_elastic | visco_plastic | coulomb
    kn: float
    nu_n: float  # 0 when normal damping is switched off
    ks: float
    nu_s: float  # 0 when tangential damping is switched off
    mu_s: float
    mu_k: float
    reset: str = "spring"  # spring (eq. 8 read literally) | total

    @property
    def has_spring(self) -> bool:
        """Laws that keep a tangential history (a spring elongation D per contact)."""
        return self.law in ("stick_slip", "visco_elastic")


def normal_force(delta, v_n, p: LawParams):
    """Eq. 3: Fn = Kn*D_n + nu_n*V_n, never tensile (grains do not glue)."""
    fn = p.kn * delta
    if p.nu_n:
        fn = fn + p.nu_n * v_n
    return np.maximum(fn, 0.0)


def rotate_history(D, n):
    """Turn the spring elongation into the current tangent plane, keeping its length
    (the 3D form; when D already lies in the plane, as in 2D on a fixed wall, nothing moves)."""
    dn = np.einsum("ij,ij->i", D, n)
    if not dn.any():
        return D
    old = np.einsum("ij,ij->i", D, D)
    D = D - dn[:, None] * n
    new = np.einsum("ij,ij->i", D, D)
    scale = np.sqrt(old / np.maximum(new, 1e-300))
    return D * np.where(new > 0, scale, 1.0)[:, None]


def tangential_force(D, V_s, fn, dt, p: LawParams):
    """One step of the tangential law for all contacts.

    D: spring elongation from the previous step, already in the tangent plane.
    Returns (F_s, D_new, slipped) where slipped is a bool array.
    """
    if p.law == "coulomb":
        return _coulomb(V_s, fn, p), D, np.zeros(len(fn), bool)
    if p.law == "visco_plastic":
        return _visco_plastic(V_s, fn, p), D, np.zeros(len(fn), bool)

    if p.law == "visco_elastic":
        mu_s = mu_k = p.mu_k  # Table 1 uses one coefficient, mu = mu_k, for the classic laws
    else:
        mu_s, mu_k = p.mu_s, p.mu_k

    D = D + V_s * dt  # eq. 7: the spring follows the relative tangential displacement
    F_t = -p.ks * D  # eq. 5 (stick): elastic ...
    if p.nu_s:
        F_t = F_t - p.nu_s * V_s  # ... plus viscous part
    mag = np.sqrt(np.einsum("ij,ij->i", F_t, F_t))
    slip = mag >= mu_s * fn  # Coulomb's static threshold reached (Fn = 0 always slips)
    if not slip.any():
        return F_t, D, slip

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
    return F_s, np.where(slip[:, None], D_slip, D), slip


def _unit(V):
    mag = np.sqrt(np.einsum("ij,ij->i", V, V))
    return np.divide(V, mag[:, None], out=np.zeros_like(V), where=mag[:, None] > 0), mag


def _coulomb(V_s, fn, p):
    """Table 1, Coulomb: F_s = -mu_k*Fn*sign(V_s); undefined (here 0) at V_s = 0."""
    u, _ = _unit(V_s)
    return -(p.mu_k * fn)[:, None] * u


def _visco_plastic(V_s, fn, p):
    """Table 1, visco-plastic: F_s = -min(nu_s*|V_s|, mu_k*Fn)*sign(V_s)."""
    u, mag = _unit(V_s)
    return -np.minimum(p.nu_s * mag, p.mu_k * fn)[:, None] * u
