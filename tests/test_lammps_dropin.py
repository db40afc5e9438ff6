# SPDX-License-Identifier: GPL-2.0-or-later
"""The LAMMPS plugin as a drop-in (issue 30, item 2): with the stock arguments and no
extra keyword, `pair_style gran/hooke/stickslip` + `fix wall/gran/stickslip` must give
stock `gran/hooke/history` + `wall/gran hooke/history` output bit for bit.

The scripts are Debian's examples (lammps-examples), read at test time and shortened;
both runs dump every atom's position, velocity, force and spin at full precision
(%.17g), and the dumps must be identical byte for byte. Examples that use these styles:
- pour/in.pour (3D pour onto a floor wall, then a chute): as shipped (newton off), and
  with newton on, serial and on 2 ranks;
- pour/in.pour.2d and in.pour.2d.molecule (2D, rigid/small molecules): they ship with the
  Hertzian styles (gran/hertz/history), which the plugin does not derive from; run here
  with hertz/history -> hooke/history in both runs, for the 2D walls (xplane, yplane,
  xmu = 0, dampflag 1) and rigid-body masses;
- rigid/in.rigid.gravity (newton on, rigid/small bodies poured onto a zplane): its pour
  region lowered from z = 80-100 to 5-25 so that bodies land within the test's steps.
Examples that do not apply: granregion/* (pair gran/hooke without history or Hertzian
styles, and region walls: wall/gran/region is not derived), granular/* (pair granular).

Each run reaches thousands of slipping contact-steps (grains landing on the floor and on
each other; counted with `record yes` while writing the test: in.pour's first 6000 steps
end with 822 slips summed over the contacts then open, the 2D pour's first 10000
with 763, the rigid bodies' 20000 with 2787).
"""
import re
import shutil

import pytest

from conftest import needs_engine
from lammps_runs import EXAMPLES, STOCK, read_dump, rename_to_stickslip, run_lammps

pytestmark = needs_engine("lammps")  # LAMMPS installed and the plugin built (the adapter's check)

DUMP = ("dump dropin all custom {every} dump.out id x y z vx vy vz fx fy fz omegax omegay omegaz\n"
        "dump_modify dropin sort id format float %.17g\n")


def pour_script(n1, n2, every, newton, damped=False):
    """examples/pour/in.pour: the pour shortened to n1 steps, the chute to n2. damped: the
    pair and the wall with tangential damping (dampflag 1, gamma_t = gamma_n/2) and
    limit_damping, so that stock's rescale of a slipping contact's shear carries the
    dashpot term (the example's dampflag 0 makes it vanish)."""
    s = (EXAMPLES / "pour" / "in.pour").read_text()
    if damped:
        s, k = re.subn(r"50\.0 NULL 0\.5 0\b", "50.0 NULL 0.5 1 limit_damping", s)
        assert k == 2, "examples/pour/in.pour changed"
    s, k = re.subn(r"^newton\s+off$", f"newton {newton}", s, flags=re.M)
    runs = list(re.finditer(r"^run\s+25000$", s, flags=re.M))
    assert k == 1 and len(runs) == 2, "examples/pour/in.pour changed"
    first, second = runs
    return (s[:first.start()] + DUMP.format(every=every) + f"run {n1}" + s[first.end():second.start()]
            + f"run {n2}" + s[second.end():])


def pour2d_script(name, n, every, newton):
    """examples/pour/in.pour.2d(.molecule) with Hookean styles (see the module's doc)."""
    s = (EXAMPLES / "pour" / name).read_text()
    s, k1 = re.subn(r"hertz/history", "hooke/history", s)
    s, k2 = re.subn(r"^newton\s+off$", f"newton {newton}", s, flags=re.M)
    s, k3 = re.subn(r"^run\s+25000$", DUMP.format(every=every) + f"run {n}", s, flags=re.M)
    assert (k1, k2, k3) == (3, 1, 1), f"examples/pour/{name} changed"
    return s


