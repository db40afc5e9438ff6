# SPDX-License-Identifier: GPL-2.0-or-later
"""YADE's compiled law (yade_law/compiled/): a YADE plugin built for Debian's YADE against YADE's
own headers, checked against the installed YADE before YADE starts with it, and the same law as
the Python one (yade_law/stickslip_yade/).

The law's contract runs on it with the other engines (tests/test_law_contract.py, engine
yade_cpp); the paper's cases against pyref with the Python law's (tests/test_yade_engine.py).
"""
import importlib.util
import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conftest import as_root, needs_engine, paper_case
import test_yade_shapes as shapes
import twin_bound

ROOT = Path(__file__).resolve().parent.parent
LAW = ROOT / "yade_law"
from stickslip.adapters.yade_cpp import LAUNCHER  # noqa: E402
# a plugin built for a YADE without MPI (run.sh: setup_yade_law), which Debian's YADE is not
WRONG = ROOT / "build" / "yade_law_wrong"
EPS = np.finfo(float).eps

pytestmark = needs_engine("yade_cpp")


def layout_check():
    spec = importlib.util.spec_from_file_location("layout_check", LAW / "compiled" / "layout_check.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(tmp_path, script, *args, launcher=LAUNCHER, ok=True):
    """A YADE script through `launcher`; its RESULT line's value (ok: it must exit 0)."""
    path = tmp_path / "script.py"
    path.write_text(script)
    p = subprocess.run([str(launcher), "-n", "-x", str(path), *map(str, args)], capture_output=True, text=True,
                       timeout=300, cwd=tmp_path, env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)})
    lines = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    if ok:
        assert p.returncode == 0 and lines, p.stdout[-2000:] + p.stderr[-2000:]
    return (json.loads(lines[-1][7:]) if lines else None), p


HEAD = f"""
import json, math, sys
sys.path.insert(0, {str(LAW)!r})
from stickslip_yade import stickslip_engines, stickslip_material
from yade import *
from yade import utils
"""


# ---------------------------------------------------------------- the layout check
def test_the_plugin_reads_yade_s_members_where_yade_keeps_them():
    """Every member the law reads or writes, set through YADE's Python attributes and read
    back through the plugin (the probe itself, not the kept verdict)."""
    check = layout_check()
    prefix = LAUNCHER.parent / "prefix"
    assert check.probe(str(prefix), check.build_info(str(prefix))) is None


def test_the_plugin_knows_it_is_one_and_keeps_the_check(tmp_path):
    """Built as a plugin (yade_law/compiled/CMakeLists.txt), the law says so: the scripts'
    backend="cpp" then asks for the layout check's verdict (compiled into a YADE built from
    source it would say False and need none)."""
    got, _ = run(tmp_path, HEAD + "print('RESULT ' + json.dumps(Law2_ScGeom_StickSlipPhys_StickSlip.asPlugin()))\n")
    assert got is True


def test_a_plugin_built_for_another_yade_is_refused_in_one_line(tmp_path):
    """The same source built with one feature's definitions left out (MPI: YADE's Scene and
    Body then have fewer members), as a plugin built against headers that do not describe the
    installed YADE would be: the check names a member it reads wrong and the headers, and the
    launcher stops with that line before YADE starts."""
    if not (WRONG / "yade-stickslip").is_file():
        why = f"{WRONG} missing (./run.sh setup builds it beside the compiled law)"
        pytest.fail(why) if as_root() else pytest.skip(why)
    check = layout_check()
    prefix = str(WRONG / "prefix")
    verdict = check.probe(prefix, check.build_info(prefix))
    assert verdict is not None and "\n" not in verdict
    assert verdict.startswith("stick-slip law: the compiled law reads ")
    assert "headers of YADE 2025.2.0, installed YADE 2023.02a" in verdict and "refused" in verdict
    member = verdict.split(" reads ", 1)[1].split(" ", 1)[0]
    assert member.split(".")[0] in ("Scene", "Body", "State", "Cell", "ForceContainer", "EnergyTracker"), verdict
    got, p = run(tmp_path, HEAD + "print('RESULT 1')\n", launcher=WRONG / "yade-stickslip", ok=False)
    assert p.returncode == 1 and got is None and "Welcome to Yade" not in p.stdout
    # (the addresses differ from process to process)
    hexes = lambda text: re.sub(r"0x[0-9a-f]+", "0x...", text)  # noqa: E731
    assert hexes(p.stderr.strip()) == hexes(verdict)


