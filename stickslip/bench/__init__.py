# SPDX-License-Identifier: GPL-2.0-or-later
"""Benchmarks and their tools: `stickslip bench` (table.py gathers the rows of pyref.py and of
each engine's module: liggghts.py, lammps.py, yade.py), the per-path instruction counts of the
C++ plugins (liggghts_paths.py, lammps_paths.py), and what they share: callgrind.py (reading
callgrind's output), proc_probe.py (the probe run from inside an engine), ratio_interval.py (a
ratio's interval over rounds). Nothing outside this package imports it but the CLI and the
tools.
"""
