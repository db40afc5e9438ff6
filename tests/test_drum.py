# SPDX-License-Identifier: GPL-2.0-or-later
"""The turning drum (issue 24): its scene format, its physics on pyref and LIGGGHTS, the
kind that measures its avalanches, and the study command's refusals."""
import copy
import math
import tomllib

import numpy as np
import pandas as pd
import pytest

from stickslip import columns
from stickslip import scene as scene_mod
from stickslip.adapters import liggghts as liggghts_adapter
from stickslip.adapters.text_dumps import read_dump
from stickslip.cli import main
from stickslip.kinds import drum
from pyref import Simulation
from conftest import needs_engine, skip_engine

needs_liggghts = needs_engine("liggghts")
BASE = tomllib.loads(scene_mod.find("drum").read_text())


def drum_data(**changes):
    """cases/drum.toml's data with changes: {"table.key": value} (a list index: "fill.0.count")."""
    data = copy.deepcopy(BASE)
    for path, value in changes.items():
        *head, last = path.split(".")
        node = data
        for h in head:
            node = node[int(h)] if isinstance(node, list) else node[h]
        if value is None:
            node.pop(last, None)
        elif isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return data


# ---------------------------------------------------------------- scene format

@pytest.mark.parametrize("changes, words", [
    ({"ring.0.count": 2}, ["ring[0].count", "at least 3"]),
    ({"ring.0.count": 90}, ["ring[0].count", "at most 80"]),
    ({"ring.0.grain_radius": 0.05}, ["ring[0].grain_radius", "< ring radius"]),
    ({"fill.0.count": 400}, ["fill[0].count", "at most"]),
    ({"fill.0.radius_spread": 0.7}, ["fill[0].radius_spread", "<= 0.5"]),
    ({"fill.0.slope": 75.0}, ["fill[0].slope", "<= 60"]),
    ({"fill.0.colour": 1}, ["fill[0].colour", "unknown key"]),
    ({"gravity_rate": 7.0}, ["gravity_rate", "<= 6.28"]),
    ({"effects.gravity": False}, ["gravity_rate", "effects.gravity = true"]),
    ({"gravity_spinup": {"rate": -0.3}}, ["gravity_spinup.duration", "missing"]),
    ({"gravity_rate": None}, ["gravity_spinup", "gravity_rate"]),
    ({"output.grains": ["q*"]}, ["output.grains", "'q*' matches no grain"]),
    ({"analysis.settle": -1.0}, ["analysis.settle", ">= 0"]),
])
def test_bad_drum_scene_is_one_line_naming_the_key(changes, words):
    with pytest.raises(scene_mod.SceneError) as e:
        scene_mod.parse(drum_data(**changes))
    msg = str(e.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_ring_and_fill_make_a_drum_whose_grains_do_not_overlap():
    sc = scene_mod.load("drum")
    ring = [g for g in sc.grains if g.fixed]
    fill = [g for g in sc.grains if not g.fixed]
    assert len(ring) == BASE["ring"][0]["count"] and len(fill) == BASE["fill"][0]["count"]
    x = np.array([g.position[:2] for g in sc.grains])
    r = np.array([g.radius for g in sc.grains])
    d = np.linalg.norm(x[:, None] - x[None], axis=2) - (r[:, None] + r[None])
    np.fill_diagonal(d, np.inf)
    moving = ~np.array([g.fixed for g in sc.grains])
    assert d[moving].min() > 0  # no grain of the fill touches another or the wall at the start
    spread = BASE["fill"][0]["radius_spread"] * BASE["fill"][0]["grain_radius"]
    assert np.abs(r[moving] - BASE["fill"][0]["grain_radius"]).max() <= spread
    room = BASE["fill"][0]["radius"]
    assert (np.linalg.norm(x[moving], axis=1) + r[moving]).max() <= room
    # the pile starts under a line at fill.slope: its highest grains lie along it
    assert sc.output.grains == [g.name for g in fill]


def test_fixed_grains_stay_put_and_gravity_turns_on_pyref():
    """A short pyref run: the ring does not move or spin although the pile presses on it,
    and the moving grains fall along the gravity of each step."""
    sc = scene_mod.load("drum", duration=0.02, every=100)
    sim = Simulation(sc)
    x0 = sim.x[sim.fixed].copy()
    sim.run()
    assert np.array_equal(sim.x[sim.fixed], x0)
    assert not sim.v[sim.fixed].any() and not sim.w[sim.fixed].any()
    assert np.array_equal(sim.g, sc.gravity_at(sc.steps * sc.dt))


def free_fall(rate, spinup, duration=0.1, dt=1e-4):
    """One grain falling freely under turning gravity."""
    data = {"name": "fall", "dimension": 2, "gravity": [0.0, -9.81], "gravity_rate": rate,
            "gravity_spinup": {"rate": spinup[0], "duration": spinup[1]},
            "effects": {"gravity": True}, "contact": {"kn": 1e5, "ks": 1e5, "mu_s": 0.5, "mu_k": 0.5},
            "time": {"dt": dt, "duration": duration}, "output": {"every": 100, "grains": ["g"]},
            "grain": [{"name": "g", "radius": 0.01, "density": 1000, "position": [0.0, 0.0]}]}
    return scene_mod.parse(data)


def exact_velocity(sc, t):
    """v(t) = integral of g(s) ds, by a quadrature far finer than the run's steps."""
    s = np.linspace(0, t, 200001)
    g = np.array([sc.gravity_at(u)[:2] for u in s])
    return np.trapezoid(g, s, axis=0)


@pytest.mark.parametrize("engine", ["pyref", pytest.param("liggghts", marks=needs_liggghts)])
def test_turning_gravity_is_the_gravity_of_each_step(engine, tmp_path):
    """Velocity Verlet averages the force of a step's two ends (trapezoid rule), so the
    velocity of a free grain under g(t) is off by at most t dt^2 max|g''| / 12 (smooth
    parts) plus dt^2 |g| |rate - spinup rate| / 4 at the kink where the rate changes;
    gravity taken one step late would be off by ~ |g| rate dt t / 2, 1e3 times more here."""
    sc = free_fall(rate=-0.5, spinup=(2.0, 0.05))
    if engine == "pyref":
        df = columns.frame(sc, Simulation(sc).run())
    else:
        df = liggghts_adapter.run(sc, tmp_path).timeseries
    g = 9.81
    bound = sc.duration * sc.dt**2 * g * 2.0**2 / 12 + sc.dt**2 * g * 2.5 / 4 + 1e-12
    late = g * 0.5 * sc.dt * sc.duration / 2
    assert bound < late / 100
    for k in (len(df) // 2, len(df) - 1):
        t = df["t"].iloc[k]
        v = np.array([df["g_vx"].iloc[k], df["g_vy"].iloc[k]])
        assert np.abs(v - exact_velocity(sc, t)).max() <= bound, (t, v, exact_velocity(sc, t))


# ---------------------------------------------------------------- the kind

def test_slope_measures_follow_a_turned_pile():
    """Turning every grain of a pile about the drum's centre by alpha (gravity fixed) turns
    the centroid's angle by exactly alpha, and turning gravity with it leaves both measures
    unchanged: their frames and signs are right. The fit follows the turn only roughly on
    this pile (a lattice's rows are steps on its surface; which grain tops a bin changes
    as it turns): the same sign, within 5 deg."""
    sc = scene_mod.parse(drum_data(**{"fill.0.count": 120, "fill.0.slope": 20.0}))  # its surface: a slope
    names, _ = drum.mobile(sc)
    x0 = np.array([[g.position[0], g.position[1]] for g in sc.grains if not g.fixed])

    def record(alpha, t=0.0):
        a = math.radians(alpha)
        c, s = math.cos(a), math.sin(a)
        xy = x0 @ np.array([[c, s], [-s, c]])  # turned counter-clockwise by alpha
        return pd.DataFrame([{"t": t, **{f"{n}_x": p[0] for n, p in zip(names, xy)},
                              **{f"{n}_y": p[1] for n, p in zip(names, xy)}}])

    turned = pd.concat([record(a) for a in (0.0, 5.0, 10.0)], ignore_index=True)
    com, fit = drum.centroid_angles(sc, turned), drum.slope_angles(sc, turned)
    # gravity_rate < 0 counts slopes rising to +x as positive: turning the pile
    # counter-clockwise steepens it
    assert com[1] - com[0] == pytest.approx(5.0, abs=1e-9)
    assert com[2] - com[0] == pytest.approx(10.0, abs=1e-9)
    assert 5.0 < fit[2] - fit[0] < 15.0
    # the pile and gravity turned together: gravity has turned by gravity_angle(t) at t
    t = 3.0
    together = record(math.degrees(sc.gravity_angle(t)), t)
    assert drum.centroid_angles(sc, together)[0] == pytest.approx(com[0], abs=1e-9)
    assert drum.slope_angles(sc, together)[0] == pytest.approx(fit[0], abs=1e-6)


def test_avalanches_are_found_in_the_kinetic_energy():
    """A made-up record: the slope rises, two energy bursts (one an avalanche that lowers
    the slope by 6 deg, one a slide that lowers it by 0.2 deg), one burst before settle."""
    sc = scene_mod.load("drum")
    scale = drum.energy_scale(sc)
    t = np.arange(0, 20, 0.01)
    theta = 20 + 1.0 * t
    ekin = np.full(len(t), 1e-9 * scale)
    for t0, t1, drop in ((1.995, 2.505, 5.0), (7.995, 8.605, 6.0), (13.995, 14.305, 0.2)):
        on = (t >= t0) & (t <= t1)
        ekin[on] = (1e-3 if drop > 1 else 2e-4) * scale
        theta[t > t1] -= drop
    df = pd.DataFrame({"t": t, "ekin": ekin, **{c: np.zeros(len(t)) for c in columns.SLIP_STATS}})
    s = drum.summarise(sc, df, theta, theta)
    assert s["avalanches"] == 1 and s["slides"] == 1  # the burst at 2 s is before settle = 4 s
    a = s["avalanche_list"][0]
    assert a["theta_start"] == pytest.approx(20 + 7.99 - 5.0, abs=1e-9)
    assert a["theta_stop"] == pytest.approx(20 + 8.61 - 11.0, abs=1e-9)
    assert s["delta_theta_mean_deg"] == pytest.approx(6.0 - 0.62, abs=1e-9)


# ---------------------------------------------------------------- engines, step for step

@needs_liggghts
def test_drum_on_liggghts_is_pyrefs_step_for_step(tmp_path):
    """The drum's first 0.05 s (3125 steps: the fill falls, hits the ring and itself,
    ~300 contacts, rolling, slips, turning gravity) on LIGGGHTS and pyref. Both solve the
    same equations, so they differ by round-off, amplified by the collisions (the pile is
    chaotic: the difference grows ~e-fold every 4 ms, 1e-20 m at the first contacts to
    ~1e-12 m at 0.05 s, and ~1 mm by 0.2 s, where the trajectories part). Any difference
    in the physics shows far above 1e-10 m: lever arms of r instead of r - delta/2 gave
    1.6e-8 m 0.01 s after the first contacts. The slip statistics are counts: equal."""
    sc = scene_mod.load("drum", duration=0.05, every=125)
    dl = liggghts_adapter.run(sc, tmp_path).timeseries
    dp = columns.frame(sc, Simulation(sc).run())
    assert list(dl.columns) == list(dp.columns)
    pos = [c for c in dp.columns if c.endswith(("_x", "_y"))]
    assert np.abs(dl[pos].to_numpy() - dp[pos].to_numpy()).max() < 1e-10
    assert dp["n_slipping"].sum() > 100
    for c in ("n_slipping", "n_slip_above_vd", "n_contacts"):
        assert (dl[c] == dp[c]).all(), c
    assert np.abs(dl["slip_fs_fn_sum"] - dp["slip_fs_fn_sum"]).max() < 1e-9


@needs_liggghts
def test_drum_on_two_mpi_ranks_is_one_ranks(tmp_path):
    """The same 0.05 s on 1 and 2 MPI ranks: the ranks split the drum, so sums run in
    another order; the same round-off bound as against pyref."""
    sc = scene_mod.load("drum", duration=0.05, every=125)
    d1 = liggghts_adapter.run(sc, tmp_path / "one").timeseries
    d2 = liggghts_adapter.run(sc, tmp_path / "two", np_ranks=2).timeseries
    pos = [c for c in d1.columns if c.endswith(("_x", "_y"))]
    assert np.abs(d1[pos].to_numpy() - d2[pos].to_numpy()).max() < 1e-10
    assert (d1["n_slipping"] == d2["n_slipping"]).all()


# ---------------------------------------------------------------- the study's refusals

@pytest.mark.parametrize("args, words", [
    (["--rate", "0.1"], ["--rate 0.1", "(0, 0.0369]", "avalanche regime"]),
    (["--fill", "0.95"], ["--fill 0.95", "[0.2, 0.7]"]),
    (["--duration", "5"], ["--duration 5", "> 9"]),
    (["--only", "history_mu0.99"], ["--only history_mu0.99", "not a run"]),
    (["--colour", "red"], ["unrecognized arguments"]),
])
def test_drum_study_refuses_bad_settings_in_one_line(args, words, tmp_path, capsys):
    assert_refused_in_one_line(["drum-study", *args], words, tmp_path, capsys)


def assert_refused_in_one_line(argv, words, tmp_path, capsys):
    """`stickslip argv --runs --out` exits with status 2 and one line holding every word,
    before any run starts."""
    try:
        code = main([*argv[:1], "--runs", str(tmp_path / "runs"), "--out", str(tmp_path / "out"), *argv[1:]])
    except SystemExit as e:  # argparse's refusal of an unknown option
        code = e.code
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err
    for w in words:
        assert w in err, (w, err)
    assert not (tmp_path / "runs").exists()


# ---------------------------------------------------------------- the study's smoke version

@pytest.mark.long
@needs_liggghts
def test_drum_study_smoke(tmp_path, monkeypatch):
    """The study's code path on the small drum (cases/drum_small.toml: 80 disks), history
    mu = 0.5 against stick-slip 0.5/0.35 (step timing), 20 s each on one LIGGGHTS rank
    (17-21 s each on an idle core). What this size can show:
    - the drum turns and avalanches happen, in both (the spin-up's is not counted);
    - in an avalanche every slipping grain-grain contact carries exactly mu Fn (history)
      and exactly Fmin = (2 mu_k - mu_s) Fn = 0.2 Fn (stick-slip, step timing: the force
      is set to Fmin at each slip, eq. 8), the mechanism behind the study's finding;
    - a study interrupted in its second run keeps the first and, resumed, runs only the
      second; a third call runs nothing and writes the same table.
    What it cannot show: the angles' differences. Each run has one avalanche after its
    settling (history at 10.1 s, stick-slip at 11.2 s; history has a slide at 7.5 s too),
    and avalanches spread by ~4 deg, as much as the differences the full study measures
    (docs/drum.md)."""
    from stickslip.studies import drum_study

    kw = dict(out=tmp_path / "out", out_runs=tmp_path / "runs", rate=0.03, duration=20.0,
              labels=drum_study.SMOKE_LABELS, full=False, ranks=1, progress=False)
    real, calls = drum_study.runner.run_scene, []

    def interrupted(*a, **k):  # Ctrl-C in the second run, once it has written part of its folder
        calls.append(a[0].name)
        if len(calls) == 2:
            a[2].mkdir(parents=True, exist_ok=True)
            (a[2] / "partial").write_text("a run cut short")
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(drum_study.runner, "run_scene", interrupted)
    with pytest.raises(KeyboardInterrupt):
        drum_study.run_study(scene_mod.find("drum_small"), **kw)
    first, second = (label for label, *_ in drum_study.matrix(0.03, full=False) if label in drum_study.SMOKE_LABELS)
    assert (tmp_path / "runs" / first / "slope.csv").is_file() and not (tmp_path / "runs" / second).exists()
    kept = (tmp_path / "runs" / first / "summary.json").stat().st_mtime_ns
    calls.clear()
    monkeypatch.setattr(drum_study.runner, "run_scene", lambda *a, **k: (calls.append(a[0].name), real(*a, **k))[1])
    study = drum_study.run_study(scene_mod.find("drum_small"), **kw).set_index("label")
    assert calls == [f"drum_{second}"]
    assert (tmp_path / "runs" / first / "summary.json").stat().st_mtime_ns == kept
    assert set(study.index) == set(drum_study.SMOKE_LABELS)
    for label in drum_study.SMOKE_LABELS:
        assert study.loc[label, "avalanches"] >= 1, label
    assert study.loc["history_mu0.50", "avalanche_slip_fs_fn"] == pytest.approx(0.5, abs=1e-9)
    assert study.loc["ss_0.50_0.35_step", "avalanche_slip_fs_fn"] == pytest.approx(0.2, abs=1e-9)
    calls.clear()
    again = drum_study.run_study(scene_mod.find("drum_small"), **kw).set_index("label")
    assert calls == []
    pd.testing.assert_frame_equal(again, study)
    for png in ("drum_calibration.png", "drum_traces.png"):
        assert (tmp_path / "out" / png).stat().st_size > 10_000


def test_drum_on_yade_is_pyrefs_in_free_fall(tmp_path):
    """YADE on the drum's first 0.005 s (500 steps; the fill falls freely, turning gravity
    on, no contact yet) against pyref. YADE starts as velocity Verlet (yade_law/README.md,
    "Twin runs": half a kick from v(0)), so positions and velocities must be pyref's to
    round-off: 500 steps of u L each, L = 0.05 m the drum's size, 3e-15 m, and
    dt g u-sized differences in velocity (1e-14 m/s allowed). Before issue 25 YADE took
    v(0) as v(-dt/2), a whole first kick: its positions were n dt^2 g(0)/2 ahead (2.5e-7 m at
    5 ms), which this would catch 1e7 times over; a gravity taken a step late would add
    dt^2/2 times the turns, ~1e-10 m here. After the first contacts differences are amplified
    by the collisions like any (test_drum_on_liggghts_is_pyrefs_step_for_step)."""
    from stickslip.adapters import yade as yade_adapter

    skip_engine("yade")
    sc = scene_mod.load("drum", duration=0.005, every=100)
    dy = yade_adapter.run(sc, tmp_path).timeseries
    dp = columns.frame(sc, Simulation(sc).run())
    for axis in "xy":
        pos = [f"{g}_{axis}" for g in sc.output.grains]
        vel = [f"{g}_v{axis}" for g in sc.output.grains]
        assert np.abs(dy[pos].to_numpy() - dp[pos].to_numpy()).max() < 1e-14, axis
        assert np.abs(dy[vel].to_numpy() - dp[vel].to_numpy()).max() < 1e-14, axis
    # the kinetic energy from those velocities (YADE: the mean of its half-step ones), to twice
    # their relative round-off, 1e-14 m/s against speeds of g t >= 0.0098 m/s after the start
    np.testing.assert_allclose(dy["ekin"], dp["ekin"], rtol=2 * 1e-14 / 0.0098, atol=0)
    assert (dy["n_contacts"] == dp["n_contacts"]).all() and (dy[list(columns.SLIP_STATS)] == 0).all().all()
    fall = 0.5 * 9.81 * 0.005**2  # m: the fall is there (1.2e-4 m), far above round-off
    assert (dp[[f"{g}_y" for g in sc.output.grains]].iloc[0] - dp[[f"{g}_y" for g in sc.output.grains]].iloc[-1]
            ).min() > 0.9 * fall
    ring = [g.name for g in sc.grains if g.fixed]
    assert not any(f"{g}_x" in dy for g in ring)  # (the ring is not recorded; fixed: tested on pyref)


# ---------------------------------------------------------------- across engines, and the map

def test_efolding_time_of_a_made_up_divergence():
    """A distance growing as 1e-20 m e^(t/3 ms) from round-off until it saturates at 1 mm
    (grains gone different ways): the fit over FIT_RANGE gives back the 3 ms."""
    from stickslip.studies.drum_engines import FIT_RANGE, efolding_time

    t = np.arange(0, 0.4, 4e-4)
    d = np.minimum(1e-20 * np.exp(t / 3e-3), 1e-3)
    tau, t0, t1 = efolding_time(t, d)
    assert tau == pytest.approx(3e-3, rel=1e-9)
    assert 1e-20 * math.exp(t0 / 3e-3) > FIT_RANGE[0] and 1e-20 * math.exp(t1 / 3e-3) < FIT_RANGE[1]
    assert math.isnan(efolding_time(t, np.full(len(t), 1e-16))[0])  # nothing grows: no time to give


def test_consistent_mu_inverts_a_made_up_history_curve():
    """History angles rising as 10 + 40 mu deg (standard error 0.5); a stick-slip run at
    22 +- 0.5 deg agrees within two combined errors with mu in 0.3 -+ 2 sqrt(0.5^2 + 0.5^2) / 40;
    one at 5 deg with none."""
    from stickslip.studies import drum_figures

    mus = [0.1, 0.2, 0.3, 0.4, 0.5]
    rows = [{"label": f"history_mu{m:.2f}", "mu_s": m, "mu_k": m, "theta_stop_mean_deg": 10 + 40 * m,
             "theta_stop_se_deg": 0.5} for m in mus]
    rows += [{"label": "ss_a", "mu_s": 0.5, "mu_k": 0.4, "theta_stop_mean_deg": 22.0, "theta_stop_se_deg": 0.5},
             {"label": "ss_b", "mu_s": 0.5, "mu_k": 0.4, "theta_stop_mean_deg": 5.0, "theta_stop_se_deg": 0.5}]
    got = drum_figures.consistent_mu(pd.DataFrame(rows), "theta_stop")
    half = 2 * math.hypot(0.5, 0.5) / 40
    [(lo, hi)] = got["ss_a"]
    assert lo == pytest.approx(0.3 - half, abs=4e-4) and hi == pytest.approx(0.3 + half, abs=4e-4)
    assert got["ss_b"] == []


def test_a_dump_cut_short_is_one_line(tmp_path):
    """A LIGGGHTS dump whose last block lost rows (a run killed while writing) is refused."""
    block = "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n0 1\nITEM: ATOMS id x \n"
    (tmp_path / "a.dump").write_text(block.format(0) + "1 0.5 \n2 0.25 \n" + block.format(10) + "1 0.5 \n")
    with pytest.raises(RuntimeError, match="cut short at step 10"):
        read_dump(tmp_path / "a.dump")
    (tmp_path / "b.dump").write_text(block.format(0) + "1 0.5 \n2 0.25 \n")
    assert read_dump(tmp_path / "b.dump")[0].tolist() == [[1.0, 0.5], [2.0, 0.25]]


@pytest.mark.parametrize("args, words", [
    (["--duration", "5"], ["--duration 5", "> 9"]),
    (["--parts", "everything"], ["--parts", "invalid choice"]),
])
def test_drum_engines_refuses_bad_settings_in_one_line(args, words, tmp_path, capsys):
    assert_refused_in_one_line(["drum-engines", "--engines", "pyref", *args], words, tmp_path, capsys)
