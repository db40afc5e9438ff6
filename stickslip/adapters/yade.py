# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for YADE (Debian's package): runs yade_law/run_scene.py in `yade -n -x`.

YADE runs on the system Python, so the scene goes over as JSON (with the masses the
scene defines: in 2D a disk's mass per unit thickness, carried by an equivalent sphere)
and the time series comes back as CSV.
"""
from __future__ import annotations

import json
import os
import subprocess
import time
from pathlib import Path

import numpy as np
import pandas as pd

from .. import columns, law_options, shipped
from . import RunResult
from . import missing

NAME = "yade"
RUNNER = shipped.path("yade_law/run_scene.py")
# where YADE finds stickslip_yade: beside the runner in a checkout (yade_law/); a wheel
# installs it as a package of its own, beside stickslip
LAW_FOLDER = RUNNER.parent if (RUNNER.parent / "stickslip_yade").is_dir() else shipped.CHECKOUT


def available():
    return missing("yade", "apt-get install yade", RUNNER, "part of this repository: yade_law/")


def scene_dict(scene):
    """Everything run_scene.py needs, in plain JSON types."""
    v = lambda a: [float(x) for x in np.asarray(a)[:3]]  # noqa: E731
    walls = []
    for w in scene.walls:
        d = {"name": w.name, "point": v(w.point), "normal": v(w.normal), "velocity": v(w.velocity)}
        if w.rotation is not None:
            d["rotation"] = {"pivot": v(w.rotation.pivot), "axis": v(w.rotation.axis),
                             "rate": scene.rotation_rate(w), "steps": scene.rotation_steps(w)}
        walls.append(d)
    c = scene.contact
    return {
        "dimension": scene.dimension, "effects": scene.effects, "gravity": v(scene.gravity),
        "contact": {"kn": c.kn, "nu_n": c.nu_n, "ks": c.ks, "nu_s": c.nu_s, "mu_s": c.mu_s, "mu_k": c.mu_k,
                    **law_options.arguments("yade", reset=c.reset, slip_timing=c.slip_timing)},
        "dt": scene.dt, "steps": scene.steps, "every": scene.output.every,
        "grains": [{"name": g.name, "radius": g.radius, "mass": scene.grain_mass(g),
                    "inertia": scene.grain_inertia(g), "position": v(g.position), "velocity": v(g.velocity),
                    "angular_velocity": [float(c) for c in g.angular_velocity],
                    "imposed": list(g.imposed), "fixed": g.fixed} for g in scene.grains],
        "gravity_rate": scene.gravity_rate, "gravity_spinup": list(scene.gravity_spinup),
        "walls": walls,
        "columns": columns.names(scene),
        "output": {"grains": scene.output.grains, "contacts": scene.output.contacts, "walls": scene.output.walls,
                   "stats": scene.output.stats, "slip_stats": scene.output.slip_stats},
    }


def run(scene, out_dir, progress=None, launcher="yade", backend="python"):
    """The scene in YADE: `launcher` starts YADE (the compiled law's launcher for backend
    "cpp", stickslip/adapters/yade_cpp.py)."""
    scene.refuse_unsupported("YADE")
    if scene.contact.law != "stick_slip":
        raise ValueError(f"the YADE law implements stick_slip only, not {scene.contact.law}")
    if scene.output.energy:
        raise ValueError("output.energy: the YADE adapter does not record the energy columns")
    work = Path(out_dir).resolve() / "yade"  # absolute: yade runs with work as its cwd
    work.mkdir(parents=True, exist_ok=True)
    (work / "scene.json").write_text(json.dumps(dict(scene_dict(scene), backend=backend), indent=1))
    csv_path = work / "timeseries_raw.csv"
    t0 = time.perf_counter()
    wall, error = None, None
    with open(work / "yade.log", "w") as log:
        env = dict(os.environ, STICKSLIP_YADE_LAW=str(LAW_FOLDER))
        p = subprocess.Popen([str(launcher), "-n", "-x", str(RUNNER), str(work / "scene.json"), str(csv_path)],
                             stdout=subprocess.PIPE, stderr=log, text=True, cwd=work, env=env)
        for line in p.stdout:
            log.write(line)
            if line.startswith("PROGRESS") and progress is not None:
                done, total = map(int, line.split()[1:3])
                progress(done, total)
            elif line.startswith("WALLTIME"):
                wall = float(line.split()[1])
            elif line.startswith("ERROR"):  # run_scene.py's one-line reason (bad value, failed run)
                error = line[6:].strip()
        p.wait()
    if error is not None:
        raise (ValueError if p.returncode == 3 else RuntimeError)(error)
    if p.returncode != 0 or not csv_path.is_file():
        raise RuntimeError(f"yade failed (exit {p.returncode}); see {work / 'yade.log'}")
    df = pd.read_csv(csv_path)
    return RunResult(df, scene.steps, wall if wall is not None else time.perf_counter() - t0)
