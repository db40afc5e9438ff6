# SPDX-License-Identifier: GPL-2.0-or-later
"""The Python stick-slip law inside YADE (yade_law/stickslip_yade/), driven as
`yade -n -x` subprocesses. Expected values are derived from the law (docs/law.md)
and the parameters; tolerances come from the time step (a slip is detected on the
first step the trial force reaches mu_s*Fn, so times are known to one step).
"""
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
LAW = ROOT / "yade_law"
sys.path.insert(0, str(ROOT))
from pyref.laws import LawParams, normal_force, rotate_history, tangential_force  # noqa: E402
from conftest import needs_engine  # noqa: E402

pytestmark = needs_engine("yade")

# example_drag.py's parameters (the paper's Table 2 and section 3.1)
R, RHO, G, V = 0.002, 2600.0, 9.81, 1e-5
KN, KS, MU_S, MU_K, DT = 1.2e7, 9.6e6, 0.5, 0.45, 2e-6
FN = RHO * math.pi * R**2 * G  # weight of the disk per metre of thickness


def yade(script, *args, tmp_path):
    p = subprocess.run(["yade", "-n", "-x", str(script), *map(str, args)], capture_output=True, text=True,
                       timeout=300, cwd=tmp_path, env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)})
    lines = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    assert p.returncode == 0 and lines, p.stdout[-2000:] + p.stderr[-2000:]
    return json.loads(lines[-1][7:])


def drag(tmp_path, *args):
    return yade(LAW / "example_drag.py", *args, tmp_path=tmp_path)


def steps_to_reach(force, per_step):
    """Steps a force growing by `per_step` from 0 needs to reach `force` (>= test)."""
    return math.ceil(force / per_step - 1e-9)


def test_drag_saw_tooth(tmp_path):
    nu_s = 33.10
    r = drag(tmp_path, "--nu_s", nu_s)
    # The grain starts at its static overlap without velocity: Fn stays the weight.
    assert r["fn_mean"] == pytest.approx(FN, rel=1e-6)
    # Stick: F = Ks*V*dt*k + nu_s*V; it slips on the first step that reaches mu_s*Fn.
    first = steps_to_reach(MU_S * FN - nu_s * V, KS * V * DT)
    assert r["first_slip"] == pytest.approx(first * DT, abs=DT / 10)
    # The highest stick force lies within one spring increment below mu_s*Fn.
    assert MU_S - KS * V * DT / FN <= r["max_stick_ratio"] < MU_S
    # Slip: the force is Fmin = (2 mu_k - mu_s) Fn exactly (eq. 8 and section 2.3).
    assert r["slip_ratios"] == pytest.approx([2 * MU_K - MU_S], abs=1e-9)
    # Period: from Fmin (spring reset) back to mu_s*Fn, the dashpot adding nu_s*V at once.
    period = steps_to_reach(2 * (MU_S - MU_K) * FN - nu_s * V, KS * V * DT) * DT
    assert r["period"] == pytest.approx(period, abs=DT / 10)
    assert 3.30e-4 <= r["period"] <= 3.30e-4 + DT  # the paper's figure, to one step
    assert r["n_slips"] == 1 + int((2500 * DT - r["first_slip"]) / period + 1e-9)
    assert r["ftx_sign"] == -1.0 and r["fty_max"] == 0.0  # opposes the motion, tangential


def test_reset_spring_vs_total_when_the_dashpot_dominates(tmp_path):
    # nu_s*V = 0.04 N/m > 2(mu_s - mu_k)Fn = 0.032 N/m: with the paper's reset the dashpot
    # alone keeps every step after the first slip slipping (flat at Fmin); with
    # reset = total (spring + dashpot = Fmin) a saw-tooth of period 2(mu_s-mu_k)Fn/(Ks V) remains.
    nu_s = 4000.0
    assert nu_s * V > 2 * (MU_S - MU_K) * FN
    first = steps_to_reach(MU_S * FN - nu_s * V, KS * V * DT)
    spring = drag(tmp_path, "--nu_s", nu_s, "--reset", "spring")
    total = drag(tmp_path, "--nu_s", nu_s, "--reset", "total")
    for r in (spring, total):
        assert r["first_slip"] == pytest.approx(first * DT, abs=DT / 10)
        assert r["slip_ratios"] == pytest.approx([2 * MU_K - MU_S], abs=1e-9)
    assert spring["n_slips"] == 2500 - first + 1
    assert spring["period"] == pytest.approx(DT, abs=DT / 10)
    period = steps_to_reach(2 * (MU_S - MU_K) * FN, KS * V * DT) * DT
    assert total["period"] == pytest.approx(period, abs=DT / 10)
    assert MU_S - KS * V * DT / FN <= total["max_stick_ratio"] < MU_S


