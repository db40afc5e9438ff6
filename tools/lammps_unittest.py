#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""LAMMPS' own tests with the sub-model stick_slip in (the LAMMPS 4 Jul 2026 build of
`STICKSLIP_SOURCE_BUILDS=lammps-2026 ./run.sh setup`, configured with ENABLE_TESTING):

  tools/lammps_unittest.py write        the sub-model's yaml cases in lammps_plugin/unittest/ again
                                        (a case whose values are unchanged keeps its date_generated)
  tools/lammps_unittest.py generate     the pair case's reference values (test_pair_style -g)
  tools/lammps_unittest.py run [BUILD]  LAMMPS' granular tests, their linear_history and mindlin
                                        cases with stick_slip/total instead, and the sub-model's own

What runs (counts printed at the end):
- LAMMPS' granular tests (unittest/granular, test_dem_01 ... test_dem_11 on their yaml
  cases, newton on and off), through ctest, with the sub-model compiled in: nothing of
  LAMMPS broken;
- every one of those cases whose tangential sub-model is linear_history or mindlin, again
  with `stick_slip/total Ks x mu mu` in its place (Ks NULL for mindlin NULL): at mu_k = mu_s
  the sub-model is that sub-model, so the case passes against the same reference values
  (those with mu = 0, frictionless, are left out and named: the law needs mu_s > 0);
- the sub-model's own cases (lammps_plugin/unittest/): a sphere dragged on a floor at
  constant speed, its torque (the wall's tangential force times the radius) a saw-tooth
  whose values are pyref's law's (write_drag_case), in step and exact timing; and a pair
  granular case for LAMMPS' pair-style tester (test_pair_style: newton on and off, restart,
  data file), its forces generated once by that tester and then checked. Its single() test is
  skipped: the tester builds the two atoms of single() with atom_style full (or ellipsoid),
  which carries no radius, and pair granular refuses an atom style without one; the
  sub-model's single() is tested by tests/test_lammps_granular.py through compute pair/local.
"""
from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from pyref.laws import LawParams, tangential_force  # noqa: E402

CASES = REPO / "lammps_plugin" / "unittest"
BUILD = REPO / "build" / "lammps_2026"

# ---------------------------------------------------------------- the drag, from pyref
# A sphere (diameter 1, density 1) on the floor z = 0 at a fixed overlap 1/64 (kn 1024:
# Fn = 16), moving along x at V = 1 (fix setforce holds its velocity; fix nve: no
# rotation), with mu_s = 0.5, mu_k = 0.45 (Fmin = 6.4), Ks = 256, a tangential dashpot
# x = 1/4 of nu_n = 1 and dt = 1/1024: the spring gains Ks V dt = 1/4 a step, the trial force
# first reaches mu_s Fn = 8 at step 31, then every 7 steps (step timing).
DRAG = dict(kn=1024.0, nu_n=1.0, ks=256.0, x=0.25, mu_s=0.5, mu_k=0.45, v=1.0, dt=1.0 / 1024, radius=0.5,
            overlap=1.0 / 64)
# segment lengths: their ends fall before, on and after slips, over several cycles
SEGMENTS = (25, 6, 1, 2, 4, 7, 13, 19, 29, 41)


def drag_series(timing, steps, slips=False):
    """The drag's tangential force on the sphere at steps 1..steps (pyref's law, the wall's
    normal +z, V_s = (V, 0, 0)): an array (steps, 3); row k-1 is step k's force. slips: also
    whether each step slipped."""
    d = DRAG
    p = LawParams(law="stick_slip", kn=d["kn"], nu_n=d["nu_n"], ks=d["ks"], nu_s=d["x"] * d["nu_n"],
                  mu_s=d["mu_s"], mu_k=d["mu_k"], slip_timing=timing)
    fn = np.array([d["kn"] * d["overlap"]])
    v = np.array([[d["v"], 0.0, 0.0]])
    D = np.zeros((1, 3))
    out, slipped = [], []
    for _ in range(steps):
        step = tangential_force(D, v, fn, d["dt"], p)
        D = step.spring
        out.append(step.force[0])
        slipped.append(bool(step.slipped[0]))
    return (np.array(out), np.array(slipped)) if slips else np.array(out)


def _rows(values):
    """A yaml block of LAMMPS' reference rows: segment, atom 1, three values."""
    return "".join(f"  {i:3d} {1:3d} {a:23.16e} {b:23.16e} {c:23.16e}\n" for i, (a, b, c) in enumerate(values))


