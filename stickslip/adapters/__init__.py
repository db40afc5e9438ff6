# SPDX-License-Identifier: GPL-2.0-or-later
"""Engine adapters: each turns a validated scene into the standard time series.

An adapter is a module `stickslip/adapters/<engine>.py` that satisfies `Adapter`
(docs/adapters.md quotes it). It knows only its engine and the scene; it never
computes headline figures (stickslip/analysis.py does, for every engine alike).
`get(name)` imports an adapter lazily, so an engine that is not installed costs
nothing until it is asked for. Beside the adapters: their dump readers
(text_dumps.py) and what the LAMMPS-family ones share (lammps_family.py); an engine's
benchmark is stickslip/bench/<engine>.py.
"""
from __future__ import annotations

import importlib
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Protocol

import pandas as pd

ENGINES = ("pyref", "liggghts", "yade", "yade_cpp", "lammps", "lammps_granular")
# Engines that ./run.sh builds from Debian's source packages only behind its set-up switch
# (STICKSLIP_SOURCE_BUILDS, run.sh): the default set-up lacks them, so a full install needs
# one only where the switch asks for it (CI's does). Engine -> the switch's words (any of them
# builds the engine).
SOURCE_BUILT = {"lammps_granular": ("lammps-2025", "lammps-2026")}
# Engines that need hardware a machine may lack (DEM-Engine: an NVIDIA GPU). `stickslip run`
# takes them; available() (every engine a full install must have, the suite's root check)
# and the reports' engine lists leave them out. Their law is pinned without the hardware
# (DEM-Engine: tests/test_deme_shim.py, the force model compiled on the CPU).
OPTIONAL_ENGINES = ("deme",)


@dataclass
class RunResult:
    timeseries: pd.DataFrame  # the columns of stickslip/columns.py, one row every output.every steps
    steps: int
    wall_time_s: float  # the engine's own run time, without post-processing
    notes: list = field(default_factory=list)  # warnings to pass on to the user


class Adapter(Protocol):
    """What `stickslip.runner.run_scene` calls. An adapter must implement `available`
    and `run`; everything else (files, processes) is its own business."""

    NAME: str

    def available(self) -> str | None:
        """None if the engine can run here, else the reason in one line."""

    def run(self, scene, out_dir: Path, progress: Callable[[int, int], None] | None) -> RunResult:
        """Run a validated scene (its engine files may go under out_dir/<engine>/); call
        progress(done, total) now and then; raise ValueError (bad input the engine
        refused) or RuntimeError (the engine failed, non-finite values included) with
        a one-line message."""


def missing(program, install, needed, build_hint):
    """available()'s answer: None when `program` is on PATH and the file `needed` exists,
    else why not in one line (`install` says how to get the program, `build_hint` the file)."""
    if shutil.which(program) is None:
        return f"`{program}` not on PATH ({install})"
    if not needed.is_file():
        return f"{needed} missing ({build_hint})"
    return None


def get(name) -> Adapter:
    if name not in ENGINES + OPTIONAL_ENGINES:
        raise ValueError(f"engine {name!r}: must be one of {', '.join(ENGINES + OPTIONAL_ENGINES)}")
    return importlib.import_module(f"stickslip.adapters.{name}")


def required(name):
    """Whether a full install here must have the engine: every one of ENGINES, but those
    built from source only when STICKSLIP_SOURCE_BUILDS names them."""
    return name not in SOURCE_BUILT or any(map(source_build_asked, SOURCE_BUILT[name]))


def source_build_asked(word):
    """Whether STICKSLIP_SOURCE_BUILDS names this source build (a word of run.sh's switch)."""
    return word in os.environ.get("STICKSLIP_SOURCE_BUILDS", "").split(",")


def available():
    """Engines that can run here, and the reason for each one that cannot (engines built
    from source that the set-up was not asked for and that are missing: in neither)."""
    ok, missing = [], {}
    for name in ENGINES:
        try:
            reason = get(name).available()
        except ModuleNotFoundError as e:  # an adapter that has not landed yet
            reason = "no adapter yet" if e.name == f"stickslip.adapters.{name}" else f"cannot import ({e})"
        if reason is None:
            ok.append(name)
        elif required(name):
            missing[name] = reason
    return ok, missing