BAD = """
import json, sys
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material
ok = dict(ks=9.6e6, nu_s=33.1, mu_s=0.5, mu_k=0.45)
out = {}
for name, kw in [("mu_k_high", {"mu_k": 0.6}), ("mu_k_low", {"mu_k": 0.2}), ("ks_zero", {"ks": 0.0}),
                 ("ks_neg", {"ks": -1.0}), ("nu_s_neg", {"nu_s": -1.0}), ("mu_s_zero", {"mu_s": 0.0}),
                 ("reset", {"reset": "half"}), ("damping", {"damping": 1.5}),
                 ("slip_timing", {"slip_timing": "late"})]:
    try:
        stickslip_engines(**dict(ok, **kw)); out[name] = None
    except ValueError as e:
        out[name] = str(e)
for name, args in [("kn_zero", (0.0, 1.0)), ("kn_neg", (-1.0, 1.0)), ("nu_n_neg", (1e7, -1.0))]:
    try:
        stickslip_material(*args); out[name] = None
    except ValueError as e:
        out[name] = str(e)
print("RESULT " + json.dumps(out))
"""


def test_bad_parameters_raise_naming_parameter_and_range(tmp_path):
    script = tmp_path / "bad.py"
    script.write_text(BAD % str(LAW))
    r = yade(script, tmp_path=tmp_path)
    expect = {"mu_k_high": ["mu_k = 0.6", "[0.25, 0.5]"], "mu_k_low": ["mu_k = 0.2", "[0.25, 0.5]"],
              "ks_zero": ["ks = 0", "> 0"], "ks_neg": ["ks = -1", "> 0"], "nu_s_neg": ["nu_s = -1", ">= 0"],
              "mu_s_zero": ["mu_s = 0", "> 0"], "reset": ["reset", "spring, total"],
              "damping": ["damping = 1.5", "[0, 1)"], "slip_timing": ["slip_timing = 'late'", "step, exact"], "kn_zero": ["kn = 0", "> 0"], "kn_neg": ["kn = -1", "> 0"],
              "nu_n_neg": ["nu_n = -1", ">= 0"]}
    for name, words in expect.items():
        assert r[name] is not None, f"{name} was accepted"
        for w in words:
            assert w in r[name], (name, r[name])


FRESH = """
import json, sys
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material
from yade import O, Vector3, utils
kn, ks, nu_s, V, U, dt = %r
mat = O.materials.append(stickslip_material(kn, 0.0))
a = O.bodies.append(utils.sphere((0, 0, 0), 0.01, material=mat, fixed=True))
b = utils.sphere((0, 0.0199, 0), 0.01, material=mat)
b.state.blockedDOFs = "xyzXYZ"  # its velocity is imposed throughout
b = O.bodies.append(b)
O.engines = stickslip_engines(ks=ks, nu_s=nu_s, mu_s=0.5, mu_k=0.45, rotation=False, check=True)
O.dt = dt
log = []
def go(n, vel):
    O.bodies[b].state.vel = Vector3(*vel)
    for _ in range(n):
        O.step()
        c = stickslip_law.contact(a, b)
        log.append(None if c is None else [c[0], [float(x) for x in c[1]], c[2], c[3]])
go(20, (V, 0, 0))   # slide sideways while touching: the spring loads
go(3, (V, U, 0))    # lift off: 3 U dt = 1.5e-4 m > the 1e-4 m overlap
go(3, (V, -U, 0))   # back into contact
go(5, (V, 0, 0))
print("RESULT " + json.dumps(log))
"""


