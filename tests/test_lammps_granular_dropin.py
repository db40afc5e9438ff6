# SPDX-License-Identifier: GPL-2.0-or-later
"""The tangential sub-model `stick_slip` (lammps_plugin/granular/) as a drop-in for each modern
LAMMPS release's own sub-models (every test runs on each release built here: 4 Feb 2025 and
4 Jul 2026, whose stock sub-models differ in their arithmetic): with mu_k = mu_s and /total
its step-timing arithmetic is that release's linear_history operation for operation (with
Ks NULL its mindlin's), so
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

from conftest import lammps_release_launcher, lammps_releases, needs_engine
from lammps_runs import read_dump, run_lammps

pytestmark = needs_engine("lammps_granular")  # a modern LAMMPS built with the sub-model

STEPS, EVERY = 3000, 1000


@pytest.fixture(params=lammps_releases())
def lmp(request):
    """The release's lmp (STICKSLIP_LAMMPS_GRANULAR: another build, e.g. a patched tree)."""
    return lammps_release_launcher(request.param)

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


def models(tangential, normal=HERTZ, extra=EXTRA, wall_tangential=None, pair_extra=""):
    """The granular model's words: (type 1's, type 2's, the walls'). tangential(ks, x, mu)
    -> the tangential sub-model's words for one set of coefficients; normal: each type's
    normal and damping words; extra: rolling/twisting words and keywords after the
    tangential ones; wall_tangential: the walls' tangential words (default: tangential);
    pair_extra: keywords of pair_coeff alone (synchronized_verlet)."""
    wall_tangential = wall_tangential or tangential
    pair = [f"{normal[t]} tangential {tangential(*TANGENTIAL[t])} {extra} {pair_extra}" for t in (0, 1)]
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


