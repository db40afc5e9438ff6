# SPDX-License-Identifier: GPL-2.0-or-later
"""What every report figure shares: one line style per engine, and saving a figure."""
from __future__ import annotations

ENGINE_LINES = {"pyref": "-", "liggghts": "--", "yade": ":", "yade_cpp": (0, (3, 1, 1, 1)), "lammps": "-.",
                "lammps_granular": (0, (5, 2, 1, 2, 1, 2)), "deme": (0, (1, 3))}


TIMING_COLOURS = {"step": "C0", "exact": "C3"}


def line(engine, timing=None):
    """An engine's line in the figures that overlay engines (keyword arguments of plot); with a
    slip timing, its colour too (a figure that shows both timings)."""
    return {"linestyle": ENGINE_LINES[engine], **({"color": TIMING_COLOURS[timing]} if timing else {})}


def label(engine, timing, law=None):
    """A run's legend entry: what it is, engine and slip timing (and the law, where a figure
    shows several): "pyref, step timing", "coulomb: pyref, step timing"."""
    return f"{law + ': ' if law else ''}{engine}, {timing} timing"


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
