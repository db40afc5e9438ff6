"""Adapter for pyref, the reference solver: runs in this process."""
from __future__ import annotations

import pandas as pd

from pyref import Simulation

from . import RunResult

NAME = "pyref"


def available():
    return None


def run(scene, out_dir, progress=None, energy=False):
    sim = Simulation(scene, energy=energy)
    columns, rows, steps, wall = sim.run(progress=progress)
    return RunResult(pd.DataFrame(rows, columns=columns), steps, wall)
