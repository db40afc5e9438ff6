# SPDX-License-Identifier: GPL-2.0-or-later
"""The LAMMPS plugin (lammps_plugin/): the stick-slip law in `pair_style
gran/hooke/stickslip` and `fix wall/gran/stickslip`, run through raw input scripts on
Debian's LAMMPS (the stock-parity checks are in test_lammps_dropin.py).

- the law's arithmetic on few contacts against values derived here: the quasi-static
  drag's saw-tooth (a disk on a wall in 2D, a sphere on a held sphere in 3D, both resets),
  every type pair with its own mu_s and mu_k, one contact followed step by step in 3D
  (lever arms, history rotation, damping), the exact slip timing;
- 1 and 2 ranks, newton on and off, give the same answers on a few-grain scene;
- every refusal is one ERROR line naming the argument and its allowed range;
- the three ways to load the styles survive `clear` and work before `read_restart`.

Round-off: the plugin and these derivations compute the same quantities in different
orders; a quantity of size S built from a handful of operations differs by a few ulps,
~1e-15 S; tolerances below allow 1e-12 S unless a comment derives another.
"""
import subprocess

import numpy as np
import pytest

from conftest import needs_engine
from lammps_runs import (CRASH_MARKERS, LIBRARY, LOADER, STOCK, error_lines, read_dump, read_thermo, 
                         run_lammps)

pytestmark = needs_engine("lammps")  # LAMMPS installed and the plugin built (the adapter's check)

F17 = "%.17g"

# the paper's drag (Table 2 material, as tests/test_liggghts_plugin.py): a disk of radius
# 2 mm and density 2600 (mass per unit thickness pi r^2 rho), Kn, Ks in N/m per m,
# absolute damping nu_n, nu_s; dragged at V
DRAG = dict(kn=1.2e7, ks=9.6e6, nu_n=41.38, nu_s=33.10, mu_s=0.5, mu_k=0.45, dt=2e-6, v=1e-5, steps=2500,
            r=0.002, mass=2600 * np.pi * 0.002 ** 2, g=9.81)


def drag_script(kind, law="", steps=None, mu_s=None, mu_k=None):
    """A disk (2D, on a yplane wall) or a sphere (3D, on a held sphere below it) of the drag's
    mass resting under gravity, moved at V along x by fix move (rotation not integrated:
    the contact point moves at V); `law`: the law's keywords. Records every step: the
    contact's Fn, tangential force (3) and slip count."""
    p = dict(DRAG)
    mu_s = p["mu_s"] if mu_s is None else mu_s
    mu_k = p["mu_k"] if mu_k is None else mu_k
    coeffs = f"{p['kn']} {p['ks']} {p['nu_n']} {p['nu_s']} {mu_s} 1"
    keywords = f"mu_k {mu_k} damping absolute record yes {law}"
    rest = 2 * p["r"] - p["mass"] * p["g"] / p["kn"]  # centre distance at rest: overlap m g / Kn
    head = f"""units si
atom_style sphere
atom_modify map array
comm_modify vel yes
neighbor 0.0005 bin
timestep {p['dt']}
"""
    if kind == "wall2d":
        return head.replace("units si", "units si\ndimension 2") + f"""boundary f f p
region box block -0.01 0.05 -0.01 0.01 -0.001 0.001 units box
create_box 1 box
create_atoms 1 single 0.0 {rest - p['r']!r} 0.0 units box
set atom 1 diameter {2 * p['r']} mass {p['mass']!r}
pair_style gran/hooke/stickslip {coeffs} {keywords}
pair_coeff * *
fix floor all wall/gran/stickslip hooke/history {coeffs} yplane 0.0 NULL {keywords}
fix grav all gravity {p['g']} vector 0 -1 0
fix mv all move linear {p['v']} NULL NULL
fix 2d all enforce2d
dump d all custom 1 dump.drag id f_floor[9] f_floor[10] f_floor[11] f_floor[12] f_floor[13] f_floor[14]
dump_modify d format float {F17}
run {steps or p['steps']}
"""
    return head + f"""boundary f f f
region box block -0.01 0.05 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
create_atoms 1 single 0.0 0.0 0.0 units box
create_atoms 1 single 0.0 0.0 {rest!r} units box
set group all diameter {2 * p['r']} mass {p['mass']!r}
group slider id 2
pair_style gran/hooke/stickslip {coeffs} {keywords}
pair_coeff * *
fix grav slider gravity {p['g']} vector 0 0 -1
fix mv slider move linear {p['v']} NULL NULL
compute pl all pair/local p11 p1 p2 p3 p12 p13 cutoff radius
compute ids all property/local patom1 patom2 cutoff radius
dump d all local 1 dump.drag c_ids[1] c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5] c_pl[6]
dump_modify d format float {F17}
run {steps or p['steps']}
"""


def drag_record(path, kind="wall2d"):
    """The drag's dump -> (Fn, tangential force on the moved body (K, 3), slip count,
    dissipated work) over steps 1..N (step 0 is the set-up: no time has passed)."""
    frames = read_dump(path)
    rows = np.array([frames[k][0] for k in sorted(frames)])[1:]
    if kind == "pair3d" and rows[0, 0] == 1:  # the held sphere (id 1) is i: the record is the force on it
        rows[:, 2:5] *= -1
    return rows[:, 1], rows[:, 2:5], rows[:, 5], rows[:, 6]


