# SPDX-License-Identifier: GPL-2.0-or-later
"""fix wall/gran/region/stickslip (lammps_plugin/fix_wall_gran_region_stickslip.*): stock
wall/gran/region's arguments with the stick-slip law, the wall the engine adapter needs
for turning and oblique planes (its agreement with pyref on the tilt: test_lammps_engine.py).

- with the stock arguments it is stock wall/gran/region hooke/history bit for bit (Debian's
  examples/granregion/in.granregion.box, its pour into a box), serial and on 2 ranks;
- each contact keeps its own wall's history when a grain's contacts change; stock's
  bookkeeping (this LAMMPS version) gives a grain that touches a third wall of a block the
  histories of other walls, shown here on one sphere;
- a contact's history travels with its grain between MPI ranks and through a restart file;
- every refusal is one ERROR line naming the argument and its allowed values.
~6 s together (most of it the example on 2 ranks).
"""
import re

import numpy as np
import pytest

from conftest import needs_engine
from lammps_runs import EXAMPLES, STOCK, error_lines, read_dump, run_lammps

pytestmark = needs_engine("lammps")  # LAMMPS installed and the plugin built (the adapter's check)

STYLE = "wall/gran/region/stickslip"
DUMP = ("dump d all custom {every} dump.out id x y z vx vy vz fx fy fz omegax omegay omegaz\n"
        "dump_modify d sort id format float %.17g\n")


def granregion_box(steps, ours):
    """examples/granregion/in.granregion.box up to its first run (100 grains poured into a
    still block region; pair gran/hooke, a wall/gran/region hooke/history), that run cut
    to `steps`, every grain dumped at its end; ours: the wall renamed."""
    s = (EXAMPLES / "granregion" / "in.granregion.box").read_text()
    first = re.search(r"^run\s+5000\s*$", s, flags=re.M)
    assert first and "wall/gran/region hooke/history" in s, "examples/granregion/in.granregion.box changed"
    s = s[:first.start()] + DUMP.format(every=steps) + f"run {steps}\n"
    return s.replace("wall/gran/region hooke/history", f"{STYLE} hooke/history") if ours else s


@pytest.mark.parametrize("ranks, steps", [(1, 5000), (2, 3000)])
def test_stock_arguments_give_stocks_region_wall_bit_for_bit(tmp_path, ranks, steps):
    """The pour lands on the box's floor by step ~600 (fix pour drops from z <= 2 onto
    z = -6 under g = 1): grains touch the floor and, in its edges and corners, two and
    three faces; both runs' final states must be the same bytes."""
    if not (EXAMPLES / "granregion" / "in.granregion.box").is_file():
        pytest.fail(f"{EXAMPLES}/granregion/in.granregion.box missing: apt-get install lammps-examples")
    dumps = []
    for ours in (False, True):
        work = tmp_path / ("ours" if ours else "stock")
        run_lammps(work, "box", granregion_box(steps, ours), exe=None if ours else STOCK, np_=ranks)
        dumps.append((work / "dump.out").read_text())
    assert dumps[0] == dumps[1]
    state = read_dump(tmp_path / "ours" / "dump.out")[steps]
    assert len(state) == 100 and (state[:, 3] < -5.0).sum() > 20  # grains resting near the floor (z = -6)


# a sphere (radius 0.5, mass 1) touching the floor (zlo) and a side (ylo) of a block region,
# moved at V along -x by fix move into the corner with a third face (xlo); stiff and
# frictional enough (xmu 10000) to stick throughout, no damping
KN, KT, V, DT, OVERLAP = 1.0e5, 1.0e4, 1.0, 0.001, 0.01
CORNER = f"""units lj
atom_style sphere
boundary f f f
comm_modify vel yes
region box block -1 11 -1 11 -1 11 units box
create_box 1 box
create_atoms 1 single 3.0 {0.5 - OVERLAP!r} {0.5 - OVERLAP!r} units box
set atom 1 diameter 1.0 mass 1.0
pair_style gran/hooke/history {KN!r} {KT!r} 0.0 0.0 0.5 0
pair_coeff * *
region cont block 0 10 0 10 0 10 units box
fix w all {{style}} hooke/history {KN!r} {KT!r} 0.0 0.0 10000 0 region cont
fix mv all move linear {-V!r} 0.0 0.0
timestep {DT!r}
dump d all custom 1 dump.out id x fx
dump_modify d format float %.17g
run 2510
"""


