# SPDX-License-Identifier: GPL-2.0-or-later
"""Studies: runs of many scenes that answer one question each, with their figures.

precision.py (error against wall time over a ladder of time steps), thresholds.py (the
speed above which every step slips), friction_speed.py (mean friction against sliding speed),
drum_study.py, drum_engines.py and drum_figures.py (the 2D drum), report_plan.py (the report's
studies as tasks and its section).
"""
