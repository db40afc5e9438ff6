# SPDX-License-Identifier: GPL-2.0-or-later
"""Run a scene on an engine and write its results: the one place a run flows through.

scene (checked) -> adapter.run -> time series (stickslip/columns.py), checked finite
-> timeseries.csv + summary.json (headline figures from stickslip/analysis.py).
"""
from __future__ import annotations

import copy
import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from . import __version__, adapters, analysis, columns
from . import scene as scene_mod
from .errors import EngineError, SceneError
from .progress import bar
from .scene import load as scene_load

# Runs bigger than this (steps x grains) are announced before they start (pyref does
# ~5e5 grain-steps/s: minutes), and so are time series bigger than this many values
# (rows x columns: ~2 GB of CSV). The absurd is refused by the reader (MAX_* there).
ANNOUNCE_GRAIN_STEPS = 1e8
ANNOUNCE_RECORDED = 1e8
# engines whose adapter runs a scene on several MPI processes (run(..., np_ranks=N))
MPI_ENGINES = ("liggghts", "lammps", "lammps_granular")


def prepare_output(out_dir) -> Path:
    """The output folder, made if needed; one clear line if it cannot be."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SceneError(f"--out {out}: is a file, not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise SceneError(f"--out {out}: cannot be made ({e.strerror})") from None
    # Write a file to know: os.access says yes to root everywhere (/sys, /proc), and the
    # results are written only after the run.
    try:
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as e:
        raise SceneError(f"--out {out}: not writable ({e.strerror})") from None
    return out


def run_scene(scene, engine, out_dir, progress=True, ranks=1, write_timeseries=True, warn=True):
    """Run a validated scene on an engine; write timeseries.csv and summary.json into
    out_dir; returns (summary, timeseries). ranks > 1: MPI processes (MPI_ENGINES only).
    write_timeseries=False: for a study that keeps only a reduction of the series (a long
    drum run's CSV is gigabytes and takes longer to write than to reduce). The run's
    warnings (summary["notes"]) go to stderr too, but with warn=False: a study that chose
    the run on purpose (a coarse step of a time-step ladder) says once what they mean."""
    adapter = adapters.get(engine)
    if ranks > 1 and engine not in MPI_ENGINES:
        raise SceneError(f"--ranks {ranks}: only {', '.join(MPI_ENGINES)} run on several MPI processes "
                         f"(engine {engine}: 1)")
    reason = adapter.available()
    if reason is not None:
        raise EngineError(f"engine {engine} is not available: {reason}")
    out_dir = prepare_output(out_dir)
    size = scene.steps * len(scene.grains)
    rows, cols = scene.steps // scene.output.every + 1, len(columns.names(scene))
    if size > ANNOUNCE_GRAIN_STEPS or rows * cols > ANNOUNCE_RECORDED:
        sys.stderr.write(f"stickslip: {scene.name} on {engine}: {scene.steps:,} steps x {len(scene.grains):,} "
                         f"grains = {size:.2g} grain-steps; time series {rows:,} rows x {cols} columns\n")
    label = f"{scene.name} [{engine}, {scene.contact.law}, {scene.contact.slip_timing}]"
    with bar(label, scene.steps, enabled=progress) as update:
        try:
            result = adapter.run(scene, out_dir, update, **({"np_ranks": ranks} if ranks > 1 else {}))
        except (RuntimeError, ValueError, OSError, FloatingPointError) as e:  # the engine's words, one line
            raise EngineError(f"{engine}: {_one_line(e)}") from None
    df = result.timeseries
    if list(df.columns) != columns.names(scene):
        raise EngineError(f"{engine}: the adapter wrote columns {list(df.columns)}, not {columns.names(scene)}")
    bad = [c for c in df.columns if not np.isfinite(df[c].to_numpy(float)).all()]
    if bad:
        row = int(np.flatnonzero(~np.isfinite(df[bad[0]].to_numpy(float)))[0])
        raise EngineError(f"{engine}: non-finite {bad[0]} at t = {df['t'].iloc[row]:g} s (the run diverged)")
    if write_timeseries:
        _write(out_dir / "timeseries.csv", lambda p: df.to_csv(p, index=False))
    summary = {
        "scene": scene.name, "engine": engine, "version": __version__, "law": scene.contact.law,
        "reset": scene.contact.reset, "slip_timing": scene.contact.slip_timing, "dt_s": scene.dt,
        "steps": int(result.steps),
        "wall_time_s": float(result.wall_time_s), "ranks": ranks, "dimension": scene.dimension, "effects": scene.effects,
    }
    summary.update(analysis.summarise(scene, df))
    notes = list(result.notes) + scene_mod.accuracy_warnings(scene) + analysis.warnings(scene, summary)
    summary["notes"] = notes
    _write(out_dir / "summary.json", lambda p: p.write_text(json.dumps(summary, indent=2, default=_plain) + "\n"))
    for note in notes if warn else ():
        sys.stderr.write(f"stickslip: warning: {note}\n")
    return summary, df


def _write(path, write):
    """Write a result file; a full disk (or a folder that stopped being writable during
    the run) is one line, not a traceback."""
    try:
        write(path)
    except OSError as e:
        raise EngineError(f"cannot write {path}: {e.strerror or e}") from None


def _plain(v):
    """JSON for numpy scalars (and NaN as null)."""
    v = v.item() if hasattr(v, "item") else v
    return None if isinstance(v, float) and math.isnan(v) else v


def _one_line(e):
    text = " ".join(str(e).split())
    return text or type(e).__name__


# Rough seconds per step (a part per step and one per grain or wall) and to start an
# engine, only to run the longest jobs first (stickslip/parallel.py). On the paper's
# small scenes a step costs about the same whatever the grains (pyref: numpy's per-call
# overhead; YADE: its Python law; the compiled YADE law: the runner's Python per step), so the
# part per step dominates there.
_STEP = {"pyref": 5e-5, "liggghts": 2e-6, "yade": 2.5e-4, "yade_cpp": 1.5e-5, "lammps": 5e-6, "lammps_granular": 5e-6}
_PER_OBJECT = {"pyref": 1e-6, "liggghts": 3e-7, "yade": 5e-6, "yade_cpp": 3e-7, "lammps": 3e-7,
               "lammps_granular": 3e-7}
_START = {"pyref": 0.0, "liggghts": 0.5, "yade": 1.5, "yade_cpp": 2.0, "lammps": 0.5, "lammps_granular": 0.5}


def cost(scene, engine, steps=None) -> float:
    """Estimated seconds of a run of `scene` (or of `steps` steps of it) on `engine`."""
    steps = scene.steps if steps is None else steps
    return _START[engine] + steps * (_STEP[engine] + _PER_OBJECT[engine] * (len(scene.grains) + len(scene.walls)))


def run_named(scene_name, engine, out_dir, overrides, warn=True):
    """A task for stickslip/parallel.py: load a scene with overrides and run it quietly;
    returns (scene, summary, timeseries). warn: run_scene's."""
    sc = scene_load(scene_name, **overrides)
    return (sc, *run_scene(sc, engine, out_dir, progress=False, warn=warn))


def task(scene_name, engine, out_dir, warn=True, **overrides):
    """(cost, function, args) of one run, for parallel.run_all. warn=False: the run's
    warnings stay in its summary (a study that chose the run says what they mean)."""
    return (cost(scene_load(scene_name, **overrides), engine), run_named,
            (scene_name, engine, out_dir, overrides, warn))


def once(tasks):
    """Tasks for parallel.run_all with every run that is asked for more than once (the
    report's case at the scene's dt is also a step of its precision ladder) kept once,
    and the function that turns their results into one per task of `tasks`, copying a
    repeated run's files into each of its folders."""
    first, keep, same = {}, [], []  # same[k]: index in keep of the run task k gets
    for t in tasks:
        _, fn, args = t
        key = (args[1], scene_mod.identity(args[0], **args[3])) if fn is run_named else object()
        if key not in first:
            first[key] = len(keep)
            keep.append(t)
        same.append(first[key])

    def results(got):
        out = []
        for t, k in zip(tasks, same):
            r, (_, fn, args) = got[k], keep[k]
            if t is not keep[k] and not isinstance(r, Exception):
                shutil.copytree(args[2], t[2][2], dirs_exist_ok=True)
                r = (r[0], copy.deepcopy(r[1]), r[2].copy())
            out.append(r)
        return out

    return keep, results
