# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for pyref, the reference solver: runs in this process."""
from __future__ import annotations

from pyref import Simulation

from .. import columns
from . import RunResult

NAME = "pyref"


def available():
    return None


def run(scene, out_dir, progress=None):
    scene.refuse_unsupported("pyref")
    rec = Simulation(scene).run(progress=progress)
    return RunResult(columns.frame(scene, rec), rec.steps, rec.wall_time_s)
