# SPDX-License-Identifier: GPL-2.0-or-later
"""What the law accepts: its parameters (ValueError naming the parameter and its range),
and the engines and shapes of the scene it runs in (refused at the first step, and again
whenever O.engines or the bodies change, with `RuntimeError: stick-slip law: ...`), and
what stops a run (a non-finite body or force)."""
import math
import numbers

import numpy as np

from . import kernel


class LawError(RuntimeError):
    """An error that stops the run, its message starting with "stick-slip law: "."""


def fail(message):
    raise LawError(f"stick-slip law: {message}")


# ---------------------------------------------------------------- parameters
def number(name, v):
    """A finite real number (Python or numpy scalar, not bool) as float, else ValueError."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real) or not math.isfinite(v):
        raise ValueError(f"{name} = {v!r}: must be a finite number")
    return float(v)


def check_parameters(ks=None, nu_s=None, mu_s=None, mu_k=None, reset=None, slip_timing=None, kn=None,
                     nu_n=None):
    """The law's parameter rules (docs/law.md), for the parameters given (None = not given):
    the kernel's one checker (pyref/laws.py). Raises ValueError naming the parameter and
    its allowed range; returns the given values (numpy scalars become floats)."""
    given = dict(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, slip_timing=slip_timing, kn=kn, nu_n=nu_n)
    return kernel.laws.check_parameters(**{k: v for k, v in given.items() if v is not None})


def flag(name, v):
    if not isinstance(v, (bool, np.bool_)):
        raise ValueError(f"{name} = {v!r}: must be True or False")
    return bool(v)


BACKENDS = ("python", "cpp")


def backend(v):
    """The law's implementation: the Python law (nothing to build) or the compiled one."""
    if v not in BACKENDS:
        raise ValueError(f"backend = {v!r}: must be one of {', '.join(BACKENDS)}")
    return v


def vector3(name, v):
    """Three finite numbers (a tuple, list, numpy array or Vector3) as a tuple of floats."""
    try:
        items = None if isinstance(v, (str, bytes)) else [v[0], v[1], v[2]]
        ok = items is not None and len(v) == 3
    except (TypeError, IndexError, KeyError):
        ok = False
    if ok:
        try:
            return tuple(number(name, x) for x in items)
        except ValueError:
            pass
    raise ValueError(f"{name} = {v!r}: must be 3 finite numbers")


def extra_engines(extra):
    """`extra`: YADE engines to run between the law and NewtonIntegrator (not a second copy
    of what the list already has)."""
    from yade.wrapper import Collider, Engine, ForceResetter, InteractionLoop, NewtonIntegrator

    if isinstance(extra, (str, bytes)) or not hasattr(extra, "__iter__"):
        raise ValueError(f"extra = {extra!r}: must be a list of YADE engines")
    extra = list(extra)
    for k, e in enumerate(extra):
        if not isinstance(e, Engine):
            raise ValueError(f"extra[{k}] = {e!r}: must be a YADE engine (e.g. RotationEngine(...))")
        if isinstance(e, (Collider, ForceResetter, InteractionLoop, NewtonIntegrator)):
            raise ValueError(f"extra[{k}] = {type(e).__name__}: stickslip_engines already has one")
    return extra


# ---------------------------------------------------------------- the scene
# What the law handles: the shapes of the bodies (with the bound functor each needs) and
# the geometry functors (the shape that meets spheres). Contacts with a Facet, Wall or Box
# take YADE's geometry; sphere pairs are recomputed (docs/law.md step 1).
BO1 = {"Sphere": "Bo1_Sphere_Aabb", "Facet": "Bo1_Facet_Aabb", "Wall": "Bo1_Wall_Aabb", "Box": "Bo1_Box_Aabb"}
IG2 = {"Ig2_Sphere_Sphere_ScGeom": "Sphere", "Ig2_Sphere_Sphere_ScGeom6D": "Sphere",
       "Ig2_Facet_Sphere_ScGeom": "Facet", "Ig2_Facet_Sphere_ScGeom6D": "Facet",
       "Ig2_Wall_Sphere_ScGeom": "Wall", "Ig2_Box_Sphere_ScGeom": "Box", "Ig2_Box_Sphere_ScGeom6D": "Box"}


