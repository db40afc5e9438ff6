# SPDX-License-Identifier: GPL-2.0-or-later
"""The tangential sub-model `stick_slip` (lammps_plugin/granular/) as a drop-in for LAMMPS
2025's own sub-models: with mu_k = mu_s and /total its step-timing arithmetic is
linear_history's operation for operation (with Ks NULL mindlin's), so
`tangential stick_slip/total Ks x mu mu` must give `tangential linear_history Ks x mu`'s run
bit for bit, and `stick_slip/total NULL x mu mu` gives `mindlin NULL x mu`'s, whatever the
normal, damping, rolling and twisting sub-models around it, in pair_style granular and in
the wall fixes (fix wall/gran granular, fix wall/gran/region granular).

The scene: a collapsing pile, 330 grains of two types (diameters 1 and 0.9, their own
pair coefficients, so that the 1-2 pairs are mixed by each sub-model's mix_coeffs) on a
lattice with random velocities, falling onto a floor (fix wall/gran granular zplane)
between two side walls (a block region under fix wall/gran/region granular) in a box
periodic along x, under gravity tilted by 24 degrees along x: the pile lands, spreads and
flows down the slope, its grains sliding on the floor, the side walls and each other and
sticking again (counted with /record: test_the_scene_sticks_and_slips). Both runs write
their thermo output (step, atoms, ke, rotational ke, pressure, pxz at %.17g) and every
grain's x, v, omega and force (%.17g, sorted by id) every 1000 steps; both must be the
same bytes. Stock and ours are not equal by construction: with mu_k = 0.9 mu_s the same
scene gives another run.

Measured on the shared 2-core machine (load 2-4): a serial run of 3000 steps ~0.3 s, a
2-rank run ~0.7 s (MPI's start-up much of it); the serial tests 0.7-1.3 s each (two or
three runs), the 2-rank ones 1.3-2.8 s: 14-17 s for the module (~7 s CPU); up to 7 s a
2-rank test when the machine is busier (load ~9).
"""
import numpy as np
import pytest

from conftest import needs_engine
from lammps_runs import read_dump, run_lammps
from stickslip.adapters import lammps_granular

pytestmark = needs_engine("lammps_granular")  # LAMMPS 2025 built with the sub-model

LMP = lammps_granular.LAUNCHER  # (STICKSLIP_LAMMPS_2025: another build, e.g. a patched copy)
STEPS, EVERY = 3000, 1000

# the normal model and its damping for each type (E, damping, nu), and the tangential
# coefficients (Ks, x, mu_s) of each type: the 1-2 pairs mix them
HERTZ = ("hertz/material 1e4 400 0.3 damping viscoelastic", "hertz/material 2e4 300 0.25 damping viscoelastic")
TANGENTIAL = ((500.0, 0.5, 0.5), (700.0, 0.4, 0.45))
WALL_TANGENTIAL = (600.0, 0.5, 0.4)
EXTRA = "limit_damping"


def stock_words(ks, x, mu):
    return f"linear_history {ks:g} {x:g} {mu:g}"


def ours_words(ks, x, mu, mu_k=None, name="stick_slip/total"):
    return f"{name} {ks:g} {x:g} {mu:g} {mu if mu_k is None else mu_k:g}"


def mindlin_stock(ks, x, mu):
    return f"mindlin NULL {x:g} {mu:g}"


def mindlin_ours(ks, x, mu, mu_k=None, name="stick_slip/total"):
    return f"{name} NULL {x:g} {mu:g} {mu if mu_k is None else mu_k:g}"


def models(tangential, normal=HERTZ, extra=EXTRA, wall_tangential=None):
    """The granular model's words: (type 1's, type 2's, the walls'). tangential(ks, x, mu)
    -> the tangential sub-model's words for one set of coefficients; normal: each type's
    normal and damping words; extra: rolling/twisting words and keywords after the
    tangential ones; wall_tangential: the walls' tangential words (default: tangential)."""
    wall_tangential = wall_tangential or tangential
    pair = [f"{normal[t]} tangential {tangential(*TANGENTIAL[t])} {extra}" for t in (0, 1)]
    return pair[0], pair[1], f"{normal[0]} tangential {wall_tangential(*WALL_TANGENTIAL)} {extra}"