# ---------------------------------------------------------------- the saw-tooth

@pytest.mark.parametrize("reset", ["spring", "total"])
@pytest.mark.parametrize("kind", ["wall2d", "pair3d"])
def test_drag_sawtooth(tmp_path, kind, reset):
    """The quasi-static drag: the friction ratio climbs to mu_s, drops to 2 mu_k - mu_s at
    each slip and climbs again (docs/law.md steps 4-5, eqs. 5, 7, 8). ~0.3 s.

    - max |F_s|/Fn: the last sticking step is below mu_s by less than one spring increment
      (the trial force grows by Ks V dt per step, the dashpot part nu_s V is constant):
      mu_s - Ks V dt/Fn <= max < mu_s.
    - the applied force at every slip is Fmin = (2 mu_k - mu_s) Fn (round-off).
    - the step after a slip carries Fmin + Ks V dt + nu_s V (reset spring: the spring alone
      holds Fmin, the dashpot adds nu_s V) or Fmin + Ks V dt (reset total), Fmin of the slip
      step (the spring keeps it). In 3D the contact normal tilts by at most
      theta = V t_end/(2r) = 1.25e-5 rad, which shortens V_s by theta^2/2: the tolerance
      adds (Ks V dt + nu_s V) theta^2.
    - interval between slips: the force must rise by 2 (mu_s - mu_k) Fn at Ks V per
      second, T = 2 (mu_s - mu_k) Fn/(Ks V), less nu_s/Ks with reset spring (the dashpot's
      part comes back at once); steps quantise it by dt either way; the count follows.
    - first slip: spring + dashpot reach mu_s Fn, Ks V t + nu_s V = mu_s Fn, within a step.
    - dissipated work (docs/law.md "Energy"): a sticking step adds nu_s V^2 dt + Ks V^2 dt^2/2
      (-F.V dt less the spring energy's increase, with F = -Ks D - nu_s V and D grown by
      V dt); a slip step releases spring energy: more than that. The record differences
      two spring energies ~Ks |D|^2 ~ 3e-9 J/m to get ~1e-14 J/m: round-off 1e-16 x 3e-9
      per rounding, ~1e-9 of the increment; 1e-8 allowed (with the 3D tilt's theta^2)."""
    run_lammps(tmp_path, "drag", drag_script(kind, f"reset {reset}"))
    fn, F, nslip, work = drag_record(tmp_path / "dump.drag", kind)
    p = DRAG
    ks, nu, V, dt, ms, mk = p["ks"], p["nu_s"], p["v"], p["dt"], p["mu_s"], p["mu_k"]
    steps = np.arange(1, p["steps"] + 1)
    fs = np.linalg.norm(F, axis=1)
    assert (fn > 0).all() and (F[:, 0] < 0).all(), "friction opposes the drag along +x"
    slip = np.diff(np.concatenate([[0.0], nslip])) > 0
    assert np.all(np.diff(np.concatenate([[0.0], nslip])) <= 1), "a step slips at most once (step timing)"
    slip_steps = steps[slip]
    assert len(slip_steps) >= 5, slip_steps
    ratio = fs / fn

    inc = ks * V * dt / fn.min()
    rmax = ratio.max()
    assert ms - inc <= rmax < ms, (rmax, ms, inc)
    assert np.allclose(ratio[slip], 2 * mk - ms, rtol=1e-12, atol=0)
    first = slip_steps[0]
    assert ratio[steps >= first].min() == pytest.approx(2 * mk - ms, rel=1e-12)

    after = slip.copy()
    after[-1] = False
    after &= ~np.roll(slip, -1)                       # slips followed by a sticking step
    idx = np.nonzero(after)[0]
    jump = fs[idx + 1] - (2 * mk - ms) * fn[idx]
    expected = ks * V * dt + (nu * V if reset == "spring" else 0.0)
    theta = V * p["steps"] * dt / (2 * p["r"]) if kind == "pair3d" else 0.0
    assert np.allclose(jump, expected, rtol=0, atol=1e-12 * fn.max() + (ks * V * dt + nu * V) * theta ** 2)

    T = 2 * (ms - mk) * fn[slip].mean() / (ks * V)
    shift = nu / ks if reset == "spring" else 0.0
    lo, hi = T - shift - dt, T - shift + dt
    intervals = np.diff(slip_steps) * dt
    assert np.all((intervals >= lo) & (intervals <= hi)), (intervals / dt, lo / dt, hi / dt)
    span = (p["steps"] - first) * dt
    assert 1 + int(np.floor(span / hi)) <= len(slip_steps) <= 1 + int(np.floor(span / lo))
    t1 = (ms * fn[first - 1] - nu * V) / (ks * V)
    assert abs(first * dt - t1) <= dt * (1 + 1e-9), (first, t1 / dt)

    gained = np.diff(np.concatenate([[0.0], work]))
    stick_gain = nu * V ** 2 * dt + ks * V ** 2 * dt ** 2 / 2
    assert np.allclose(gained[~slip], stick_gain, rtol=1e-8 + theta ** 2, atol=0)
    assert np.all(gained[slip] > stick_gain)


