"""The stick-slip friction law of Khellaf & Mansouri (2024) for YADE, in Python.

Use in an ordinary YADE script (see yade_law/README.md):

    import sys; sys.path.insert(0, "/path/to/yade_law")
    from stickslip_yade import stickslip_material, stickslip_engines
    mat = O.materials.append(stickslip_material(kn=1.2e7, nu_n=41.38))
    ... bodies with material=mat ...
    O.engines = stickslip_engines(ks=9.6e6, nu_s=33.1, mu_s=0.5, mu_k=0.45, gravity=(0, -9.81, 0))

The native Law2_ScGeom_ViscElPhys_Basic gives the normal force (eq. 3, never tensile);
a PyRunner placed before NewtonIntegrator adds the tangential force of this law,
exactly as docs/law.md states it (3D form: the spring elongation D is kept in the
current tangent plane). YADE does not call Python subclasses of Law2 classes, and
extra attributes cannot be attached to interactions, so per-contact state lives in a
dict keyed by (id1, id2) and is renewed when a contact is made again.
"""
from __future__ import annotations

import builtins
import math

import numpy as np

RESETS = ("spring", "total")


def check_parameters(ks, nu_s, mu_s, mu_k, reset="spring", kn=None, nu_n=None):
    """Raise ValueError naming the parameter and its allowed range (docs/law.md)."""
    def finite(name, v):
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"{name} = {v!r}: must be a finite number")

    for name, v in (("ks", ks), ("nu_s", nu_s), ("mu_s", mu_s), ("mu_k", mu_k)):
        finite(name, v)
    if kn is not None:
        finite("kn", kn)
        if kn <= 0:
            raise ValueError(f"kn = {kn:g}: must be > 0")
    if nu_n is not None:
        finite("nu_n", nu_n)
        if nu_n < 0:
            raise ValueError(f"nu_n = {nu_n:g}: must be >= 0")
    if ks <= 0:
        raise ValueError(f"ks = {ks:g}: must be > 0")
    if nu_s < 0:
        raise ValueError(f"nu_s = {nu_s:g}: must be >= 0")
    if mu_s <= 0:
        raise ValueError(f"mu_s = {mu_s:g}: must be > 0")
    if not mu_s / 2 <= mu_k <= mu_s:
        raise ValueError(f"mu_k = {mu_k:g}: must be in [mu_s/2, mu_s] = [{mu_s / 2:g}, {mu_s:g}] "
                         f"so that 0 <= Fmin = (2 mu_k - mu_s) Fn <= mu_k Fn")
    if reset not in RESETS:
        raise ValueError(f"reset = {reset!r}: must be one of {', '.join(RESETS)}")


def stickslip_material(kn, nu_n=0.0, density=2600.0, label=None):
    """A ViscElMat whose contacts get kn = Kn and cn = nu_n (Ip2 puts two materials in
    series, so each side carries twice the value) and no native shear force."""
    from yade import ViscElMat

    check_parameters(1.0, 0.0, 1.0, 1.0, kn=kn, nu_n=nu_n)
    mat = ViscElMat(kn=2.0 * kn, cn=2.0 * nu_n, ks=0.0, cs=0.0, frictionAngle=0.0, density=density)
    if label:
        mat.label = label
    return mat


