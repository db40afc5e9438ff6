# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's arithmetic: the repository's numpy kernel pyref/laws.py (turn of the history,
eqs. 5, 7, 8, the exact slip timing, the energy split), imported, never copied.

pyref/laws.py needs numpy only. This module puts the folder that holds pyref on sys.path
(the repository's root, above yade_law/; or, installed from the wheel, the folder that
holds this package too) and checks that the kernel found is that one.
"""
import os
import sys

_HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the folder holding stickslip_yade
_REPO = _HERE if os.path.isdir(os.path.join(_HERE, "pyref")) else os.path.dirname(_HERE)
if _REPO not in sys.path:
    sys.path.append(_REPO)
from pyref import laws  # noqa: E402

if os.path.realpath(os.path.dirname(os.path.dirname(laws.__file__))) != os.path.realpath(_REPO):
    raise ImportError(f"stickslip_yade needs the law kernel installed with it ({_REPO}/pyref/laws.py), "
                      f"but `pyref` was already imported from {os.path.dirname(laws.__file__)}")

LawParams, rotate_history, tangential_force = laws.LawParams, laws.rotate_history, laws.tangential_force
dot = laws._dot  # row-wise dot products of (K, 3) arrays
RESETS, SLIP_TIMINGS = laws.RESETS, laws.SLIP_TIMINGS
