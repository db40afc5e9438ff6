# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract (docs/law.md) as data and the one-contact drivers that hold every
engine to it: cases.py, the rows (one contact held in prescribed states, the expected values
worked out by hand, compare()); runners.py, one driver per engine that runs a row and
returns its trace, RUNNERS; deme_shim.py, DEM-Engine's force model compiled on the CPU.
tests/test_law_contract.py runs every row on every engine; tools/ reach the rows from here.
The drivers of the C++ engines run the plugins a checkout builds (./run.sh setup); pyref's
runs wherever the package is installed."""
