# SPDX-License-Identifier: GPL-2.0-or-later
"""DEM-Engine's force model (deme_model/stick_slip.cu) pinned without a GPU: the same file,
compiled on the CPU through deme_model/shim/ (stickslip/contract/deme_shim.py), through every row of the
law's contract in float, and the parts the contract's rows do not reach (the engine's
Hertz-Mindlin normal force, a tensile Fn, a turning wall's velocity, the sweep's per-owner
coefficients).

Tolerances, for float: a row exact in double is exact in float too (its values are small
multiples of powers of 2, with fewer than 24 significant bits); a row's ulps count its
roundings, the same count in any binary format, so they are float ulps here
(cases.compare with dtype float32); the bounds that add up roundings (the 100
slips of max_explicit_slips, the turning pair's |D|) use float's epsilon 2^-23. The one
row about a single ulp takes mu_s one float ulp above 15/32 (deme_shim.float_case).
"""
import math

import numpy as np
import pytest

from stickslip.contract import cases as lc, deme_shim as shim

F32 = np.float32


@pytest.mark.parametrize("sweep", [False, True], ids=["materials", "sweep_record"])
@pytest.mark.parametrize("case", lc.CASES, ids=lambda c: c.name)
def test_contract_in_float(case, sweep):
    """Every row of the contract, with the coefficients as material properties (the contact
    wildcards read back) and per owner (the sweep; the owners' record read back)."""
    case = shim.float_case(case)
    lc.compare(case, shim.run_case(case, sweep=sweep), dtype=F32)


def _slide_on_wall(c, steps, mats=(1, 1)):
    """A grain on the floor (overlap 1/32: Fn = 1) sliding one X a step along x, no dashpot;
    the trace of each step (force on A, spring, slips)."""
    trace = lc.empty_trace(steps)
    x = np.array([[0.0, 0.0, lc.R - lc.DELTA]])
    v = np.array([[lc.X / lc.DT, 0.0, 0.0]])
    for k in range(steps):
        delta, area, b2a, kin, a_pos, b_pos = shim.contract_geometry(lc.Case("", "", "wall", (), 0.5, 0.5), x, v,
                                                                     np.zeros((1, 3)))
        kin[shim.L["K_AMAT"]], kin[shim.L["K_BMAT"]] = mats
        force = c.step(delta, area, kin, a_pos, b_pos)
        trace["fn"][k], trace["F"][k] = force[2], (force[0], force[1], 0.0)
        trace["D"][k], trace["slips"][k] = c.wc[:3], int(c.wc[3])
    return trace


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_coefficients_per_type_pair(timing):
    """mu_s and mu_k read for the contact's own pair of material types (the engine's
    mu[bodyAMatType][bodyBMatType], mu_k likewise): every pair different
    (cases.TYPE_PAIRS), within 1 float ulp."""
    coeff = lc.type_pair_coefficients()
    for pair in lc.TYPE_PAIRS:
        c = shim.Contact(f"ss_hooke_{timing}_spring")
        for (i, j), (ms, mk) in coeff.items():
            c.pairwise("mu", i, j, ms)
            c.pairwise("mu_k", i, j, mk)
            c.pairwise("kn", i, j, lc.KN)
            c.pairwise("ks", i, j, lc.KS)
        lc.compare_type_pair(pair, _slide_on_wall(c, lc.TYPE_PAIR_STEPS, pair), np.array([lc.X, 0.0, 0.0]),
                             dtype=F32)