# ---------------------------------------------------------------- using it wrong: one line
def test_without_the_launcher_the_compiled_law_says_how_to_start_yade(tmp_path):
    script = HEAD + """
try:
    stickslip_engines(ks=1e4, nu_s=0.0, mu_s=0.5, mu_k=0.45, backend="cpp")
    print("RESULT null")
except RuntimeError as e:
    print("RESULT " + json.dumps(str(e)))
"""
    got, _ = run(tmp_path, script, launcher="yade")
    assert got.startswith("backend = 'cpp': the compiled law is not loaded in this YADE; start YADE with "
                          "build/yade_law/yade-stickslip")


BAD = HEAD + """
ok = dict(ks=9.6e6, nu_s=33.1, mu_s=0.5, mu_k=0.45)
out = {}
for name, kw in [("mu_k_high", {"mu_k": 0.6}), ("mu_k_low", {"mu_k": 0.2}), ("ks_zero", {"ks": 0.0}),
                 ("ks_nan", {"ks": float("nan")}), ("nu_s_neg", {"nu_s": -1.0}), ("mu_s_zero", {"mu_s": 0.0})]:
    for how in ("engines", "functor"):
        try:
            if how == "engines":
                stickslip_engines(**dict(ok, **kw), backend="cpp")
            else:
                Ip2_ViscElMat_ViscElMat_StickSlipPhys(**dict(ok, **kw))
            out[name + "/" + how] = None
        except ValueError as e:
            out[name + "/" + how] = str(e)
for name, kw in [("reset", {"reset": "half"}), ("slip_timing", {"slip_timing": "late"})]:
    for how in ("engines", "functor"):
        try:
            if how == "engines":
                stickslip_engines(**ok, **kw, backend="cpp")
            else:
                Law2_ScGeom_StickSlipPhys_StickSlip(**kw)
            out[name + "/" + how] = None
        except ValueError as e:
            out[name + "/" + how] = str(e)
try:
    stickslip_engines(**ok, backend="fortran")
except ValueError as e:
    out["backend"] = str(e)
print("RESULT " + json.dumps(out))
"""


def test_bad_parameters_are_refused_naming_the_parameter_and_range(tmp_path):
    """Through stickslip_engines and on the compiled functors themselves (set from Python,
    as a hand-written engine list does): ValueError, the Python law's words."""
    got, _ = run(tmp_path, BAD)
    words = {"mu_k_high": ["mu_k = 0.6", "[0.25, 0.5]"], "mu_k_low": ["mu_k = 0.2", "[0.25, 0.5]"],
             "ks_zero": ["ks = 0", "> 0"], "ks_nan": ["ks = nan", "finite"], "nu_s_neg": ["nu_s = -1", ">= 0"],
             "mu_s_zero": ["mu_s = 0", "> 0"], "reset": ["reset", "spring, total"],
             "slip_timing": ["slip_timing", "late", "step, exact"]}
    for name, ws in words.items():
        for how in ("engines", "functor"):
            msg = got[f"{name}/{how}"]
            assert msg is not None and "\n" not in msg, (name, how, msg)
            for w in ws:
                assert w in msg, (name, how, msg)
    assert got["backend"] == "backend = 'fortran': must be one of python, cpp"


NAN = HEAD + """
mat = O.materials.append(stickslip_material(1e4, 0.5))
O.bodies.append(utils.wall(0.0, axis=2, material=mat))
b = O.bodies.append(utils.sphere((0, 0, 0.0099), 0.01, material=mat))
O.engines = stickslip_engines(ks=8e3, nu_s=0.0, mu_s=0.5, mu_k=0.45, gravity=(0, 0, -9.81), backend="cpp")
O.dt = 1e-5
for _ in range(3):
    O.step()
O.bodies[b].state.vel = Vector3(float("nan"), 0.0, 0.0)
try:
    O.step()
    print("RESULT null")
except RuntimeError as e:
    print("RESULT " + json.dumps([str(e), O.iter]))
"""


