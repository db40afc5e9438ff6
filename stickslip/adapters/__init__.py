"""Engine adapters: each turns a validated scene into the standard time series.

See docs/adapters.md for the contract. `get(name)` imports an adapter lazily, so
an engine that is not installed costs nothing until it is asked for.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field

import pandas as pd

ENGINES = ("pyref", "liggghts", "yade")


@dataclass
class RunResult:
    timeseries: pd.DataFrame
    steps: int
    wall_time_s: float
    notes: list = field(default_factory=list)


def get(name):
    if name not in ENGINES:
        raise ValueError(f"engine {name!r}: must be one of {', '.join(ENGINES)}")
    return importlib.import_module(f"stickslip.adapters.{name}")


def available():
    """Engines that can run here, and the reason for each one that cannot."""
    ok, missing = [], {}
    for name in ENGINES:
        try:
            reason = get(name).available()
        except ModuleNotFoundError as e:  # an adapter that has not landed yet
            reason = "no adapter yet" if e.name == f"stickslip.adapters.{name}" else f"cannot import ({e})"
        if reason is None:
            ok.append(name)
        else:
            missing[name] = reason
    return ok, missing