def pile(words, newton="off"):
    """The collapsing pile up to its fixes: what a restart file holds (the box, the
    grains, the pair style and its coefficients)."""
    return f"""atom_style sphere
boundary p f fm
newton {newton}
processors * 1 1
comm_modify vel yes
region reg block -6 6 -3 3 -0.5 10 units box
create_box 2 reg
neighbor 0.2 bin
neigh_modify delay 0
timestep 0.001
lattice sc 1.05
region fill block -5.9 5.9 -2.9 2.9 0.6 6 units box
create_atoms 1 region fill
set type 1 type/fraction 2 0.5 8731
set type 1 diameter 1.0 density 1.0
set type 2 diameter 0.9 density 1.0
velocity all create 1.0 4928459 loop geom
pair_style granular
pair_coeff 1 1 {words[0]}
pair_coeff 2 2 {words[1]}
"""


def fixes(words, record=False):
    """What a restart file does not hold: integration, gravity, the floor (fix wall/gran
    granular zplane) and the side walls (fix wall/gran/region granular on a block region:
    regions are not kept in restart files either); record: the walls
    keep per-atom contact values (`contacts`: columns 9-14 are the sub-model's record)."""
    contacts = " contacts" if record else ""
    return f"""fix 1 all nve/sphere
fix 2 all gravity 1.0 vector 0.45 0 -1
fix floor all wall/gran granular {words[2]} zplane 0.0 NULL{contacts}
region side block INF INF -3 3 INF INF side in units box
fix side all wall/gran/region granular {words[2]} region side{contacts}
"""


def output(every=EVERY, record=False, record_every=100):
    """Thermo (%.17g) every 250 steps; every grain's x, v, omega and force (%.17g, sorted by
    id) every `every` steps; record: every `record_every` steps the pair contacts' record
    (ids, pair/local p13-p18: Fn, F_s on the first grain, slips, work) and the walls' (each
    grain's floor then side columns 9-14)."""
    s = f"""compute erot all erotate/sphere
thermo_style custom step atoms ke c_erot press pxz
thermo_modify format float %.17g
thermo 250
dump d all custom {every} dump.atoms id x y z vx vy vz omegax omegay omegaz fx fy fz
dump_modify d sort id format float %.17g
"""
    if record:
        walls = " ".join(f"f_{w}[{c}]" for w in ("floor", "side") for c in range(9, 15))
        s += f"""compute pl all pair/local p13 p14 p15 p16 p17 p18 cutoff radius
compute ids all property/local patom1 patom2 cutoff radius
dump loc all local {record_every} dump.contacts c_ids[1] c_ids[2] c_pl[*]
dump_modify loc format float %.17g
dump walls all custom {record_every} dump.walls id {walls}
dump_modify walls sort id format float %.17g
"""
    return s


def scene(tangential, normal=HERTZ, extra=EXTRA, newton="off", wall_tangential=None, record=False):
    """The whole run, STEPS steps (the module's docstring)."""
    words = models(tangential, normal, extra, wall_tangential)
    return pile(words, newton) + fixes(words, record) + output(record=record) + f"run {STEPS}\n"


def thermo_text(log):
    """The thermo block of a log: the header line to the line before 'Loop time'."""
    text = log.read_text()
    start = text.index("\n   Step ")
    return text[start:text.index("\nLoop time", start)]


def run(tmp_path, name, script, np_=1):
    work = tmp_path / name
    run_lammps(work, name, script, exe=LMP, np_=np_)
    return work


