# SPDX-License-Identifier: GPL-2.0-or-later
"""pyref's kernel for the paper's Table 1 laws other than stick-slip (Coulomb, visco-plastic,
visco-elastic) and the energy it reports, one step at a time with values worked out by
hand (exact in binary). pyref and YADE run this kernel; LIGGGHTS and LAMMPS have only
stick-slip. Cost: < 0.1 s."""
import numpy as np
import pytest

from pyref.laws import LawParams, tangential_force

DT = 1.0 / 16
# three contacts: sliding along +x, along -y with twice the normal force, at rest
V = np.array([[0.25, 0.0, 0.0], [0.0, -0.5, 0.0], [0.0, 0.0, 0.0]])
FN = np.array([1.0, 2.0, 1.0])
D0 = np.array([[0.125, 0.0, 0.0], [0.0, 0.0625, 0.0], [0.0, 0.0, 0.0]])  # (any spring: not used)


def params(law, **kw):
    base = dict(law=law, kn=32.0, nu_n=0.0, ks=1.0, nu_s=0.5, mu_s=0.5, mu_k=0.375)
    base.update(kw)
    return LawParams(**base)


def test_coulomb_opposes_the_sliding_direction_with_mu_k_fn():
    """Table 1: F = -mu_k Fn V/|V| (0 at rest); the spring is kept, nothing counts as a slip
    step; all the work -F.V dt is the slip's, none the dashpot's."""
    s = tangential_force(D0, V, FN, DT, params("coulomb"), energy=True)
    assert np.array_equal(s.force, [[-0.375, 0, 0], [0, 0.75, 0], [0, 0, 0]])
    assert np.array_equal(s.spring, D0) and s.slipped.dtype == bool and not s.slipped.any()
    work = np.array([0.375 * 0.25, 0.75 * 0.5, 0.0]) * DT  # -F.V dt
    assert np.array_equal(s.dissipated_slip, work) and np.array_equal(s.dissipated_dashpot, np.zeros(3))


def test_visco_plastic_is_the_smaller_of_the_dashpot_and_mu_k_fn():
    """Table 1: F = -min(nu_s |V|, mu_k Fn) V/|V|: 0.5 * 0.25 = 0.125 < 0.375 (dashpot),
    0.5 * 0.5 = 0.25 < 0.75; with nu_s = 2: 0.5 > 0.375 and 1.0 > 0.75 (capped). Its work
    is booked as the dashpot's."""
    s = tangential_force(D0, V, FN, DT, params("visco_plastic"), energy=True)
    assert np.array_equal(s.force, [[-0.125, 0, 0], [0, 0.25, 0], [0, 0, 0]])
    work = np.array([0.125 * 0.25, 0.25 * 0.5, 0.0]) * DT
    assert np.array_equal(s.dissipated_dashpot, work) and np.array_equal(s.dissipated_slip, np.zeros(3))
    assert np.array_equal(s.spring, D0) and not s.slipped.any()
    capped = tangential_force(D0, V, FN, DT, params("visco_plastic", nu_s=2.0))
    assert np.array_equal(capped.force, [[-0.375, 0, 0], [0, 0.75, 0], [0, 0, 0]])
    # energy only when asked (both classic laws)
    assert capped.dissipated_dashpot is None and capped.dissipated_slip is None
    plain = tangential_force(D0, V, FN, DT, params("coulomb"))
    assert plain.dissipated_dashpot is None and plain.dissipated_slip is None


def test_visco_elastic_slips_at_mu_k_fn_and_stays_there():
    """Table 1's visco-elastic law: the spring law with one coefficient mu = mu_k as threshold
    and level (mu_s is not its). No dashpot: spring 0.125 + 0.25/16 = 0.140625 along x on
    contact 1, below 0.375: sticks; contact 2's spring 0.0625 - 0.5/16 = 0.03125 along y,
    sticks; with a spring at 0.4 (between mu_k Fn = 0.375 and mu_s Fn = 0.5) it slips to
    mu_k Fn = 0.375 exactly, where stick-slip would stick."""
    p = params("visco_elastic", nu_s=0.0)
    s = tangential_force(D0, V, FN, DT, p)
    assert np.array_equal(s.force, [[-0.140625, 0, 0], [0, -0.03125, 0], [0, 0, 0]]) and not s.slipped.any()
    D = np.array([[0.375, 0.0, 0.0]])  # + 0.25/16 = 0.390625 > 0.375
    s = tangential_force(D, V[:1], FN[:1], DT, p)
    assert s.slipped.all() and np.array_equal(s.force, [[-0.375, 0, 0]]) and np.array_equal(s.spring, [[0.375, 0, 0]])
    s = tangential_force(D, V[:1], FN[:1], DT, params("stick_slip", nu_s=0.0))
    assert not s.slipped.any() and np.array_equal(s.force, [[-0.390625, 0, 0]])


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_stick_slip_energy_books_a_sticking_and_a_slipping_step(timing):
    """docs/law.md, Energy: the contact received -F.V dt, its spring stored Ks(|D|^2 - |D0|^2)/2,
    the rest was dissipated; the dashpot took nu_s |V|^2 dt times the share of the step it
    stuck, the slips the rest. Contact 1 sticks: spring 0.125 -> 0.140625, trial force
    0.140625 + nu_s V = 0.265625 < mu_s Fn = 0.5: all the loss is the dashpot's. Contact 2
    (Fn = 2, T = 1, Fmin = 0.5) starts at 0.71875 + 0.25 = 0.96875 and its trial force
    reaches T exactly at the step's end (spring 0.75): it slips, spring reset to Fmin. Step
    timing: force Fmin = 0.5, the step counts as slipped (dashpot share 0). Exact timing:
    the slip at theta = 1 restarts the trial force at Fmin + nu_s |V| = 0.75 with nothing
    of the step left (E3, E7), applied 0.75; it stuck all the step (share 1)."""
    p = params("stick_slip", slip_timing=timing)
    D = np.array([[0.125, 0.0, 0.0], [0.0, -0.71875, 0.0]])
    s = tangential_force(D, V[:2], FN[:2], DT, p, energy=True)
    f2, share2 = (0.5, 0.0) if timing == "step" else (0.75, 1.0)
    assert np.array_equal(s.slipped, [False, True])
    assert np.array_equal(s.force, [[-0.265625, 0, 0], [0, f2, 0]])
    assert np.array_equal(s.spring, [[0.140625, 0, 0], [0, -0.5, 0]])
    received = np.array([0.265625 * 0.25, f2 * 0.5]) * DT
    stored = 0.5 * np.array([0.140625 ** 2 - 0.125 ** 2, 0.5 ** 2 - 0.71875 ** 2])
    dashpot = 0.5 * np.array([0.25 ** 2, 0.5 ** 2 * share2]) * DT
    # (every value here is a short binary fraction: the sums are exact)
    assert np.array_equal(s.dissipated_dashpot, dashpot)
    assert np.array_equal(s.dissipated_slip, received - stored - dashpot)