def test_sweep_coefficients_per_owner():
    """The sweep's rule: a wall contact takes its grain's (A's) mu_s, mu_k; a grain pair the
    mean of its two grains' (owner wildcards). Threshold T in X units on the floor: A's 18
    (B's 8 is ignored), so the first slip is at step 18; for a pair with A's 18 and B's 8
    (Fmin 12 and 2) the mean is T = 13, Fmin = 7: slips at 13, then every 6 steps."""
    X = lc.X
    c = shim.Contact("ss_hooke_sweep_record")
    c.pairwise("kn", 1, 1, lc.KN)
    c.pairwise("ks", 1, 1, lc.KS)
    for owner, (t, fmin) in ((0, (18, 12)), (1, (8, 2))):
        c.owner("W_MU_S", owner, t * X)
        c.owner("W_MU_K", owner, (t + fmin) / 2 * X)
    tr = _slide_on_wall(c, 20)
    assert list(np.nonzero(np.diff(np.r_[0, tr["slips"]]))[0] + 1) == [18]
    # the pair: grain j at rest beside i (normal x), i sliding along y
    c.wc[:] = 0
    slips = []
    x = np.array([[-(1 - lc.DELTA) / 2, 0.0, 0.0], [(1 - lc.DELTA) / 2, 0.0, 0.0]])
    v = np.array([[0.0, X / lc.DT, 0.0], [0.0, 0.0, 0.0]])
    for _ in range(25):
        delta, area, _, kin, a_pos, b_pos = shim.contract_geometry(lc.Case("", "", "pair", (), 0.5, 0.5), x, v,
                                                                   np.zeros((2, 3)))
        c.step(delta, area, kin, a_pos, b_pos)
        slips.append(int(c.wc[3]))
    assert list(np.nonzero(np.diff(np.r_[0, slips]))[0] + 1) == [13, 19, 25]
    assert c.owned("R_FN", 1) == 1.0 and c.owned("R_FY", 1) == -c.owned("R_FY", 0) != 0.0  # B's record: B's force


def _hertz_contact(variant="ss_hertz_step_spring", E=1e8, nu=0.3, cor=0.5, mu=0.5, mu_k=0.45):
    c = shim.Contact(variant)
    c.material("E", 1, E)
    c.material("nu", 1, nu)
    c.pairwise("CoR", 1, 1, cor)
    c.pairwise("mu", 1, 1, mu)
    c.pairwise("mu_k", 1, 1, mu_k)
    for owner in (0, 1):
        c.owner("W_MU_S", owner, mu)
        c.owner("W_MU_K", owner, mu_k)
    return c


def _hertz_reference(E, nu, cor, m1, m2, delta, area, vn_closing):
    """FullHertzianForceModel.cu's normal force and Mindlin's kt, gt, in double (independent
    of the shim): effective moduli, contact radius from the area, damping from CoR."""
    E_eff = 1 / (2 * (1 - nu * nu) / E)
    G_eff = 1 / (2 * 2 * (2 - nu) * (1 + nu) / E)
    m = m1 * m2 / (m1 + m2)
    a = math.sqrt(area / math.pi)
    Sn = 2 * E_eff * a
    loge = math.log(cor)
    beta = loge / math.sqrt(loge * loge + math.pi ** 2)
    fn = 2 / 3 * Sn * delta + 2 * math.sqrt(5 / 6) * beta * math.sqrt(Sn * m) * (-vn_closing)
    kt = 8 * G_eff * a
    gt = -2 * math.sqrt(5 / 3) * beta * math.sqrt(m * kt)
    return fn, kt, gt


@pytest.mark.parametrize("variant", ["ss_hertz_step_spring", "ss_hertz_sweep_record"])
def test_hertz_mindlin_is_the_engines(variant):
    """With the engine's normal force (the default): Fn is FullHertzianForceModel.cu's
    (k_n delta + gamma_n v, from E, nu, CoR, the masses and the contact area) and the trial
    force -kt D - gt V_s with Mindlin's kt and gt. Two spheres r = 2 mm, delta = 1e-5 m,
    closing at 1e-3 m/s and sliding at 0.02 m/s: one step of dt = 1e-6 s loads D = V_s dt.
    Float bound: each value goes through ~20 float operations from the same inputs:
    relative 20 * 2^-24 ~ 1.2e-6, taken as 2e-6."""
    r, delta, dt, m = 2e-3, 1e-5, 1e-6, 8.7e-5
    c = _hertz_contact(variant)
    d = 2 * r - delta
    x = np.array([[-d / 2, 0, 0], [d / 2, 0, 0]])
    b2a = np.array([-1.0, 0, 0])
    cp = x[1] + (r - delta / 2) * b2a
    area = math.pi * (r * delta - delta * delta / 4)
    va = np.array([1e-3, 0.02, 0.0])  # closing along +x (A moves towards B), sliding along y
    kin = shim.kinematics(b2a, va, (0, 0, 0), (0, 0, 0), (0, 0, 0), cp - x[0], cp - x[1], dt, 0.0, shim.SPHERE_SPHERE,
                          masses=(m, m))
    force = c.step(delta, area, kin)
    fn, kt, gt = _hertz_reference(1e8, 0.3, 0.5, m, m, delta, area, 1e-3)
    assert fn > 0
    assert abs(force @ b2a - fn) <= 2e-6 * abs(fn), (force @ b2a, fn)
    ft = -kt * 0.02 * dt - gt * 0.02  # along y: spring V dt and the dashpot
    assert abs(ft) < 0.5 * fn  # (sticks)
    assert abs(force[1] - ft) <= 2e-6 * abs(ft), (force[1], ft)
    assert force[2] == 0.0


