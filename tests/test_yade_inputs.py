# SPDX-License-Identifier: GPL-2.0-or-later
"""Bad input to the YADE law is one clear line (issue 15 §3): every argument of
stickslip_material / stickslip_engines is checked (ValueError naming it and what is
allowed), numpy scalars are numbers, and a run whose values go non-finite stops with a
message naming the body or contact and the iteration, also through run_scene.py (one
`ERROR` line, non-zero exit)."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LAW = ROOT / "yade_law"
from conftest import needs_engine  # noqa: E402

pytestmark = needs_engine("yade")

ARGS = """
import json, sys, numpy as np
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material
from yade import O, NewtonIntegrator, RotationEngine, Vector3, utils
ok = dict(ks=8e3, nu_s=0.1, mu_s=0.5, mu_k=0.45)
bad_engines = {
    "ks_str": {"ks": "8e3"}, "ks_nan": {"ks": float("nan")}, "ks_bool": {"ks": True},
    "mu_k_inf": {"mu_k": float("inf")}, "reset_num": {"reset": 1}, "slip_timing": {"slip_timing": "EXACT"},
    "gravity_nan": {"gravity": (0.0, float("nan"), 0.0)}, "gravity_2": {"gravity": (0.0, -9.81)},
    "gravity_str": {"gravity": "down"}, "gravity_num": {"gravity": 9.81},
    "damping_str": {"damping": "0.1"}, "damping_neg": {"damping": -0.1},
    "rotation_str": {"rotation": "no"}, "rotation_int": {"rotation": 0}, "check_str": {"check": "yes"},
    "extra_num": {"extra": [5]}, "extra_str": {"extra": "RotationEngine"},
    "extra_newton": {"extra": [NewtonIntegrator()]},
}
bad_material = {
    "density_str": {"kn": 1e4, "density": "2600"}, "density_zero": {"kn": 1e4, "density": 0.0},
    "density_nan": {"kn": 1e4, "density": float("nan")}, "kn_str": {"kn": "1e4"},
    "kn_nan": {"kn": np.float64("nan")}, "nu_n_neg": {"kn": 1e4, "nu_n": np.float32(-1.0)},
    "label_num": {"kn": 1e4, "label": 3},
}
out = {}
for table, make in ((bad_engines, lambda kw: stickslip_engines(**dict(ok, **kw))),
                    (bad_material, lambda kw: stickslip_material(**kw))):
    for name, kw in table.items():
        try:
            make(kw)
            out[name] = None
        except ValueError as e:
            out[name] = "ValueError: " + str(e)
        except Exception as e:
            out[name] = type(e).__name__ + ": " + str(e)
# numpy scalars and arrays are numbers: a run with them goes through
mat = O.materials.append(stickslip_material(np.float32(1e4), np.int64(0), density=np.float64(2600), label="m"))
O.bodies.append(utils.wall(0.0, axis=2, material=mat))
b = O.bodies.append(utils.sphere((0, 0, 0.002 - 1e-7), 0.002, material=mat))  # about its static overlap
O.bodies[b].state.vel = Vector3(0.01, 0, 0)
O.engines = stickslip_engines(ks=np.float32(8e3), nu_s=np.int64(0), mu_s=np.float64(0.5), mu_k=np.float32(0.45),
                              gravity=np.array([0.0, 0.0, -9.81]), damping=np.float32(0.0), rotation=np.bool_(True),
                              extra=(RotationEngine(ids=[], rotationAxis=(0, 0, 1), angularVelocity=0.0),))
O.dt = 1e-5
for _ in range(50):
    O.step()
