# SPDX-License-Identifier: GPL-2.0-or-later
"""Headline figures of a run, computed from the standard time series alone.

The same code reads every engine's output, so engines are compared on equal terms:
the scene's case kind (stickslip/kinds/) computes them, kinds/stick_resolution.py warns.
"""
from __future__ import annotations

from . import kinds
from .kinds import stick_resolution


def summarise(scene, df) -> dict:
    """The figures written to summary.json (beside the run's own facts)."""
    return kinds.get(scene.analysis["kind"]).summarise(scene, df)


def warnings(scene, summary) -> list:
    return stick_resolution.warnings(scene, summary)
