# SPDX-License-Identifier: GPL-2.0-or-later
"""What the LIGGGHTS and LAMMPS adapters share (LIGGGHTS is a LAMMPS fork: same command
line, same screen output, same input-script syntax for what both write): numbers written in
full, the box around a scene, the run's folder, and running the script: serial or on MPI
ranks, its progress read from its thermo lines, its loop time, and its first ERROR line as
the one line the user sees. Their dumps: text_dumps.py."""
from __future__ import annotations

import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np

from .text_dumps import id_ranges


def fmt(x):
    """A number as the script reads it back to the last bit."""
    return repr(float(x))


def vec(a):
    return " ".join(fmt(x) for x in a)


def box(scene):
    """The simulation box (lo, hi) around the grains and the walls' points, and the margin
    left on every side: room for the grains to move (ten of the largest radius and 2 cm).
    In 2D z is periodic and inert, but as thick as the margin: LIGGGHTS bins mesh walls in
    3D and needs a bin on either side of the grains."""
    pos = np.array([g.position for g in scene.grains])
    rmax = max(g.radius for g in scene.grains)
    pts = np.vstack([pos] + [w.point[None, :] for w in scene.walls]) if scene.walls else pos
    margin = 10 * rmax + 0.02
    lo, hi = pts.min(axis=0) - margin, pts.max(axis=0) + margin
    if scene.dimension == 2:
        lo[2], hi[2] = -margin, margin
    for axis, (a, b) in scene.periodic.items():  # a periodic box is the scene's own
        lo["xyz".index(axis)], hi["xyz".index(axis)] = a, b
    return lo, hi, margin


def boundary(scene):
    """The `boundary` command: 2D z periodic (and inert), 3D the scene's periodic axes."""
    if scene.dimension == 2:
        return "boundary f f p"
    return "boundary " + " ".join("p" if a in scene.periodic else "f" for a in "xyz")


def gravity(scene):
    """`fix gravity` for the scene's gravity (none when it is zero). Turning gravity
    (Scene.gravity_at) is one angle of the `spherical` style: fix gravity evaluates its
    variables at every step (`step` being the step whose positions it acts on), parsing each
    formula anew, so one short formula costs a quarter of the two of the `vector` style (16 %
    of the drum's step on LIGGGHTS). 2D: (sin theta, cos theta), theta = theta0 - a; 3D:
    phi = phi0 + a (about z)."""
    g = np.asarray(scene.gravity, float)
    gn = float(np.linalg.norm(g))
    if gn == 0:
        return []
    if scene.gravity_ramp is not None:  # turned in steps by the run's control loop
        raise ValueError("a gravity ramp's gravity is ramp_script.ramp_setup's")
    u = g / gn
    if not scene.gravity_rate:
        return [f"fix gravity all gravity {gn!r} vector {vec(u)}"]
    (r0, t0), deg, t = scene.gravity_spinup, 180.0 / math.pi, f"step*{fmt(scene.dt)}"
    a = f"({fmt(r0 * deg)}*{t}+{fmt((scene.gravity_rate - r0) * deg)}*({t}>{fmt(t0)})*({t}-{fmt(t0)}))"
    if scene.dimension == 2:
        return [f"variable gtheta equal {fmt(math.degrees(math.atan2(u[0], u[1])))}-{a}",
                f"fix gravity all gravity {gn!r} spherical 0.0 v_gtheta"]
    theta, phi = math.degrees(math.acos(u[2])), math.degrees(math.atan2(u[1], u[0]))
    return [f"variable gphi equal {fmt(phi)}+{a}", f"fix gravity all gravity {gn!r} spherical v_gphi {fmt(theta)}"]


