# SPDX-License-Identifier: GPL-2.0-or-later
"""The wheel's files from outside the Python packages (pyproject.toml says the rest).

In the repository the YADE law, the DEM-Engine model and the files the package reads (the
scene files, the YADE scene runner, the force model's text, the measured map of `stickslip
calibrate`) sit in their own folders. A wheel carries them: stickslip_yade and
stickslip_deme as modules of their own, as a script imports them, and the files under
stickslip/data/ at their paths from the repository's root (stickslip/shipped.py finds them
there). MANIFEST.in puts the same files into the sdist, from which the wheel is built.
"""
import glob
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

# repository path -> path in the wheel
MODULES = {"yade_law/stickslip_yade": "stickslip_yade", "deme_model/stickslip_deme.py": "stickslip_deme.py"}
# repository paths (patterns) copied to stickslip/data/<the same path>
DATA = ("cases/*.toml", "yade_law/run_scene.py", "deme_model/stick_slip.cu", "docs/granular-3d/points.csv",
        "docs/granular-3d/validation.csv", "docs/granular-3d/leave_pair_out.csv")


class BuildPyWithShipped(build_py):
    def run(self):
        super().run()
        if self.editable_mode:  # an editable install reads the repository's own files
            return
        copies = dict(MODULES)
        for pattern in DATA:
            found = sorted(glob.glob(pattern))
            if not found:  # (a file MANIFEST.in left out of the sdist)
                raise FileNotFoundError(f"{pattern}: no such file to put into the wheel")
            copies.update({f: f"stickslip/data/{f}" for f in found})
        for source, target in copies.items():
            target = Path(self.build_lib) / target
            target.parent.mkdir(parents=True, exist_ok=True)
            if Path(source).is_dir():
                shutil.copytree(source, target, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__"))
            else:
                shutil.copy2(source, target)


setup(cmdclass={"build_py": BuildPyWithShipped})