def assert_same_run(a, b):
    """Two runs' thermo output and dumps are the same bytes (and the dumps hold a pile
    that moved: nothing was compared otherwise)."""
    last = read_dump(a / "dump.atoms")[STEPS]
    assert len(last) == 330 and np.abs(last[:, 4:7]).max() > 0.1 and np.abs(last[:, 10:13]).max() > 0
    ta, tb = (thermo_text(d / f"log.{d.name}").split("\n") for d in (a, b))
    differ = [(la, lb) for la, lb in zip(ta, tb) if la != lb]
    assert ta == tb, "thermo output differs, first at\n{}\n{}".format(*(differ or [("(lengths)", "")])[0])
    assert (b / "dump.atoms").read_bytes() == (a / "dump.atoms").read_bytes(), "dumps differ"


@pytest.mark.parametrize("np_,newton", [(1, "off"), (1, "on"), (2, "off"), (2, "on")])
def test_stick_slip_total_is_linear_history_bit_for_bit(tmp_path, np_, newton):
    """Hertz with viscoelastic damping and limit_damping, pair and both walls: stock
    linear_history and stick_slip/total with mu_k = mu_s give the same bytes, serial and
    on 2 ranks (split along x: the flow carries grains and contacts across the ranks'
    boundary and the periodic one), newton on and off."""
    stock = run(tmp_path, "stock", scene(stock_words, newton=newton), np_)
    ours = run(tmp_path, "ours", scene(ours_words, newton=newton), np_)
    assert_same_run(stock, ours)