def test_a_third_wall_keeps_each_walls_history(tmp_path):
    """While the sphere slides along the floor and the side, each of the two springs grows
    by V dt a step (docs/law.md eq. 7; the contacts began at the set-up, step 0), so after
    step k each holds Kt k V dt along +x on the sphere: fx = 2 Kt k V dt. At step 2501 the
    sphere enters the corner: the new contact with xlo pushes with Kn (0.5 - x) and has no
    spring (it moves along its normal), and the two springs go on: fx = 2 Kt k V dt +
    Kn (0.5 - x). Stock's region wall (update_contacts fills c2r by history slot, its force
    loop reads it by contact) gives the floor the side's spring and the side a new one:
    fx = Kt k V dt + Kt V dt + Kn (0.5 - x), a spring's force short. Round-off: the springs
    are sums of k terms V dt (relative k u), the positions fix move's (x0 - V k dt): 1e-10
    relative covers both."""
    fx = {}
    for style in ("wall/gran/region", STYLE):
        work = tmp_path / style.replace("/", "_")
        run_lammps(work, "corner", CORNER.format(style=style), exe=STOCK if style == "wall/gran/region" else None)
        frames = read_dump(work / "dump.out")
        fx[style] = {k: frames[k][0, 1:] for k in frames}
    x = {k: v[0] for k, v in fx[STYLE].items()}
    first = min(k for k in x if x[k] < 0.5)  # the step the sphere first overlaps xlo
    for k in (first - 1, first, first + 5):
        xlo = KN * max(0.5 - x[k], 0.0)
        assert fx[STYLE][k][1] == pytest.approx(2 * KT * k * V * DT + xlo, rel=1e-10), k
        # stock, from the step the corner is entered: the side's spring started anew
        side = k if k < first else k - first + 1
        assert fx["wall/gran/region"][k][1] == pytest.approx(KT * (k + side) * V * DT + xlo, rel=1e-10), k


def test_a_contacts_history_travels_between_ranks(tmp_path):
    """A grain resting on a region plane that moves along x (a conveyor: `region ... move`,
    0.1 length units per time unit), held back by a constant force its spring must carry
    (10, a fifth of mu_s Fn; the belt's start adds at most 0.1 sqrt(Kt m) = 10: it sticks),
    translation only, is carried across the middle of the box (x = 5), where 2 ranks split
    it: the grain and its contact's history move to the other rank at the neighbour-list
    rebuild after it (every 0.15 of motion). 1 and 2 ranks must give the same bytes (a
    history lost on the way would reset the spring: the grain would slip back by F/Kt)."""
    rest = 100.0 / KN  # the overlap of its weight, m g / Kn
    script = f"""units lj
atom_style sphere
boundary f f f
processors * 1 1
comm_modify vel yes
region box block 0 10 -1 1 -1 1 units box
create_box 1 box
create_atoms 1 single 4.9 0.0 {0.5 - rest!r} units box
set atom 1 diameter 1.0 mass 1.0
pair_style gran/hooke/history {KN!r} {KT!r} 10.0 NULL 0.5 1
pair_coeff * *
variable dx equal 0.1*step*{DT!r}
region belt plane 0 0 0 0 0 1 side in units box move v_dx NULL NULL
fix w all {STYLE} hooke/history {KN!r} {KT!r} 10.0 NULL 0.5 1 region belt mu_k 0.45 record yes
fix grav all gravity 100.0 vector 0 0 -1
fix hold all addforce -10.0 0.0 0.0
fix nve all nve
timestep {DT!r}
dump d all custom 100 dump.out id x y z vx vy vz fx fy fz omegax omegay omegaz f_w[9] f_w[10] f_w[13]
dump_modify d format float %.17g
run 3000
"""
    out = []
    for ranks in (1, 2):
        proc = run_lammps(tmp_path / f"r{ranks}", "belt", script, np_=ranks)
        assert f"{ranks} by 1 by 1 MPI processor grid" in proc.stdout
        out.append((tmp_path / f"r{ranks}" / "dump.out").read_text())
    assert out[0] == out[1]
    frames = read_dump(tmp_path / "r1" / "dump.out")
    last = frames[max(frames)][0]
    # columns: id x y z vx vy vz fx fy fz omegax omegay omegaz Fn Fs_x slips
    assert last[1] > 5.15  # carried across the middle (x = 5) and past a rebuild
    assert last[13] > 0 and last[15] == 0 and last[14] == pytest.approx(10.0, rel=0.1)  # held, never slipped


