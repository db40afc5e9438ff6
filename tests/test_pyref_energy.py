# SPDX-License-Identifier: GPL-2.0-or-later
"""The friction law never adds energy, and the energy books balance."""
import numpy as np
import pytest

from stickslip import scene as scene_mod
from conftest import run_pyref


def balance(case, **kw):
    sc = scene_mod.load(case, **kw)
    df, sim = run_pyref(sc, energy=True)
    total = df.e_kin + df.e_elastic + df.e_dissipated - df.w_gravity - df.w_drive
    err = float((total - total.iloc[0]).abs().max())
    scale = float(max(df.e_dissipated.abs().max(), df.w_gravity.abs().max(), df.w_drive.abs().max(),
                      df.e_kin.max()))
    return err / scale, sc, df


@pytest.mark.parametrize("case,kw", [
    ("drag", {}),
    ("tray", {"duration": 0.05}),
    ("tilt", {"duration": 0.05}),
    ("tray", {"duration": 0.05, "law": "visco_elastic"}),
    ("tray", {"duration": 0.05, "law": "coulomb"}),
])
def test_energy_balance_converges_first_order(case, kw):
    """Kinetic + elastic + dissipated = work of gravity and drives, up to the time
    discretisation. The laws book dissipation with the end-of-step force while the
    integrator moves grains with the trapezoid of two forces, a first-order mismatch:
    halving dt must halve the imbalance (ratio 2, accepted 1.6-2.6). For the smooth
    laws it must also stay below omega*dt = 2*dt/dt_crit (the phase error per step of
    the stiffest contact), Coulomb's jumping force is exempt from that bound."""
    e1, sc, _ = balance(case, **kw)
    e2, _, _ = balance(case, dt=sc.dt / 2, **kw)
    if e1 > 1e-9:
        assert 1.6 < e1 / e2 < 2.6, (e1, e2)
    if sc.contact.law != "coulomb":
        assert e1 <= 2 * sc.dt / sc.critical_dt(), e1


@pytest.mark.parametrize("case,kw", [("drag", {}), ("tray", {"duration": 0.05}), ("tilt", {"duration": 0.05}),
                                     ("drag", {"reset": "total"})])
def test_friction_never_adds_energy(case, kw):
    """Per contact and per step, the tangential law takes energy out or stores it:
    work received - increase of spring energy >= 0 (round-off: 1e-12 of the step's work)."""
    sc = scene_mod.load(case, **kw)
    from pyref import Simulation

    sim = Simulation(sc, record=False, energy=True)
    worst, booked = 0.0, 0
    for _ in range(min(sc.steps, 4000)):
        sim.step()
        e_t = sim.last_e_t
        if len(e_t):
            worst = min(worst, float(e_t.min()))
            booked += 1
    assert booked > 0, "no step booked the law's energy: the check would be empty"
    assert worst >= -1e-18, worst
