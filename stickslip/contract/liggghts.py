# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract on LIGGGHTS (runners.py): each case as a LIGGGHTS input with the
plugin's model and its record on, run by the adapter's launcher, read back from the model's
own record through the adapter's dump reader."""
from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from ..adapters.lammps_family import fmt as _f, run_script, serial_mpi_env
from ..adapters.liggghts import LAUNCHER, law_settings
from ..adapters.text_dumps import read_dump
from . import cases as lc


def liggghts_script(case):
    """A LIGGGHTS input for the case: grains created at their places with the model's
    record on, no integrator (grains stay where `set` puts them), each segment a `run`
    (a turn: `fix move rotate`, which also sets the spins), every step dumped at %.17g."""
    settings = law_settings(case.reset, case.timing)
    lines = ["atom_style sphere", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "units si", "region box block -4 4 -4 4 -4 4 units box",
             "create_box 1 box", "neighbor 0.25 bin", "neigh_modify delay 0"]
    for k, (name, value) in enumerate((("kn", lc.KN), ("kt", lc.KS), ("gamman_abs", case.nu_n),
                                       ("gammat_abs", case.nu_s), ("coefficientFriction", case.mu_s),
                                       ("coefficientKineticFriction", case.mu_k))):
        lines.append(f"fix m{k} all property/global {name} peratomtypepair 1 {_f(value)}")
    lines += [f"pair_style gran model hooke/stiffness tangential stick_slip {settings}", "pair_coeff * *",
              f"timestep {_f(lc.DT)}"]
    x0 = lc.rest_positions(case, case.segments[0].delta)
    for x in x0:
        lines.append(f"create_atoms 1 single {_f(x[0])} {_f(x[1])} {_f(x[2])} units box")
    lines.append(f"set atom * diameter {_f(2 * lc.R)} density 1000")
    fmt = lambda n: " ".join(["%.17g"] * n)  # noqa: E731
    cols = "id x y z vx vy vz omegax omegay omegaz"
    if case.geometry == "wall":
        lines.append(f"fix floor all wall/gran model hooke/stiffness tangential stick_slip primitive type 1 "
                     f"zplane 0.0 {settings}")
        cols += " " + " ".join(f"f_history_floor[{k}]" for k in range(1, 9))
    else:
        lines += ["compute pl all pair/gran/local id history",
                  "dump c all local 1 dump.pair " + " ".join(f"c_pl[{k}]" for k in (1, 2, 4, 5, 6, 7, 8, 9, 10, 11)),
                  f'dump_modify c format "{fmt(10)}"']
    ncol = len(cols.split())
    lines += [f"dump d all custom 1 dump.atoms {cols}", f'dump_modify d sort id format "%d {fmt(ncol - 1)}"']
    for seg in case.segments:
        if seg.omega:
            period = 2 * math.pi / seg.omega
            lines += [f"fix turn all move rotate 0 0 0 0 0 1 {_f(period)}", f"run {seg.steps}", "unfix turn"]
            continue
        for a, x in enumerate(lc.rest_positions(case, seg.delta)):
            v = seg.velocity if a == 0 else (0.0, 0.0, 0.0)
            lines.append(f"set atom {a + 1} x {_f(x[0])} y {_f(x[1])} z {_f(x[2])} "
                         f"vx {_f(v[0])} vy {_f(v[1])} vz {_f(v[2])}")
        lines.append(f"run {seg.steps}")
    return "\n".join(lines) + "\n"


def run_liggghts_script(script, work: Path):
    """Runs a LIGGGHTS input (in.contract) in `work` on the plugin's launcher, as the adapter
    runs its scenes (one process, no MPI daemon); an ERROR line raises ValueError."""
    (work / "in.contract").write_text(script)
    cmd = [str(LAUNCHER), "-in", "in.contract", "-echo", "none", "-log", "log.contract"]
    run_script("LIGGGHTS", cmd, work, 0, None, serial_env=serial_mpi_env(work))


def run_liggghts(case):
    """The LIGGGHTS plugin's model (liggghts_plugin/tangential_model_stick_slip.h), read from
    its own record: f_history_floor[1..8] (wall) or compute pair/gran/local's history
    (pair): D (3), Fn, F_s (3), slips since the contact began."""
    with tempfile.TemporaryDirectory(prefix="contract-") as tmp:
        work = Path(tmp)
        run_liggghts_script(liggghts_script(case), work)
        atoms = read_dump(work / "dump.atoms")
        pairs = read_dump(work / "dump.pair") if case.geometry == "pair" else None
    out = lc.empty_trace(case.steps)
    for k in range(case.steps):
        a = atoms[k + 1]
        if case.geometry == "wall":
            h = a[0][10:18]
            normal = np.array([0.0, 0.0, -1.0])
        else:
            rows = pairs.get(k + 1, np.zeros((0, 10)))
            if not len(rows):
                continue
            row = rows[0]
            h = row[2:10].copy()
            if row[0] > row[1]:  # stored as seen from grain 2: D and F_s change sign
                h[0:3], h[4:7] = -h[0:3], -h[4:7]
            d = a[1][1:4] - a[0][1:4]
            normal = d / np.linalg.norm(d)
        out["D"][k], out["fn"][k], out["F"][k], out["slips"][k], out["n"][k] = h[0:3], h[3], h[4:7], int(h[7]), normal
    return out


