# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract on every engine (stickslip/contract/cases.py): one-contact cases with
exact numbers, each engine's record compared to hand-worked values to the ulp."""
import math

import numpy as np
import pytest

from conftest import skip_engine
from stickslip.adapters import ENGINES, OPTIONAL_ENGINES
from stickslip.contract import cases as lc, runners


@pytest.mark.parametrize("engine", sorted(runners.RUNNERS))
@pytest.mark.parametrize("case", lc.CASES, ids=lambda c: c.name)
def test_contract(case, engine):
    skip_engine(engine)
    lc.compare(case, runners.RUNNERS[engine](case))


def test_every_engine_has_the_contract():
    """An engine added to stickslip.adapters.ENGINES must bring its contract runner (or
    say whose kernel it runs); an optional one (OPTIONAL_ENGINES) a runner or a CPU shim."""
    missing = set(ENGINES) - set(runners.RUNNERS) - set(runners.SHARED_KERNEL)
    assert not missing, f"engines without a contract runner in stickslip/contract/runners.py: {sorted(missing)}"
    unpinned = set(OPTIONAL_ENGINES) - set(runners.RUNNERS) - set(runners.CPU_SHIMS)
    assert not unpinned, f"optional engines whose law no test runs without their hardware: {sorted(unpinned)}"
    undecided = set(runners.RUNNERS) - set(runners.TYPE_PAIR_RUNNERS) - set(runners.NO_TYPE_PAIRS)
    assert not undecided, f"engines with neither a per-type-pair runner nor a reason: {sorted(undecided)}"


@pytest.mark.parametrize("timing", ["step", "exact"])
@pytest.mark.parametrize("engine", sorted(runners.TYPE_PAIR_RUNNERS))
def test_coefficients_per_type_pair(engine, timing):
    """mu_s and mu_k read for the contact's own pair of types: every pair different. In
    both timings (each reads them on its own path): without a dashpot and with every slip
    at a step's very end, the exact timing's slips restart at Fmin with nothing of the step
    left (E3, E7), which is the step timing's result."""
    skip_engine(engine)
    traces = runners.TYPE_PAIR_RUNNERS[engine](timing)
    # (1, 1) is the wall's own type on LIGGGHTS (no contact); LAMMPS' grains use all three
    assert set(lc.TYPE_PAIRS) - {(1, 1)} <= set(traces) <= set(lc.TYPE_PAIRS)
    for pair, trace in traces.items():
        w = lc.X * (np.array([1.0, 0, 0]) if 1 in pair else np.array([0, 1.0, 0]))
        lc.compare_type_pair(pair, trace, w)


def _stick_shares(case):
    """The share of each step the contact spent sticking, as pyref's kernel reports it: the
    dashpot's dissipation nu_s |V_s|^2 dt times that share (docs/law.md, Energy). The case's
    wall contact driven step by step (the floor's normal is fixed: D needs no turn)."""
    from pyref.laws import LawParams, tangential_force

    p = LawParams("stick_slip", lc.KN, case.nu_n, lc.KS, case.nu_s, case.mu_s, case.mu_k, case.reset, case.timing)
    D, shares = np.zeros((1, 3)), []
    for seg in case.segments:
        assert seg.delta == lc.DELTA and case.geometry == "wall"  # Fn = 1 throughout
        V = np.array([lc.tangential(case, seg.velocity)])
        for _ in range(seg.steps):
            step = tangential_force(D, V, np.array([1.0]), lc.DT, p, energy=True)
            D = step.spring
            shares.append(step.dissipated_dashpot[0] / (case.nu_s * (V[0] @ V[0]) * lc.DT))
    return np.array(shares)