def validate_scene(engines, token, bodies):
    """Refuse whatever the law cannot handle, naming it: a contact that never reaches the
    law, or gets a second tangential force, must not run silently. `token` names the law's
    runner in its command; `bodies`: kinematics.Bodies (the shapes present)."""
    from yade.wrapper import Collider, InteractionLoop, NewtonIntegrator, PyRunner

    def where(kind):
        return [k for k, e in enumerate(engines) if isinstance(e, kind)]

    loops, newton = where(InteractionLoop), where(NewtonIntegrator)
    mine = [k for k in where(PyRunner) if f"('{token}')" in engines[k].command]
    if len(loops) != 1 or len(newton) != 1:
        fail(f"O.engines has {len(loops)} InteractionLoop and {len(newton)} NewtonIntegrator: the law works "
             f"with one of each (see stickslip_engines or yade_law/README.md, 'Your own engine list')")
    if len(mine) > 1 or (mine and not loops[0] < mine[0] < newton[0]):
        fail("the stick-slip runner must appear once, after the InteractionLoop and before "
             "NewtonIntegrator (as stickslip_runner(...) in yade_law/README.md)")
    loop = engines[loops[0]]
    for what, functors, allowed in (
            ("Law2", loop.lawDispatcher.functors, ("Law2_ScGeom_ViscElPhys_Basic",)),
            ("Ip2", loop.physDispatcher.functors, ("Ip2_ViscElMat_ViscElMat_ViscElPhys",)),
            ("Ig2", loop.geomDispatcher.functors, tuple(IG2))):
        for f in functors:
            name = type(f).__name__
            if name not in allowed:
                fail(f"{name} in the InteractionLoop: the stick-slip law works with {what} functors "
                     f"{', '.join(allowed)} only")
    geoms = {IG2[type(f).__name__] for f in loop.geomDispatcher.functors}
    bounds = {type(f).__name__ for e in engines if isinstance(e, Collider)
              for f in getattr(getattr(e, "boundDispatcher", None), "functors", ())}
    for shape, body in bodies.shapes.items():
        if shape == "Clump":  # clumps have no bound; their members collide
            continue
        if shape not in BO1:
            fail(f"body {body} is a {shape}: the stick-slip law handles Sphere, Facet, Wall, Box and "
                 f"clumps of spheres")
        if BO1[shape] not in bounds:
            fail(f"body {body} is a {shape} but the collider has no {BO1[shape]}: it would never touch anything")
        needed = shape != "Sphere" or bodies.nspheres > 1
        if "Sphere" in bodies.shapes and needed and shape not in geoms:
            fail(f"body {body} is a {shape} but the InteractionLoop has no Ig2 functor for {shape}-Sphere "
                 f"contacts (Ig2_{shape}_Sphere_ScGeom): spheres would pass through it")


def check_new_contact(I, p):
    """YADE's ViscEl law adds no shear force only with zero friction, and then only if its
    spring is on or its shear dashpot off (ks = 0 with cs > 0 damps tangentially)."""
    if p.tangensOfFrictionAngle != 0 or (p.ks == 0 and p.cs != 0):
        fail(f"contact ({I.id1}, {I.id2}) has tan(frictionAngle) = {p.tangensOfFrictionAngle:g}, "
             f"ks = {p.ks:g}, cs = {p.cs:g}: YADE's ViscEl law would add its own tangential force; "
             f"give the bodies stickslip_material(...) (or ViscElMat with frictionAngle = 0)")


# ---------------------------------------------------------------- run-time
def finite_bodies(it, P, V, W):
    """Name the first body with a non-finite position, velocity or spin."""
    for what, X in (("position", P), ("velocity", V), ("angular velocity", W)):
        ok = np.isfinite(X).all(axis=1)
        if not ok.all():
            i = int(np.flatnonzero(~ok)[0])
            fail(f"body {i} has a non-finite {what} {X[i].tolist()} at iteration {it}: the run has "
                 f"blown up (time step above the stability limit?) or was given a non-finite value")


def finite_forces(it, i1, i2, fn, F_s):
    """Name the first contact with a non-finite force."""
    k = int(np.flatnonzero(~(np.isfinite(fn) & np.isfinite(F_s).all(axis=1)))[0])
    fail(f"non-finite force on contact ({i1[k]}, {i2[k]}) at iteration {it} (Fn = {fn[k]!r}, "
         f"F_s = {F_s[k].tolist()}): bodies at the same place, or a blown-up run")
