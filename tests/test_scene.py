# SPDX-License-Identifier: GPL-2.0-or-later
"""Malformed scenes are refused with a message naming the key and the allowed range."""
import subprocess
import sys
import tomllib

import numpy as np
import pytest

from stickslip import scene as scene_mod
from stickslip.scene import SceneError, grains, reader

DRAG = scene_mod.find("drag").read_text()


def parse(text):
    return scene_mod.parse(tomllib.loads(text))


def edit(old, new, text=DRAG):
    assert old in text, old
    return text.replace(old, new, 1)


@pytest.mark.parametrize("old,new,words", [
    ("mu_k = 0.45", "mu_k = 0.55", ["contact.mu_k", "[0.25, 0.5]"]),   # mu_k > mu_s
    ("mu_k = 0.45", "mu_k = 0.2", ["contact.mu_k", "[0.25, 0.5]"]),    # mu_k < mu_s/2
    ("ks = 9.6e6", "ks = -9.6e6", ["contact.ks", "> 0"]),
    ("kn = 1.2e7", "kn = 0", ["contact.kn", "> 0"]),
    ("nu_n = 41.38", "nu_n = -1", ["contact.nu_n", ">= 0"]),
    ("density = 2600", "density = -2600", ["grain[0].density", "> 0"]),
    ("radius = 0.002", "radius = 0", ["grain[0].radius", "> 0"]),
    ("\ndt = 2e-6", "\ndt = 1e-3", ["time.dt", "stability limit", "<="]),
    ("every = 1", "every = 1\ncolour = 3", ["output.colour", "unknown key"]),
    ("law = \"stick_slip\"", "law = \"sticky\"", ["contact.law", "stick_slip"]),
    ("position = [0.0, 0.0019999733]", "position = [0.0, 0.0019999733, 0.0]", ["grain[0].position", "2 finite numbers"]),
    ("dimension = 2", "dimension = 4", ["dimension", "2", "3"]),
    ("[time]\n", "[time]\nfoo = 1\n", ["time.foo", "unknown key"]),
    ("\ndt = 2e-6\n", "\n", ["time.dt", "missing"]),
    ("imposed = [\"x\"]", "imposed = [\"q\"]", ["grain[0].imposed"]),
    ("contacts = [[\"grain\", \"floor\"]]", "contacts = [[\"grain\", \"roof\"]]", ["output.contacts"]),
    ("gravity = true", "gravity = false\nmagnetism = true", ["effects.magnetism", "unknown key"]),
    ("normal = [0.0, 1.0]", "normal = [0.0, 1.0]\nvelocity = [1.0, 0.0]", ["moving_walls"]),
    # drag has rotation off: a spinning grain needs it; in 2D the spin is one number (about z)
    ("imposed = [\"x\"]", "imposed = [\"x\"]\nangular_velocity = 5.0", ["grain[0].angular_velocity", "rotation"]),
    # issue 15 section 3: wrong types and shapes, [analysis] checked at load
    ("dimension = 2", "dimension = 2.0", ["dimension", "integer 2"]),
    ("grains = [\"grain\"]", "grains = 5", ["output.grains", "expected a list"]),
    ("every = 1", "every = 1.5", ["output.every", "whole number"]),
    ("every = 1", "every = 0", ["output.every", "[1, 2147483647]"]),
    ("every = 1", "every = 2147483648", ["output.every", "[1, 2147483647]"]),  # LIGGGHTS: a 32-bit int
    ("grain = \"grain\"\n", "grain = \"grian\"\n", ["analysis.grain", "grain name"]),
    ("kind = \"drag\"", "kind = \"drag\"\ncolour = 1", ["analysis.colour", "unknown key"]),
    ("kind = \"drag\"", "kind = \"drag\"\nwall = \"floor\"", ["analysis.wall", "unknown key"]),
    ("contact = [\"grain\", \"floor\"]", "contact = [\"grain\", \"flor\"]", ["analysis.contact", "recorded"]),
    ("name = \"drag\"", "name = \"drag\"\ncolour = 1", ["colour", "unknown key"]),
    ("name = \"drag\"", "name = \"../../x\"", ["name = '../../x'", "letters, digits"]),
    ("name = \"drag\"", "name = 5", ["name", "expected a string"]),
    ("[effects]", "effects = [1, 2]\n[other]", ["effects", "expected a table"]),
    ("kn = 1.2e7", "kn = \"1.2e7\"", ["contact.kn", "finite number"]),
    ("kn = 1.2e7", "kn = nan", ["contact.kn", "finite number"]),
    ("kn = 1.2e7", "kn = 1e300", ["contact.kn", "|x| <= 1e+100"]),
    ("radius = 0.002", "radius = 1e-60", ["grain[0].radius", "mass", "[1e-100, 1e+100]"]),
    ("density = 2600", "density = true", ["grain[0].density", "finite number"]),
    ("position = [0.0, 0.0019999733]", "position = [0.0, inf]", ["grain[0].position", "finite numbers"]),
    ("\nduration = 5e-3", "\nduration = 1e9", ["time.duration / time.dt", "<= 1e+10"]),
    ("\ndt = 2e-6", "\ndt = 1e-300", ["time.duration / time.dt", "<= 1e+10"]),
    ("\ndt = 2e-6", "\ndt = 5e-324", ["time.duration / time.dt = inf"]),
])
def test_bad_scene_names_key_and_range(old, new, words):
    with pytest.raises(SceneError) as e:
        parse(edit(old, new))
    msg = str(e.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_angular_velocity_is_one_number_in_2d_and_needs_rotation():
    spinning = edit("rotation = false", "rotation = true")
    sc = parse(edit("imposed = [\"x\"]", "imposed = [\"x\"]\nangular_velocity = 5.0", spinning))
    assert list(sc.grains[0].angular_velocity) == [0.0, 0.0, 5.0]
    with pytest.raises(SceneError, match=r"grain\[0\]\.angular_velocity: expected a finite number"):
        parse(edit("imposed = [\"x\"]", "imposed = [\"x\"]\nangular_velocity = [0.0, 5.0]", spinning))


def test_shipped_cases_are_valid():
    for name in ("drag", "tray", "tilt"):
        sc = scene_mod.load(name)
        assert sc.dt <= sc.critical_dt()


def test_critical_dt_is_the_leapfrog_limit_of_one_contact():
    # Undamped grain on a wall: w = sqrt(kn/m), oscillator limit 2/w, impact limit pi/(5 w).
    sc = scene_mod.load("drag", effect_normal_damping=False, effect_tangential_damping=False, kn=1e6, ks=1e5)
    m = sc.grain_mass(sc.grains[0])
    w = (1e6 / m) ** 0.5
    limits = scene_mod.stability_limits(sc)
    assert limits["normal"] == pytest.approx(2 / w, rel=1e-12)
    assert limits["tangential"] == pytest.approx(2 / (1e5 / m) ** 0.5, rel=1e-12)
    assert sc.critical_dt() == pytest.approx(3.141592653589793 / w / 5, rel=1e-12)


def test_cli_bad_arguments_exit_2_with_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(edit("mu_k = 0.45", "mu_k = 0.6"))
    for args in (["run", str(bad)], ["run", "nosuchcase"], ["run", "drag", "--dt", "-1"],
                 ["run", "drag", "--engine", "ansys"], ["run", "drag", "--dt", "1"]):
        p = subprocess.run([sys.executable, "-m", "stickslip.cli", *args], capture_output=True, text=True,
                           cwd=tmp_path, env={"PYTHONPATH": str(scene_mod.CASES_DIR.parent), "PATH": "/usr/bin"})
        assert p.returncode == 2, (args, p.stderr)
        assert len(p.stderr.strip().splitlines()) == 1, p.stderr
        assert "Traceback" not in p.stderr


def test_cli_run_writes_timeseries_and_summary(tmp_path):
    import json

    import pandas as pd

    out = tmp_path / "o"
    p = subprocess.run([sys.executable, "-m", "stickslip.cli", "run", "drag", "--quiet", "--out", str(out)],
                       capture_output=True, text=True, env={"PYTHONPATH": str(scene_mod.CASES_DIR.parent),
                                                           "PATH": "/usr/bin"})
    assert p.returncode == 0, p.stderr
    s = json.loads((out / "summary.json").read_text())
    for k in ("fs_fn_max", "fs_fn_min", "fs_fn_mean", "slip_count", "slip_period_s",
              "engine", "law", "dt_s", "steps", "wall_time_s"):
        assert k in s
    df = pd.read_csv(out / "timeseries.csv")
    assert len(df) == s["steps"] + 1
    assert {"t", "grain_x", "grain_vy", "grain-floor_fn", "grain-floor_fs", "grain-floor_slip"} <= set(df.columns)


def test_start_overlap_limit_is_max_start_overlap():
    """A grain may start overlapping a wall or a grain by at most MAX_START_OVERLAP of the
    (smaller) radius: just inside the limit loads, just outside is refused; a centre on or
    behind a wall, and two grains at one centre, are refused with the names."""
    r, lim = 0.002, scene_mod.MAX_START_OVERLAP
    for overlap, ok in ((0.99 * lim, True), (1.01 * lim, False), (1.0, False), (1.5, False), (3.0, False)):
        text = edit("position = [0.0, 0.0019999733]", f"position = [0.0, {r * (1 - overlap)!r}]")
        if ok:
            parse(text)
            continue
        with pytest.raises(SceneError) as e:
            parse(text)
        where = "deep inside" if overlap < 1 else "behind"
        assert f"grain 'grain' starts {where} wall 'floor'" in str(e.value), str(e.value)
        assert f"at most {lim:g} of its radius" in str(e.value)
    twin = "\n[[grain]]\nname = \"twin\"\nradius = 0.002\ndensity = 2600\nposition = [{x}, 0.0019999733]\n"
    for gap, ok in ((2 * r * (1 - 0.99 * lim / 2), True), (2 * r - 1.01 * lim * r, False), (r, False), (0.0, False)):
        text = DRAG + twin.format(x=repr(gap))
        if ok:
            parse(text)
            continue
        with pytest.raises(SceneError, match=r"grains 'grain' and 'twin' start overlapping by .* at most 0.1 of the smaller"):
            parse(text)


def test_near_pairs_finds_every_touching_pair_without_a_quadratic_search():
    """grains.near_pairs against all pairs, on grains whose radii span 1:100; and the
    candidates it returns stay proportional to the grains when one big grain sits among
    many small ones (a search radius set by the big grain returned ~1000 per grain)."""
    rng = np.random.default_rng(3)
    for dim in (2, 3):
        n = 400
        x = rng.uniform(0, 0.05, (n, dim))
        r = 10 ** rng.uniform(-4, -2, n)
        a, b = grains.near_pairs(x, r)
        found = {(min(i, j), max(i, j)) for i, j in zip(a, b)}
        i, j = np.triu_indices(n, 1)
        touching = np.linalg.norm(x[i] - x[j], axis=1) < r[i] + r[j]
        assert {(p, q) for p, q in zip(i[touching], j[touching])} <= found
        assert touching.sum() > 20  # the check has something to find
    small = np.stack(np.meshgrid(np.arange(200), np.arange(200)), -1).reshape(-1, 2) * 2.1e-4
    x = np.vstack([small, [[-0.01, -0.01]]])
    r = np.r_[np.full(len(small), 1e-4), 2e-3]
    a, _ = grains.near_pairs(x, r)
    assert len(a) < 5 * len(x), len(a)


def test_sizes_are_refused_before_any_grain_is_made(monkeypatch):
    """Steps, grains, grain-steps: refused from the numbers alone (a huge lattice used to be
    built first: 10^6 grains took 22 s and 0.9 GB); recorded values likewise, by rule."""
    monkeypatch.setattr(reader, "lattice", lambda *a: pytest.fail("a lattice was built"))
    lattice = "\n[[lattice]]\norigin = [0.0, 1.0]\ncounts = [{n}, {n}]\nradius = 1e-4\ndensity = 2600\n"
    side = int(reader.MAX_GRAINS ** 0.5) + 1
    with pytest.raises(SceneError, match=r"lattice\[0\]\.counts: .* at most 1e\+07"):
        parse(DRAG + lattice.format(n=side))
    with pytest.raises(SceneError, match=r"at most 1e\+07 per scene"):
        parse(DRAG + lattice.format(n=side - 1) + lattice.format(n=100))
    n = 1000  # 10^6 grains, within the limit; 2e7 steps make 2e13 grain-steps
    with pytest.raises(SceneError, match=r"time.duration / time.dt x grains = .* grain-steps; at most 1e\+13"):
        parse(edit("duration = 5e-3", f"duration = {2e-6 * 2 * reader.MAX_GRAIN_STEPS / n**2}",
                   DRAG + lattice.format(n=n)))


def test_recorded_values_are_bounded():
    """1e9 values (rows x columns) of time series at most; drag records 10 columns."""
    steps = 2 * reader.MAX_RECORDED // 10
    with pytest.raises(SceneError, match=r"output.every = 1: the time series would hold 2e\+09 values"):
        parse(edit("duration = 5e-3", f"duration = {steps * 2e-6!r}"))
    parse(edit("every = 1", "every = 4", edit("duration = 5e-3", f"duration = {steps * 2e-6!r}")))


BOX = """
name = "box"
dimension = 3
[contact]
kn = 10.0
ks = 8.0
mu_s = 0.5
mu_k = 0.45
[time]
dt = 1e-5
duration = {duration}
[output]
every = 100
[[lattice]]
origin = [0.0, 0.0, 0.0]
counts = [20, 20, 20]
radius = 0.001
density = 2600
"""


class _Standin:
    """An engine that records what the user had been told when it started, then stops
    as a user would (Ctrl-C)."""
    NAME = "standin"
    told = None

    @staticmethod
    def available():
        return None

    @classmethod
    def run(cls, scene, out_dir, progress=None):
        cls.told = cls.capsys.readouterr().err
        raise KeyboardInterrupt


@pytest.mark.parametrize("duration,announced", [(0.2, True), (0.1, False)])
def test_big_run_is_announced_before_it_starts(duration, announced, monkeypatch, tmp_path, capsys):
    """Over runner.ANNOUNCE_GRAIN_STEPS (1e8) the size of the run is said before the engine
    starts: 8000 grains x 20 000 steps = 1.6e8 is announced, x 10 000 steps = 8e7 is not."""
    from stickslip import adapters, cli, runner

    assert runner.ANNOUNCE_GRAIN_STEPS == 1e8
    _Standin.capsys = capsys
    monkeypatch.setattr(adapters, "get", lambda name: _Standin)
    path = tmp_path / "box.toml"
    path.write_text(BOX.format(duration=duration))
    status = cli.main(["run", str(path), "--quiet", "--out", str(tmp_path / "o")])
    assert status == 130 and capsys.readouterr().err == "stickslip: interrupted\n"
    steps = round(duration / 1e-5)
    line = (f"stickslip: box on pyref: {steps:,} steps x 8,000 grains = {steps * 8000:.2g} grain-steps; "
            f"time series {steps // 100 + 1:,} rows x 1 columns\n")
    assert _Standin.told == (line if announced else "")


def test_non_finite_run_is_one_line_and_status_1(monkeypatch, tmp_path, capsys):
    """pyref raises FloatingPointError at the first non-finite position or velocity; the
    runner makes it one line, exit status 1, and no summary is written."""
    from pyref import Simulation
    from stickslip import cli

    step = Simulation.step

    def diverging(self):
        step(self)
        if self.step_no == 50:
            self.v[0, 1] = np.inf

    monkeypatch.setattr(Simulation, "step", diverging)
    status = cli.main(["run", "drag", "--duration", "2e-4", "--quiet", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert status == 1
    assert err == "stickslip: error: pyref: non-finite position or velocity at step 50 (t = 0.0001 s)\n"
    assert not (tmp_path / "o" / "summary.json").exists()


def test_non_finite_time_series_is_one_line_and_status_1(monkeypatch, tmp_path, capsys):
    """An engine that returns NaN in its time series (LIGGGHTS and YADE did, exit 0): the
    runner checks every column, says which and when, exit status 1."""
    import pandas as pd

    from stickslip import adapters, cli, columns
    from stickslip.adapters import RunResult

    class NaNEngine:
        NAME = "nan"

        @staticmethod
        def available():
            return None

        @staticmethod
        def run(scene, out_dir, progress=None):
            names = columns.names(scene)
            df = pd.DataFrame({c: np.zeros(11) for c in names})
            df["t"] = np.arange(11) * scene.dt
            df.loc[7, "grain-floor_fn"] = np.nan
            return RunResult(df, 10, 0.0)

    monkeypatch.setattr(adapters, "get", lambda name: NaNEngine)
    status = cli.main(["run", "drag", "--duration", "2e-5", "--quiet", "--out", str(tmp_path / "o")])
    assert status == 1
    assert capsys.readouterr().err == "stickslip: error: pyref: non-finite grain-floor_fn at t = 1.4e-05 s (the run diverged)\n"
    assert not (tmp_path / "o" / "summary.json").exists()


def test_a_fault_of_ours_is_one_line_and_status_1(monkeypatch, tmp_path, capsys):
    """Anything unforeseen (here a ZeroDivisionError in the runner) is one line naming the
    error, exit status 1; STICKSLIP_TRACEBACK=1 lets the traceback through."""
    from stickslip import cli, runner

    def fault(*a, **k):
        return 1 / 0

    monkeypatch.setattr(runner, "run_scene", fault)
    argv = ["run", "drag", "--quiet", "--out", str(tmp_path / "o")]
    assert cli.main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith("stickslip: error: internal error (ZeroDivisionError: division by zero)") and \
        err.count("\n") == 1, err
    monkeypatch.setenv("STICKSLIP_TRACEBACK", "1")
    with pytest.raises(ZeroDivisionError):
        cli.main(argv)
