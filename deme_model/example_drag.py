#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The paper's drag (Khellaf & Mansouri 2024, section 3.1, Table 2) on DEM-Engine with the
stick-slip force model: the 2D disk (r = 2 mm, 2600 kg/m3) as an equivalent sphere of its
mass per metre, held in the xy-plane without rolling, pushed along a fixed floor at
1e-5 m/s under its weight. Prints the mean friction ratio |F_s|/Fn over steps 1001-2500
(whole saw-teeth: mu_k = 0.45 plus the dashpot's share, 0.4505) and the slips (11), as the
LIGGGHTS and LAMMPS examples do.

    python3 deme_model/example_drag.py      (an NVIDIA GPU, `pip install -e '.[gpu]'`)

The first run compiles the force model into the engine's kernels (minutes on a cold cache).
"""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import stickslip_deme  # noqa: E402

R, DENSITY, V, DT, STEPS = 0.002, 2600.0, 1e-5, 2e-6, 2500
MASS = DENSITY * math.pi * R**2  # the disk's mass per metre, the equivalent sphere's
Y0 = 0.0019999733  # the centre above the floor at its static overlap m g / kn = 2.67e-8 m
TABLE2 = {"kn": 1.2e7, "nu_n": 41.38, "ks": 9.6e6, "nu_s": 33.10, "mu": 0.5, "mu_k": 0.45}
GRAIN, FLOOR = 1, 200  # families
# The engine subtracts its box's corner from every position in float, and the overlap is
# 1e-5 of the radius, close to float's resolution: a cube of edge 2^-2 m centred on the
# floor keeps the corner exact, a centre on a multiple of 2^-23 of the half edge is held
# exactly, and the floor moves by nanometres so that the overlap with the float radius is
# the static one (as `stickslip run --engine deme` places a scene: stickslip/adapters/deme.py).
HALF = 0.125
GRID = HALF * 2.0**-23


def build(deme):
    """The solver, set up but not initialised."""
    try:
        solver = deme.DEMSolver([0])  # the first GPU (DEM-Engine 3 takes a list of devices)
    except TypeError:
        solver = deme.DEMSolver()
    solver.SetVerbosity("ERROR")
    stickslip_deme.attach(solver, normal="hooke", slip_timing="step", reset="spring", record=True)
    mat = solver.LoadMaterial(dict(TABLE2))
    solver.InstructBoxDomainDimension((-HALF, HALF), (-HALF, HALF), (-HALF, HALF))
    solver.InstructBoxDomainBoundingBC("none", mat)
    solver.SetGravitationalAcceleration([0.0, -9.81, 0.0])
    y = float(np.round(Y0 / GRID) * GRID)
    grain = solver.AddClumps(solver.LoadSphereType(MASS, R, mat), [[0.0, y, 0.0]])
    grain.SetVel([[V, 0.0, 0.0]])
    grain.SetFamily(GRAIN)
    solver.SetFamilyPrescribedLinVel(GRAIN, repr(V), "none", "0", False)  # x held at V, z at 0
    solver.SetFamilyPrescribedAngVel(GRAIN, "0", "0", "0", False)  # no rolling
    solver.Track(grain)
    floor = solver.AddExternalObject()
    shift = (R - float(np.float32(R))) + (y - Y0)
    floor.AddPlane([0.0, shift, 0.0], [0.0, 1.0, 0.0], mat)
    floor.SetInitPos([0.0, 0.0, 0.0])
    floor.SetMass(1.0)
    floor.SetFamily(FLOOR)
    solver.SetFamilyFixed(FLOOR)
    solver.SetTimeStepSize(DT)
    solver.SetIntegrator("centered_difference")
    return solver


def steps(solver, n):
    # the engine steps while its time, summed in float, is below the duration: n dt could
    # give n + 1 steps, (n - 1/2) dt gives n
    solver.DoDynamicsThenSync((n - 0.5) * DT)


def main(deme):
    solver = build(deme)
    solver.Initialize()
    steps(solver, 1000)
    ratios = []
    for _ in range(STEPS - 1000):
        steps(solver, 1)
        rec = stickslip_deme.read_record(solver, GRAIN)  # the grain's contact in the last step
        ratios.append(math.sqrt(rec["fx"] ** 2 + rec["fy"] ** 2 + rec["fz"] ** 2) / rec["fn"])
    print(f"mean friction ratio |F_s|/F_n over steps 1001-{STEPS}: {np.mean(ratios):.5f} (paper: mu_k = 0.45)")
    print(f"slips: {int(rec['slips'])}; the ratio saw-tooths between 2 mu_k - mu_s = 0.4 and mu_s = 0.5")


if __name__ == "__main__":
    import deme

    main(deme)