def test_every_type_pair_has_its_own_coefficients(tmp_path):
    """Three types, six sliders (2D): a disk of type a dragged on a held disk of type b,
    one per type pair, each pair with its own mu_s and mu_k from pair_coeff (the
    pair_style's 0.5/0.45 used by none). Each saw-tooth must peak within one spring
    increment below its own mu_s and drop to its own 2 mu_k - mu_s; the friction on the
    slider opposes its motion and the slip count never falls, also after the contacts
    have moved to the other body's neighbour list (second run). ~0.5 s."""
    coeffs = {(1, 1): (0.50, 0.45), (1, 2): (0.55, 0.50), (1, 3): (0.40, 0.32), (2, 2): (0.45, 0.40),
              (2, 3): (0.60, 0.52), (3, 3): (0.35, 0.30)}
    script = type_pairs_script(coeffs, "off")
    run_lammps(tmp_path, "pairs", script)
    frames = read_pairs(tmp_path)
    p = DRAG
    # per contact (its atom ids): type pair, Fn, tangential force on the slider along x,
    # slip count, over steps 1..N (the record is the force on patom1; sliders have odd ids)
    series = {}
    for step in sorted(frames)[1:]:
        for r in frames[step]:
            ids = (int(min(r[0], r[1])), int(max(r[0], r[1])))
            on_slider = r[5] if int(r[0]) % 2 == 1 else -r[5]
            types = tuple(sorted((int(r[2]), int(r[3]))))
            series.setdefault(ids, []).append((types, r[4], on_slider, np.hypot(r[5], r[6]), r[7]))
    seen = set()
    for ids, rows in series.items():
        assert len(rows) == p["steps"], ids
        key = rows[0][0]
        seen.add(key)
        ms, mk = coeffs[key]
        fn, fx, fs, nslip = (np.array([r[k] for r in rows]) for k in (1, 2, 3, 4))
        ratio = fs / fn
        assert (fx < 0).all(), (key, "friction opposes the slider's motion along +x")
        assert np.all(np.diff(nslip) >= 0), (key, "the slip count never falls")
        slip = np.diff(np.concatenate([[0.0], nslip])) > 0
        assert slip.sum() >= 3, (key, slip.sum())
        inc = p["ks"] * p["v"] * p["dt"] / fn.min()
        assert ms - inc <= ratio.max() < ms, (key, ratio.max())
        assert np.allclose(ratio[slip], 2 * mk - ms, rtol=1e-12, atol=0), key
    assert seen == set(coeffs)
    held_first = [int(frames[k][0][0]) % 2 == 0 for k in (1199, 1201)]
    assert held_first == [False, True], "the contacts must change lists (transfer_history)"


def test_pair_local_without_record_caps_at_each_pairs_own_threshold():
    """Without `record`, compute pair/local's p1-p3 re-evaluate the force from the stored
    spring (single(): trial force, brought to Fmin at or above mu_s Fn), with the contact's
    own type pair's coefficients. The contract's six type pairs (stickslip/contract/cases.py,
    Fn = 1, one X a step, step timing, reset spring) with a dashpot nu_s V = 7 X: before
    the first slip the spring holds k X after step k, and the re-evaluation is the applied
    force k + 7; the first slip comes where k + 7 reaches T (k = T - 7); from then on every
    step slips (Fmin + 1 + 7 >= T, since T - Fmin = 6 for every pair), the spring is Fmin and
    its re-evaluation Fmin + 7 >= T is brought back to Fmin. A pair read with another pair's
    coefficients (a larger T) reports Fmin + 7 instead. ~0.4 s."""
    from stickslip.contract import cases as lc
    from stickslip.contract.lammps import lammps_type_pairs

    dashpot = 7  # nu_s V in X: nu_s = 7/16, V = 1/4 = X/dt
    rows = lammps_type_pairs("step", nu_s=dashpot * lc.X / 0.25, record=False)
    assert set(rows) == set(lc.TYPE_PAIRS)
    for pair, got in rows.items():
        t, fmin = lc.TYPE_PAIRS[pair]
        assert t - fmin <= dashpot and t - dashpot >= 1, "the derivation above needs these"
        w = lc.X * (np.array([1.0, 0, 0]) if 1 in pair else np.array([0, 1.0, 0]))
        for k in range(1, lc.TYPE_PAIR_STEPS + 1):
            f = k + dashpot if k < t - dashpot else fmin
            # exact before the first slip; after it Fmin/|F| F: sqrt(F.F) = |F| exactly for a
            # force along one axis, then a quotient and a product: within 1 ulp
            tol = np.spacing(f * lc.X)
            assert np.all(np.abs(got[k - 1] + f * w) <= tol), (pair, k, got[k - 1] / lc.X, -f)