def test_hertz_tensile_fn_uses_its_magnitude():
    """Bodies parting fast with strong damping: the engine's Hertz normal force is tensile
    (Fn < 0; docs/law.md step 2: the threshold and Fmin then use |Fn|). The spring, loaded
    by a step of sliding at 10 m/s, is far above mu_s |Fn|: it slips to Fmin =
    (2 mu_k - mu_s)|Fn| along the trial force (the force opposes the sliding), and the
    spring holds Fmin/kt (reset spring). With Fn's sign kept, Fmin < 0 would turn the force
    to push along the sliding."""
    r, delta, dt, m = 2e-3, 1e-6, 1e-6, 8.7e-5
    c = _hertz_contact(cor=0.05)
    d = 2 * r - delta
    x = np.array([[-d / 2, 0, 0], [d / 2, 0, 0]])
    b2a = np.array([-1.0, 0, 0])
    cp = x[1] + (r - delta / 2) * b2a
    area = math.pi * (r * delta - delta * delta / 4)
    va = np.array([-1.0, 10.0, 0.0])  # parting at 1 m/s, sliding along +y
    kin = shim.kinematics(b2a, va, (0, 0, 0), (0, 0, 0), (0, 0, 0), cp - x[0], cp - x[1], dt, 0.0, shim.SPHERE_SPHERE,
                          masses=(m, m))
    force = c.step(delta, area, kin)
    fn, kt, _ = _hertz_reference(1e8, 0.3, 0.05, m, m, delta, area, -1.0)
    assert fn < 0 and abs(force @ b2a - fn) <= 2e-6 * abs(fn)
    fmin = (2 * 0.45 - 0.5) * abs(fn)
    assert force[1] < 0 and abs(-force[1] - fmin) <= 4e-6 * fmin, (force, fmin)
    assert c.wc[3] == 1.0 and abs(c.wc[1] - fmin / kt) <= 4e-6 * fmin / kt, (c.wc, fmin / kt)


def test_turning_wall_velocity_at_its_surface_point():
    """docs/law.md step 1: a wall's velocity is taken at its surface point nearest the grain's
    centre, not at the engine's contact point (midway in the overlap, delta/2 inside the
    wall). A plane through its owner's pivot (the origin), normal +y, turning about z at
    omega = 1 rad/s, and a grain at rest on it straight above the pivot: the surface point is
    the pivot, so V_s = 0 and, without a spring load or a normal velocity, no tangential
    force; at the contact point the plane moves at omega delta/2 = 1/64 along x, which with
    Ks = 1, nu_s = 1 would give a force of (dt + nu_s)/64."""
    c = shim.Contact("ss_hooke_step_spring")
    for name, value in (("kn", lc.KN), ("ks", 1.0), ("nu_s", 1.0), ("mu", 1e3), ("mu_k", 1e3)):
        c.pairwise(name, 1, 1, value)
    delta = 1 / 32
    xa = np.array([0.0, lc.R - delta, 0.0])
    b2a = np.array([0.0, 1.0, 0.0])
    cp = xa - b2a * (lc.R - delta / 2)  # (0, -delta/2, 0)
    kin = shim.kinematics(b2a, (0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 1.0), cp - xa, cp, lc.DT, 0.0,
                          shim.SPHERE_ANALYTICAL)
    force = c.step(delta, math.pi * (lc.R ** 2 - (lc.R - delta) ** 2), kin)
    assert force[1] == lc.KN * delta and force[0] == 0.0 and force[2] == 0.0, force