def integrated(scene, ids):
    """The group to integrate, and the lines that make it: fixed grains are not integrated
    (they keep their place and zero velocity and spin), and two of them never act on each
    other, so their pairs are kept out of the neighbour list; a driven lid's grains (group lid)
    move as one body of their own (lid_script.py), which never acts on itself either."""
    apart = {}  # group name -> its atom ids
    fixed = [ids[g.name] for g in scene.grains if g.fixed]
    if fixed:
        apart["fixed"] = fixed
    if scene.lid is not None:
        apart["lid"] = [ids[n] for n in scene.lid.names]
    if not apart:
        return "all", []
    return "moving", ([f"group {name} id {id_ranges(members)}" for name, members in apart.items()]
                      + ["group moving subtract all " + " ".join(apart)]
                      + [f"neigh_modify exclude group {name} {name}" for name in apart])


def serial_mpi_env(folder):
    """Environment variables for one process of an MPI engine: Open MPI's isolated singleton,
    which starts no daemon (0.35 s less a run, measured; the same results), with its session
    directory under `folder`. Every isolated singleton names that directory alike
    (ompi.HOST.UID/jf.0/1 in the temporary folder), so two that start and end at the same
    time remove each other's, and the one starting dies in MPI_Init (`orte_session_dir
    failed`: seen in the test suite's parallel runs); a folder of each run's own keeps them
    apart."""
    return {"OMPI_MCA_ess_singleton_isolated": "1", "OMPI_MCA_orte_tmpdir_base": str(folder)}


def work_folder(scene, out_dir, engine):
    """out_dir/<engine>, made, without the dumps of an earlier run; after refusing what the
    LAMMPS-family plugins do not do: another tangential law, and the energy books (their
    record has each contact's tangential work, not its split into slips and dashpot)."""
    if scene.contact.law != "stick_slip":
        raise ValueError(f"the {engine} plugin implements stick_slip only, not {scene.contact.law}")
    if scene.output.energy:
        raise ValueError(f"output.energy: the {engine} adapter does not record the energy columns")
    work = Path(out_dir).resolve() / engine.lower()
    work.mkdir(parents=True, exist_ok=True)
    for old in work.glob("*.dump"):
        old.unlink()
    return work


def run_script(engine, cmd, work, steps, progress, np_ranks=1, env=None, serial_env=None):
    """Run `cmd` (the launcher and its arguments, reading an input script in `work`) on
    np_ranks MPI processes, its screen kept in work/screen.txt; returns the engine's own run
    time (the sum of its `Loop time of` lines). An ERROR line raises ValueError with its
    text (the scene or script was refused), a failed run without one RuntimeError.
    `env`: environment variables for the run, `serial_env`: more for a run on one process."""
    env = dict(os.environ, **(env or {}))
    if np_ranks == 1:
        env.update(serial_env or {})
    if np_ranks > 1:
        cmd = ["mpirun", "-np", str(np_ranks)] + list(cmd)
        if os.geteuid() == 0:  # OpenMPI refuses root unless told (CI runs as root)
            env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    loop, err = [], []
    with open(work / "screen.txt", "w") as screen:
        # errors="replace": LIGGGHTS 3.8's Error::all() sometimes appends bytes read through
        # a dangling pointer (its "special message"), which are not valid UTF-8
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             encoding="utf-8", errors="replace", cwd=work, env=env)
        for line in p.stdout:
            screen.write(line)
            fields = line.split()
            if len(fields) == 2 and fields[0].isdigit() and progress is not None:
                progress(int(fields[0]), steps)
            elif line.startswith("Loop time of"):
                loop.append(float(fields[3]))
            elif line.startswith("ERROR"):
                # "ERROR: text (file:line)" or "ERROR on proc N: text (file:line)"
                err.append(re.sub(r"\s*\([^()]*:\d+\)\s*$", "", line.split(":", 1)[1].strip()))
        p.wait()
    if err:
        raise ValueError(f"{engine}: {err[0]}")
    if p.returncode != 0 or not loop:
        raise RuntimeError(f"{engine} failed (exit {p.returncode}); see {work / 'screen.txt'}")
    return sum(loop)
