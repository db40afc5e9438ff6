"""The law's arithmetic: the repository's numpy kernel pyref/laws.py (turn of the history,
eqs. 5, 7, 8, the exact slip timing, the energy split), imported, never copied.

pyref/laws.py needs numpy only. This module puts the repository's root on sys.path and
checks that the kernel found is this repository's own.
"""
import os
import sys

_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if _REPO not in sys.path:
    sys.path.append(_REPO)
from pyref import laws  # noqa: E402

if os.path.realpath(os.path.dirname(os.path.dirname(laws.__file__))) != os.path.realpath(_REPO):
    raise ImportError(f"stickslip_yade needs the law kernel of its own repository ({_REPO}/pyref/laws.py), "
                      f"but `pyref` was already imported from {os.path.dirname(laws.__file__)}")

LawParams, rotate_history, tangential_force = laws.LawParams, laws.rotate_history, laws.tangential_force
dot = laws._dot  # row-wise dot products of (K, 3) arrays
RESETS, SLIP_TIMINGS = laws.RESETS, laws.SLIP_TIMINGS
