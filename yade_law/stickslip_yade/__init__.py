# SPDX-License-Identifier: GPL-2.0-or-later
"""The stick-slip friction law of Khellaf & Mansouri (2024) for YADE, in Python.

Use in an ordinary YADE script (full example: yade_law/example_drag.py, README.md):

    import sys; sys.path.insert(0, "/path/to/yade_law")
    from stickslip_yade import stickslip_material, stickslip_engines
    mat = O.materials.append(stickslip_material(kn=1.2e7, nu_n=41.38))
    ... spheres / boxes / walls with material=mat ...
    O.engines = stickslip_engines(ks=9.6e6, nu_s=33.1, mu_s=0.5, mu_k=0.45, gravity=(0, -9.81, 0))

The native Law2_ScGeom_ViscElPhys_Basic applies the normal force (eq. 3, never tensile;
kn = Kn, cn = nu_n, no native shear force). A PyRunner placed before NewtonIntegrator adds
the tangential force of docs/law.md (3D form: the spring elongation D is kept in the
current tangent plane). The law's arithmetic is the repository's numpy kernel
pyref/laws.py; this package gathers the kinematics from YADE and hands the forces back.

Where things are, one idea per module:
- engines.py       stickslip_material, stickslip_engines, insert_stickslip: what a script calls
- runner.py        stickslip_runner, the PyRunner that runs the law each step, and its command
- law.py           StickSlipLaw: one step, from the bodies' states to the forces handed back
- kinematics.py    the bodies as the law reads them (spheres, radii, states in one call, the cell)
- contacts.py      contact bookkeeping: the per-contact state, finding a step's contacts
- geometry.py      per-contact normal, overlap, lever arms, relative velocity, YADE's Fn
- kernel.py        the law's arithmetic: the repository's pyref/laws.py, imported
- energy.py        the energy books in O.energy
- checkpoints.py   the state saved with the scene (O.tags) and restored at a load
- checks.py        what the law accepts: parameters, the scene's engines and shapes; errors
- compiled.py      the compiled law (yade_law/compiled/) from a script: its engines, its contacts
- verlet_start.py  velocity_verlet_start: YADE's first step as velocity Verlet's start

Why it is written this way (measured on YADE 2023.02a, see README.md, "How the Python law is
fast enough"): YADE never calls a Python subclass of a Law2 class and interactions take no extra
attributes, so the per-contact state lives here, in arrays, and is saved with the scene
through O.tags; every attribute read from YADE costs 0.3-0.7 us per contact, about a whole
step of YADE's native law, so a step reads no per-contact attribute of a sphere pair.
"""
__version__ = "1.0.0"  # the project's version, pyproject.toml's (tests/test_release.py checks they agree)

from .checks import check_parameters
from .engines import insert_stickslip, stickslip_engines, stickslip_material
from .kernel import rotate_history, tangential_force
from .law import StickSlipLaw
from .runner import resume, step, stickslip_runner
from .verlet_start import velocity_verlet_start

__all__ = ["stickslip_material", "stickslip_engines", "stickslip_runner", "insert_stickslip", "velocity_verlet_start",
           "check_parameters", "StickSlipLaw", "step", "resume", "rotate_history", "tangential_force"]

try:  # YADE's savers store the law's state first (checkpoints.py); outside YADE there is nothing to hook
    from .checkpoints import install_save_hooks

    install_save_hooks()
except ImportError:
    pass