def rigid_script(n, every, newton):
    """examples/rigid/in.rigid.gravity, its pour region lowered."""
    s = (EXAMPLES / "rigid" / "in.rigid.gravity").read_text()
    s, k1 = re.subn(r"^newton\s+on$", f"newton {newton}", s, flags=re.M)
    s, k2 = re.subn(r"pourreg block 5 15 5 15 80 100", "pourreg block 5 15 5 15 5 25", s)
    s, k3 = re.subn(r"^run\s+100000$", DUMP.format(every=every) + f"run {n}", s, flags=re.M)
    assert (k1, k2, k3) == (1, 1, 1), "examples/rigid/in.rigid.gravity changed"
    return s


def assert_stock_and_ours_identical(tmp_path, script, np_, files=()):
    """Run the script with the stock styles on the stock lmp and renamed on the launcher;
    the dumps must be identical bytes, and must hold moving grains."""
    for sub in ("stock", "ours"):
        (tmp_path / sub).mkdir()
        for f in files:
            shutil.copy(f, tmp_path / sub)
    ours = rename_to_stickslip(script)
    assert ours.count("stickslip") >= 2, "the script uses neither stock style"
    run_lammps(tmp_path / "stock", "example", script, exe=STOCK, np_=np_)
    run_lammps(tmp_path / "ours", "example", ours, np_=np_)
    stock_dump, our_dump = (tmp_path / "stock" / "dump.out"), (tmp_path / "ours" / "dump.out")
    frames = read_dump(our_dump)
    last = frames[max(frames)]
    assert len(last) > 0 and abs(last[:, 7:10]).max() > 0, "no forces in the dump: nothing was compared"
    assert stock_dump.read_bytes() == our_dump.read_bytes(), "stock and stickslip dumps differ"


# cost (2-core machine, idle): serial ~1 s per run, 2 ranks ~3 s per run (MPI start-up);
# two runs per case
@pytest.mark.parametrize("np_,newton,damped", [(1, "off", False), (1, "on", False), (2, "off", False),
                                               (2, "on", False), (1, "off", True)])
def test_pour_is_stock_bit_for_bit(tmp_path, np_, newton, damped):
    """examples/pour/in.pour, its first 5000 steps (402 then 804 grains; landing from step
    ~2200) and the chute's set-up; also with tangential damping and limit_damping."""
    assert_stock_and_ours_identical(tmp_path, pour_script(5000, 0, 1000, newton, damped), np_)


def test_pour2d_is_stock_bit_for_bit(tmp_path):
    """examples/pour/in.pour.2d (Hookean), 10000 steps: the first grains land at ~7700."""
    assert_stock_and_ours_identical(tmp_path, pour2d_script("in.pour.2d", 10000, 2000, "off"), 1)


def test_pour2d_molecule_is_stock_bit_for_bit(tmp_path):
    """examples/pour/in.pour.2d.molecule (Hookean): rigid V-shaped molecules (rigid/small),
    pair and wall contacts use the bodies' masses."""
    assert_stock_and_ours_identical(tmp_path, pour2d_script("in.pour.2d.molecule", 10000, 2000, "off"), 1,
                                    files=[EXAMPLES / "pour" / "molecule.vshape"])


@pytest.mark.parametrize("np_,newton", [(1, "on"), (2, "off")])
def test_rigid_gravity_is_stock_bit_for_bit(tmp_path, np_, newton):
    """examples/rigid/in.rigid.gravity: rigid bodies of 5 spheres poured on a zplane wall."""
    assert_stock_and_ours_identical(tmp_path, rigid_script(20000, 5000, newton), np_,
                                    files=[EXAMPLES / "rigid" / "molecule.data"])


@pytest.mark.slow
@pytest.mark.parametrize("np_,newton", [(1, "off"), (2, "on")])
def test_full_pour_is_stock_bit_for_bit(tmp_path, np_, newton):
    """The whole in.pour: 3000 grains poured (25000 steps), then the chute (25000 steps).
    ~70 s per run serial."""
    assert_stock_and_ours_identical(tmp_path, pour_script(25000, 25000, 5000, newton), np_)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["in.pour.2d", "in.pour.2d.molecule"])
def test_pour2d_two_ranks_is_stock_bit_for_bit(tmp_path, name):
    """The 2D pours on 2 ranks with newton on (~4 and ~9 s per run)."""
    assert_stock_and_ours_identical(tmp_path, pour2d_script(name, 12000, 2000, "on"), 2,
                                    files=[EXAMPLES / "pour" / "molecule.vshape"])
