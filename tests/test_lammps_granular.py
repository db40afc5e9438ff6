# SPDX-License-Identifier: GPL-2.0-or-later
"""The tangential sub-model `stick_slip` in LAMMPS 2025's granular model (lammps_plugin/granular/,
the adapter stickslip/adapters/lammps_granular.py) against pyref on the paper's cases.

LAMMPS and pyref integrate the same way (tests/test_lammps_engine.py's docstring), and the
adapter's granular model (`hooke Kn nu_n damping velocity tangential stick_slip/record Ks x mu_s
mu_k limit_damping`, x chosen so that x * nu_n is nu_s to the last bit) is docs/law.md's law
in the paper's cases, which lock rotation (so the lever arm, the one rule where LAMMPS'
granular model differs from the law, does not enter): on the same scene and dt the runs differ
by the order of floating-point operations only, and are held to tests/twin_bound.py's
round-off bound, as the legacy styles are. Row 0 is compared too: the sub-model's record is
written by the set-up's force evaluation.

These tests need LAMMPS 2025 (STICKSLIP_SOURCE_BUILDS=lammps-2025 ./run.sh setup; CI builds
it): they skip without it, and fail instead when the set-up was asked for it (conftest).
Costs (2 cores): drag 0.5 s, tray (0.5 s simulated) 1 s, tilt 1.5 s a timing; pyref's runs
are shared with the other engines' tests (paper_case).
"""

import pytest

from stickslip import scene as scene_mod
from stickslip.adapters import lammps_granular
from conftest import lammps_release_launcher, lammps_releases, needs_engine, paper_case, skip_engine
from twin_bound import assert_round_off_apart

pytestmark = needs_engine("lammps_granular")


def run_granular(name, tmp_path, ranks=1, **kw):
    sc = scene_mod.load(name, **kw)
    return sc, lammps_granular.run(sc, tmp_path, np_ranks=ranks).timeseries


def pyref_case(name, timing, **kw):
    return (paper_case(name, **kw) if timing == "step" else paper_case(name, slip_timing=timing, **kw))[1]


def test_the_build_is_there():
    """Under CI (whose set-up builds LAMMPS 2025) a missing build fails here instead of
    skipping every test of this file."""
    skip_engine("lammps_granular")


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_drag_is_pyrefs_twin(tmp_path, timing):
    """Every row of the drag (2500 steps; a primitive wall: fix wall/gran granular) within
    round-off of pyref's, in both slip timings."""
    sc, dl = run_granular("drag", tmp_path, slip_timing=timing)
    text = (tmp_path / "lammps" / "in.scene").read_text()
    assert "wall/gran granular hooke" in text and "tangential stick_slip" in text
    assert_round_off_apart(sc, dl, pyref_case("drag", timing), slips_where_pressed=True)
    assert dl["grain-floor_slip"].sum() >= 5


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_tilt_is_pyrefs_twin(tmp_path, timing):
    """Every row of the tilt (125 000 steps: the plate turning and stopping, stick,
    stick-slip and sliding) within round-off of pyref's; the plate is a region plane turned
    by `rotate v_theta` under fix wall/gran/region granular."""
    sc, dl = run_granular("tilt", tmp_path, slip_timing=timing)
    text = (tmp_path / "lammps" / "in.scene").read_text()
    assert "wall/gran/region granular" in text and "rotate v_theta0" in text
    assert_round_off_apart(sc, dl, pyref_case("tilt", timing), slips_where_pressed=True)
    assert dl["grain-plate_slip"].sum() > 100


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_tray_is_pyrefs_twin(tmp_path, timing):
    """The tray's first 0.5 s (a grain pair through pair_style granular, three walls) within
    round-off of pyref's, grain 1 held up."""
    from stickslip import analysis

    sc, dl = run_granular("tray", tmp_path, slip_timing=timing, duration=0.5)
    assert_round_off_apart(sc, dl, pyref_case("tray", timing, duration=0.5), slips_where_pressed=True)
    assert not analysis.summarise(sc, dl)["reached_bottom"]
    assert dl["grain1-grain2_slip"].sum() > 10