out["numpy_run"] = [stickslip_law.n_contacts(), O.bodies[b].state.vel[0]]
print("RESULT " + json.dumps(out))
"""


def yade(tmp_path, text, *args):
    script = tmp_path / "s.py"
    script.write_text(text)
    p = subprocess.run(["yade", "-n", "-x", str(script), *map(str, args)], capture_output=True, text=True,
                       timeout=300, cwd=tmp_path, env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)})
    got = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    assert p.returncode == 0 and got, p.stdout[-2000:] + p.stderr[-2000:]
    return json.loads(got[-1][7:])


def test_every_argument_is_checked_numpy_scalars_accepted(tmp_path):
    r = yade(tmp_path, ARGS % str(LAW))
    expect = {
        "ks_str": ["ks = '8e3'", "finite number"], "ks_nan": ["ks = nan", "finite number"],
        "ks_bool": ["ks = True", "finite number"], "mu_k_inf": ["mu_k = inf", "finite number"],
        "reset_num": ["reset = 1", "spring, total"], "slip_timing": ["slip_timing = 'EXACT'", "step, exact"],
        "gravity_nan": ["gravity = (0.0, nan, 0.0)", "3 finite numbers"],
        "gravity_2": ["gravity = (0.0, -9.81)", "3 finite numbers"],
        "gravity_str": ["gravity = 'down'", "3 finite numbers"], "gravity_num": ["gravity = 9.81", "3 finite"],
        "damping_str": ["damping = '0.1'", "finite number"], "damping_neg": ["damping = -0.1", "[0, 1)"],
        "rotation_str": ["rotation = 'no'", "True or False"], "rotation_int": ["rotation = 0", "True or False"],
        "check_str": ["check = 'yes'", "True or False"], "extra_num": ["extra[0] = 5", "YADE engine"],
        "extra_str": ["extra = 'RotationEngine'", "list of YADE engines"],
        "extra_newton": ["extra[0] = NewtonIntegrator", "already has one"],
        "density_str": ["density = '2600'", "finite number"], "density_zero": ["density = 0", "> 0"],
        "density_nan": ["density = nan", "finite number"], "kn_str": ["kn = '1e4'", "finite number"],
        "kn_nan": ["kn = nan", "finite number"], "nu_n_neg": ["nu_n = -1", ">= 0"],
        "label_num": ["label = 3", "string"],
    }
    for name, words in expect.items():
        got = r[name]
        assert got is not None and got.startswith("ValueError: ") and "\n" not in got, (name, got)
        for w in words:
            assert w in got, (name, got)
    # The numpy-built run touched the floor and felt friction (v below its start 0.01 m/s).
    assert r["numpy_run"][0] == 1 and 0 < r["numpy_run"][1] < 0.01


BLOWUP = """
import json, sys
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material
from yade import O, Vector3, utils
case = sys.argv[1]
mat = O.materials.append(stickslip_material(1e4, 0.1))
O.bodies.append(utils.wall(0.0, axis=2, material=mat))
a = O.bodies.append(utils.sphere((0, 0, 0.0019), 0.002, material=mat))
b = O.bodies.append(utils.sphere((0.003, 0, 0.0019), 0.002, material=mat))
if case == "same_place":  # two spheres at one centre: no normal direction
    O.bodies[b].state.pos = O.bodies[a].state.pos
elif case == "nan_velocity":
    O.bodies[b].state.vel = Vector3(float("nan"), 0, 0)
O.engines = stickslip_engines(ks=8e3, nu_s=0.1, mu_s=0.5, mu_k=0.45, gravity=(0, 0, -9.81))
O.dt = 1e-5
out = {"error": None}
try:
    for _ in range(10):
        O.step()
except RuntimeError as e:
    out["error"] = stickslip_law.error
    out["iter"] = O.iter