# other sub-models around the tangential one: (normal words per type, extra words, ranks, newton)
VARIANTS = {
    # rolling resistance (sds) and twisting (marshall: it takes Ks, the dashpot and mu_s
    # from the tangential sub-model), restitution-based damping
    "rolling_twisting": (("hertz/material 1e4 0.6 0.3 damping coeff_restitution",
                          "hertz/material 2e4 0.5 0.25 damping coeff_restitution"),
                         "rolling sds 200 20 0.1 twisting marshall limit_damping", 2, "on"),
    # a Hookean normal force with mass-scaled damping (pair gran/hooke/history's)
    "hooke": (("hooke 2000 30 damping mass_velocity", "hooke 3000 40 damping mass_velocity"), EXTRA, 1, "off"),
    # adhesive normal models: the friction threshold is their own |Fne + 2 F_pulloff|
    "dmt": (("dmt 1e4 400 0.3 0.2 damping viscoelastic", "dmt 2e4 300 0.25 0.3 damping viscoelastic"),
            "", 1, "on"),
    "jkr": (("jkr 1e4 400 0.3 0.2 damping viscoelastic", "jkr 2e4 300 0.25 0.3 damping viscoelastic"),
            "", 1, "off"),
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_any_normal_damping_rolling_and_twisting(tmp_path, variant):
    """The same drop-in with other normal, damping, rolling and twisting sub-models."""
    normal, extra, np_, newton = VARIANTS[variant]
    stock = run(tmp_path, "stock", scene(stock_words, normal, extra, newton), np_)
    ours = run(tmp_path, "ours", scene(ours_words, normal, extra, newton), np_)
    assert_same_run(stock, ours)


def test_ks_null_is_mindlin_bit_for_bit(tmp_path):
    """Ks NULL (Mindlin's 8 G* a from the material of hertz/material) against `mindlin NULL x
    mu`, newton on; mixed types take 8 G* of the mixed material, as mindlin."""
    stock = run(tmp_path, "stock", scene(mindlin_stock, newton="on"))
    ours = run(tmp_path, "ours", scene(mindlin_ours, newton="on"))
    assert_same_run(stock, ours)


def test_the_walls_alone_are_a_drop_in(tmp_path):
    """The floor (fix wall/gran granular zplane) and the side walls (fix wall/gran/region
    granular) with stick_slip/total, the grain pairs with linear_history in both runs:
    the walls' contacts alone give stock's bytes."""
    stock = run(tmp_path, "stock", scene(stock_words))
    ours = run(tmp_path, "ours", scene(stock_words, wall_tangential=ours_words))
    assert_same_run(stock, ours)


def test_the_scene_sticks_and_slips(tmp_path):
    """What the drop-in tests compare is not equal by construction:
    - stick_slip/total/record with mu_k = mu_s is stock's run too (the record changes no
      force; its history is 9 values a contact, transferred with their own signs);
    - its record counts slips (pair/local p17, the walls' column 13) in grain pairs, on the
      floor and on the side walls, and contacts that stick: of the contacts open at two
      dumps 100 steps apart, some slipped in between and some did not;
    - mu_k = 0.9 mu_s, the law's own drop after a slip, gives another run."""
    stock = run(tmp_path, "stock", scene(stock_words))
    ours = run(tmp_path, "record", scene(lambda *c: ours_words(*c, name="stick_slip/total/record"), record=True))
    assert_same_run(stock, ours)

    frames = read_dump(ours / "dump.contacts")
    slipped = stuck = 0
    steps = sorted(frames)
    for a, b in zip(steps, steps[1:]):
        before = {(int(r[0]), int(r[1])): r[6] for r in frames[a]}
        for r in frames[b]:
            key = (int(r[0]), int(r[1]))
            if key in before or key[::-1] in before:
                n = r[6] - before.get(key, before.get(key[::-1]))
                slipped += n > 0
                stuck += n == 0
    total = {s: frames[s][:, 6].sum() for s in steps}
    walls = read_dump(ours / "dump.walls")[STEPS]
    print(f"pair slips open at the end: {total[STEPS]:.0f}; persisting contacts over 100 steps: "
          f"{slipped} slipped, {stuck} stuck; floor slips {walls[:, 5].sum():.0f}, side {walls[:, 11].sum():.0f}")
    assert slipped > 100 and stuck > 100
    assert walls[:, 5].sum() > 100 and walls[:, 11].sum() > 0

    lower = run(tmp_path, "lower", scene(lambda ks, x, mu: ours_words(ks, x, mu, 0.9 * mu)))
    assert (lower / "dump.atoms").read_bytes() != (stock / "dump.atoms").read_bytes()


def test_linear_history_classic_scales_the_spring_by_the_contact_radius(tmp_path):
    """Why the reference is linear_history, not linear_history_classic: in LAMMPS 4 Feb 2025
    `linear_history_classic` (and with it the classic `fix wall/gran hooke/history`, which
    LAMMPS now builds from it) multiplies Ks by the contact radius a = sqrt(delta R), unlike
    pair gran/hooke/history and this LAMMPS' 29 Sep 2021 (Debian 12), whose walls give
    linear_history's force. One grain (R 0.5) overlapping the floor by 1e-3 slides at
    v = 1 along x, no rotation, no tangential dashpot: after one step (dt 1e-6) the spring
    holds v dt and the floor's tangential force is -Ks v dt, or -Ks a v dt (a ~ 0.022)."""
    v, dt, ks = 1.0, 1e-6, 200.0
    forces = {}
    granular = "granular hooke 1000 0 damping velocity tangential"
    for name, wall in (("linear_history", f"{granular} linear_history {ks} 0 0.5"),
                       ("classic", f"{granular} linear_history_classic {ks} 0 0.5"),
                       ("hooke/history", f"hooke/history 1000 {ks} 10 0 0.5 0")):
        script = f"""atom_style sphere
boundary f f f
comm_modify vel yes
region reg block -2 2 -2 2 -2 2 units box
create_box 1 reg
create_atoms 1 single 0 0 0.499 units box
set group all diameter 1.0 density 1.0
velocity all set {v} 0 0 units box
pair_style granular
pair_coeff * * hooke 1000 0 damping velocity tangential linear_history 200 0 0.5
timestep {dt}
fix 1 all nve/sphere
fix w all wall/gran {wall} zplane 0.0 NULL contacts
dump d all custom 1 dump.one id z f_w[2]
dump_modify d format float %.17g
run 1
"""
        work = run(tmp_path, name.replace("/", "_"), script)
        forces[name] = read_dump(work / "dump.one")[1][0, 1:]
    z, fx = forces["linear_history"]
    assert fx == -ks * (v * dt)
    a = np.sqrt((0.5 - z) * 0.5)
    for name in ("classic", "hooke/history"):
        assert forces[name][0] == z
        assert forces[name][1] == pytest.approx(-ks * a * (v * dt), rel=1e-12), name