def _float_turned_normal(beta):
    """A plane's normal, +y turned by beta about z, as the engine has it: the prescribed
    quaternion cast to float (adapters/deme.turning_prescription), then applyOriQToVector3's
    formula in float (its length 1 + ~1e-7, not 1)."""
    return shim.apply_ori_q((0.0, 1.0, 0.0), (0.0, 0.0, F32(math.sin(beta / 2)), F32(math.cos(beta / 2))))


@pytest.mark.parametrize("variant", ["ss_hooke_step_spring", "ss_hertz_step_spring"])
def test_plane_distance_taken_in_double(variant):
    """Step 0: on a plane the model takes the overlap from the grain's distance in double along
    the normal made unit, not the engine's overlapDepth (r less a float distance, along a
    float normal 1 + ~1e-7 long). The tilt's grain (r = 5 mm, overlap 1.67e-7 m = 3.3e-5 r,
    at rest) on its plate turned by 200 angles up to 0.4676 rad: Fn is the exact overlap's,
    kn delta (Hooke) or the engine's Hertz from delta and the circle pi (r^2 - d^2), within
    float: ~20 roundings, 2e-6. The engine's own overlap is off by up to 0.45 % on these
    angles (its float distance steps by ulp(r) = 4.7e-10 m, 0.28 %, and the normal's length
    error r ~1e-7 adds ~0.3 %): the test checks that it is above 0.3 %, so that it can fail."""
    r, delta, kn, m = F32(0.005), 1.67e-7, 1.2e7, 1.36e-3
    hertz = "hertz" in variant
    c = _hertz_contact(variant) if hertz else shim.Contact(variant)
    if not hertz:
        for name, value in (("kn", kn), ("ks", 9.6e6), ("mu", 0.5), ("mu_k", 0.45)):
            c.pairwise(name, 1, 1, value)
    worst_engine = worst_model = 0.0
    for beta in np.linspace(0.0, 0.4676, 200):
        n_exact = np.array([-math.sin(beta), math.cos(beta), 0.0])
        n = _float_turned_normal(beta)
        a_pos = (float(r) - delta) * n_exact  # above the plate's pivot, the plane's point
        dist_engine = float(F32(a_pos @ n.astype(float)))  # planeSignedDistance: double dot, float result
        overlap_engine = float(r) - dist_engine
        area_engine = math.pi * (float(r) ** 2 - dist_engine ** 2)
        cp = a_pos - n * (dist_engine + overlap_engine / 2)
        kin = shim.kinematics(n, (0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0), cp - a_pos, cp, 8e-6, 0.0,
                              shim.SPHERE_ANALYTICAL, masses=(m, 1.0), radius=r)
        c.wc[:] = 0
        force = c.step(overlap_engine, area_engine, kin, a_pos, (0.0, 0.0, 0.0))
        fn = float(force @ n.astype(float))
        if hertz:
            area = math.pi * (float(r) ** 2 - (float(r) - delta) ** 2)
            want, _, _ = _hertz_reference(1e8, 0.3, 0.5, m, 1.0, delta, area, 0.0)
        else:
            want = kn * delta
        worst_model = max(worst_model, abs(fn / want - 1))
        worst_engine = max(worst_engine, abs(overlap_engine / delta - 1))
    assert worst_model <= 2e-6, worst_model
    assert worst_engine > 3e-3, worst_engine


