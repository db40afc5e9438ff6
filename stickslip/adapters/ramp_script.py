# SPDX-License-Identifier: GPL-2.0-or-later
"""The parts of a LAMMPS-family input script (LIGGGHTS is a LAMMPS fork: same variables,
`if`, `jump` and `fix gravity`) that both adapters write the same way: a scene's gravity
ramp as a control loop, and the bulk columns (columns.BULK, columns.RAMP) as a dump.

The ramp (docs/scene-format.md, Scene.gravity_ramp): the run is made of intervals of
`output.every` steps. Before each interval the angle moves by rate * every * dt (the
phase's rate) and gravity is set to the scene's gravity turned by it (Scene.gravity_tilted);
after it, the phase's condition is tested on the state at its end; when it holds the next
interval belongs to the next phase, and after the last phase, past `max_angle` (or below
0) or at time.duration the run ends. Gravity's direction is held in three variables that
hold plain numbers, so `fix gravity` reads them at every step at the cost of parsing a
number (a formula there would be parsed anew at every step).

LIGGGHTS (measured: a segmentation fault, fix gravity evaluating another variable)
redefines an equal-style variable by removing it and appending it anew, so every variable
defined after it moves down one place, and a fix, compute or dump that holds a variable's
place (fix gravity, compute reduce of an atom-style variable, dump custom) then reads
another. So `fix gravity` reads rp_gx..rp_gz, defined once, early, as the names of the
variables redefined at each interval (rp_hx..), and every variable the loop redefines is
defined after all the others (ramp_state, last before the first run).
"""
from __future__ import annotations

import math

import numpy as np

from .. import columns
from . import lammps_family
from .lammps_family import fmt as _fmt


def bulk_variables(scene, group):
    """Equal-style variables of the moving grains' centre of mass (bk_cx, ...) and velocity
    (bk_vx, ...), and their velocity along the ramp's downhill direction (bk_down)."""
    lines = [f"variable bk_c{a} equal xcm({group},{a})" for a in "xyz"]
    lines += [f"variable bk_v{a} equal vcm({group},{a})" for a in "xyz"]
    if scene.gravity_ramp is not None:
        u = scene.downhill()
        lines.append("variable bk_down equal " + "+".join(f"v_bk_v{a}*{_fmt(u[k])}" for k, a in enumerate("xyz")))
    return lines


def bulk_dump(scene, moving, precision):
    """The lines that write `bulk.dump` (when the scene has a ramp, output.bulk or a lid): the
    bulk variables of the group `moving`, then on grain 1's row (a group of one atom) the ramp's
    angle and phase, the bulk columns and the lid's (lid_script.drive's variables), per row
    (atom-style copies of equal-style variables). precision(dump, ncols): the engine's
    dump_modify line for full precision."""
    if not (scene.output.bulk or scene.gravity_ramp is not None or scene.lid is not None):
        return []
    names = []
    if scene.gravity_ramp is not None:
        names += ["rp_th", "rp_ph"]
    if scene.output.bulk:
        names += [f"bk_c{a}" for a in "xyz"] + [f"bk_v{a}" for a in "xyz"]
    if scene.lid is not None:
        names += list(columns.LID)
    return (bulk_variables(scene, moving) + ["group bk_one id 1"] + [f"variable a_{n} atom v_{n}" for n in names]
            + [f"dump bulk bk_one custom {scene.output.every} bulk.dump id " + " ".join(f"v_a_{n}" for n in names),
               precision("bulk", len(names) + 1)])


def run(scene, run_lines):
    """The run: `run_lines` (text_dumps.run_lines: progress, then one `run`), or with a ramp
    the same progress lines and the control loop in place of the `run`."""
    lines = run_lines(scene.steps)
    return lines if scene.gravity_ramp is None else lines[:-1] + ramp_loop(scene)


def gravity(scene):
    """The script's gravity: a ramp's (ramp_setup), else lammps_family.gravity's."""
    return ramp_setup(scene) if scene.gravity_ramp is not None else lammps_family.gravity(scene)


def steps_run(scene, df):
    """The steps the run made, from its last row: a ramp may end it before scene.steps."""
    return int(round(df["t"].iloc[-1] / scene.dt))


def ramp_setup(scene):
    """The gravity fix of a ramp: its direction read from rp_gx..rp_gz, which name the
    variables the loop sets (rp_hx..)."""
    mag = float(np.linalg.norm(scene.gravity))
    return ([f"variable rp_g{a} equal v_rp_h{a}" for a in "xyz"] + ["variable rp_stepnow equal step"]
            + [f"fix gravity all gravity {mag!r} vector v_rp_gx v_rp_gy v_rp_gz"])


def ramp_state(scene):
    """The variables the loop redefines (rp_th: angle, rad; rp_ph: phase; rp_n: intervals in
    the phase; rp_hx..: gravity's direction), at their starting values: after every other
    variable of the script (see the module's docstring)."""
    u = scene.gravity_tilted(0.0) / np.linalg.norm(scene.gravity)
    return (["variable rp_th equal 0.0", "variable rp_ph equal 0", "variable rp_n equal 0"]
            + [f"variable rp_h{a} equal {_fmt(u[k])}" for k, a in enumerate("xyz")]
            + [f"variable rp_t{a} equal 0.0" for a in "xyz"])


def ramp_loop(scene):
    """The control loop that replaces `run <steps>`: one interval per pass, phases in order."""
    ramp, every = scene.gravity_ramp, scene.output.every
    k = ramp.axis
    a = scene.gravity / np.linalg.norm(scene.gravity)
    b = np.cross(k, a)  # gravity(theta) = |g| (a cos theta + b sin theta): k is perpendicular to a
    total = scene.steps
    lines = ramp_state(scene) + ["run 0"]
    for i, ph in enumerate(ramp.phases):
        step_angle = ph.rate * every * scene.dt
        lines += [f"label rp_phase{i}", f"variable rp_ph equal {i}", "variable rp_n equal 0",
                  f"label rp_loop{i}",
                  f"variable rp_th equal ${{rp_th}}+{_fmt(step_angle)}",
                  "variable rp_n equal ${rp_n}+1"]
        for j, axis in enumerate("xyz"):
            # the number, not the formula: fix gravity evaluates these at every step
            lines += [f"variable rp_t{axis} equal {_fmt(a[j])}*cos(v_rp_th)+{_fmt(b[j])}*sin(v_rp_th)",
                      f"variable rp_h{axis} equal ${{rp_t{axis}}}"]
        lines.append(f"run {every} pre no post no")
        if ph.until == "duration":
            intervals = max(1, math.ceil(ph.value / (every * scene.dt) - 1e-9))
            cond = f"${{rp_n}} >= {intervals}"
        else:
            cond = f"${{bk_down}} {'>' if ph.until == 'speed_above' else '<'} {_fmt(ph.value)}"
        lines += [f'if "{cond}" then "jump SELF rp_phase{i + 1}"',
                  f'if "${{rp_stepnow}} >= {total}" then "jump SELF rp_end"',
                  f'if "${{rp_th}} > {_fmt(ramp.max_angle)}" then "jump SELF rp_end"',
                  'if "${rp_th} < 0.0" then "jump SELF rp_end"',
                  f"jump SELF rp_loop{i}"]
    lines += [f"label rp_phase{len(ramp.phases)}", "label rp_end"]
    return lines