def drag_case(timing, date):
    """The yaml case of unittest/granular (driver test_dem_04, sliding) for the drag in one
    slip timing: positions, velocities, torques and angular velocities at the end of each
    segment, computed as LAMMPS' velocity Verlet moves the sphere (x gains dt V a step) and
    pyref's law gives the wall's tangential force F (torque -R n x F, n = +z); `date`: when
    its values were generated (date_generated, as LAMMPS' yaml cases give it)."""
    d = DRAG
    name = "stick_slip" + ("/exact" if timing == "exact" else "")
    ends = np.cumsum(SEGMENTS)
    force = drag_series(timing, ends[-1])
    z0 = d["radius"] - d["overlap"]
    x, step, pos, vel, tor = 0.0, 0, [], [], []
    for end in ends:
        while step < end:
            x += d["dt"] * d["v"]
            step += 1
        f = force[end - 1]
        pos.append((x, 0.0, z0))
        vel.append((d["v"], 0.0, 0.0))
        tor.append((d["radius"] * f[1], -d["radius"] * f[0], 0.0))
    model = (f"hooke {d['kn']:g} {d['nu_n']:g} damping velocity tangential {name} {d['ks']:g} {d['x']:g} "
             f"{d['mu_s']:g} {d['mu_k']:g}")
    return f"""---
lammps_version: 4 Jul 2026
tags: granular
date_generated: {date}
epsilon: {1e-13 if timing == "step" else 1e-12}
skip_tests:
prerequisites: ! |
  atom sphere
  pair granular
pre_commands: ! |
  units lj
  dimension 3
  boundary p p f
  atom_style sphere
  region box block -2.0 2.0 -2.0 2.0 -0.5 2.0 units box
  create_box 1 box
  create_atoms 1 single 0.0 0.0 {z0!r} units box
  set group all diameter 1.0 density 1.0
  velocity all set {d['v']:g} 0.0 0.0
  comm_modify vel yes
  neighbor 0.3 bin
  timestep {d['dt']!r}
post_commands: ! |
  fix integr all nve
  fix floor all wall/gran granular {model} zplane 0.0 NULL
  fix hold all setforce 0.0 0.0 0.0
input_file:
natoms: 1
pair_style: granular
pair_coeff: ! |
  * * {model}
run_segments: ! |-
  {' '.join(map(str, SEGMENTS))}
run_pos: ! |2
{_rows(pos)}run_vel: ! |2
{_rows(vel)}run_torque: ! |2
{_rows(tor)}run_omega: ! |2
{_rows([(0.0, 0.0, 0.0)] * len(ends))}...
"""


# ------------------------------------------------- the pair granular case of test_pair_style
# 64 spheres of two types (diameters 1 and 0.95) on a jittered cubic lattice of spacing 0.9 in
# a periodic box: every neighbour overlaps (by ~0.05-0.1), with random velocities and
# spins such that, over the tester's 4 steps of dt 0.001, some contacts slip and some stick
# (test_lammps_unittest.py counts them). Type 1 pairs: hooke, Ks given; type 2:
# hertz/material with Ks NULL (Mindlin's stiffness), rolling and twisting; 1-2: hooke, the
# exact timing and spring + dashpot reset.
PAIR_COEFFS = (
    "1 1 hooke 1000 20 damping velocity tangential stick_slip 800 0.5 0.3 0.25",
    "2 2 hertz/material 1e5 0.5 0.3 damping tsuji tangential stick_slip NULL 1.0 0.3 0.2 "
    "rolling sds 500 50 0.1 twisting marshall",
    "1 2 hooke 1000 20 damping velocity tangential stick_slip/total/exact 800 0.5 0.2 0.12",
)
SPACING, CELLS = 0.9, 4
# the pair case's input and data files, named for it in LAMMPS' folder of force-style inputs
PAIR_INPUT_FILE, PAIR_DATA = "in.granular_stick_slip", "data.granular_stick_slip"

PAIR_INPUT = f"""# pair granular on 64 overlapping spheres ({PAIR_DATA}), for test_pair_style
variable  newton_pair index  on
variable  units       index  lj
variable  input_dir   index  .
variable  data_file   index  ${{input_dir}}/{PAIR_DATA}
variable  pair_style  index  granular

atom_style      sphere
atom_modify     map array
units           ${{units}}
boundary        p p p
newton          ${{newton_pair}}
comm_modify     vel yes
neighbor        0.3 bin
neigh_modify    delay 0 every 1 check yes
timestep        0.001

pair_style      ${{pair_style}}
read_data       ${{data_file}}
"""


