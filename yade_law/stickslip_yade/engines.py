# SPDX-License-Identifier: GPL-2.0-or-later
"""The material and the engine lists: what a YADE script calls (yade_law/README.md)."""
from . import checks, compiled
from .runner import publish_view, stickslip_runner


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
                      damping=0.0, rotation=True, extra=(), check=False, backend="python"):
    """The engine list for O.engines: collision detection (spheres, facets, walls, boxes),
    the law, `extra` engines (e.g. a RotationEngine), then Newton's integration.

    backend "python": YADE's ViscEl law for the normal force, then this package's law in a
    PyRunner; "cpp": the compiled law (yade_law/compiled/, YADE started through
    build/yade_law/yade-stickslip), the same law at YADE's native speed. Either way the law
    is published as `builtins.stickslip_law`, with the same queries (contact, lookup, ...)."""
    from yade import (Bo1_Box_Aabb, Bo1_Facet_Aabb, Bo1_Sphere_Aabb, Bo1_Wall_Aabb, ForceResetter,
                      Ig2_Box_Sphere_ScGeom, Ig2_Facet_Sphere_ScGeom, Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom,
                      InsertionSortCollider, InteractionLoop, Ip2_ViscElMat_ViscElMat_ViscElPhys,
                      Law2_ScGeom_ViscElPhys_Basic, NewtonIntegrator)

    gravity = checks.vector3("gravity", gravity)
    damping = checks.number("damping", damping)
    if not 0 <= damping < 1:
        raise ValueError(f"damping = {damping!r}: must be in [0, 1)")
    extra = checks.extra_engines(extra)
    geometry = [Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()]
    collider = InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb(), Bo1_Wall_Aabb(), Bo1_Box_Aabb()])
    if checks.backend(backend) == "cpp":
        p = checks.check_parameters(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing)
        rotation = checks.flag("rotation", rotation)
        compiled.require()
        ip2, law, guard = compiled.functors(p["ks"], p["nu_s"], p["mu_s"], p["mu_k"], reset, slip_timing, rotation)
        publish_view(compiled.CompiledLaw(law))
        return [ForceResetter(), collider, InteractionLoop(geometry, [ip2], [law]), guard, *extra,
                NewtonIntegrator(gravity=gravity, damping=damping)]
    runner = stickslip_runner(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    return [
        ForceResetter(),
        collider,
        InteractionLoop(geometry, [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
        runner,
        *extra,
        NewtonIntegrator(gravity=gravity, damping=damping),
    ]


def insert_stickslip(engines, ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True,
                     check=False, backend="python"):
    """Your engine list with the law put in: its InteractionLoop must use
    Ip2_ViscElMat_ViscElMat_ViscElPhys and Law2_ScGeom_ViscElPhys_Basic. backend "python":
    the law's runner right after the InteractionLoop (the law checks the rest at its first
    step); "cpp": the compiled law's Ip2 and Law2 in their place and its guard after the
    loop. The list is not otherwise changed."""
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
    at = loops[0] + 1
    if checks.backend(backend) == "cpp":
        p = checks.check_parameters(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing)
        compiled.require()
        ip2, law, guard = compiled.functors(p["ks"], p["nu_s"], p["mu_s"], p["mu_k"], reset, slip_timing,
                                            checks.flag("rotation", rotation))
        loop = engines[loops[0]]
        loop.physDispatcher.functors, loop.lawDispatcher.functors = [ip2], [law]
        publish_view(compiled.CompiledLaw(law))
        return engines[:at] + [guard] + engines[at:]
    runner = stickslip_runner(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    return engines[:at] + [runner] + engines[at:]