def _share_expected(name):
    """Worked out by hand: a slip takes no time, so a step that slips inside and sticks again
    stuck all of it; a step that slips at its very end stuck all of it; E4 and E6 slide
    (stick 0) from their slip to the step's end."""
    if name == "slip_inside_step_exact_timing_reset_spring":
        return np.ones(30), 0.0
    if name == "dashpot_keeps_it_sliding_exact_timing":
        return np.r_[np.ones(8), np.zeros(4)], 0.0
    if name == "plastic_flow_reset_total_inside_step_exact_timing":
        theta = (math.sqrt(320.0) - 17.0) / 1.25  # the slip inside step 21 (cases._flow_after_hit)
        return np.r_[np.ones(20), theta], 64 * lc.EPS  # (the root's cancellation: ~20 eps relative)
    if name == "max_explicit_slips_slides_exact_timing":
        theta = lc.max_slips_follow(CASE[name])[0]  # sticks between its 100 slips, then slides
        return np.r_[np.ones(16), theta], 100 * 8 * lc.EPS * (1 + 1 / 4)  # (_max_slips_step's bound / rate)
    raise KeyError(name)


CASE = {c.name: c for c in lc.CASES}


@pytest.mark.parametrize("name", ["slip_inside_step_exact_timing_reset_spring", "dashpot_keeps_it_sliding_exact_timing",
                                  "plastic_flow_reset_total_inside_step_exact_timing",
                                  "max_explicit_slips_slides_exact_timing"])
def test_stick_share_exact_timing(name):
    """The exact timing's share of the step spent sticking (pyref's kernel, which YADE runs;
    it weighs the dashpot's dissipation), against hand-worked values."""
    expected, tol = _share_expected(name)
    got = _stick_shares(CASE[name])
    assert np.all(np.abs(got - expected) <= tol), (name, got, expected)


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_kernel_off_the_tables_units(timing):
    """Two values the table cannot reach (Ks = 1 and mu_s Fn < 2 there), on pyref's kernel
    (and the energy with Ks = 2).
    (a) Ks = 2: a spring of 15/64 plus V dt = 1/64 gives |F_t| = 2 * 16/64 = T = 1/2 at the
    step's end: it slips to Fmin = (2 * 3/8 - 1/2) * 1 = 1/4 and the spring holds Fmin/Ks =
    1/8 (eq. 8; exact: E3-E7 with nothing of the step left). (b) T = 4 (Fn = 8): nu_s |V| =
    1, spring 3 - 1/64: the trial force meets T at the step's end, restarts at Fmin + nu_s|V|
    = 2 + 1 = 3 < T, so it does not slide (E4 needs |F| >= T): exact timing applies 3, step
    timing Fmin = 2; the spring 2 in both."""
    from pyref.laws import LawParams, tangential_force

    V = np.array([[0.25, 0.0, 0.0]])
    p = LawParams("stick_slip", 32.0, 0.0, 2.0, 0.0, 0.5, 0.375, "spring", timing)
    s = tangential_force(np.array([[15 / 64, 0.0, 0.0]]), V, np.array([1.0]), lc.DT, p, energy=True)
    assert s.slipped.all() and np.array_equal(s.force, [[-0.25, 0, 0]]) and np.array_equal(s.spring, [[0.125, 0, 0]])
    # energy with Ks = 2: received -F.V dt, the spring's store Ks(|D|^2 - |D0|^2)/2 given back; no dashpot
    received, stored = 0.25 * 0.25 * lc.DT, 0.5 * 2.0 * (0.125 ** 2 - (15 / 64) ** 2)
    assert s.dissipated_dashpot[0] == 0.0 and s.dissipated_slip[0] == received - stored
    p = LawParams("stick_slip", 32.0, 0.0, 1.0, 4.0, 0.5, 0.375, "spring", timing)
    s = tangential_force(np.array([[3 - 1 / 64, 0.0, 0.0]]), V, np.array([8.0]), lc.DT, p)
    applied = 3.0 if timing == "exact" else 2.0
    assert s.slipped.all() and np.array_equal(s.force, [[-applied, 0, 0]]) and np.array_equal(s.spring, [[2.0, 0, 0]])