def pair_data(seed=20260704):
    """The pair case's data file: the spheres' types, diameters, densities, positions, velocities and spins."""
    rng = np.random.default_rng(seed)
    n = CELLS ** 3
    side = SPACING * CELLS
    grid = np.array([(i, j, k) for i in range(CELLS) for j in range(CELLS) for k in range(CELLS)], float)
    x = (grid + 0.5) * SPACING + rng.uniform(-0.05, 0.05, (n, 3))
    types = rng.integers(1, 3, n)
    v = rng.uniform(-2.0, 2.0, (n, 3))
    w = rng.uniform(-2.0, 2.0, (n, 3))
    atoms = "".join(f"{i + 1} {t} {1.0 if t == 1 else 0.95:g} 1 {a:.6f} {b:.6f} {c:.6f}\n"
                    for i, (t, (a, b, c)) in enumerate(zip(types, x)))
    vels = "".join(f"{i + 1} {a:.6f} {b:.6f} {c:.6f} {p:.6f} {q:.6f} {r:.6f}\n"
                   for i, ((a, b, c), (p, q, r)) in enumerate(zip(v, w)))
    return (f"pair granular test: {n} overlapping spheres (tools/lammps_unittest.py)\n\n{n} atoms\n2 atom types\n\n"
            f"0 {side:g} xlo xhi\n0 {side:g} ylo yhi\n0 {side:g} zlo zhi\n\n"
            f"Atoms # sphere\n\n{atoms}\nVelocities\n\n{vels}")


def pair_skeleton():
    """The yaml case before test_pair_style -g adds its reference values. single() is
    skipped: LAMMPS' tester makes its two atoms with atom_style full, which pair granular
    refuses (it needs radius and rmass). `pair_style granular` is given again after the
    coefficients (post_commands; it keeps them): pair granular keeps its cutoff in no restart
    file, and the tester's restart and data stages would otherwise run without a contact."""
    coeffs = "".join(f"  {c}\n" for c in PAIR_COEFFS)
    return f"""---
lammps_version: 4 Jul 2026
tags: granular
epsilon: 5e-13
skip_tests: single
prerequisites: ! |
  atom sphere
  pair granular
pre_commands: ! ""
post_commands: ! |
  pair_style granular
input_file: {PAIR_INPUT_FILE}
pair_style: granular
pair_coeff: ! |
{coeffs}extract: ! ""
natoms: {CELLS ** 3}
...
"""


PAIR_SKELETON = "atomic-pair-granular_stick_slip.skeleton"  # (not a .yaml: ctest takes every yaml of the folder)
PAIR_CASE = "atomic-pair-granular_stick_slip.yaml"


DRAG_FILES = {"step": "dem04-stick-slip-drag-3d.yaml", "exact": "dem04-stick-slip-exact-drag-3d.yaml"}


def date_generated(case):
    """A yaml case's date_generated (None without one)."""
    m = re.search(r"^date_generated: (.+)$", case, re.M)
    return m[1] if m else None


def write():
    """The drag's yaml cases, and the pair case's input, data and skeleton (its reference
    values: `generate`)."""
    files = {}
    for timing, name in DRAG_FILES.items():
        path = CASES / "granular" / name
        old = path.read_text() if path.is_file() else ""
        same = drag_case(timing, date_generated(old)) if old else None
        files[path] = same if same == old else drag_case(timing, time.ctime())  # (as LAMMPS writes it)
    styles = CASES / "force-styles"
    files.update({styles / PAIR_INPUT_FILE: PAIR_INPUT, styles / PAIR_DATA: pair_data(),
                  styles / PAIR_SKELETON: pair_skeleton()})
    for path, text in files.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        print(f"wrote {path.relative_to(REPO)}")


def generate(build=BUILD):
    """The pair case's reference values, from LAMMPS' own tester (test_pair_style -g) on the
    build's copy of the input and data: the yaml beside the skeleton."""
    styles = build / "source" / "unittest" / "force-styles" / "tests"
    out = CASES / "force-styles" / PAIR_CASE
    proc = subprocess.run([str(build / "build" / "test_pair_style"), str(styles / PAIR_SKELETON), "-g", str(out)],
                          cwd=styles, capture_output=True, text=True)
    if proc.returncode != 0 or not out.is_file():
        raise SystemExit(f"test_pair_style -g failed:\n{proc.stdout[-3000:]}{proc.stderr[-3000:]}")
    print(f"wrote {out.relative_to(REPO)}")


# ------------------------------------------------------- LAMMPS' cases with the sub-model
# `tangential linear_history Ks x mu` and `tangential mindlin Ks|NULL x mu` (not the
# classic, rescale or force variants): a number or ${variable} each
WORD = r"(\S+)"
STOCK = re.compile(rf"tangential (linear_history|mindlin) {WORD} {WORD} {WORD}(?=\s)")