def test_a_non_finite_contact_stops_the_run_naming_the_body(tmp_path):
    """NaN fails loudly: the law's guard stops the step before the integrator, with the line."""
    got, _ = run(tmp_path, NAN)
    msg, it = got
    assert msg.startswith("stick-slip law: body 1 has a non-finite velocity [nan, 0, 0] at iteration 3"), msg
    assert "\n" not in msg and it == 3


def test_a_contact_at_zero_overlap_has_no_spring():
    """docs/law.md step 3: a contact begins at delta > 0; YADE keeps a sphere touching a wall at
    zero overlap as a contact, to which the law gives no force and no spring. A grain loaded
    for 10 steps (spring 10 w, w = V dt), one step at exactly zero overlap, then 5 steps
    pressed again: its spring restarts from zero (1..5 w, no slip), as after a contact that
    ended. (The law's contract holds the overlap either pressed or apart.)"""
    from stickslip.contract import cases as lc, yade as contract_yade

    v = lc.DIAGONAL
    case = lc.Case("zero_overlap", "step 3", "wall", (lc.Segment(10, v), lc.Segment(1, v, delta=0.0), lc.Segment(5, v)),
                   lc.D24, lc.D_MU_K)
    trace = contract_yade.run_cases([case])[0]
    w = np.array(lc.tangential(case, v)) * lc.DT
    assert np.array_equal(trace["D"][9], 10 * w) and trace["slips"][9] == 0  # loaded, no slip
    assert trace["fn"][10] == 0.0 and not trace["F"][10].any() and not trace["D"][10].any()
    for k in range(1, 6):
        assert np.array_equal(trace["D"][10 + k], k * w), (k, trace["D"][10 + k])
        assert np.array_equal(trace["F"][10 + k], -k * w * lc.KS) and trace["fn"][10 + k] == 1.0


MOMENTA = HEAD + """
r1, r2 = 0.002, 0.0015
mat = O.materials.append(stickslip_material(1e4, 0.5))
if sys.argv[2] == "spheres":
    a = O.bodies.append(utils.sphere((0.0, 0.0, 0.0), r1, material=mat))
else:  # a free box (YADE makes it body 1 of the contact), a sphere on its top face off its centre
    a = O.bodies.append(utils.box((0.0, 0.0, 0.0), (0.004, 0.003, r1), material=mat, dynamic=True))
b = O.bodies.append(utils.sphere((r1 + r2 - 2e-5, 1e-4, -2e-4) if sys.argv[2] == "spheres" else
                                 (0.002, -0.001, r1 + r2 - 2e-5), r2, material=mat))
O.engines = stickslip_engines(ks=8e3, nu_s=0.01, mu_s=0.5, mu_k=0.4, backend=sys.argv[1])
O.dt = 1e-5
sa, sb = O.bodies[a].state, O.bodies[b].state
sa.vel, sa.angVel = Vector3(0.0, 0.03, -0.01), Vector3(20.0, -5.0, 40.0)
sb.vel, sb.angVel = Vector3(0.0, -0.01, 0.02), Vector3(-10.0, 30.0, 0.0)
if sys.argv[2] == "box":
    sa.vel, sa.angVel = Vector3(0.03, -0.01, 0.0), Vector3(0.0, 0.0, 5.0)
sa.blockedDOFs = sb.blockedDOFs = "xyzXYZ"  # kinematics imposed
rows = []
for k in range(60):
    x1, x2 = list(sa.pos), list(sb.pos)  # where the law sees them in the step
    O.step()
    f1, f2, t1, t2 = O.forces.f(a), O.forces.f(b), O.forces.t(a), O.forces.t(b)
    I = O.interactions[a, b]
    assert (I.id1, I.id2) == (a, b)
    _, fs, _, slips = stickslip_law.contact(a, b)
    rows.append([list(f1), list(f2), list(t1), list(t2), x1, x2, slips, I.geom.penetrationDepth,
                 math.sqrt(sum(c * c for c in fs))])
print("RESULT " + json.dumps(rows))
"""


