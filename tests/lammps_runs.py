# SPDX-License-Identifier: GPL-2.0-or-later
"""Running Debian's LAMMPS and the stick-slip plugin (lammps_plugin/) from the tests.

The plugin's build (`./run.sh setup`): build/lammps_plugin/ holds the launcher
lmp-stickslip (lmp's command line), libstickslip_lammps.so (LD_PRELOAD) and stickslip.lmp
(the one-line `include` for the stock lmp). Test modules mark themselves
`needs_engine("lammps")` (conftest): a skip off root, a failure as root.
"""
import os
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from stickslip.adapters.lammps_family import serial_mpi_env
from stickslip.adapters import lammps as lammps_adapter

ROOT = Path(__file__).resolve().parent.parent
BUILD = lammps_adapter.BUILD  # (STICKSLIP_LAMMPS_BUILD: another build, tools/mutate_cpp.py)
LAUNCHER = BUILD / "lmp-stickslip"
LIBRARY = BUILD / "libstickslip_lammps.so"
LOADER = BUILD / "stickslip.lmp"
STOCK = shutil.which("lmp")
EXAMPLES = Path("/usr/share/lammps/examples")

MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
CRASH_MARKERS = ("Segmentation fault", "segmentation fault", "core dumped", "Traceback",
                 "Signal:", "signal 11", "Aborted", "terminate called")


def run_lammps(workdir, name, script, exe=None, np_=1, env=None, timeout=600, check=True):
    """Write `in.<name>` into workdir and run it there with `exe` (None: the launcher) on
    np_ ranks; returns the CompletedProcess (.seconds: its wall time). check: it must end
    without an error."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / f"in.{name}").write_text(script)
    cmd = [str(exe or LAUNCHER), "-in", f"in.{name}", "-log", f"log.{name}", "-echo", "none", "-nocite"]
    full_env = dict(os.environ, OMP_NUM_THREADS="1", **(env or {}))
    if np_ == 1:
        # Open MPI's singleton start-up without its daemon: ~0.4 s less per run (measured;
        # nothing here spawns processes), its session directory the run's own
        full_env.update(serial_mpi_env(workdir))
    else:
        cmd = ["mpirun", "-np", str(np_), "--oversubscribe"] + cmd
        # a session folder of the run's own (short: Open MPI puts sockets in it): mpiruns that
        # start together in the shared one race to create it ("orte_session_dir failed")
        session = tempfile.mkdtemp(prefix="ompi-")
        full_env.update(MPI_ENV, OMPI_MCA_orte_tmpdir_base=session)
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, errors="replace",
                              timeout=timeout, env=full_env)
    finally:
        if np_ > 1:
            shutil.rmtree(session, ignore_errors=True)
    proc.seconds = time.perf_counter() - t0
    if check:
        assert proc.returncode == 0 and "ERROR" not in proc.stdout, (
            f"{name}: exit {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


def error_lines(proc):
    """The ERROR lines a run printed (stdout, where LAMMPS writes them)."""
    return [line for line in proc.stdout.splitlines() if line.startswith("ERROR")]


def read_dump(path):
    """A custom or local dump -> {step: 2D array (rows as written)}."""
    frames = {}
    lines = Path(path).read_text().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            step = int(lines[i + 1])
            n = int(lines[i + 3])
            j = i + 4
            while not lines[j].startswith("ITEM: ATOMS") and not lines[j].startswith("ITEM: ENTRIES"):
                j += 1
            ncol = len(lines[j].split()) - 2
            rows = [list(map(float, s.split())) for s in lines[j + 1:j + 1 + n]]
            frames[step] = np.array(rows, dtype=float).reshape(n, ncol)
            i = j + 1 + n
        else:
            i += 1
    return frames


def read_thermo(log):
    """Thermo output of a log -> {column: array}, the rows of every run with the last
    run's header (runs of one script print the same columns)."""
    header, cols, rows = None, None, []
    for line in Path(log).read_text().split("\n"):
        parts = line.split()
        if parts and parts[0] == "Step":
            header = cols = parts
            continue
        if cols and len(parts) == len(cols) and re.match(r"^\s*-?\d", line):
            try:
                rows.append([float(p) for p in parts])
                continue
            except ValueError:
                pass
        cols = None
    return {c: np.array([r[k] for r in rows]) for k, c in enumerate(header or [])}


def rename_to_stickslip(script):
    """The drop-in: the stock styles renamed, every other argument unchanged."""
    out = script.replace("gran/hooke/history", "gran/hooke/stickslip")
    return re.sub(r"wall/gran(\s+)hooke/history", r"wall/gran/stickslip\1hooke/history", out)