def with_stick_slip(text):
    """A LAMMPS yaml case with every linear_history and mindlin replaced by stick_slip/total
    at mu_k = mu_s, or None if it has neither."""
    new, n = STOCK.subn(lambda m: f"tangential stick_slip/total {m[2]} {m[3]} {m[4]} {m[4]}", text)
    return new if n else None


def frictionless(text):
    """Whether a case's linear_history or mindlin has mu = 0 (a number, or a variable of its
    `variables` block): outside the law's range (mu_s > 0: docs/law.md, Parameter rules), so
    stick_slip refuses it where linear_history takes it."""
    block = re.search(r"^variables: ! \|\n((?:  .*\n)*)", text, re.M)
    values = dict(line.split(None, 1) for line in block[1].split("\n") if line.strip()) if block else {}
    for m in STOCK.finditer(text):
        mu = m[4]
        if mu.startswith("${"):
            mu = values.get(mu[2:-1], mu).strip()
        try:
            if float(mu) == 0.0:
                return True
        except ValueError:
            pass
    return False


def driver(case):
    """The test program of a granular yaml case (its name's prefix: dem04-... -> test_dem_04)."""
    number = re.match(r"dem(\d\d)-", case.name)[1]
    return f"test_dem_{number}"


def run(build=BUILD):
    """Runs everything of the module's docstring; returns (summary lines, all passed)."""
    build = Path(build).resolve()
    binary = build / "build"
    lines, ok = [], True

    ctest = subprocess.run(["ctest", "-R", "^DEM", "-j2", "--output-on-failure"], cwd=binary,
                           capture_output=True, text=True)
    got = re.search(r"(\d+)% tests passed, (\d+) tests failed out of (\d+)", ctest.stdout)
    if not got:
        return [f"ctest printed no summary:\n{ctest.stdout[-3000:]}{ctest.stderr[-2000:]}"], False
    total, failed = int(got[3]), int(got[2])
    ours = len(set(re.findall(r"DEM\d\d:stick-slip[\w-]*", ctest.stdout)))
    lines.append(f"LAMMPS' granular tests (ctest -R ^DEM): {total - failed} of {total} passed "
                 f"({ours} of them the sub-model's own cases)")
    ok &= failed == 0 and ours == len(DRAG_FILES)
    if failed:
        lines.append(ctest.stdout[-4000:])

    tests = build / "source" / "unittest" / "granular" / "tests"
    passed = n = 0
    without_friction = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in sorted(tests.glob("dem*-*.yaml")):
            text = with_stick_slip(case.read_text())
            if text is None or "stick-slip" in case.name:
                continue
            if frictionless(case.read_text()):
                without_friction.append(case.stem)
                continue
            variant = Path(tmp) / f"{case.stem}-as-stick-slip.yaml"
            variant.write_text(text)
            proc = subprocess.run([str(binary / driver(case)), str(variant)], cwd=tmp, capture_output=True,
                                  text=True)
            n += 1
            if proc.returncode == 0 and "[  PASSED  ]" in proc.stdout:
                passed += 1
            else:
                lines.append(f"{case.name} with stick_slip/total failed:\n{proc.stdout[-3000:]}")
    lines.append(f"LAMMPS' linear_history and mindlin cases with stick_slip/total at mu_k = mu_s: "
                 f"{passed} of {n} passed; {len(without_friction)} left out, frictionless (mu = 0, which the "
                 f"law refuses: mu_s > 0): {', '.join(without_friction)}")
    ok &= passed == n and n > 0

    styles = build / "source" / "unittest" / "force-styles" / "tests"
    for case in sorted((CASES / "force-styles").glob("*.yaml")):
        proc = subprocess.run([str(binary / "test_pair_style"), str(styles / case.name)], cwd=binary,
                              capture_output=True, text=True)
        counts = re.search(r"\[  PASSED  \] (\d+) test", proc.stdout)
        skipped = re.search(r"\[  SKIPPED \] (\d+) test", proc.stdout)
        good = proc.returncode == 0 and counts is not None
        lines.append(f"test_pair_style {case.name}: {'passed' if good else 'FAILED'} "
                     f"({counts[1] if counts else 0} passed, {skipped[1] if skipped else 0} skipped)")
        if not good:
            lines.append(proc.stdout[-3000:])
        ok &= good
    return lines, ok


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=("write", "generate", "run"))
    ap.add_argument("build", nargs="?", type=Path, default=BUILD, help="the LAMMPS 4 Jul 2026 build's folder")
    a = ap.parse_args(argv)
    if a.what in ("write", "generate"):
        write() if a.what == "write" else generate(a.build)
        return 0
    lines, ok = run(a.build)
    print("\n".join(lines))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