@pytest.mark.parametrize("backend", ["python", "cpp"])
@pytest.mark.parametrize("shape", ["spheres", "box"])
def test_a_contact_keeps_momentum_and_angular_momentum(tmp_path, backend, shape):
    """Newton's third law on a contact sliding and spinning, between two unequal spheres and
    between a free box and a sphere: the forces on the two bodies are opposite, and the
    torques balance the couple of those forces about any point: t1 + t2 + x1 x f1 + x2 x f2
    = 0. Between spheres both forces act at YADE's contact point, midway in the overlap:
    each term is a few roundings of |x| |f|, the bound 16 ulps of the largest term. On the
    box the law takes the tangential force at the box's surface (its side has no lever arm
    into the overlap, docs/law.md step 1) and at the sphere's midway point, delta/2 apart
    along the normal: the bound adds delta/2 |F_s|. (The torque of the tangential force is
    r |F_s|, ~1e5 ulps of that and ~1e2 times delta/2 |F_s|: a torque left out on one body,
    or a lever arm at the radius instead of midway, breaks the balance.)"""
    rows, _ = run(tmp_path, MOMENTA, backend, shape)
    assert rows[-1][6] > 0  # it slid: both the stuck and the slipping force were balanced
    for k, (f1, f2, t1, t2, x1, x2, _, delta, fs) in enumerate(rows):
        f1, f2, t1, t2, x1, x2 = map(np.array, (f1, f2, t1, t2, x1, x2))
        assert np.linalg.norm(f1) > 0 and np.array_equal(f1, -f2), k
        couple = t1 + t2 + np.cross(x1, f1) + np.cross(x2, f2)
        scale = max(np.abs(t1).max(), np.abs(t2).max(), np.linalg.norm(x2) * np.linalg.norm(f1))
        bound = 16 * EPS * scale + (0.5 * delta * fs * (1 + 1e-9) if shape == "box" else 0.0)
        assert np.linalg.norm(couple) <= bound, (k, couple, bound)
        assert np.linalg.norm(t1) > 1e3 * EPS * scale and np.linalg.norm(t2) > 50 * bound, k  # F_s has torques


@pytest.mark.parametrize("name", ["reset_spring_after_slip_step_timing", "reset_total_after_slip_exact_timing"])
def test_the_books_take_each_step_s_work(name):
    """docs/law.md, Energy: each step the books take the work the contact's force did on the
    relative motion less the spring's gain, -F.V_s dt - Ks (|D|^2 - |D_prev|^2) / 2 (slip and
    dashpot together), and hold the spring's energy Ks |D|^2 / 2; on a step that sticks, the
    dashpot's share is nu_s |V_s|^2 dt. A contract case with a dashpot and slips (the grain's
    tangential velocity V_s is the segment's), read back from O.energy at each step. Each
    difference of the running sums is exact to a few roundings of the sums: 8 ulps of them."""
    from stickslip.contract import cases as lc, yade as contract_yade

    case = next(c for c in lc.CASES if c.name == name)
    assert len(case.segments) == 1 and case.nu_s > 0
    trace = contract_yade.run_cases([case])[0]
    vs = np.array(lc.tangential(case, case.segments[0].velocity))
    books, F, D = trace["books"], trace["F"], trace["D"]
    assert trace["slips"][-1] >= 2  # it stuck and slipped
    spent, d_prev = 0.0, np.zeros(3)
    for k in range(case.steps):
        work = -F[k] @ vs * lc.DT - 0.5 * lc.KS * (D[k] @ D[k] - d_prev @ d_prev)
        booked = books[k, 0] + books[k, 1] - spent
        bound = 8 * EPS * (abs(spent) + abs(work) + abs(F[k] @ vs * lc.DT))
        assert abs(booked - work) <= bound, (k, booked, work)
        assert books[k, 2] == pytest.approx(0.5 * lc.KS * D[k] @ D[k], rel=4 * EPS), k
        stuck = trace["slips"][k] == (trace["slips"][k - 1] if k else 0)
        if stuck:
            dashpot = books[k, 1] - (books[k - 1, 1] if k else 0.0)
            assert dashpot == pytest.approx(case.nu_s * vs @ vs * lc.DT, rel=8 * EPS, abs=8 * EPS * books[k, 1]), k
        spent, d_prev = books[k, 0] + books[k, 1], D[k]