def test_contact_broken_and_made_again_starts_fresh(tmp_path):
    kn, ks, nu_s, V, U, dt = 1e5, 8e4, 2.0, 1e-3, 5.0, 1e-5
    script = tmp_path / "fresh.py"
    script.write_text(FRESH % (str(LAW), (kn, ks, nu_s, V, U, dt)))
    log = yade(script, tmp_path=tmp_path)
    assert log[19] is not None and log[19][0] == pytest.approx(kn * 1e-4, rel=1e-6)
    # While sticking, |F| = Ks*V*dt*k + nu_s*V (sphere-sphere path, normal force as YADE's).
    assert math.hypot(*log[19][1]) == pytest.approx(ks * V * dt * 20 + nu_s * V, rel=1e-6)
    gone = [k for k, c in enumerate(log) if c is None]
    assert gone and gone[-1] < 26 and all(c is not None for c in log[gone[-1] + 1:])
    before, after = log[gone[0] - 1], log[gone[-1] + 1]
    # A fresh spring carries one step of tangential motion: |F| <= (Ks dt + nu_s)|V_s|,
    # |V_s| <= V + U*sin(tilt of the normal), the tilt from the x-drift V*dt*steps.
    tilt = V * dt * 31 / 0.0199
    bound = (ks * dt + nu_s) * (V + U * tilt) * 1.01
    assert math.hypot(*after[1]) <= bound < math.hypot(*before[1]) / 3
    assert after[3] == 0


PACKING = """
import json, sys, numpy as np
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material
from yade import O, Vector3, utils
mat = O.materials.append(stickslip_material(1e4, 0.5))
rng = np.random.default_rng(0)
O.bodies.append(utils.wall(0.0, axis=2, material=mat))
for i in range(64):  # a 4 x 4 x 4 lattice, shaken, falls into the box
    c = np.array([i % 4, i // 4 % 4, i // 16]) * 0.0045 + (0.0035, 0.0035, 0.003)
    b = utils.sphere(tuple(c), 0.002 * rng.uniform(0.9, 1.0), material=mat)
    b.state.vel = Vector3(*rng.uniform(-0.05, 0.05, 3))
    O.bodies.append(b)
for x, ax in ((0.0, 0), (0.022, 0), (0.0, 1), (0.022, 1)):
    O.bodies.append(utils.wall(x, axis=ax, material=mat))
O.engines = stickslip_engines(ks=8e3, nu_s=0.2, mu_s=0.5, mu_k=0.4, gravity=(0, 0, -9.81), check=True)
O.dt = 1e-5
most, changes, last = 0, 0, set()
for _ in range(6000):
    O.step()
    most = max(most, stickslip_law.n_contacts())
    now = set(stickslip_law.keys.tolist())
    changes += len(now ^ last)
    last = now
print("RESULT " + json.dumps({"most": most, "fn_error": stickslip_law.max_fn_error,
      "slips": int(stickslip_law.count.sum()), "checked": stickslip_law.checked, "changes": changes,
      "full_reads": stickslip_law.full_reads, "set_checks": stickslip_law.set_checks}))
"""


def test_recomputed_sphere_geometry_matches_yade(tmp_path):
    # check=True makes the law compare its numpy normals and normal forces with YADE's
    # own (I.geom.normal, I.phys.normalForce) at every step, and raise if they differ.
    script = tmp_path / "pack.py"
    script.write_text(PACKING.replace("%r", repr(str(LAW)), 1))
    r = yade(script, tmp_path=tmp_path)
    # Settled, every grain touches something: at least 64 / 2 contacts.
    assert r["most"] >= 32 and r["checked"] > 10000 and r["fn_error"] < 1e-9 and r["slips"] > 0
    # check=True also compared the law's contact set with YADE's every step: contacts were
    # made and broken many times, and mostly found without reading the whole set.
    assert r["set_checks"] == 6000 and r["changes"] > 500 and r["full_reads"] <= 60  # 1 measured