def type_pairs_script(coeffs, newton, extra=""):
    p = DRAG
    rest = 2 * p["r"] - p["mass"] * p["g"] / p["kn"]
    atoms, lines = [], []
    for k, (a, b) in enumerate(sorted(coeffs)):
        x = 0.01 * k
        # the slider first: its neighbour list holds the contact until LAMMPS' spatial
        # sort, switched on at the second run, puts the held disk (in a lower bin) first;
        # the contact then moves to the held disk's list with its history seen from the
        # other body (transfer_history)
        atoms.append(f"create_atoms {a} single {x} {rest!r} 0.0 units box")      # slider
        atoms.append(f"create_atoms {b} single {x} 0.0 0.0 units box")           # held
    for (a, b), (ms, mk) in sorted(coeffs.items()):
        lines.append(f"pair_coeff {a} {b} mu_s {ms} mu_k {mk}")
    n = len(coeffs)
    held = " ".join(str(2 * k + 2) for k in range(n))
    return f"""units si
dimension 2
atom_style sphere
atom_modify map array sort 0 0.0
boundary f f p
newton {newton}
comm_modify vel yes
region box block -0.01 {0.01 * n} -0.01 0.01 -0.001 0.001 units box
create_box 3 box
neighbor 0.0005 bin
# rebuild the lists every 50 steps: the contacts' histories pass through the history fix
# (and, on 2 ranks, between the ranks) as they would in a flowing scene
neigh_modify every 50 delay 0 check no
{chr(10).join(atoms)}
set group all diameter {2 * p['r']} mass {p['mass']!r}
group held id {held}
group slider subtract all held
pair_style gran/hooke/stickslip {p['kn']} {p['ks']} {p['nu_n']} {p['nu_s']} 0.5 1 mu_k 0.45 damping absolute record yes {extra}
{chr(10).join(lines)}
timestep {p['dt']}
fix grav slider gravity {p['g']} vector 0 -1 0
fix mv slider move linear {p['v']} NULL NULL
fix 2d all enforce2d
dump a all custom 100 dump.atoms id x y z vx vy vz fx fy fz
dump_modify a sort id format float {F17}
{record_dump(1)}
run 1200
atom_modify sort 1000 0.00225
# (a compute pair/local made before atom_modify sort lists no pair afterwards in this
# LAMMPS, stock styles too: the record is read through new ones)
undump d1
uncompute pl1
uncompute ids1
{record_dump(2)}
run {p['steps'] - 1200}
"""


def record_dump(k):
    """Every contact's record, every step, into dump.pairs<k>."""
    return f"""compute pl{k} all pair/local p11 p1 p2 p12 p13 cutoff radius
compute ids{k} all property/local patom1 patom2 ptype1 ptype2 cutoff radius
dump d{k} all local 1 dump.pairs{k} c_ids{k}[1] c_ids{k}[2] c_ids{k}[3] c_ids{k}[4] c_pl{k}[1] c_pl{k}[2] c_pl{k}[3] &
  c_pl{k}[4] c_pl{k}[5]
dump_modify d{k} format float {F17}"""


def read_pairs(folder):
    """The two record dumps of type_pairs_script, one dict by step."""
    frames = read_dump(folder / "dump.pairs1")
    frames.update(read_dump(folder / "dump.pairs2"))
    return frames


@pytest.mark.parametrize("law", ["", "slip_timing exact reset spring history_rotation keep_length lever_arm contact"])
def test_ranks_and_newton_do_not_change_a_few_grain_scene(tmp_path, law):
    """The six sliders across the two ranks' boundary (x = 0.025: the pair at 0.02-0.03
    sits on it): serial newton off, 2 ranks newton on and off must write the same atoms'
    dump and the same record for every contact (as sets of rows: ranks write their own
    contacts), bit for bit; each contact is one force evaluation per step, computed with
    the same operations whichever rank or side holds it. ~5 s (two 2-rank runs)."""
    coeffs = {(1, 1): (0.50, 0.45), (1, 2): (0.55, 0.50), (1, 3): (0.40, 0.32), (2, 2): (0.45, 0.40),
              (2, 3): (0.60, 0.52), (3, 3): (0.35, 0.30)}
    results = {}
    for np_, newton in [(1, "off"), (2, "on"), (2, "off")]:
        d = tmp_path / f"{np_}{newton}"
        run_lammps(d, "pairs", type_pairs_script(coeffs, newton, law), np_=np_)
        local = read_pairs(d)
        canon = {}
        for step, rows in local.items():
            out = []
            for r in rows:
                r = r.copy()
                if r[0] > r[1]:  # seen from the other body: ids and types swap, the force changes sign
                    r[[0, 1]], r[[2, 3]], r[5:7] = r[[1, 0]], r[[3, 2]], -r[5:7]
                out.append(tuple(r))
            canon[step] = sorted(out)
        results[np_, newton] = ((d / "dump.atoms").read_bytes(), canon)
    ref = results[1, "off"]
    assert len(ref[1]) == DRAG["steps"] + 1 and all(len(v) == 6 for v in ref[1].values())
    for key, res in results.items():
        assert res[0] == ref[0], f"atoms differ: {key}"
        assert res[1] == ref[1], f"contact records differ: {key}"


# ---------------------------------------------------------------- one contact, step by step