def test_one_and_two_ranks_are_identical(tmp_path):
    """The tray's impact (its grain pair split between the ranks) and the tilt's start give
    the same bits on 1 and 2 MPI ranks (each grain has at most one pair contact, so no sum
    changes order)."""
    for name, kw in (("tray", {"duration": 0.01}), ("tilt", {"duration": 0.005})):
        _, d1 = run_granular(name, tmp_path / f"{name}1", **kw)
        _, d2 = run_granular(name, tmp_path / f"{name}2", ranks=2, **kw)
        assert d1.equals(d2), name
        assert "on 2 procs" in (tmp_path / f"{name}2" / "lammps" / "log.lammps").read_text()


def test_a_scene_with_rotation_says_where_the_lever_arm_differs(tmp_path):
    """LAMMPS' granular model takes V_s with the radii as lever arms: a scene with rotation
    gets a note saying so (the drum's first steps)."""
    sc = scene_mod.load("drum_small", duration=0.002)
    res = lammps_granular.run(sc, tmp_path)
    assert any("lever arm" in n for n in res.notes)


def test_a_tangential_dashpot_without_a_normal_one_is_refused(tmp_path):
    """The granular model scales the tangential dashpot by the normal damping's prefactor:
    nu_s > 0 with nu_n = 0 cannot be written, and the adapter says so in one line."""
    sc = scene_mod.load("drag", duration=0.0001)
    sc.effects["normal_damping"] = False
    with pytest.raises(ValueError, match="nu_s > 0 needs nu_n > 0"):
        lammps_granular.run(sc, tmp_path)


@pytest.mark.parametrize("nu_s, nu_n", [(33.10, 41.38), (0.1, 0.3), (1.0, 3.0), (2.5e-3, 7.0)])
def test_the_dashpot_ratio_gives_nu_s_to_the_last_bit(nu_s, nu_n):
    x = lammps_granular.dashpot_ratio(nu_s, nu_n)
    assert x * nu_n == nu_s


def test_unlike_types_mix_by_geometric_means(tmp_path):
    """Types 1 and 2 given their own coefficients only (pair_coeff 1 1, 2 2): a 1-2 contact
    takes the geometric means, mu_s = sqrt(0.25 * 1.0) = 0.5 and mu_k = sqrt(0.2 * 0.8).
    A grain pair of types 1 and 2 slides at 1/64 of a unit a step with Fn = 1 and Ks = 1
    (stickslip/contract/cases.py's units): the spring reaches mu_s = 0.5 at step 32 exactly, the first
    slip, and the force drops to 2 mu_k - mu_s (1 ulp: the slip's rescale). Read from
    compute pair/local's record (p13-p17)."""
    import math

    import numpy as np

    import lammps_runs
    from stickslip.contract import cases as lc
    from stickslip.contract.lammps import LAMMPS_HEAD, _f, granular_model, lammps_pair_local, lammps_pair_row

    d = 2 * lc.R - lc.DELTA
    own = {1: (0.25, 0.2), 2: (1.0, 0.8)}
    lines = [LAMMPS_HEAD.format(ntypes=2, dt=_f(lc.DT)), "pair_style granular"]
    for t, (ms, mk) in own.items():
        case = lc.Case("", "", "pair", (), ms, mk)
        lines.append(f"pair_coeff {t} {t} {granular_model(case)}")
    for b, (t, x) in enumerate(((1, -d / 2), (2, d / 2))):
        v = 0.25 if b == 0 else 0.0  # 1/64 a step along y
        lines += [f"create_atoms {t} single {_f(x)} 0.0 0.0 units box",
                  f"set atom {b + 1} diameter {_f(2 * lc.R)} density 1000 vx 0.0 vy {_f(v)} vz 0.0"]
    # places and velocities held (nothing integrated, as the contract's rows): grain 1 moves
    # at 0.25 along y without moving, grain 2 is still
    lines += ["variable zero equal 0.0", "variable vy equal 0.25", "group g1 id 1", "group g2 id 2",
              "fix mv1 g1 move variable v_zero v_zero v_zero v_zero v_vy v_zero",
              "fix mv2 g2 move variable v_zero v_zero v_zero v_zero v_zero v_zero"]
    lines += lammps_pair_local((13, 14, 15, 16, 17)) + ["run 40"]
    lammps_runs.run_lammps(tmp_path, "mix", "\n".join(lines) + "\n", exe=lammps_granular.LAUNCHER)
    pairs = lammps_runs.read_dump(tmp_path / "dump.pairs")
    rows = np.array([lammps_pair_row(pairs[s], 1, [1, 2, 3]) for s in range(1, 41)])
    slips = rows[:, 4]
    mu_s, mu_k = math.sqrt(0.25 * 1.0), math.sqrt(0.2 * 0.8)
    assert slips[30] == 0 and slips[31] == 1  # the first slip at step 32: 32/64 = mu_s
    fmin = (2 * mu_k - mu_s) * 1.0
    assert abs(np.linalg.norm(rows[31, 1:4]) - fmin) <= np.spacing(fmin), (rows[31], fmin)