def test_a_restart_continues_each_contacts_history(tmp_path):
    """The belt of the test above, serial: 1000 steps, write_restart, read_restart and 1000
    more, against 2000 in one run. The spring holds the grain against the 10 units of force
    with D = 1e-3; a history lost at the restart would let it slip back by ~1e-3. A run split
    in two is not one run in LAMMPS (the second run's set-up evaluates the forces again with
    the full-step velocities: lammps_plugin/README.md), which moves the grain by ~1e-7 here
    (measured 1.4e-7): the two must agree within 1e-5, a hundredth of a lost spring."""
    rest = 100.0 / KN
    setup = f"""pair_style gran/hooke/history {KN!r} {KT!r} 10.0 NULL 0.5 1
pair_coeff * *
comm_modify vel yes
variable dx equal 0.1*step*{DT!r}
region belt plane 0 0 0 0 0 1 side in units box move v_dx NULL NULL
fix w all {STYLE} hooke/history {KN!r} {KT!r} 10.0 NULL 0.5 1 region belt mu_k 0.45 record yes
fix grav all gravity 100.0 vector 0 0 -1
fix hold all addforce -10.0 0.0 0.0
fix nve all nve
timestep {DT!r}
"""
    start = f"""units lj
atom_style sphere
atom_modify map array
boundary f f f
region box block 0 10 -1 1 -1 1 units box
create_box 1 box
create_atoms 1 single 4.9 0.0 {0.5 - rest!r} units box
set atom 1 diameter 1.0 mass 1.0
""" + setup
    end = "dump d all custom 1000 dump.out id x f_w[13]\ndump_modify d format float %.17g\n"
    run_lammps(tmp_path / "one", "belt", start + end + "run 2000\n")
    run_lammps(tmp_path / "two", "first", start + "run 1000\nwrite_restart belt.restart\n")
    run_lammps(tmp_path / "two", "second", "read_restart belt.restart\n" + setup + end + "run 1000\n")
    one, two = read_dump(tmp_path / "one" / "dump.out")[2000][0], read_dump(tmp_path / "two" / "dump.out")[2000][0]
    assert abs(one[1] - two[1]) < 1e-5 and one[2] == two[2] == 0  # the same place, no slip in either


@pytest.mark.parametrize("args, words", [
    ("hooke/history 1e5 NULL 0 NULL 0.5 0 region nope", ["region 'nope' does not exist"]),
    ("hooke/history 1e5 NULL 0 NULL 0.5 0 region cont wiggle x 1 1", ["wiggle is not allowed", "move, rotate"]),
    ("hertz/history 1e5 NULL 0 NULL 0.5 0 region cont", ["fstyle 'hertz/history'", "hooke/history"]),
    ("hooke/history 1e5 NULL 0 NULL 0.5 0 region cont mu_k 0.2", ["mu_k = 0.2", "[0.25, 0.5]"]),
    ("hooke/history 1e5 NULL 0 NULL 0.5 0 region cont bounce yes", ["unknown keyword 'bounce'", "record"]),
    ("hooke/history 1e5 NULL 0 NULL 0.5 0 zplane 0 NULL", ["wallstyle 'zplane'", "region regionID"]),
    ("hooke/history -1 NULL 0 NULL 0.5 0 region cont", ["Kn = -1", "Kn > 0"]),
])
def test_bad_input_is_one_error_line(tmp_path, args, words):
    script = f"""units lj
atom_style sphere
region box block 0 10 0 10 0 10 units box
create_box 1 box
region cont block 1 9 1 9 1 9 units box
pair_style gran/hooke/history 1e5 NULL 0 NULL 0.5 0
pair_coeff * *
fix w all {STYLE} {args}
run 0
"""
    proc = run_lammps(tmp_path, "bad", script, check=False)
    errors = error_lines(proc)
    assert len(errors) == 1, proc.stdout[-2000:]
    assert errors[0].startswith(f"ERROR: fix w {STYLE}: ")
    for w in words:
        assert w in errors[0], (w, errors[0])
    assert np.all([m not in proc.stdout + proc.stderr for m in ("Segmentation", "Traceback")])
