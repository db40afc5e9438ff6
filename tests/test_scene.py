"""Malformed scenes are refused with a message naming the key and the allowed range."""
import subprocess
import sys
import tomllib

import pytest

from stickslip import scene as scene_mod
from stickslip.scene import SceneError

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