@pytest.mark.parametrize("timing, nu_s", [("step", 0.25), ("exact", 1.0)])
def test_single_gives_the_force_the_law_would_apply_now(tmp_path, timing, nu_s):
    """pair granular's single() without /record (compute pair/local p1-p3; LAMMPS' pair-style
    tester cannot call it: it builds its atoms with atom_style full, which has no radius):
    the force the law would apply with no time passing from the contact's spring and
    velocity, -Ks D - nu_s V, dropped to Fmin along itself where it reaches mu_s Fn. A grain
    pair in the contract's units (Fn = 1, Ks = 1, dt = 1/16), grain 1 sliding at 0.25 along y
    for 40 steps, mu_s 0.5, mu_k 0.4: in step timing with nu_s 0.25 the spring loads, slips
    and loads again (sticking and just-slipped states, no drop in single()); in exact timing
    with nu_s 1 (nu_s |V| = 0.25 >= mu_s Fn - Fmin = 0.2) the contact slides after its first
    slip (E4) with the spring holding Fmin + nu_s |V| > mu_s Fn, so single() drops it to Fmin.
    The spring is pyref's after each step, single() pyref's law at dt = 0 in step timing.
    Every value is a sum of multiples of 1/64 but for a drop's rescale, one rounding in each
    (the same operations): 2 ulps of mu_s Fn allowed."""
    import numpy as np

    import lammps_runs
    from pyref.laws import LawParams, tangential_force
    from stickslip.contract import cases as lc
    from stickslip.contract.lammps import LAMMPS_HEAD, _f, lammps_pair_local, lammps_pair_row

    lmp = lammps_release_launcher(lammps_releases()[-1])
    mu_s, mu_k, v, steps = 0.5, 0.4, 0.25, 40
    model = lammps_granular.model_words(lc.KN, 1.0, lc.KS, nu_s, mu_s, mu_k, "spring", timing, record=False)
    d = 2 * lc.R - lc.DELTA
    lines = [LAMMPS_HEAD.format(ntypes=1, dt=_f(lc.DT)), "pair_style granular", f"pair_coeff * * {model}"]
    for b, x in enumerate((-d / 2, d / 2)):
        lines += [f"create_atoms 1 single {_f(x)} 0.0 0.0 units box",
                  f"set atom {b + 1} diameter {_f(2 * lc.R)} density 1000 vx 0.0 vy {_f(v if b == 0 else 0.0)} vz 0.0"]
    lines += ["variable zero equal 0.0", f"variable vy equal {_f(v)}", "group g1 id 1", "group g2 id 2",
              "fix mv1 g1 move variable v_zero v_zero v_zero v_zero v_vy v_zero",
              "fix mv2 g2 move variable v_zero v_zero v_zero v_zero v_zero v_zero"]
    lines += lammps_pair_local((1, 2, 3)) + [f"run {steps}"]
    lammps_runs.run_lammps(tmp_path, "single", "\n".join(lines) + "\n", exe=lmp)
    pairs = lammps_runs.read_dump(tmp_path / "dump.pairs")
    got = np.array([lammps_pair_row(pairs[s], 1, [0, 1, 2]) for s in range(1, steps + 1)])

    law = dict(law="stick_slip", kn=lc.KN, nu_n=1.0, ks=lc.KS, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k)
    step, now = LawParams(**law, slip_timing=timing), LawParams(**law, slip_timing="step")
    fn, V, D = np.array([lc.KN * lc.DELTA]), np.array([[0.0, v, 0.0]]), np.zeros((1, 3))
    want, slipped, above = [], [], []
    for _ in range(steps):
        s = tangential_force(D, V, fn, lc.DT, step)
        D = s.spring
        slipped.append(bool(s.slipped[0]))
        above.append(np.linalg.norm(-lc.KS * D[0] - nu_s * V[0]) >= mu_s * fn[0])  # single() drops it
        want.append(tangential_force(D, V, fn, 0.0, now).force[0])
    np.testing.assert_allclose(got, np.array(want), rtol=0, atol=2 * np.spacing(mu_s))
    assert sum(slipped) >= 2 and not all(slipped)
    assert sum(above) >= 20 if timing == "exact" else not any(above)


