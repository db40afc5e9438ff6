# SPDX-License-Identifier: GPL-2.0-or-later
"""What every report figure shares: one line style per engine, and saving a figure."""
from __future__ import annotations

ENGINE_LINES = {"pyref": "-", "liggghts": "--", "yade": ":", "yade_cpp": (0, (3, 1, 1, 1)), "lammps": "-.",
                "lammps_granular": (0, (5, 2, 1, 2, 1, 2)), "deme": (0, (1, 3))}


def line(engine):
    """An engine's line in the figures that overlay engines (keyword arguments of plot)."""
    return {"linestyle": ENGINE_LINES[engine]}


def pyplot():
    """matplotlib's pyplot on the file-only backend (no screen here or in CI)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, out, name, dpi=120):
    """Write `fig` as out/name (PNG) and close it; returns the name."""
    fig.tight_layout()
    fig.savefig(out / name, dpi=dpi)
    pyplot().close(fig)
    return name