print("RESULT " + json.dumps(out))
"""


@pytest.mark.parametrize("case,words", [
    ("same_place", ["contact (1, 2) at iteration 0", "same centre"]),
    ("nan_velocity", ["body 2 has a non-finite velocity", "at iteration 0"]),
])
def test_non_finite_values_stop_the_run_naming_where(tmp_path, case, words):
    r = yade(tmp_path, BLOWUP % str(LAW), case)
    assert r["error"] is not None and r["iter"] == 0, r
    for w in words:
        assert w in r["error"], r["error"]


def run_scene(tmp_path, mutate):
    """run_scene.py on the drag scene as the adapter writes it, after `mutate(scene dict)`."""
    sys.path.insert(0, str(ROOT))
    from stickslip import scene as scene_mod
    from stickslip.adapters import yade as adapter

    d = adapter.scene_dict(scene_mod.load("drag", duration=2e-4))
    mutate(d)
    (tmp_path / "scene.json").write_text(json.dumps(d))
    p = subprocess.run(["yade", "-n", "-x", str(LAW / "run_scene.py"), "scene.json", "out.csv"], capture_output=True,
                       text=True, timeout=300, cwd=tmp_path,
                       env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "STICKSLIP_YADE_LAW": str(LAW)})
    errors = [x for x in p.stdout.splitlines() if x.startswith("ERROR")]
    return p.returncode, errors, (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("mutate,code,words", [
    (lambda d: d["contact"].update(slip_timing="late"), 3, ["slip_timing = 'late'", "step, exact"]),
    (lambda d: d["contact"].update(mu_k=0.9), 3, ["mu_k = 0.9", "[mu_s/2, mu_s]"]),
    (lambda d: d["grains"][0].update(velocity=[float("nan"), 0.0, 0.0]), 4,
     ["stick-slip law: body 1 has a non-finite", "iteration 0"]),
])
def test_runner_turns_errors_into_one_line_and_nonzero_exit(tmp_path, mutate, code, words):
    rc, errors, wrote = run_scene(tmp_path, mutate)
    assert rc == code and len(errors) == 1 and not wrote, (rc, errors)
    for w in words:
        assert w in errors[0], errors[0]


def test_runner_records_only_what_output_asks_for(tmp_path):
    def ask_little(d):
        d["output"].update(grains=[], contacts=[], walls=[], stats=False)
        d["columns"] = ["t"]  # what stickslip.columns.names gives for such an [output]
        d["every"] = 25

    rc, errors, wrote = run_scene(tmp_path, ask_little)
    assert rc == 0 and not errors and wrote
    lines = (tmp_path / "out.csv").read_text().splitlines()
    # 2e-4 s at dt = 2e-6 s: 100 steps, a row every 25 steps and the start; only time asked.
    assert lines[0] == "t" and len(lines) == 1 + 100 // 25 + 1


START = """
import json, sys
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material, velocity_verlet_start
from yade import O, utils
case = sys.argv[1]
mat = O.materials.append(stickslip_material(1e4, 0.1))
O.bodies.append(utils.wall(0.0, axis=2, material=mat))
O.bodies.append(utils.sphere((0, 0, 0.0019), 0.002, material=mat))
if case == "clump":
    O.bodies.appendClumped([utils.sphere((0.01, 0, 0.003), 0.002, material=mat),
                            utils.sphere((0.013, 0, 0.003), 0.002, material=mat)])
O.engines = stickslip_engines(ks=8e3, nu_s=0.1, mu_s=0.5, mu_k=0.45, gravity=(0, 0, -9.81))
O.dt = 1e-5
if case == "late":
    O.step()
try:
    velocity_verlet_start()
    out = None
except (RuntimeError, ValueError) as e:
    out = [type(e).__name__, str(e)]
print("RESULT " + json.dumps(out))
"""


@pytest.mark.parametrize("case,words", [
    ("late", ["RuntimeError", "velocity_verlet_start", "iteration 1", "starts a run (iteration 0)"]),
    ("clump", ["ValueError", "velocity_verlet_start", "is not a free sphere"]),
])
def test_velocity_verlet_start_refuses_what_it_cannot_start(tmp_path, case, words):
    """velocity_verlet_start (yade_law/README.md, "Twin runs") starts a run of free spheres:
    called after the first step, or with a clump, it says so in one line."""
    got = yade(tmp_path, START % str(LAW), case)
    assert got is not None, case
    for w in words:
        assert w in " ".join(got), got