def one_contact_script(law):
    """3D: a held sphere and a slider overlapping by 1e-4 m, the slider moved at
    V = (10, 3, 0) m/s with a fixed spin w (fix move; nothing integrated), 3 steps. The
    normal turns by ~5e-3 rad a step; the spring loads below the threshold."""
    return f"""units si
atom_style sphere
atom_modify map array
boundary f f f
comm_modify vel yes
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
neighbor 0.0005 bin
create_atoms 1 single 0.0 0.0 0.0 units box
create_atoms 1 single 0.0 0.0 0.0039 units box
set group all diameter 0.004 mass 0.0326725635973338
set atom 2 omega 200.0 -500.0 1000.0
group slider id 2
pair_style gran/hooke/stickslip 1.2e7 4.8e6 41.38 5.0 0.5 1 record yes {law}
pair_coeff * *
timestep 2e-6
fix mv slider move linear 10.0 3.0 0.0
compute pl all pair/local p11 p1 p2 p3 p12 cutoff radius
compute ids all property/local patom1 patom2 cutoff radius
dump d all local 1 dump.one c_ids[1] c_ids[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5]
dump_modify d format float {F17}
dump a all custom 1 dump.atoms id x y z
dump_modify a sort id format float {F17}
run 3
"""


def law_by_hand(xs, v, w, rotation, lever, damping, kn=1.2e7, ks=4.8e6, nu_n=41.38, nu_s=5.0, r=0.002,
                mass=0.0326725635973338, dt=2e-6):
    """docs/law.md steps 1-4 for the held sphere i (at rest) and the slider j, from the
    slider's positions xs[k] at steps 0..K: Fn and the tangential force on i for steps 1..K
    (step 0, the set-up, loads no spring; no slip happens)."""
    D = np.zeros(3)
    out = []
    m = mass * mass / (2 * mass) if damping == "mass" else 1.0  # meff of the pair, or absolute
    for k in range(1, len(xs)):
        d = xs[k] - 0.0
        dist = np.linalg.norm(d)
        n = d / dist                                   # from i to j
        delta = 2 * r - dist
        c = r - delta / 2 if lever == "contact" else r
        v_rel = np.zeros(3) - (v + np.cross(w, -c * n))  # i at rest and not spinning
        v_n = v_rel @ n
        V_s = v_rel - v_n * n
        fn = kn * delta + m * nu_n * v_n
        if rotation == "project":
            D = D + V_s * dt
            D = D - (D @ n) * n
        else:
            dn = D @ n
            if dn != 0.0:
                turned = D - dn * n
                D = turned * np.linalg.norm(D) / np.linalg.norm(turned)
            D = D + V_s * dt
        F = -ks * D - m * nu_s * V_s
        out.append((fn, F))
    return out


@pytest.mark.parametrize("rotation,lever,damping", [("project", "radius", "absolute"),
                                                    ("keep_length", "radius", "absolute"),
                                                    ("keep_length", "contact", "absolute"),
                                                    ("project", "contact", "mass")])
def test_one_contact_follows_the_law_step_by_step(tmp_path, rotation, lever, damping):
    """docs/law.md steps 1-4 in 3D with a turning normal and spin, derived here from the
    dumped positions: Fn (eq. 3) and the tangential force (eqs. 5-7) of every step, to
    round-off. The overlap 2r - |d| loses up to |d|/delta = 39 times the digits of |d|
    (cancellation), so Fn and F agree to 40 x 1e-12 relative. Each setting must matter:
    the other lever arm or rotation rule, computed the same way, misses by more than that.
    ~0.2 s."""
    run_lammps(tmp_path, "one", one_contact_script(
        f"history_rotation {rotation} lever_arm {lever} damping {damping}"))
    atoms = read_dump(tmp_path / "dump.atoms")
    xs = [atoms[k][1][1:4] for k in sorted(atoms)]
    local = read_dump(tmp_path / "dump.one")
    v, w = np.array([10.0, 3.0, 0.0]), np.array([200.0, -500.0, 1000.0])
    tol = 40 * 1e-12
    mine = law_by_hand(xs, v, w, rotation, lever, damping)
    for k, (fn, F) in zip(sorted(local)[1:], mine):
        row = local[k][0]
        assert row[:2].tolist() == [1, 2]
        assert row[2] == pytest.approx(fn, rel=tol)
        assert np.allclose(row[3:6], F, rtol=0, atol=tol * np.linalg.norm(F)), (k, row[3:6], F)
        assert row[6] == 0, "no slip"
    other = law_by_hand(xs, v, w, "project" if rotation == "keep_length" else "keep_length",
                        "radius" if lever == "contact" else "contact", damping)
    F_last, F_other = mine[-1][1], other[-1][1]
    assert np.linalg.norm(F_last - F_other) > 100 * tol * np.linalg.norm(F_last), "the settings must matter"


# ---------------------------------------------------------------- exact slip timing