def run_liggghts_type_pairs(timing="step"):
    """Five contacts side by side, one per pair of types with different coefficients
    (cases.TYPE_PAIRS): grains of types 2 and 3 on the wall (type 1), sliding along x,
    and pairs 2-3, 2-2, 3-3 (normal x) sliding along y. Returns {type pair: trace}."""
    coeff = lc.type_pair_coefficients()
    mu_s = " ".join(_f(coeff[tuple(sorted((i, j)))][0]) for i in (1, 2, 3) for j in (1, 2, 3))
    mu_k = " ".join(_f(coeff[tuple(sorted((i, j)))][1]) for i in (1, 2, 3) for j in (1, 2, 3))
    same = lambda v: " ".join([_f(v)] * 9)  # noqa: E731
    settings = law_settings("spring", timing)
    d = 2 * lc.R - lc.DELTA
    z = lc.R - lc.DELTA
    # (id, type, position, velocity): two grains on the floor, then three pairs up high
    grains = [(1, 2, (-3.0, 0.0, z), (0.25, 0, 0)), (2, 3, (-1.0, 0.0, z), (0.25, 0, 0))]
    contacts = {(1, 2): ("wall", 1), (1, 3): ("wall", 2)}
    for k, ((ti, tj), cx) in enumerate((((2, 3), -2.0), ((2, 2), 0.5), ((3, 3), 3.0))):
        a = 3 + 2 * k
        grains += [(a, ti, (cx - d / 2, 0.0, 2.0), (0, 0.25, 0)), (a + 1, tj, (cx + d / 2, 0.0, 2.0), (0, 0, 0))]
        contacts[(ti, tj)] = ("pair", a)
    lines = ["atom_style sphere", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "units si", "region box block -4 4 -4 4 -4 4 units box",
             "create_box 3 box", "neighbor 0.25 bin", "neigh_modify delay 0",
             f"fix m0 all property/global kn peratomtypepair 3 {same(lc.KN)}",
             f"fix m1 all property/global kt peratomtypepair 3 {same(lc.KS)}",
             f"fix m2 all property/global gamman_abs peratomtypepair 3 {same(0)}",
             f"fix m3 all property/global gammat_abs peratomtypepair 3 {same(0)}",
             f"fix m4 all property/global coefficientFriction peratomtypepair 3 {mu_s}",
             f"fix m5 all property/global coefficientKineticFriction peratomtypepair 3 {mu_k}",
             f"pair_style gran model hooke/stiffness tangential stick_slip {settings}", "pair_coeff * *",
             f"timestep {_f(lc.DT)}"]
    for gid, t, x, v in grains:
        lines += [f"create_atoms {t} single {_f(x[0])} {_f(x[1])} {_f(x[2])} units box",
                  f"set atom {gid} diameter {_f(2 * lc.R)} density 1000 vx {_f(v[0])} vy {_f(v[1])} vz {_f(v[2])}"]
    lines += [f"fix floor all wall/gran model hooke/stiffness tangential stick_slip primitive type 1 zplane 0.0 "
              f"{settings}",
              "compute pl all pair/gran/local id history",
              "dump c all local 1 dump.pair " + " ".join(f"c_pl[{k}]" for k in (1, 2, 4, 5, 6, 7, 8, 9, 10, 11)),
              'dump_modify c format "' + " ".join(["%.17g"] * 10) + '"',
              "dump d all custom 1 dump.atoms id " + " ".join(f"f_history_floor[{k}]" for k in range(1, 9)),
              'dump_modify d sort id format "%d ' + " ".join(["%.17g"] * 8) + '"',
              f"run {lc.TYPE_PAIR_STEPS}"]
    with tempfile.TemporaryDirectory(prefix="contract-") as tmp:
        work = Path(tmp)
        run_liggghts_script("\n".join(lines) + "\n", work)
        atoms, pairs = read_dump(work / "dump.atoms"), read_dump(work / "dump.pair")
    out = {}
    for pair, (kind, gid) in contacts.items():
        tr = lc.empty_trace(lc.TYPE_PAIR_STEPS)
        for k in range(lc.TYPE_PAIR_STEPS):
            if kind == "wall":
                h = atoms[k + 1][gid - 1][1:9]
            else:
                row = next(r for r in pairs[k + 1] if {int(r[0]), int(r[1])} == {gid, gid + 1})
                h = row[2:10].copy()
                if row[0] > row[1]:
                    h[0:3], h[4:7] = -h[0:3], -h[4:7]
            tr["D"][k], tr["fn"][k], tr["F"][k], tr["slips"][k] = h[0:3], h[3], h[4:7], int(h[7])
        out[pair] = tr
    return out
