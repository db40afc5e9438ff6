# SPDX-License-Identifier: GPL-2.0-or-later
"""Files the package reads that sit outside it in the repository: the scene files (cases/),
the YADE law's scene runner (yade_law/run_scene.py), the DEM-Engine model
(deme_model/stick_slip.cu) and the measured map that `stickslip calibrate` reads
(docs/granular-3d/). A built wheel carries copies under stickslip/data/, at the same
relative paths (setup.py); a checkout of the repository has none and reads its own files.
"""
from importlib import resources
from pathlib import Path

# the folder above the package: the repository's root in a checkout (from a wheel: the
# folder of the installed packages)
CHECKOUT = Path(__file__).resolve().parent.parent


def path(relative):
    """The file or folder `relative` (a path from the repository's root, e.g. "cases"):
    the wheel's copy when the package is installed from one, else the repository's."""
    packaged = resources.files("stickslip") / "data" / relative
    return Path(str(packaged)) if packaged.exists() else CHECKOUT / relative
