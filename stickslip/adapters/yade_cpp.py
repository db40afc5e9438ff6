# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for YADE with the compiled law (yade_law/compiled/, built by ./run.sh setup): the
YADE adapter's scene runner (yade_law/run_scene.py) started through the compiled law's
launcher, with the law's backend "cpp". Everything else is the YADE adapter's."""
from __future__ import annotations

import os
from pathlib import Path

from .. import shipped
from . import missing, yade

NAME = "yade_cpp"
# the build ./run.sh setup makes; STICKSLIP_YADE_LAW_BUILD: another build folder (the mutants')
BUILD = Path(os.environ.get("STICKSLIP_YADE_LAW_BUILD", shipped.CHECKOUT / "build" / "yade_law"))
LAUNCHER = BUILD / "yade-stickslip"


def available():
    return missing("yade", "apt-get install yade", LAUNCHER, "./run.sh setup builds the compiled YADE law")


def run(scene, out_dir, progress=None):
    return yade.run(scene, out_dir, progress, launcher=LAUNCHER, backend="cpp")