def fixes(words, record=False, moving=False):
    """What a restart file does not hold: integration, gravity, the floor (fix wall/gran
    granular zplane) and the side walls (fix wall/gran/region granular on a block region:
    regions are not kept in restart files either); record: the walls
    keep per-atom contact values (`contacts`: columns 9-14 are the sub-model's record);
    moving: the side walls move, back and forth along y (0.05 at a period of 0.5)."""
    contacts = " contacts" if record else ""
    side = "region side block INF INF -3 3 INF INF side in units box"
    if moving:
        side = f"variable dy equal 0.05*sin(2*PI*step*dt/0.5)\n{side} move NULL v_dy NULL"
    return f"""fix 1 all nve/sphere
fix 2 all gravity 1.0 vector 0.45 0 -1
fix floor all wall/gran granular {words[2]} zplane 0.0 NULL{contacts}
{side}
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


def scene(tangential, normal=HERTZ, extra=EXTRA, newton="off", wall_tangential=None, record=False, pair_extra="",
          moving=False):
    """The whole run, STEPS steps (the module's docstring)."""
    words = models(tangential, normal, extra, wall_tangential, pair_extra)
    return pile(words, newton) + fixes(words, record, moving) + output(record=record) + f"run {STEPS}\n"


def thermo_text(log):
    """The thermo block of a log: the header line to the line before 'Loop time'."""
    text = log.read_text()
    start = text.index("\n   Step ")
    return text[start:text.index("\nLoop time", start)]


def run(tmp_path, name, script, lmp, np_=1):
    work = tmp_path / name
    run_lammps(work, name, script, exe=lmp, np_=np_)
    return work


def lammps_version(work):
    """The release that made a run, from its log's first line: (year, month, day)."""
    import datetime

    first = (work / f"log.{work.name}").read_text().split("\n", 1)[0]  # LAMMPS (4 Feb 2025)
    return datetime.datetime.strptime(first[first.index("(") + 1:first.index(")")].split(" - ")[0], "%d %b %Y").date()


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
def test_stick_slip_total_is_linear_history_bit_for_bit(tmp_path, np_, newton, lmp):
    """Hertz with viscoelastic damping and limit_damping, pair and both walls: stock
    linear_history and stick_slip/total with mu_k = mu_s give the same bytes, serial and
    on 2 ranks (split along x: the flow carries grains and contacts across the ranks'
    boundary and the periodic one), newton on and off."""
    stock = run(tmp_path, "stock", scene(stock_words, newton=newton), lmp, np_)
    ours = run(tmp_path, "ours", scene(ours_words, newton=newton), lmp, np_)
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
def test_any_normal_damping_rolling_and_twisting(tmp_path, variant, lmp):
    """The same drop-in with other normal, damping, rolling and twisting sub-models."""
    normal, extra, np_, newton = VARIANTS[variant]
    stock = run(tmp_path, "stock", scene(stock_words, normal, extra, newton), lmp, np_)
    ours = run(tmp_path, "ours", scene(ours_words, normal, extra, newton), lmp, np_)
    assert_same_run(stock, ours)


def test_moving_region_wall_with_tsuji_damping(tmp_path, lmp):
    """The side walls move back and forth (a moving region of fix wall/gran/region granular:
    its contacts take the wall's velocity), tsuji damping, rolling and twisting: stick_slip/total
    is linear_history's run, and with Ks NULL mindlin's, on 2 ranks newton off."""
    normal = ("hertz/material 1e4 0.6 0.3 damping tsuji", "hertz/material 2e4 0.5 0.25 damping tsuji")
    extra = "rolling sds 200 20 0.1 twisting marshall"
    for stock_tangential, ours_tangential in ((stock_words, ours_words), (mindlin_stock, mindlin_ours)):
        stock = run(tmp_path, "stock", scene(stock_tangential, normal, extra, moving=True), lmp, 2)
        ours = run(tmp_path, "ours", scene(ours_tangential, normal, extra, moving=True), lmp, 2)
        assert_same_run(stock, ours)


def test_ks_null_is_mindlin_bit_for_bit(tmp_path, lmp):
    """Ks NULL (Mindlin's 8 G* a from the material of hertz/material) against `mindlin NULL x
    mu`, newton on; mixed types take 8 G* of the mixed material, as mindlin."""
    stock = run(tmp_path, "stock", scene(mindlin_stock, newton="on"), lmp)
    ours = run(tmp_path, "ours", scene(mindlin_ours, newton="on"), lmp)
    assert_same_run(stock, ours)


def test_the_walls_alone_are_a_drop_in(tmp_path, lmp):
    """The floor (fix wall/gran granular zplane) and the side walls (fix wall/gran/region
    granular) with stick_slip/total, the grain pairs with linear_history in both runs:
    the walls' contacts alone give stock's bytes."""
    stock = run(tmp_path, "stock", scene(stock_words), lmp)
    ours = run(tmp_path, "ours", scene(stock_words, wall_tangential=ours_words), lmp)
    assert_same_run(stock, ours)


def test_the_scene_sticks_and_slips(tmp_path, lmp):
    """What the drop-in tests compare is not equal by construction:
    - stick_slip/total/record with mu_k = mu_s is stock's run too (the record changes no
      force; its history is 9 values a contact, transferred with their own signs);
    - its record counts slips (pair/local p17, the walls' column 13) in grain pairs, on the
      floor and on the side walls, and contacts that stick: of the contacts open at two
      dumps 100 steps apart, some slipped in between and some did not;
    - mu_k = 0.9 mu_s, the law's own drop after a slip, gives another run."""
    stock = run(tmp_path, "stock", scene(stock_words), lmp)
    ours = run(tmp_path, "record", scene(lambda *c: ours_words(*c, name="stick_slip/total/record"), record=True), lmp)
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

    lower = run(tmp_path, "lower", scene(lambda ks, x, mu: ours_words(ks, x, mu, 0.9 * mu)), lmp)
    assert (lower / "dump.atoms").read_bytes() != (stock / "dump.atoms").read_bytes()


# releases before synchronized verlet (pair granular's keyword synchronized_verlet)
SYNCHRONIZED_SINCE = __import__("datetime").date(2025, 2, 5)


def test_synchronized_verlet_is_linear_history_and_mindlin_bit_for_bit(tmp_path, lmp):
    """pair_coeff's synchronized_verlet (LAMMPS after 4 Feb 2025; Vyas et al. 2025): the
    spring is turned into the half step's tangent plane before it is loaded and into the
    full step's after, and the dashpot's velocity with it, as linear_history and mindlin do
    (the host's rotate_rescale_vec): stick_slip/total at mu_k = mu_s gives their bytes, on
    2 ranks newton on (linear_history) and serial newton off (Ks NULL: mindlin). The walls
    take no such keyword. Not equal by construction: the keyword changes stock's run."""
    if not _synchronized(tmp_path, lmp):
        pytest.skip("this release has no synchronized verlet")
    sync = "synchronized_verlet"
    stock = run(tmp_path, "stock", scene(stock_words, newton="on", pair_extra=sync), lmp, 2)
    ours = run(tmp_path, "ours", scene(ours_words, newton="on", pair_extra=sync), lmp, 2)
    assert_same_run(stock, ours)
    plain = run(tmp_path, "plain", scene(stock_words, newton="on"), lmp, 2)
    assert (plain / "dump.atoms").read_bytes() != (stock / "dump.atoms").read_bytes()
    stock = run(tmp_path, "mindlin_stock", scene(mindlin_stock, pair_extra=sync), lmp)
    ours = run(tmp_path, "mindlin_ours", scene(mindlin_ours, pair_extra=sync), lmp)
    assert_same_run(stock, ours)


def _synchronized(tmp_path, lmp):
    """Whether this release has synchronized verlet (from the version its log states)."""
    work = run(tmp_path, "version", "info system\n", lmp)
    return lammps_version(work) >= SYNCHRONIZED_SINCE


def test_exact_timing_refuses_synchronized_verlet(tmp_path, lmp):
    """Exact timing integrates the spring along one tangent plane over the step, which
    synchronized verlet turns twice within it: /exact refuses it in one ERROR line naming the
    sub-model (LAMMPS' own check of allow_synchronization); step timing takes it."""
    if not _synchronized(tmp_path, lmp):
        pytest.skip("this release has no synchronized verlet")
    from lammps_runs import error_lines

    for name, fails in (("stick_slip/exact", True), ("stick_slip/total/exact/record", True), ("stick_slip", False)):
        script = pile(models(lambda *c: ours_words(*c, name=name), pair_extra="synchronized_verlet")) + "run 0\n"
        proc = run_lammps(tmp_path / "refuse", "refuse", script, exe=lmp, check=False)
        errors = error_lines(proc)
        if fails:
            assert len(errors) == 1 and "synchronized verlet" in errors[0] and name in errors[0], proc.stdout[-2000:]
        else:
            assert proc.returncode == 0 and not errors, proc.stdout[-2000:]


def test_linear_history_classic_and_the_classic_wall(tmp_path, lmp):
    """Why the reference is linear_history, not linear_history_classic: in LAMMPS 4 Feb 2025
    `linear_history_classic` (and with it the classic `fix wall/gran hooke/history`, which
    LAMMPS builds from it) multiplies Ks by the contact radius a = sqrt(delta R), unlike
    pair gran/hooke/history and Debian 12's LAMMPS (29 Sep 2021), whose walls give
    linear_history's force; LAMMPS 4 Jul 2026 no longer scales it (its
    linear_history_classic sets no contact-radius flag; mindlin_classic does). One grain
    (R 0.5) overlapping the floor by 1e-3 slides at v = 1 along x, no rotation, no
    tangential dashpot: after one step (dt 1e-6) the spring holds v dt and the floor's
    tangential force is -Ks v dt, or -Ks a v dt (a ~ 0.022)."""
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
        work = run(tmp_path, name.replace("/", "_"), script, lmp)
        forces[name] = read_dump(work / "dump.one")[1][0, 1:]
    z, fx = forces["linear_history"]
    assert fx == -ks * (v * dt)
    a = np.sqrt((0.5 - z) * 0.5)
    scaled = lammps_version(work) < SYNCHRONIZED_SINCE  # (4 Feb 2025 and before)
    for name in ("classic", "hooke/history"):
        assert forces[name][0] == z
        assert forces[name][1] == pytest.approx(-ks * (a if scaled else 1.0) * (v * dt), rel=1e-12), name
