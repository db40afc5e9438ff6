# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract on each engine: one function per engine that runs a case of
stickslip/contract/cases.py (the contact held in the states the case prescribes, nothing
integrated) and returns what the contact recorded at the end of each step, a trace
(cases.empty_trace: Fn, the force on i, the spring, the slips since the contact began, the
normal), which cases.compare() holds against the hand-worked values.

A new engine is one more driver (a module here, reusing its adapter's script writing and
reading) and one entry in RUNNERS (tests/test_law_contract.py fails for an engine of
stickslip.adapters.ENGINES that has neither an entry nor a reason in SHARED_KERNEL), and one
in TYPE_PAIR_RUNNERS or NO_TYPE_PAIRS. Drivers here: pyref (below), LIGGGHTS (liggghts.py),
LAMMPS' two routes (lammps.py), YADE's compiled law (yade.py); DEM-Engine's force model through its
CPU shim (deme_shim.py).
"""
from __future__ import annotations

from .. import law_options, scene as scene_mod
from ..adapters.lammps_family import fmt as _f
from . import cases as lc
from .lammps import run_lammps, run_lammps_granular, run_lammps_granular_type_pairs, run_lammps_type_pairs
from .liggghts import run_liggghts, run_liggghts_type_pairs
from .yade import run_yade_cpp

# YADE's Python law calls pyref's kernel (yade_law/stickslip_yade/kernel.py imports pyref/laws.py):
# the law's arithmetic there is pyref's; its own tests check its geometry and integration. YADE's
# compiled law (yade_cpp) has arithmetic of its own and runs the contract (yade.py).
SHARED_KERNEL = {"yade": "runs pyref's kernel (yade_law/stickslip_yade/kernel.py imports pyref/laws.py)"}
# Engines of stickslip.adapters.OPTIONAL_ENGINES, whose hardware CI lacks: where their law's
# own file runs every row without it.
CPU_SHIMS = {"deme": "tests/test_deme_shim.py: deme_model/stick_slip.cu compiled on the CPU (deme_model/shim/, "
                     "stickslip/contract/deme_shim.py), every row in float"}


# ---------------------------------------------------------------- pyref

def _pyref_scene(case):
    grains = "".join(f"""
[[grain]]
name = "{name}"
radius = {lc.R!r}
density = 1000.0
position = [{_f(x[0])}, {_f(x[1])}, {_f(x[2])}]
""" for name, x in zip("ij", lc.rest_positions(case, case.segments[0].delta)))
    wall = """
[[wall]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
""" if case.geometry == "wall" else ""
    options = "\n".join(law_options.words("pyref", explicit=True, reset=case.reset, slip_timing=case.timing))
    text = f"""
name = "contract"
dimension = 3
[effects]
rotation = {str(any(s.omega for s in case.segments)).lower()}
normal_damping = {str(case.nu_n > 0).lower()}
tangential_damping = {str(case.nu_s > 0).lower()}
[contact]
kn = {lc.KN!r}
nu_n = {case.nu_n!r}
ks = {lc.KS!r}
nu_s = {case.nu_s!r}
mu_s = {case.mu_s!r}
mu_k = {case.mu_k!r}
{options}
[time]
dt = {lc.DT!r}
duration = {case.steps * lc.DT!r}
""" + grains + wall
    import tomllib
    return scene_mod.parse(tomllib.loads(text))


def run_pyref(case):
    """pyref's contact pass (pyref/solver.py: geometry, the history carried from step to step
    or dropped, then pyref/laws.py) at each prescribed state; nothing is integrated."""
    from pyref import Simulation

    sim = Simulation(_pyref_scene(case), record=False)
    out = lc.empty_trace(case.steps)
    x = sim.x.copy()
    k, slips = 0, 0
    for seg in case.segments:
        start = x
        for s in range(1, seg.steps + 1):
            x, v, w = lc.state(case, seg, s, start)
            sim.x, sim.v, sim.w = x.copy(), v.copy(), w.copy()
            sim.f, sim.torque = sim._forces()
            c = sim.contacts
            if len(c.key):
                slips += int(c.slipped[0])
                out["fn"][k], out["F"][k], out["D"][k], out["n"][k] = c.fn[0], c.force[0], sim.D[0], c.n[0]
                out["slips"][k] = slips
            else:
                slips = 0
            k += 1
    return out


RUNNERS = {"pyref": run_pyref, "liggghts": run_liggghts, "lammps": run_lammps, "lammps_granular": run_lammps_granular,
           "yade_cpp": run_yade_cpp}
TYPE_PAIR_RUNNERS = {"liggghts": run_liggghts_type_pairs, "lammps": run_lammps_type_pairs,
                     "lammps_granular": run_lammps_granular_type_pairs}
# Cases an engine cannot express, and why (the README's table shows them).
NO_TYPE_PAIRS = {"pyref": "one material per scene: one mu_s, mu_k for every contact",
                 "yade_cpp": "the law's parameters are its Ip2 functor's: one mu_s, mu_k for every contact"}
