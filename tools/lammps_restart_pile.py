#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Does a LAMMPS `read_restart` run write the split run's bytes on a pile that LAMMPS' own
processor grid splits (docs/testing.md, History, "LAMMPS restarts")? tests/test_lammps_restart.py
pins the test pile, split along x; this measures other piles, split where LAMMPS chooses.

For our styles (the law with mu_k 0.4, exact timing, record) and for stock gran/hooke/history
+ wall/gran, on 2 ranks: the pile run N1 steps then 200 more in one process (the split run),
against N1 steps, write_restart, and read_restart + 200 steps in a new process. Prints
whether the dumps are the same bytes, the largest differences of x, v and f every 50 steps,
and the kinetic energy's relative difference at the first steps.

    .venv/bin/python tools/lammps_restart_pile.py OUT [--pile column|tall|burst|si] [--n1 N] [--newton on|off]

column: 392 spheres dropped in a 7 x 7 column (--tall: 1225); burst: 625 spheres on a lattice
closer than their diameter, which bursts upward past the box's shrink-wrapped top; si: 392
spheres of 1 mm in SI units, settled (N1 30 000). ~10-30 s a pile on 2 cores (si: 2.5 min).
"""
import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from stickslip.adapters.lammps import LAUNCHER  # noqa: E402
from stickslip.adapters.lammps_family import run_script  # noqa: E402
from stickslip.adapters.text_dumps import read_dump  # noqa: E402

LAW = "mu_k 0.4 reset spring slip_timing exact history_rotation keep_length record yes"
N2 = 200
# (units, box, fill region, lattice, diameter, density, gravity, dt, contact args, skin, N1)
PILES = {
    "column": ("lj", "-3.5 3.5 -3.5 3.5 -0.5 30", "-3.4 3.4 -3.4 3.4 0.6 8.5", 1.05, 1.0, 1.0, 1.0, 0.001,
               "2000.0 NULL 50.0 NULL 0.5 0", 0.2, 4000),
    "tall": ("lj", "-3.5 3.5 -3.5 3.5 -0.5 30", "-3.4 3.4 -3.4 3.4 0.6 25", 1.05, 1.0, 1.0, 1.0, 0.001,
             "2000.0 NULL 50.0 NULL 0.5 0", 0.2, 4000),
    "burst": ("lj", "-2.1 2.1 -2.1 2.1 -0.5 25.5", "-2.05 2.05 -2.05 2.05 0.6 25.4", 0.98, 1.0, 1.0, 1.0, 0.001,
              "2000.0 NULL 50.0 NULL 0.5 0", 0.2, 1500),
    "si": ("si", "-0.0035 0.0035 -0.0035 0.0035 -0.0005 0.03", "-0.0034 0.0034 -0.0034 0.0034 0.0006 0.0085",
           0.00105, 0.001, 2500.0, 9.81, 2e-6, "2000.0 NULL 20000.0 NULL 0.5 0", 0.0002, 30000),
}


def scripts(pile, styles, newton, n1):
    units, box, fill, lat, d, rho, g, dt, args, skin, _ = PILES[pile]
    pair = f"gran/hooke/history {args}" if styles == "stock" else f"gran/hooke/stickslip {args} {LAW}"
    wall = f"wall/gran hooke/history {args}" if styles == "stock" else f"wall/gran/stickslip hooke/history {args}"
    fixes = (f"fix 1 all nve/sphere\nfix 2 all gravity {g} vector 0 0 -1\n"
             f"fix zlower all {wall} zplane 0.0 NULL {LAW if styles == 'ours' else ''}\n")
    head = f"""units {units}
atom_style sphere
boundary p p fm
newton {newton}
comm_modify vel yes
region reg block {box} units box
create_box 1 reg
neighbor {skin} bin
neigh_modify delay 0
timestep {dt}
lattice sc {lat}
region fill block {fill} units box
create_atoms 1 region fill
set group all diameter {d} density {rho}
{"velocity all create 1.0 4928459 loop geom" if units == "lj" else ""}
pair_style {pair}
pair_coeff * *
""" + fixes
    values = "p1 p2 p3 p4" if styles == "stock" else "p11 p1 p2 p3 p12 p13"
    output = f"""compute pl all pair/local {values} cutoff radius