def test_exact_timing_without_slip_is_the_step_mode(tmp_path):
    """slip_timing exact (docs/law.md E0): a step without slip computes exactly what the
    step mode computes. The wall drag's first slip comes at step ~832; up to step 800 the
    two modes' dumps must be identical bytes, and the first slip must make them differ
    (else the keyword did nothing). ~0.5 s."""
    for mode in ("step", "exact"):
        for n in (800, 1000):
            run_lammps(tmp_path / f"{mode}{n}", "drag", drag_script("wall2d", f"slip_timing {mode}", steps=n))
    same = [(tmp_path / f"{m}800" / "dump.drag").read_bytes() for m in ("step", "exact")]
    assert same[0] == same[1]
    step, exact = (read_dump(tmp_path / f"{m}1000" / "dump.drag") for m in ("step", "exact"))
    assert step[800][0][5] == 0, "no slip before step 800"
    first_diff = min(k for k in exact if not np.array_equal(exact[k], step[k]))
    first_slip = min(k for k in exact if exact[k][0][5] > 0)
    assert first_diff == first_slip


@pytest.mark.parametrize("reset", ["spring", "total"])
def test_exact_timing_slips_inside_the_step(tmp_path, reset):
    """The drag in the exact timing (2D wall; V constant, so V_s and the dashpot nu_s V are
    the same in every step and the force stays along -x). With rate = Ks V dt, a step
    that does not slip adds rate to |F|, as the step mode; a step k that slips starts from
    the previous step's trial force f (recorded: no slip ends in E4 here, so the applied
    force is the trial force), reaches T = mu_s Fn_k at theta = (T - f)/rate (E2, at once
    if f >= T), drops to Fmin + kept (E3; kept = nu_s V with reset spring, 0 with total)
    and loads again for the rest of the step: |F_k| = Fmin + kept + rate (1 - theta).
    Sizes ~0.2 N, a handful of operations: round-off 1e-12 Fn. ~0.3 s."""
    run_lammps(tmp_path, "drag", drag_script("wall2d", f"slip_timing exact reset {reset}"))
    fn, F, nslip, _ = drag_record(tmp_path / "dump.drag")
    p = DRAG
    rate = p["ks"] * p["v"] * p["dt"]
    kept = p["nu_s"] * p["v"] if reset == "spring" else 0.0
    f = np.linalg.norm(F, axis=1)
    slipped = np.diff(np.concatenate([[0.0], nslip])) > 0
    # along x but for round-off of the projection onto the tangent plane
    assert slipped.sum() >= 5 and np.all(np.abs(F[:, 1:]) <= 1e-12 * f[:, None])
    T, fmin = p["mu_s"] * fn, (2 * p["mu_k"] - p["mu_s"]) * fn
    k = np.arange(1, len(f))
    stick = k[~slipped[1:]]
    assert np.allclose(f[stick] - f[stick - 1], rate, rtol=0, atol=1e-12 * fn.max())
    slip = k[slipped[1:]]
    theta = np.maximum(T[slip] - f[slip - 1], 0.0) / rate
    assert np.all(theta <= 1.0)
    assert np.allclose(f[slip], fmin[slip] + kept + rate * (1 - theta), rtol=0, atol=1e-12 * fn.max())
    # in the step timing the same steps end at Fmin exactly: the exact timing must not
    assert np.all(f[slip] > fmin[slip] + kept)


# ---------------------------------------------------------------- refusals

BOX3D = """atom_style sphere
boundary f f f
region box block 0 10 0 10 0 10 units box
create_box 2 box
create_atoms 1 single 5 5 5 units box
comm_modify vel yes
"""
BOX2D = """dimension 2
atom_style sphere
boundary f f p
region box block 0 10 0 10 -0.5 0.5 units box
create_box 1 box
create_atoms 1 single 5 5 0 units box
comm_modify vel yes
"""
PAIR = "pair_style gran/hooke/stickslip 2000 NULL 50 NULL 0.5 0"
WALL = "fix w all wall/gran/stickslip hooke/history 2000 NULL 50 NULL 0.5 0"

