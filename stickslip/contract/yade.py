# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract on YADE's compiled law (runners.py): each case as a YADE script with the
law's engines and no integrator (the bodies stay where the script puts them before each step),
run by the compiled law's launcher, read back from the contact's own record (StickSlipPhys:
the spring, the normal force, the force, the slip count) and, beside the contract, from the
energy books the law keeps (trace["books"])."""
from __future__ import annotations

import json
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..adapters.yade_cpp import LAUNCHER
from . import cases as lc

SCRIPT = r"""
import json, sys
from yade import *
from yade import utils


def run(case):
  O.reset()
  O.dt = case["dt"]
  O.trackEnergy = True  # the books the law keeps (docs/law.md, Energy), read at each step
  mat = O.materials.append(ViscElMat(kn=2 * case["kn"], cn=2 * case["nu_n"], ks=0.0, cs=0.0, frictionAngle=0.0,
                                     density=1000.0))
  if case["geometry"] == "wall":  # the floor z = 0 (id 0, the first of its interactions), grain i above it
      O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=mat))
  grains = [O.bodies.append(utils.sphere(x, case["r"], material=mat)) for x in case["states"][0][0]]
  ip2 = Ip2_ViscElMat_ViscElMat_StickSlipPhys(ks=case["ks"], nu_s=case["nu_s"], mu_s=case["mu_s"], mu_k=case["mu_k"])
  law = Law2_ScGeom_StickSlipPhys_StickSlip(reset=case["reset"], slip_timing=case["timing"])
  O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()], verletDist=0.0),
               InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [ip2], [law]),
               StickSlipGuard(law=law)]
  i, j = grains[0], (0 if case["geometry"] == "wall" else grains[1])
  rows = []
  for x, v, w in case["states"]:
      for b, xb, vb, wb in zip(grains, x, v, w):
          s = O.bodies[b].state
          s.pos, s.vel, s.angVel = Vector3(*xb), Vector3(*vb), Vector3(*wb)
      O.step()
      I = O.interactions[i, j] if O.interactions.has(i, j) else None
      if I is None or not I.isReal or I.geom.penetrationDepth < 0:
          rows.append(None)
          continue
      p, g = I.phys, I.geom
      # the record is body 1's; grain i is body 1 of a pair, body 2 on the wall (YADE puts the wall first)
      sign = 1.0 if I.id1 == i else -1.0
      books = dict(O.energy.items())
      rows.append({"fn": max(0.0, p.Fn + p.Fv), "F": [-sign * c for c in p.shearForce],
                   "D": [sign * c for c in p.spring], "slips": p.slips, "n": [sign * c for c in g.normal],
                   "books": [books["stickslip_slip"], books["stickslip_dashpot"], books["stickslip_spring"]]})
  return rows


print("RESULT " + json.dumps([run(case) for case in json.load(open(sys.argv[1]))]))
"""


def case_dict(case):
    """The case's constants and each step's prescribed states of its grains."""
    states, x = [], lc.rest_positions(case, case.segments[0].delta)
    for seg in case.segments:
        start = x
        for s in range(1, seg.steps + 1):
            x, v, w = lc.state(case, seg, s, start)
            states.append((x.tolist(), v.tolist(), w.tolist()))
    return {"geometry": case.geometry, "dt": lc.DT, "kn": lc.KN, "ks": lc.KS, "r": lc.R, "nu_n": case.nu_n,
            "nu_s": case.nu_s, "mu_s": case.mu_s, "mu_k": case.mu_k, "reset": case.reset, "timing": case.timing,
            "states": states}


def run_cases(cases):
    """Every case in one YADE process (YADE starts in seconds; a case runs in milliseconds),
    each in a scene of its own (O.reset); returns their traces."""
    with tempfile.TemporaryDirectory(prefix="contract-") as tmp:
        work = Path(tmp)
        (work / "contract.py").write_text(SCRIPT)
        (work / "cases.json").write_text(json.dumps([case_dict(c) for c in cases]))
        p = subprocess.run([str(LAUNCHER), "-n", "-x", "contract.py", "cases.json"], cwd=work, capture_output=True,
                           text=True, timeout=600, env={"PATH": "/usr/bin:/bin", "HOME": tmp})
    lines = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    if p.returncode != 0 or not lines:
        raise RuntimeError(f"YADE (compiled law) failed on the contract: {(p.stdout + p.stderr)[-1500:]}")
    traces = []
    for case, rows in zip(cases, json.loads(lines[-1][7:])):
        out = lc.empty_trace(case.steps)
        out["books"] = np.full((case.steps, 3), np.nan)  # O.energy's slip, dashpot and spring entries
        for k, row in enumerate(rows):
            if row is None:
                continue
            out["fn"][k], out["F"][k], out["D"][k] = row["fn"], np.array(row["F"]), np.array(row["D"])
            out["slips"][k], out["n"][k], out["books"][k] = row["slips"], np.array(row["n"]), row["books"]
        traces.append(out)
    return traces


_TRACES = {}  # case name -> trace: the table runs once per process


def run_yade_cpp(case):
    """YADE's compiled law (yade_law/compiled/StickSlipPM.cpp), read from its own record; the
    whole table is run at the first call (a case not in the table runs alone)."""
    if case.name not in _TRACES or _TRACES[case.name][0] != case:
        table = list(lc.CASES) if case in lc.CASES else [case]
        for c, trace in zip(table, run_cases(table)):
            _TRACES[c.name] = (c, trace)
    return _TRACES[case.name][1]
