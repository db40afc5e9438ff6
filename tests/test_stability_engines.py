"""Hard cases on the engines (issue 5): the scenes of tests/test_stability.py that a
scene file can express, run through the LIGGGHTS and YADE adapters.

Invariants checked on every step's row (every = 1): all values finite, |Fs| <= mu_s*Fn
(1e-9 relative: the engines' records pass through text dumps with 17 digits, and the
threshold test itself is exact), Fs = 0 where Fn = 0.
"""
import math

import numpy as np
import pytest

from stickslip import adapters
from test_stability import make

ENGINES = ["liggghts", "yade"]


def engine_or_skip(name):
    reason = adapters.get(name).available()
    if reason is not None:
        pytest.skip(f"{name}: {reason}")
    return adapters.get(name)


def run_checked(engine, sc, tmp_path):
    sc.output.every = 1
    sc.output.grains = ["g"]
    sc.output.contacts = [["g", "floor"]]
    df = engine_or_skip(engine).run(sc, tmp_path).timeseries
    assert np.isfinite(df.to_numpy(dtype=float)).all()
    fn, fs = df["g-floor_fn"].to_numpy(), df["g-floor_fs"].to_numpy()
    mu_s = sc.contact.mu_s
    assert np.all(fs <= mu_s * fn * (1 + 1e-9) + 1e-300)
    assert np.all(fs[fn == 0] == 0)
    return df


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("ratio,zeta", [(0.01, 0.0), (10.0, 0.0), (0.01, 1.0), (10.0, 1.0)])
def test_runs_at_0_9_of_the_limit_stay_bounded(engine, ratio, zeta, tmp_path):
    """As in test_stability: a grain dropped with 10x its static overlap while sliding,
    at 0.9*dt_crit, at the corners of Ks/Kn in [0.01, 10] x damping in [0, critical];
    its speed stays below v0 + sqrt(2 E0/m) with 20 % for the impacts' restitution."""
    kn, m = 1.2e7, 2600 * math.pi * 0.005**2
    ks = ratio * kn
    overlap = 10 * m * 9.81 / kn
    sc = make(kn=kn, ks=ks, nu_n=zeta * 2 * math.sqrt(kn * m), nu_s=zeta * 2 * math.sqrt(ks * m),
              height=0.005 - overlap, vel=[0.05, 0.0], dt_factor=0.9)
    sc.duration = 4000 * sc.dt
    df = run_checked(engine, sc, tmp_path)
    v_bound = 1.2 * (0.05 + math.sqrt(kn * overlap**2 / m))
    assert np.hypot(df["g_vx"], df["g_vy"]).max() < v_bound


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("mu_k,mean", [(0.5, 0.5), (0.25, 0.25)])
def test_plain_slider_and_zero_fmin(engine, mu_k, mean, tmp_path):
    """mu_k = mu_s holds mu_s*Fn while sliding; mu_k = mu_s/2 gives Fmin = 0 and a mean of
    mu_s/2 over whole saw-tooth periods (1 %: the dashpot's share)."""
    sc = make(dim=2, vel=[1e-4, 0.0], imposed=["x"], mu_k=mu_k, dt=2e-6, duration=0.01)
    df = run_checked(engine, sc, tmp_path)
    slips = np.nonzero(df["g-floor_slip"].to_numpy())[0]
    assert len(slips) >= 5
    ratio = (df["g-floor_fs"] / df["g-floor_fn"]).to_numpy()
    window = ratio[slips[0] + 1: slips[-1] + 1]
    assert window.min() >= 2 * mu_k - 0.5 - 1e-9
    assert window.mean() == pytest.approx(mean, rel=0.01)


@pytest.mark.parametrize("engine", ENGINES)
def test_contact_opening_while_sliding(engine, tmp_path):
    """A grain bouncing while dragged: the contact opens and closes; Fs = 0 whenever
    Fn = 0 (checked in run_checked) and the contact did open."""
    sc = make(vel=[0.01, 0.0], imposed=["x"], height=0.005 - 2e-5, nu_n=0.0, duration=0.02, dt=2e-6)
    df = run_checked(engine, sc, tmp_path)
    assert (df["g-floor_fn"].iloc[1:] == 0).any() and df["g-floor_slip"].sum() > 0


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("angle_deg", [1.0, 20.0])
def test_grazing_impacts_at_high_speed(engine, angle_deg, tmp_path):
    """A sphere hitting the floor at 10 m/s at a grazing angle, rotation on: never through
    the floor, and its speed never above what the start speed and the fall allow,
    v^2 <= v0^2 + 2 g (z0 - z) (the contact is dissipative; 1e-6 for the impact's
    numerical restitution at w_n*dt = 0.009)."""
    a = math.radians(angle_deg)
    sc = make(dim=3, kn=1e5, ks=8e4, nu_n=0.5, nu_s=0.2, rotation=True, height=0.0052,
              vel=[10 * math.cos(a), 0.0, -10 * math.sin(a)], duration=0.002, dt=1e-6)
    df = run_checked(engine, sc, tmp_path)
    assert df["g_z"].min() > 0
    v2 = df["g_vx"]**2 + df["g_vy"]**2 + df["g_vz"]**2
    assert np.all(v2 <= (100 + 2 * 9.81 * (0.0052 - df["g_z"])) * (1 + 1e-6))


@pytest.mark.parametrize("engine", ENGINES)
def test_randomised_parameter_sets(engine, tmp_path):
    """8 seeded random parameter sets (the generator of test_stability): every step finite
    and |Fs| <= mu_s*Fn."""
    rng = np.random.default_rng(20261122)
    for k in range(8):
        dim = int(rng.choice([2, 3]))
        kn = 10 ** rng.uniform(4, 7)
        ks = kn * 10 ** rng.uniform(-2, 1)
        r = 0.005
        m = 2600 * (math.pi * r**2 if dim == 2 else 4 / 3 * math.pi * r**3)
        mu_s = rng.uniform(0.1, 1.0)
        mu_k = rng.uniform(mu_s / 2, mu_s)
        zeta_n, zeta_s = rng.uniform(0, 1, 2)
        speed = 10 ** rng.uniform(-5, 0)
        vel = [speed, 0.0] if dim == 2 else [speed, 0.0, 0.0]
        sc = make(dim=dim, kn=kn, ks=ks, nu_n=zeta_n * 2 * math.sqrt(kn * m),
                  nu_s=zeta_s * 2 * math.sqrt(ks * m), mu_s=mu_s, mu_k=mu_k,
                  reset=str(rng.choice(["spring", "total"])), rotation=bool(rng.integers(2)),
                  vel=vel, height=r - 3 * m * 9.81 / kn, dt_factor=rng.uniform(0.1, 0.9))
        sc.duration = 400 * sc.dt
        run_checked(engine, sc, tmp_path / str(k))