class StickSlipLaw:
    """The tangential law for all interactions; call `step()` once per time step."""

    def __init__(self, ks, nu_s, mu_s, mu_k, reset="spring", lever_arms=False):
        check_parameters(ks, nu_s, mu_s, mu_k, reset)
        self.ks, self.nu_s, self.mu_s, self.mu_k, self.reset = ks, nu_s, mu_s, mu_k, reset
        self.lever_arms = lever_arms  # torques only when rotation is simulated
        self.state = {}  # (id1, id2) -> [D (3,), iterMadeReal, slip count]
        self.last = {}  # (id1, id2) -> (fn, F_s on id1, slipped) of the last step

    def step(self):
        from yade import O, Vector3

        dt = O.dt
        keys, rows, refs = [], [], []
        for I in O.interactions:  # real (touching) interactions only
            g = I.geom
            n, s = g.normal, g.shearInc
            keys.append((I.id1, I.id2, I.iterMadeReal))
            rows.append((n[0], n[1], n[2], s[0], s[1], s[2], I.phys.normalForce.norm()))
            if self.lever_arms:
                refs.append((g.refR1, g.refR2))
        if not keys:
            self.state, self.last = {}, {}
            return
        a = np.array(rows)
        n, fn = a[:, 0:3], a[:, 6]
        # shearInc is id2's tangential displacement relative to id1 this step; the law is
        # written for i = id1, whose relative velocity is the opposite (eq. 6).
        V_s = -a[:, 3:6] / dt
        D = np.zeros((len(keys), 3))
        state = {}
        for k, (i1, i2, made) in enumerate(keys):
            old = self.state.get((i1, i2))
            if old is not None and old[1] == made:
                D[k] = old[0]
        # Turn the spring into the current tangent plane, keeping its length (3D form).
        dn = np.einsum("ij,ij->i", D, n)
        if dn.any():
            old_len = np.einsum("ij,ij->i", D, D)
            D = D - dn[:, None] * n
            new_len = np.einsum("ij,ij->i", D, D)
            D *= np.where(new_len > 0, np.sqrt(old_len / np.maximum(new_len, 1e-300)), 1.0)[:, None]
        D = D + V_s * dt  # eq. 7
        F_t = -self.ks * D - self.nu_s * V_s  # eq. 5
        mag = np.sqrt(np.einsum("ij,ij->i", F_t, F_t))
        slip = mag >= self.mu_s * fn  # Coulomb's static threshold
        f_min = (2 * self.mu_k - self.mu_s) * fn
        scale = np.where(slip, f_min / np.maximum(mag, 1e-300), 1.0)
        F_s = F_t * scale[:, None]  # slip: Fmin along the trial direction
        if self.reset == "spring":
            D_slip = -F_s / self.ks  # eq. 8: Ks |D| = Fmin
        else:
            D_slip = -(F_s + self.nu_s * V_s) / self.ks  # spring + dashpot = Fmin
        D = np.where(slip[:, None], D_slip, D)

        addF, addT = O.forces.addF, O.forces.addT
        last = {}
        for k, (i1, i2, made) in enumerate(keys):
            f = F_s[k]
            old = self.state.get((i1, i2))
            count = (old[2] if old is not None and old[1] == made else 0) + int(slip[k])
            state[(i1, i2)] = (D[k], made, count)
            last[(i1, i2)] = (fn[k], f, bool(slip[k]))
            F = Vector3(f[0], f[1], f[2])
            addF(i1, F)
            addF(i2, -F)
            if self.lever_arms:
                r1, r2 = refs[k]
                nv = Vector3(n[k, 0], n[k, 1], n[k, 2])
                addT(i1, (nv * r1).cross(F))
                addT(i2, (nv * r2).cross(F))
        self.state, self.last = state, last  # ended contacts are dropped here


def stickslip_engines(ks, nu_s, mu_s, mu_k, reset="spring", gravity=(0.0, 0.0, 0.0), rotation=False,
                      extra=()):
    """The engine list for O.engines: collision detection, native normal law, this law,
    then Newton's integration. `extra` engines (e.g. a RotationEngine) go before Newton."""
    from yade import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, Bo1_Wall_Aabb, ForceResetter, Ig2_Box_Sphere_ScGeom,
                      Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                      Ip2_ViscElMat_ViscElMat_ViscElPhys, Law2_ScGeom_ViscElPhys_Basic, NewtonIntegrator,
                      PyRunner)

    law = StickSlipLaw(ks, nu_s, mu_s, mu_k, reset, lever_arms=rotation)
    # PyRunner commands run in __main__: publish the callable where any script sees it.
    builtins.stickslip_law = law
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
                        [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
        PyRunner(command="stickslip_law.step()", iterPeriod=1, initRun=True, label="stickslip_runner"),
        *extra,
        NewtonIntegrator(gravity=tuple(gravity), damping=0.0),
    ]