compute ids all property/local patom1 patom2 cutoff radius
dump loc all local 50 dump.contacts c_ids[1] c_ids[2] c_pl[*]
dump_modify loc format float %.17g
dump atoms all custom 50 dump.atoms id x y z vx vy vz fx fy fz omegax omegay omegaz
dump_modify atoms sort id format float %.17g
compute ke all ke
thermo_style custom step atoms c_ke
thermo_modify format float %.17g
thermo 1
"""
    split = head + f"thermo 1000\nrun {n1}\n" + output + f"run {N2}\n"
    writer = head + f"thermo 1000\nrun {n1}\nwrite_restart restart.n1\n"
    reader = (f"newton {newton}\nread_restart restart.n1\nneighbor {skin} bin\nneigh_modify delay 0\n"
              + fixes + output + f"run {N2}\n")
    return split, writer, reader


def kinetic(log):
    out = {}
    for line in Path(log).read_text().splitlines():
        s = line.split()
        if len(s) == 3 and s[0].isdigit():
            try:
                out[int(s[0])] = float(s[2])
            except ValueError:
                pass
    return out


def run_lammps(folder, name, script, np_):
    """`script` as in.<name> in `folder`, run there on np_ ranks as the adapters run theirs
    (its log: log.<name>); an ERROR line raises ValueError."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"in.{name}").write_text(script)
    cmd = [str(LAUNCHER), "-in", f"in.{name}", "-log", f"log.{name}", "-echo", "none", "-nocite"]
    run_script("LAMMPS", cmd, folder, 0, None, np_ranks=np_, env={"OMP_NUM_THREADS": "1"})


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--pile", choices=sorted(PILES), default="column")
    ap.add_argument("--n1", type=int, help="steps before the restart (default: the pile's)")
    ap.add_argument("--newton", choices=("on", "off"), default="off")
    a = ap.parse_args()
    n1 = a.n1 or PILES[a.pile][-1]
    for styles in ("ours", "stock"):
        d = a.out / styles
        split, writer, reader = scripts(a.pile, styles, a.newton, n1)
        run_lammps(d / "split", "split", split, np_=2)
        run_lammps(d / "writer", "writer", writer, np_=2)
        (d / "reader").mkdir(parents=True, exist_ok=True)
        (d / "reader" / "restart.n1").write_bytes((d / "writer" / "restart.n1").read_bytes())
        run_lammps(d / "reader", "reader", reader, np_=2)
        grid = next(ln.strip() for ln in (d / "split" / "log.split").read_text().splitlines() if "processor grid" in ln)
        same = all((d / "reader" / f).read_bytes() == (d / "split" / f).read_bytes()
                   for f in ("dump.atoms", "dump.contacts"))
        print(f"{styles}: {a.pile}, {grid}, N1 {n1}: dumps byte-identical: {same}")
        got, ref = read_dump(d / "reader" / "dump.atoms"), read_dump(d / "split" / "dump.atoms")
        for step in sorted(ref):
            diff = np.abs(got[step] - ref[step])
            print(f"  step {step}: max |dx| {diff[:, 1:4].max():.3g}, |dv| {diff[:, 4:7].max():.3g}, "
                  f"|df| {diff[:, 7:10].max():.3g} (largest |f| {np.abs(ref[step][:, 7:10]).max():.3g})")
        kg, kr = kinetic(d / "reader" / "log.reader"), kinetic(d / "split" / "log.split")
        for step in (n1, n1 + 1, n1 + 10, n1 + N2):
            print(f"  kinetic energy at step {step}: relative difference {abs(kg[step] - kr[step]) / kr[step]:.3g}")


if __name__ == "__main__":
    main()