def test_non_plane_keeps_the_engines_overlap():
    """Step 0 recomputes a plane's distance only: a grain inside a cylinder (radius 4, axis z
    through B's point, the grain 2 along the axis from it) has the engine's overlap 1/32
    (Fn = 1 exactly). Its distance along the normal is the cylinder's radius from the
    engine's (r - overlap), beyond 1e-4 r: the model keeps overlapDepth. Taken as a plane it
    would see an overlap of 4 and Fn = 129."""
    c = shim.Contact("ss_hooke_step_spring")
    for name, value in (("kn", lc.KN), ("ks", 1.0), ("mu", 0.5), ("mu_k", 0.45)):
        c.pairwise(name, 1, 1, value)
    delta, rc = lc.DELTA, 4.0
    a_pos = np.array([rc - lc.R + delta, 0.0, 2.0])
    b2a = np.array([-1.0, 0.0, 0.0])  # inward, towards the axis
    cp = a_pos - b2a * (lc.R - delta / 2)
    kin = shim.kinematics(b2a, (0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0), cp - a_pos, cp, lc.DT, 0.0,
                          shim.SPHERE_ANALYTICAL, radius=lc.R)
    force = c.step(delta, math.pi * (2 * lc.R * delta - delta * delta), kin, a_pos, (0.0, 0.0, 0.0))
    assert force[0] == -1.0 and force[1] == 0.0 and force[2] == 0.0, force


def test_the_library_has_every_variant():
    """The shim's build carries each combination of the model's options the tests use."""
    assert set(shim.functions()) == set(shim.VARIANTS)


def _slow_shrink(label, nu_s):
    """cases.py's max_explicit_slips rows with mu_k = 63/128 (Fmin = 31/64, r = 31/32 for
    15/16): the part q across u stays larger through the 100 slips followed one by one
    (0.0104 after them, not 4e-4), so E7's closed form after them differs from one taken
    after 50 by 1.3e-3 along u, above float's bound 800 eps (T + rate) = 4.3e-4 (which the
    original rows' 5e-5 is not); and the slides row (nu_s = 1/4096: kept = T - Fmin) meets
    E7 with L = 0 instead of rounding into E4 as the original does in float, where
    1 - t.u falls to its rounding."""
    return lc.Case(f"max_explicit_slips_{label}_slow_shrink", "E7 after MAX_EXPLICIT_SLIPS slips (float rows)", "wall",
                   (lc.Segment(16, lc.ALONG_X), lc.Segment(1, (0.0, 64.0, 0.0))), 0.5, 63 / 128, nu_s=nu_s,
                   timing="exact")


E7_CASES = [c for c in lc.CASES if c.name.startswith("max_explicit_slips")] + [
    _slow_shrink("periodic", 0.0), _slow_shrink("slides", 1 / 4096)]


@pytest.mark.parametrize("case", E7_CASES, ids=lambda c: c.name)
def test_closed_form_after_the_followed_slips_in_float(case):
    """E7 in float, along u and across it. Along u (the slips' times summed: cases.py's
    bound, 800 eps (T + rate)); across u, a bound of its own: the part q shrinks by r at
    each slip exactly in arithmetic, and each slip adds to it the roundings of adding along
    u and of taking q out (4 eps T), which shrink by r after: at most 4 eps T / (1 - r), plus
    the relative rounding of q itself over the N + n slips (3 (N + n) eps |q|). The shim's
    own differences are ~5e-10; q's sign turned would be 3e-4."""
    lc.compare(case, shim.run_case(case), dtype=F32)
    lc.compare(case, shim.run_case(case, sweep=True), dtype=F32)
    T, fmin = case.mu_s, 2 * case.mu_k - case.mu_s
    r = fmin / T
    theta, a, q, rest, L = lc.max_slips_follow(case)
    n = math.floor(rest / L) if L > 0 else 0
    q_end = r ** n * q
    bound = 4 * F32_EPS * T / (1 - r) + 3 * (100 + n) * F32_EPS * q_end
    got = shim.run_case(case)["F"][-1]
    want_across = -q_end if L > 0 else 0.0  # (the force on i: its part across u along -x, cases.py)
    assert abs(got[0] - want_across) <= bound, (got[0], want_across, bound)


F32_EPS = 2.0 ** -23
