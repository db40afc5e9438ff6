# SPDX-License-Identifier: GPL-2.0-or-later
"""The hard cases of tests/test_stability_engines.py on YADE in the exact slip timing
(issue 13: "the hard-case suite passes in exact mode"), and a drag with hundreds of
slips in one step. Same invariants: every recorded value finite, |Fs| <= mu_s*Fn
(1e-9 relative), Fs = 0 where Fn = 0 (run_checked)."""
import math

import numpy as np
import pytest

from stickslip import scene as scene_mod
from test_stability import make, random_parameter_scene
from test_stability_engines import run_checked


def exact(sc):
    sc.contact.slip_timing = "exact"
    return sc


@pytest.mark.parametrize("ratio,zeta", [(0.01, 0.0), (10.0, 0.0), (0.01, 1.0), (10.0, 1.0)])
def test_runs_at_0_9_of_the_limit_stay_bounded_exact(ratio, zeta, tmp_path):
    """As test_stability_engines: a grain dropped with 10x its static overlap while sliding,
    at 0.9 dt_crit; its speed stays below v0 + sqrt(2 E0/m) with 20 %."""
    kn, m = 1.2e7, 2600 * math.pi * 0.005**2
    ks = ratio * kn
    overlap = 10 * m * 9.81 / kn
    sc = exact(make(kn=kn, ks=ks, nu_n=zeta * 2 * math.sqrt(kn * m), nu_s=zeta * 2 * math.sqrt(ks * m),
                    height=0.005 - overlap, vel=[0.05, 0.0], dt_factor=0.9))
    sc.duration = 4000 * sc.dt
    df = run_checked("yade", sc, tmp_path)
    assert np.hypot(df["g_vx"], df["g_vy"]).max() < 1.2 * (0.05 + math.sqrt(kn * overlap**2 / m))


@pytest.mark.parametrize("angle_deg", [1.0, 20.0])
def test_grazing_impacts_exact(angle_deg, tmp_path):
    a = math.radians(angle_deg)
    sc = exact(make(dim=3, kn=1e5, ks=8e4, nu_n=0.5, nu_s=0.2, rotation=True, height=0.0052,
                    vel=[10 * math.cos(a), 0.0, -10 * math.sin(a)], duration=0.002, dt=1e-6))
    df = run_checked("yade", sc, tmp_path)
    assert df["g_z"].min() > 0
    v2 = df["g_vx"]**2 + df["g_vy"]**2 + df["g_vz"]**2
    assert np.all(v2 <= (100 + 2 * 9.81 * (0.0052 - df["g_z"])) * (1 + 1e-6))


def test_contact_opening_while_sliding_exact(tmp_path):
    sc = exact(make(vel=[0.01, 0.0], imposed=["x"], height=0.005 - 2e-5, nu_n=0.0, duration=0.02, dt=2e-6))
    df = run_checked("yade", sc, tmp_path)
    assert (df["g-floor_fn"].iloc[1:] == 0).any() and df["g-floor_slip"].sum() > 0


def test_randomised_parameter_sets_exact(tmp_path):
    rng = np.random.default_rng(20261123)
    for k in range(6):
        sc = exact(random_parameter_scene(rng))
        sc.duration = 400 * sc.dt
        run_checked("yade", sc, tmp_path / str(k))


def test_hundreds_of_slips_in_one_step_exact(tmp_path):
    """The paper's drag at 0.2 m/s without tangential damping: one step loads the spring by
    Ks*V*dt = 3.84 N/m, some 120 times the force drop 2(mu_s - mu_k)*Fn = 0.032 N/m, so every
    step holds about 120 slips (E7's closed form). Finite, within the cone, and cheap
    per step: the kernel's loop is bounded (100 passes) whatever V*dt is."""
    sc = exact(scene_mod.load("drag", duration=2000 * 2e-6, nu_s=0.0))
    sc.grains[0].velocity[:] = [0.2, 0.0, 0.0][:len(sc.grains[0].velocity)]
    rate = sc.contact.ks * 0.2 * sc.dt
    fn = 2600 * math.pi * 0.002**2 * 9.81
    assert rate / (2 * (sc.contact.mu_s - sc.contact.mu_k) * fn) > 100
    sc.output.every = 1
    from stickslip.adapters import yade as adapter

    df = adapter.run(sc, tmp_path).timeseries
    assert np.isfinite(df.to_numpy(dtype=float)).all()
    ratio = (df["grain-floor_fs"] / df["grain-floor_fn"]).to_numpy()[10:]
    # Every step slips; the end-of-step force lies between Fmin and mu_s*Fn.
    assert (df["grain-floor_slip"].to_numpy()[10:] == 1).all()
    assert ratio.min() >= (2 * sc.contact.mu_k - sc.contact.mu_s) - 1e-9 and ratio.max() <= sc.contact.mu_s + 1e-9