REPLAY = """
import json, math, sys
sys.path.insert(0, %r)
from stickslip_yade import stickslip_engines, stickslip_material
from yade import O, Vector3, utils
kn, nu_n, ks, nu_s, mu_s, mu_k, r, dt, steps, reset = %r
mat = O.materials.append(stickslip_material(kn, nu_n, density=2600.0))
base = utils.sphere((0, 0, 0), r, material=mat)
base.state.blockedDOFs = "xyz"  # held in place, free to spin
base = O.bodies.append(base)
d = 2 * r - 1.3e-7  # about the static overlap, off-centre: an oblique normal that turns
ball = utils.sphere((0.2 * d, 0.1 * d, d * math.sqrt(1 - 0.05)), r, material=mat)
ball.state.vel = Vector3(0.05, -0.03, 0.0)
ball.state.angVel = Vector3(0.0, 0.0, 20.0)
ball = O.bodies.append(ball)
O.engines = stickslip_engines(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=reset, gravity=(0, 0, -9.81))
O.dt = dt
log = []
for _ in range(steps):
    # what the law sees in the coming step: x(t), v(t - dt/2), omega(t - dt/2)
    kin = [list(O.bodies[i].state.pos) + list(O.bodies[i].state.vel) + list(O.bodies[i].state.angVel)
           for i in (base, ball)]
    O.step()
    c = stickslip_law.contact(base, ball)
    log.append([kin, None if c is None else [c[0], [float(x) for x in c[1]], c[2]]])
print("RESULT " + json.dumps(log))
"""


@pytest.mark.parametrize("reset", ["spring", "total"])
def test_3d_sphere_contact_replays_through_pyref_law(tmp_path, reset):
    # A spinning ball slides and rolls on a spinning sphere in 3D (the fast numpy path,
    # rotation on). Each step's kinematics, as YADE had them when the law ran, are fed to
    # pyref's law functions (an independent implementation of docs/law.md): Fn, F_s and the
    # slip flag must agree to round-off, the spring being turned as the normal turns. The
    # ball's spin change checks the torque: dw = dt * (c n x F_s) / I, c = r - delta/2 (no other torque).
    P = [1e5, 1.0, 8e4, 0.5, 0.5, 0.45, 0.005, 1e-5, 2000, reset]
    script = tmp_path / "replay.py"
    script.write_text(REPLAY % (str(LAW), P))
    log = yade(script, tmp_path=tmp_path)
    kn, nu_n, ks, nu_s, mu_s, mu_k, r, dt, steps, reset = P
    law = LawParams("stick_slip", kn, nu_n, ks, nu_s, mu_s, mu_k, reset)
    inertia = 0.4 * 2600.0 * 4 / 3 * math.pi * r**3 * r**2
    # Round-off scale: 1e-9 of the largest static friction force of the run (the overlap
    # alone carries kn * eps * 2r ~ 1e-13 N of round-off; sums over steps add to it).
    scale = 1e-9 * mu_s * max(got[0] for _, got in log if got is not None)
    D, slips, touching, turn, n0 = np.zeros((1, 3)), 0, 0, 0.0, None
    for k, (kin, got) in enumerate(log):
        a, b = np.array(kin[0]), np.array(kin[1])
        dist = np.linalg.norm(b[:3] - a[:3])
        n = (b[:3] - a[:3]) / dist
        n0 = n if n0 is None else n0
        if dist >= 2 * r:
            assert got is None
            D = np.zeros((1, 3))
            continue
        touching += 1
        turn = max(turn, math.degrees(math.acos(min(1.0, n @ n0))))
        c = r - 0.5 * (2 * r - dist)  # lever arm to the contact point midway in the overlap (docs/law.md)
        v_rel = (a[3:6] + np.cross(a[6:9], c * n)) - (b[3:6] + np.cross(b[6:9], -c * n))
        v_n = v_rel @ n
        fn = normal_force(np.array([2 * r - dist]), np.array([v_n]), law)
        D = rotate_history(D, n[None])
        F, D, slipped = tangential_force(D, (v_rel - v_n * n)[None], fn, dt, law)[:3]
        slips += int(slipped[0])
        assert got[0] == pytest.approx(fn[0], abs=scale), k
        assert np.abs(np.array(got[1]) - F[0]).max() <= scale, k
        assert got[2] == bool(slipped[0]), k
        if k + 1 < len(log):
            dw = np.array(log[k + 1][0][1][6:9]) - b[6:9]
            expect = dt * np.cross(c * n, F[0]) / inertia
            assert np.abs(dw - expect).max() <= dt * r * scale / inertia + 1e-12, k
    # The run must exercise what it claims: long contact, sticks and slips, a turning normal.
    assert touching > 1000 and 10 < slips < touching - 100 and turn > 3.0