# (name, script, words the ERROR line must hold: the argument, and the allowed range or values)
REFUSALS = [
    ("pair too few", BOX3D + "pair_style gran/hooke/stickslip 2000 NULL 50 NULL 0.5", ["needs Kn Kt", "got 5"]),
    ("pair Kn", BOX3D + "pair_style gran/hooke/stickslip -1 NULL 50 NULL 0.5 0", ["Kn = -1", "Kn > 0"]),
    ("pair Kt", BOX3D + "pair_style gran/hooke/stickslip 2000 -5 50 NULL 0.5 0", ["Kt = -5", "Kt > 0"]),
    ("pair gamma_n", BOX3D + "pair_style gran/hooke/stickslip 2000 NULL -1 NULL 0.5 0", ["gamma_n = -1", ">= 0"]),
    ("pair xmu text", BOX3D + "pair_style gran/hooke/stickslip 2000 NULL 50 NULL abc 0", ["xmu = 'abc'", "10000"]),
    ("pair dampflag", BOX3D + "pair_style gran/hooke/stickslip 2000 NULL 50 NULL 0.5 2", ["dampflag = '2'", "0 or 1"]),
    ("pair mu_k low", BOX3D + PAIR + " mu_k 0.2", ["mu_k = 0.2", "[0.25, 0.5]"]),
    ("pair mu_k high", BOX3D + PAIR + " mu_k 0.6", ["mu_k = 0.6", "[0.25, 0.5]"]),
    ("pair mu_k text", BOX3D + PAIR + " mu_k x", ["mu_k = 'x'", "mu_s/2 <= mu_k <= mu_s"]),
    ("pair mu_k missing", BOX3D + PAIR + " mu_k", ["mu_k needs a value", "mu_s/2 <= mu_k <= mu_s"]),
    ("pair unknown keyword", BOX3D + PAIR + " friction 0.3", ["unknown keyword 'friction'", "mu_k, reset"]),
    ("pair value missing", BOX3D + PAIR + " reset", ["keyword reset needs a value", "total or spring"]),
    ("pair bad value", BOX3D + PAIR + " slip_timing later", ["slip_timing 'later'", "exact or step"]),
    ("pair bad damping", BOX3D + PAIR + " damping viscous", ["damping 'viscous'", "absolute or mass"]),
    ("pair_coeff mu_k", BOX3D + PAIR + "\npair_coeff * * mu_s 0.5 mu_k 0.1", ["pair_coeff 1 1", "mu_k = 0.1",
                                                                             "[0.25, 0.5]"]),
    ("pair_coeff mu_s vs pair_style mu_k", BOX3D + PAIR + " mu_k 0.45\npair_coeff 1 2 mu_s 0.3",
     ["pair_coeff 1 2 (mu_k from pair_style)", "mu_k = 0.45", "[0.15, 0.3]"]),
    ("pair_coeff unknown keyword", BOX3D + PAIR + "\npair_coeff * * friction 0.3", ["unknown keyword 'friction'",
                                                                                   "mu_s, mu_k"]),
    ("pair_coeff value missing", BOX3D + PAIR + "\npair_coeff * * mu_s", ["keyword mu_s needs a value"]),
    ("pair_coeff negative mu_s", BOX3D + PAIR + "\npair_coeff * * mu_s -0.1", ["mu_s = -0.1", "0 <= mu_s"]),
    ("pair_coeff order", BOX3D + PAIR + "\npair_coeff 2 1", ["pair_coeff 2 1", "lower type first"]),
    ("record changed", BOX3D + PAIR + "\npair_coeff * *\nrun 0\n" + PAIR + " record yes\nrun 0",
     ["record cannot change", "pair_style none"]),
    ("wall fstyle", BOX3D + "fix w all wall/gran/stickslip hertz/history 2000 NULL 50 NULL 0.5 0 zplane 0 NULL",
     ["fstyle 'hertz/history'", "hooke/history"]),
    ("wall too few", BOX3D + WALL, ["needs hooke/history Kn", "wallstyle"]),
    ("wall Kn", BOX3D + "fix w all wall/gran/stickslip hooke/history 0 NULL 50 NULL 0.5 0 zplane 0 NULL",
     ["Kn = 0", "Kn > 0"]),
    ("wall xmu", BOX3D + "fix w all wall/gran/stickslip hooke/history 2000 NULL 50 NULL -1 0 zplane 0 NULL",
     ["xmu (mu_s) = -1", "0 <= xmu <= 10000"]),
    ("wall region", BOX3D + WALL + " region box", ["wallstyle region", "xplane, yplane, zplane, zcylinder"]),
    ("wall unknown style", BOX3D + WALL + " plane 0 NULL", ["wallstyle 'plane'", "xplane, yplane, zplane"]),
    ("wall lo hi", BOX3D + WALL + " zplane 5 1", ["zplane lo must be below hi"]),
    ("wall lo hi missing", BOX3D + WALL + " zplane 5", ["zplane needs lo hi"]),
    ("wall radius", BOX3D + WALL + " zcylinder -2", ["zcylinder radius = -2", "> 0"]),
    ("wall periodic", BOX3D.replace("boundary f f f", "boundary f f p") + WALL + " zplane 0 NULL",
     ["zplane lies across a periodic dimension", "non-periodic"]),
    ("wall 2D zplane", BOX2D + WALL + " zplane 0 NULL", ["zplane is meaningless with dimension 2",
                                                        "xplane, yplane, zcylinder"]),
    ("wall 2D shear z", BOX2D + WALL + " yplane 0 NULL shear z 1.0", ["shear along z is meaningless with dimension 2",
                                                                     "x or y"]),
    ("wall 2D wiggle z", BOX2D + WALL + " zcylinder 4 wiggle z 1 1", ["wiggle along z is meaningless with dimension 2"]),
    ("wall shear normal", BOX3D + WALL + " zplane 0 NULL shear z 1.0", ["shear of a plane must be along the plane"]),
    ("wall wiggle and shear", BOX3D + WALL + " zplane 0 NULL wiggle x 1 1 shear y 1",
     ["wiggle and shear cannot be combined"]),
    ("wall wiggle period", BOX3D + WALL + " zplane 0 NULL wiggle z 1 0", ["wiggle period = 0", "> 0"]),
    ("wall mu_k", BOX3D + WALL + " zplane 0 NULL mu_k 0.1", ["mu_k = 0.1", "[0.25, 0.5]"]),
    ("wall unknown keyword", BOX3D + WALL + " zplane 0 NULL sticky yes", ["unknown keyword 'sticky'", "wiggle, shear"]),
    ("wall bad value", BOX3D + WALL + " zplane 0 NULL history_rotation turn",
     ["history_rotation 'turn'", "project or keep_length"]),
]


