# SPDX-License-Identifier: GPL-2.0-or-later
"""The material and the engine lists: what a YADE script calls (yade_law/README.md)."""
from . import checks
from .runner import stickslip_runner


def stickslip_material(kn, nu_n=0.0, density=2600.0, label=None):
    """A ViscElMat whose contacts get kn = Kn and cn = nu_n (Ip2 puts the two materials
    in series, so each side carries twice the value) and no native shear force."""
    from yade import ViscElMat

    p = checks.check_parameters(kn=kn, nu_n=nu_n)
    density = checks.number("density", density)
    if not density > 0:
        raise ValueError(f"density = {density:g}: must be > 0")
    if label is not None and not isinstance(label, str):
        raise ValueError(f"label = {label!r}: must be a string")
    mat = ViscElMat(kn=2.0 * p["kn"], cn=2.0 * p["nu_n"], ks=0.0, cs=0.0, frictionAngle=0.0, density=density)
    if label:
        mat.label = label
    return mat


def stickslip_engines(ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", gravity=(0.0, 0.0, 0.0),
                      damping=0.0, rotation=True, extra=(), check=False):
    """The engine list for O.engines: collision detection (spheres, facets, walls, boxes),
    YADE's ViscEl law for the normal force, this law, `extra` engines (e.g. a
    RotationEngine), then Newton's integration. The law object is published as
    `builtins.stickslip_law` (a PyRunner's command runs in __main__)."""
    from yade import (Bo1_Box_Aabb, Bo1_Facet_Aabb, Bo1_Sphere_Aabb, Bo1_Wall_Aabb, ForceResetter,
                      Ig2_Box_Sphere_ScGeom, Ig2_Facet_Sphere_ScGeom, Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom,
                      InsertionSortCollider, InteractionLoop, Ip2_ViscElMat_ViscElMat_ViscElPhys,
                      Law2_ScGeom_ViscElPhys_Basic, NewtonIntegrator)

    gravity = checks.vector3("gravity", gravity)
    damping = checks.number("damping", damping)
    if not 0 <= damping < 1:
        raise ValueError(f"damping = {damping!r}: must be in [0, 1)")
    extra = checks.extra_engines(extra)
    runner = stickslip_runner(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb(), Bo1_Wall_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(),
                         Ig2_Box_Sphere_ScGeom()],
                        [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
        runner,
        *extra,
        NewtonIntegrator(gravity=gravity, damping=damping),
    ]


def insert_stickslip(engines, ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True,
                     check=False):
    """Your engine list with the law's runner put right after its InteractionLoop. The list
    is not otherwise changed: its InteractionLoop must already use
    Ip2_ViscElMat_ViscElMat_ViscElPhys and Law2_ScGeom_ViscElPhys_Basic (the law checks the
    rest at its first step)."""
    from yade.wrapper import InteractionLoop

    engines = list(engines)
    loops = [k for k, e in enumerate(engines) if isinstance(e, InteractionLoop)]
    if len(loops) != 1:
        raise ValueError(f"engines has {len(loops)} InteractionLoop: insert_stickslip needs exactly one")
    for what, functors, want in (("Ip2", engines[loops[0]].physDispatcher.functors,
                                  "Ip2_ViscElMat_ViscElMat_ViscElPhys"),
                                 ("Law2", engines[loops[0]].lawDispatcher.functors, "Law2_ScGeom_ViscElPhys_Basic")):
        names = [type(f).__name__ for f in functors]
        if names != [want]:
            raise ValueError(f"engines: the InteractionLoop's {what} functors are {names}; the stick-slip law needs "
                             f"[{want}()] there (YADE's ViscEl law gives the normal force)")
    runner = stickslip_runner(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    return engines[:loops[0] + 1] + [runner] + engines[loops[0] + 1:]