# ---------------------------------------------------------------- save and load
SAVE = HEAD + """
def build():
    mat = O.materials.append(stickslip_material(1e4, 0.5))
    O.bodies.append(utils.wall(0.0, axis=2, material=mat))
    r = 0.002
    for k, (vx, vy, wz) in enumerate(((0.05, 0.0, 0.0), (-0.03, 0.02, 40.0), (0.0, 0.0, 80.0))):
        b = utils.sphere((0.02 * k, 0.0, r - 1e-6), r, material=mat)
        b.state.vel, b.state.angVel = Vector3(vx, vy, 0.0), Vector3(0.0, 30.0 * k, wz)
        O.bodies.append(b)
    for k, vx in ((0, 0.02), (1, -0.01)):  # a pressed pair: each touches the floor and the other
        b = utils.sphere((0.08 + k * (2 * r - 2e-5), 0.0, r - 1e-6), r, material=mat)
        b.state.vel, b.state.angVel = Vector3(vx, 0.01 * (k + 1), 0.0), Vector3(5.0, -10.0, 0.0)
        O.bodies.append(b)
    O.engines = stickslip_engines(ks=8e3, nu_s=0.01, mu_s=0.5, mu_k=0.4, gravity=(0, 0, -9.81),
                                  slip_timing=sys.argv[3], backend="cpp")
    O.dt = 1e-5
    O.trackEnergy = True

def snapshot():
    return {"bodies": [[x.hex() for x in list(b.state.pos) + list(b.state.vel) + list(b.state.angVel)]
                       for b in O.bodies],
            "contacts": sorted([I.id1, I.id2, [x.hex() for x in I.phys.spring], [x.hex() for x in I.phys.shearForce],
                                I.phys.slips] for I in O.interactions),
            "energy": {k: v.hex() for k, v in O.energy.items()}, "iter": O.iter}

mode, path = sys.argv[1], sys.argv[2]
if mode == "load":  # a new process: nothing of the law imported, the scene file only
    O.load(path)
    for _ in range(1000):
        O.step()
    print("RESULT " + json.dumps(snapshot()))
else:
    build()
    for _ in range(1000):
        O.step()
    O.save(path)
    for _ in range(1000):
        O.step()
    print("RESULT " + json.dumps(snapshot()))
"""


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_a_saved_scene_continues_in_a_new_process_to_the_byte(tmp_path, timing):
    """Grains sliding and rolling on a floor, two pressed together (no body gets more than two
    contact forces, so their sum does not depend on the order YADE adds them in; a native law
    resumes bit for bit there: tests/test_yade_checkpoint.py): the run continued after O.save
    and the same run continued by O.load in a new process agree in every bit: positions,
    velocities, spins, each contact's spring, force and slip count, the energy books. The
    springs are the phys' members, saved with the scene."""
    path = tmp_path / "scene.yade.gz"
    whole, _ = run(tmp_path, SAVE, "save", path, timing)
    resumed, _ = run(tmp_path, SAVE, "load", path, timing)
    assert whole["iter"] == resumed["iter"] == 2000
    assert any(c[4] for c in whole["contacts"]) and len(whole["contacts"]) >= 5  # it slipped; grains still touch
    assert resumed == whole


# ---------------------------------------------------------------- the record
@pytest.mark.parametrize("timing", ["step", "exact"])
def test_the_energy_books_balance_on_a_pour(tmp_path, timing):
    """The compiled law's energy books (the Python law's keys in O.energy) on the 125-sphere
    pour of tests/test_yade_energy.py, within the bound derived there: O.energy.total() stays
    at its start value up to the time discretisation's first-order mismatch."""
    import test_yade_energy as energy

    energy.check_balance(energy.pour(tmp_path, timing, nu_s=0.03, backend="cpp", launcher=LAUNCHER))