@pytest.mark.parametrize("reset", ["stick_slip/record", "stick_slip/total/record"])
def test_the_record_books_the_work_each_step(tmp_path, reset):
    """The record's dissipated work (the wall's column 14; docs/law.md "Energy": the work the
    contact received, -F_s.V_s dt, less the increase of the spring's energy Ks |D|^2 / 2) on
    the paper's drag, a disk on a plane wall (fix wall/gran granular), V_s held at V along
    the wall (x velocity held, rotation locked). A sticking step grows D by V dt, so it adds
    -F.V dt - Ks (2 D.V dt + V^2 dt^2)/2 = nu_s V^2 dt + Ks V^2 dt^2 / 2 exactly; a slip step
    also releases spring energy, so it adds more. The record takes the difference of two
    spring energies ~Ks |D|^2 ~ 4e-9 J/m for an increment ~3e-14 J/m: one rounding of each,
    1e-16 x 4e-9, is ~1e-11 of the increment; 1e-8 allowed. The contract's rows read no work,
    so a wrong sign or term in the book is seen here only. ~1 s."""
    import numpy as np

    from lammps_runs import read_dump, run_lammps

    lmp = lammps_release_launcher(lammps_releases()[-1])
    kn, nu_n, ks, x, ms, mk, dt, V = 1.2e7, 41.38, 9.6e6, 0.7999033349444176, 0.5, 0.45, 2e-6, 1e-5
    nu_s = x * nu_n
    model = f"hooke {kn} {nu_n} damping velocity tangential {reset} {ks} {x!r} {ms} {mk} limit_damping"
    script = f"""units si
dimension 2
atom_style sphere
atom_modify map array
boundary f f p
comm_modify vel yes
region box block -0.01 0.05 -0.001 0.01 -0.001 0.001 units box
create_box 1 box
neighbor 0.0004 bin
create_atoms 1 single 0.0 0.0019999733 0.0 units box
set atom 1 diameter 0.004
set atom 1 mass 0.032672563597333844
pair_style granular
pair_coeff * * {model}
timestep {dt}
fix floor all wall/gran granular {model} yplane 0.0 NULL contacts
fix gravity all gravity 9.81 vector 0 -1 0
velocity all set {V} 0.0 0.0 units box
fix integrate all nve
fix drag all setforce 0.0 NULL NULL
fix twod all enforce2d
dump d all custom 1 dump.drag id f_floor[9] f_floor[10] f_floor[11] f_floor[12] f_floor[13] f_floor[14]
dump_modify d format float %.17g
run 2500
"""
    run_lammps(tmp_path, "drag", script, exe=lmp)
    frames = read_dump(tmp_path / "dump.drag")
    rows = np.array([frames[k][0] for k in sorted(frames)])
    slips, work = rows[:, 5], rows[:, 6]
    slipped = np.diff(slips) > 0
    gained = np.diff(work)
    stick_gain = nu_s * V ** 2 * dt + ks * V ** 2 * dt ** 2 / 2
    assert slipped.sum() >= 5 and (~slipped).sum() > 1000
    assert np.allclose(gained[~slipped], stick_gain, rtol=1e-8, atol=0), gained[~slipped][:5] / stick_gain
    assert np.all(gained[slipped] > stick_gain)