@pytest.mark.parametrize("name,script,words", REFUSALS, ids=[r[0] for r in REFUSALS])
def test_bad_input_stops_with_one_error_line(tmp_path, name, script, words):
    """Bad input: one ERROR line naming the argument and its allowed range or values; the
    run stops (non-zero exit), no crash. ~0.15 s each."""
    proc = run_lammps(tmp_path, "bad", script + "\nrun 0\n", check=False)
    errors = error_lines(proc)
    assert proc.returncode != 0 and len(errors) == 1, (proc.returncode, proc.stdout[-2000:])
    for w in words:
        assert w in errors[0], (w, errors[0])
    for marker in CRASH_MARKERS:
        assert marker not in proc.stdout + proc.stderr, (marker, proc.stderr[-1000:])


def test_refusal_fails_without_the_check(tmp_path):
    """The error tests can fail: a good line runs (the same script with mu_k in range)."""
    proc = run_lammps(tmp_path, "good", BOX3D + PAIR + " mu_k 0.3\npair_coeff * *\nrun 0\n", check=False)
    assert proc.returncode == 0 and not error_lines(proc)


# ---------------------------------------------------------------- loading

def loader_scene(tag):
    """A few grains poured on a wall (both styles, non-default law settings), a `clear`,
    the same again, then a restart file."""
    body = f"""atom_style sphere
boundary f f f
region box block 0 4 0 4 0 6 units box
create_box 1 box
create_atoms 1 random 20 4242 box
set group all diameter 0.8 density 1.0
velocity all create 1.0 1 loop geom
pair_style gran/hooke/stickslip 2000.0 NULL 50.0 NULL 0.5 1 mu_k 0.4 reset spring slip_timing exact record yes
pair_coeff * *
comm_modify vel yes
neighbor 0.2 bin
timestep 0.001
fix 1 all nve/sphere
fix 2 all gravity 1.0 vector 0 0 -1
fix w all wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 zplane 0.0 6.0 mu_k 0.4 record yes
fix side all wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 xplane 0.0 4.0
fix side2 all wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 yplane 0.0 4.0
thermo_style custom step ke
thermo_modify format float %.15g
thermo 100
run 300
"""
    return body + "clear\n" + body + f"write_restart restart.{tag}\n"


def loader_restart(tag):
    return f"""read_restart restart.{tag}
comm_modify vel yes
neighbor 0.2 bin
fix 1 all nve/sphere
fix 2 all gravity 1.0 vector 0 0 -1
fix w all wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 zplane 0.0 6.0 mu_k 0.4 record yes
fix side all wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 xplane 0.0 4.0
fix side2 all wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 yplane 0.0 4.0
compute pl all pair/local p12 p13
thermo_style custom step ke
thermo_modify format float %.15g
run 100
"""


LOADERS = {
    "launcher": dict(exe=None, env=None, line=""),
    "include": dict(exe=STOCK, env=None, line=f"include {LOADER}\n"),
    "preload": dict(exe=STOCK, env={"LD_PRELOAD": str(LIBRARY)}, line=""),
}


@pytest.mark.parametrize("how,np_", [("launcher", 1), ("include", 1), ("preload", 1), ("launcher", 2),
                                     ("include", 2), ("preload", 2)])
def test_loaders_survive_clear_and_read_restart(tmp_path, how, np_):
    """Each way to load the styles: the launcher, `include stickslip.lmp` in the stock lmp,
    LD_PRELOAD into it; serial and on 2 ranks (mpirun). A script defines
    both styles, runs, clears, defines them again and writes a restart file; a second
    script (a new process) starts with read_restart. Both runs must end without error and,
    serial, write the same thermo output as the launcher (the same library computes). The
    stock lmp without the loader must not know the styles (so the check can fail). ~1-3 s."""
    how_ = LOADERS[how]
    env = how_["env"]  # (mpirun's environment reaches the ranks it starts on this machine)
    run_lammps(tmp_path, "scene", how_["line"] + loader_scene(how), exe=how_["exe"], np_=np_, env=env)
    run_lammps(tmp_path, "restart", how_["line"] + loader_restart(how), exe=how_["exe"], np_=np_, env=env)
    mine = read_thermo(tmp_path / "log.scene")
    assert len(mine["KinEng"]) >= 6 and mine["KinEng"][-1] > 0
    if how != "launcher" and np_ == 1:
        ref = tmp_path / "ref"
        run_lammps(ref, "scene", loader_scene("launcher"))
        assert np.array_equal(read_thermo(ref / "log.scene")["KinEng"], mine["KinEng"])
    if how == "include" and np_ == 1:
        bare = run_lammps(tmp_path / "bare", "scene", loader_scene("bare"), exe=STOCK, check=False)
        assert "Unrecognized pair style 'gran/hooke/stickslip'" in bare.stdout


def test_stock_lammps_package_untouched():
    """The plugin adds styles at run time; Debian's lammps files are as installed
    (dpkg --verify prints nothing for unmodified packages). ~0.3 s."""
    out = subprocess.run(["dpkg", "--verify", "lammps", "liblammps0", "liblammps-dev"], capture_output=True,
                         text=True)
    assert out.returncode == 0 and out.stdout.strip() == "", out.stdout