# ---------------------------------------------------------------- the same law as the Python one
@pytest.mark.parametrize("scene", shapes.SCENES)
def test_drop_in_scenes_equal_the_python_law(scene):
    """Sphere pairs, a still, translating and turning facet, a pair across a periodic
    boundary (the cell still and sheared), a sphere on a facet through its image across a
    sheared cell's boundary, a clump on a facet (tests/test_yade_shapes.py), kinematics
    imposed: the compiled law's force on each contact at each step against the Python law's,
    in one YADE process.
    Both do the same operations in another order: each force may differ by a few roundings of
    mu*Fn per step, and the spring carries them on while the contact sticks (a slip puts both
    at Fmin): over the 700 steps at most 700 * 8 ulps of mu*Fn."""
    runs = shapes.scene_runs(("native", "law", "cpp"), launcher=LAUNCHER)
    law, cpp = runs[scene, "law"], runs[scene, "cpp"]
    fmax = shapes.MU * shapes.KN * shapes.DELTA * 1.01
    keys = set().union(*law)
    assert keys and keys == set().union(*cpp) and len(law) == len(cpp) == 700
    for key in keys:
        rows = [(a.get(key), b.get(key)) for a, b in zip(law, cpp) if key in a or key in b]
        assert all(a is not None and b is not None for a, b in rows), key
        assert [a[2] for a, _ in rows] == [b[2] for _, b in rows], key  # slips in the same steps
        err = np.abs(np.array([a[1] for a, _ in rows]) - np.array([b[1] for _, b in rows])).max()
        assert err <= 700 * 8 * EPS * fmax, (key, err)


@pytest.mark.parametrize("scene", shapes.NATIVE_SCENES)
def test_drop_in_scenes_reproduce_native_within_what_the_contract_keeps(scene):
    """At mu_k = mu_s without dashpot, against YADE's native Law2_ScGeom_ViscElPhys_Basic, the
    compiled law within the differences tests/test_yade_shapes.py derives for the Python law:
    YADE's first-order turn of its spring with the pair's twist, and the clump's lever arms.
    (Bit for bit it cannot be: YADE keeps the spring as a force, adds ks*dt*V_s to it and turns
    it with ScGeom::rotate, the law keeps the elongation D and turns it keeping its length.)"""
    runs = shapes.scene_runs(("native", "law", "cpp"), launcher=LAUNCHER)
    shapes.like_native(scene, runs[scene, "native"], runs[scene, "cpp"])


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_the_drag_is_pyrefs_and_the_python_law_s_twin(tmp_path, timing):
    """Every row of the paper's drag within the round-off bound of tests/twin_bound.py of
    pyref's run and of the Python law's."""
    from stickslip import scene as scene_mod
    from stickslip.adapters import yade as yade_adapter, yade_cpp

    sc = scene_mod.load("drag", slip_timing=timing)
    dc = yade_cpp.run(sc, tmp_path / "cpp").timeseries
    dy = yade_adapter.run(sc, tmp_path / "python").timeseries
    _, dp = paper_case("drag") if timing == "step" else paper_case("drag", slip_timing=timing)
    twin_bound.assert_round_off_apart(sc, dc, dp)
    twin_bound.assert_round_off_apart(sc, dc, dy)
    assert dc["grain-floor_slip"].sum() >= 5


@pytest.mark.parametrize("case,kw", [("tilt", {"slip_timing": "step"}), ("tilt", {"slip_timing": "exact"}),
                                     ("tray", {"duration": 0.5})])
def test_the_tilt_and_tray_are_pyrefs_twins(tmp_path, case, kw):
    """The tilt (125 000 steps: the plate turning and stopping, stick, stick-slip, sliding) and
    the tray's first 0.5 s, every row within tests/twin_bound.py's round-off bound of pyref's
    (the Python law's runs of these take 40-110 s: tests/test_yade_engine.py holds it to the
    same bound)."""
    from stickslip import scene as scene_mod
    from stickslip.adapters import yade_cpp

    sc = scene_mod.load(case, **kw)
    dc = yade_cpp.run(sc, tmp_path).timeseries
    _, dp = paper_case(case, **kw)
    box = 0.01 if any(w.rotation for w in sc.walls) else 0.0  # run_scene.py's turning box, half thick
    twin_bound.assert_round_off_apart(sc, dc, dp, box)
