# SPDX-License-Identifier: GPL-2.0-or-later
"""Facets, periodic cells and clumps with the YADE law (issue 19).

1. With mu_k = mu_s and nu_s = 0 the law is the classic elastic-plastic (Cundall-Strack)
   spring, so it must reproduce YADE's native Law2_ScGeom_ViscElPhys_Basic with its own
   shear spring (ViscElMat ks, cs = 0, frictionAngle = atan(mu)) on the same kinematics:
   sphere pairs, a sphere on a still, translating and rotating facet, two spheres across
   a periodic boundary, a clump on a facet. The kinematics are imposed, so both runs see
   the same geometry and the forces compare step by step (tolerances derived per case).
2. What the law cannot handle is refused at the first step, naming it.
3. Three of the examples Debian's YADE ships, with the law swapped in at test time.
"""
import json
import math
import re
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

LAW = Path(__file__).resolve().parent.parent / "yade_law"
EXAMPLES = Path("/usr/share/doc/yade/examples")
import conftest  # noqa: E402
from conftest import needs_engine, skip_engine  # noqa: E402

pytestmark = needs_engine("yade")

KN, KS, MU, R, DT, DELTA = 1e4, 8e3, 0.4, 0.01, 1e-5, 1e-4

SCENE = """
import sys, json, math
sys.path.insert(0, {law!r})
from stickslip_yade import stickslip_engines, stickslip_material
from yade import *
from yade import utils
KN, KS, MU, R, DELTA = {kn!r}, {ks!r}, {mu!r}, {r!r}, {delta!r}
if mode == "native":  # the same normal law, YADE's own shear spring and Coulomb limit
    mat = O.materials.append(ViscElMat(kn=2 * KN, cn=0.0, ks=2 * KS, cs=0.0, frictionAngle=math.atan(MU), density=2600))
else:
    mat = O.materials.append(stickslip_material(KN, 0.0))

def held(b, vel=(0, 0, 0), ang=(0, 0, 0)):  # velocity imposed, as are the contact kinematics
    b.state.blockedDOFs = "xyzXYZ"
    b.state.vel, b.state.angVel = Vector3(*vel), Vector3(*ang)
    return O.bodies.append(b)

extra, spin = [], Vector3(0, 0, 0)
if scene.startswith("spheres"):
    held(utils.sphere((0, 0, 0), R, material=mat))
    n = Vector3(0.3, 0.2, 1).normalized()
    if scene == "spheres_rolling":  # spin across the normal: the lever arms matter, no twist
        spin = n.cross(Vector3(1, 0, 0)).normalized() * 30.0
    moving = held(utils.sphere(n * (2 * R - DELTA), R, material=mat), ang=spin)
    plan = [(300, (0.02, -0.01, 0.0)), (400, (-0.02, 0.015, 0.0))]
elif scene.startswith("facet"):
    f = O.bodies.append(utils.facet([(-0.1, -0.1, 0), (0.1, -0.1, 0), (0, 0.15, 0)], material=mat))
    moving = held(utils.sphere((0.01, 0.0, R - DELTA), R, material=mat))
    plan = [(300, (0.02, 0.01, 0.0)), (400, (-0.02, -0.005, 0.0))]
    if scene == "facet_translating":  # the facet moves under a still sphere
        extra, plan = [TranslationEngine(ids=[f], translationAxis=(1, 0.5, 0), velocity=0.02)], [(700, None)]
    elif scene == "facet_rotating":  # turning about its own normal through a point off the contact
        extra = [RotationEngine(ids=[f], rotationAxis=(0, 0, 1), angularVelocity=2.0, rotateAroundZero=True,
                                zeroPoint=(0, 0, 0))]
        plan = [(700, None)]
    elif scene == "facet_rolling":  # the sphere spinning about a tangent: its lever arm (midway in the overlap) counts
        O.bodies[moving].state.angVel = Vector3(0, 30.0, 0)
elif scene in ("periodic", "periodic_sheared"):  # two spheres touching across the x boundary of the cell
    O.periodic = True
    O.cell.setBox(0.1, 0.1, 0.1)
    if scene == "periodic_sheared":  # the cell sheared (v_y = 0.2 x): the image moves
        O.cell.velGrad = Matrix3(0, 0, 0, 0.2, 0, 0, 0, 0, 0)
    held(utils.sphere((0.005, 0.05, 0.05), R, material=mat))
    moving = held(utils.sphere((0.1 - 0.015 + DELTA, 0.05, 0.05), R, material=mat))
    plan = [(300, (0.0, 0.02, -0.01)), (400, (0.0, -0.02, 0.005))]
elif scene == "periodic_facet":  # a sphere on a facet through its image across z, the cell sheared (v_x = 0.2 z)
    O.periodic = True
    O.cell.setBox(0.1, 0.1, 0.1)
    O.cell.velGrad = Matrix3(0, 0, 0.2, 0, 0, 0, 0, 0, 0)
    O.bodies.append(utils.facet([(0.02, 0.02, 0.095), (0.08, 0.02, 0.095), (0.05, 0.08, 0.095)], material=mat))
    moving = held(utils.sphere((0.05, 0.04, 0.095 + R - DELTA - 0.1), R, material=mat))
    plan = [(300, (0.01, 0.005, 0.0)), (400, (-0.01, -0.0025, 0.0))]
elif scene == "clump":  # a clump of two spheres dragged and turned on a facet
    O.bodies.append(utils.facet([(-0.2, -0.2, 0), (0.2, -0.2, 0), (0, 0.3, 0)], material=mat))
    moving, _ = O.bodies.appendClumped([utils.sphere((-0.008, 0, R - DELTA), R, material=mat),
                                        utils.sphere((0.008, 0, R - DELTA), R, material=mat)])
    O.bodies[moving].state.blockedDOFs = "xyzXYZ"
    O.bodies[moving].state.angVel = Vector3(0, 0, 3.0)
    plan = [(300, (0.02, 0.01, 0.0)), (400, (-0.02, 0.0, 0.0))]
if mode == "native":
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom()],
                                 [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
                 *extra, NewtonIntegrator()]
else:  # the Python law ("law") or the compiled one ("cpp", YADE started through its launcher)
    O.engines = stickslip_engines(ks=KS, nu_s=0.0, mu_s=MU, mu_k=MU, extra=extra, check=mode == "law",
                                  backend="cpp" if mode == "cpp" else "python")
O.dt = {dt!r}
log = []
for steps, vel in plan:
    if vel is not None:
        O.bodies[moving].state.vel = Vector3(*vel)
    for _ in range(steps):
        O.step()
        row = {{}}
        for I in O.interactions:
            b1, b2 = O.bodies[I.id1].state, O.bodies[I.id2].state
            twist = 0.5 * abs(I.geom.normal.dot(b1.angVel + b2.angVel))  # spin of the pair about the normal
            arm = (b1.angVel.norm() + b2.angVel.norm()) * I.geom.penetrationDepth / 2
            if mode == "native":  # its shear force acts on id2; with cs = 0 it is the whole of it
                row[f"{{I.id1}}-{{I.id2}}"] = [I.phys.normalForce.norm(), list(-I.phys.shearForce), False, twist, arm]
            else:
                fn, ft, slipped, _ = stickslip_law.contact(I.id1, I.id2)
                row[f"{{I.id1}}-{{I.id2}}"] = [fn, list(ft), slipped, twist, arm]
        log.append(row)
"""


# Runs a case's script once per case in ONE YADE process, the scene reset before each
# (O.reset()): a YADE process costs ~1.2 s of CPU to start, more than most of these cases.
# Each case runs in a copy of the namespace YADE gives a script (its classes: Vector3, ...)
# with the case's names set (`case`, or `scene` and `mode`); what it leaves in the variable
# named third on the command line is the case's result.
BATCH = """
import sys, json
BASE = dict(globals())
CASES, CODE, RESULT_NAME = json.loads(sys.argv[1]), sys.argv[2], sys.argv[3]
out = []
for names in CASES:
    O.reset()
    space = dict(BASE, **names)
    exec(compile(open(CODE).read(), CODE, "exec"), space)
    out.append(space[RESULT_NAME])
print("RESULT " + json.dumps(out))
"""


def batch(name, code, cases, result_name, launcher="yade"):
    """{case: result} of `code` run for every case of `cases` (dicts of names) in one YADE
    process (started by `launcher`: the compiled law's for its cases), once per test session
    (conftest.shared_result)."""
    def make():
        folder = Path(tempfile.mkdtemp(prefix=name, dir=conftest.SHARED))
        (folder / "case.py").write_text(code)
        (folder / "batch.py").write_text(BATCH)
        got = yade(folder, folder / "batch.py", json.dumps(cases), folder / "case.py", result_name, launcher=launcher)
        return [json.dumps(c, sort_keys=True) for c in cases], got
    keys, got = conftest.shared_result(name, code + json.dumps(cases) + result_name + str(launcher), make)
    return dict(zip(keys, got))


def yade(tmp_path, script, *args, timeout=600, launcher="yade"):
    p = subprocess.run([str(launcher), "-n", "-x", str(script), *map(str, args)], capture_output=True, text=True,
                       timeout=timeout, cwd=tmp_path, env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)})
    got = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    assert p.returncode == 0 and got, p.stdout[-3000:] + p.stderr[-3000:]
    return json.loads(got[-1][7:])


def longest_stick(flags):
    """The longest run of consecutive steps without a slip."""
    best = run = 0
    for f in flags:
        run = 0 if f else run + 1
        best = max(best, run)
    return best + 1


SCENES = ["spheres", "spheres_rolling", "facet", "facet_translating", "facet_rotating", "facet_rolling", "periodic",
          "periodic_sheared", "periodic_facet",
          "clump"]
# The scenes YADE's native law is a reference for: in a cell that deforms, YADE 2023.02a's
# Law2_ScGeom_ViscElPhys_Basic adds the image's shift velocity with the wrong sign
# (yade_law/README.md), so its shear spring there loads with 2 shiftVel too much or too
# little; the law's V_s in a sheared cell is held by
# test_periodic_homogeneous_shear_loads_the_spring_with_the_image_motion instead.
NATIVE_SCENES = [s for s in SCENES if s not in ("periodic_sheared", "periodic_facet")]


def scene_runs(modes, launcher="yade"):
    """{(scene, mode): log} of every scene in each mode (native, law, cpp), one YADE process."""
    runs = batch("cundall-strack", SCENE.format(law=str(LAW), kn=KN, ks=KS, mu=MU, r=R, delta=DELTA, dt=DT),
                 [{"scene": s, "mode": m} for s in SCENES for m in modes], "log", launcher=launcher)
    return {(s, m): runs[json.dumps({"mode": m, "scene": s}, sort_keys=True)] for s in SCENES for m in modes}


@pytest.mark.parametrize("scene", NATIVE_SCENES)
def test_reproduces_native_cundall_strack(scene):
    runs = scene_runs(("native", "law"))
    like_native(scene, runs[scene, "native"], runs[scene, "law"])


def like_native(scene, native, law):
    """A law's run of a scene against YADE's native one, within the differences the contract
    keeps (below)."""
    assert len(native) == len(law) == 700
    fmax = MU * KN * DELTA * 1.01  # the largest friction force: mu*Fn, Fn ~ Kn*delta
    keys = set().union(*native)
    assert keys and keys == set().union(*law)
    for key in keys:
        rows = [(a[key], b[key]) for a, b in zip(native, law) if key in a or key in b]
        assert all(key in a and key in b for a, b in zip(native, law) if key in a or key in b), key
        nat = np.array([a[1] for a, _ in rows])
        ours = np.array([b[1] for _, b in rows])
        assert np.abs(nat).max() > 0.5 * MU * KN * DELTA  # the contact was loaded to its limit
        assert any(b[2] for _, b in rows) and not all(b[2] for _, b in rows)  # it stuck and slipped
        # Round-off and the native rule turning its spring with the normal (a first-order
        # rotation, |F| drifts by theta^2/2 per step; theta <= 1e-5 here): 1e-7 of mu*Fn.
        tol = 1e-7 * fmax
        # One difference the contract keeps (docs/law.md step 3), growing only while the
        # contact sticks (a slip puts both at mu*Fn): the native law turns its spring with
        # the pair's mean spin about the normal (ScGeom::rotate's twist), the law only
        # turns it into the tangent plane. Over the longest stick phase of N steps:
        # mu*Fn*max(twist)*dt*N. Both take lever arms to the contact point midway in the
        # overlap, r - delta/2, since issue 25: no allowance for arms, but on the clump, which
        # still parts from native by more than the twist allows (measured 1.32e-3 N against
        # 1.25e-3): there the old allowance Ks*max(|w| delta/2)*dt*N stays until the cause
        # (how each law moves a clump member's contact point) is pinned down.
        n_stick = longest_stick(b[2] for _, b in rows)
        twist = max(b[3] for _, b in rows)
        arm = max(b[4] for _, b in rows) if scene == "clump" else 0.0
        tol += (KS * arm + fmax * twist) * DT * n_stick
        err = np.abs(nat - ours).max()
        assert err <= tol, (key, err, tol)
        if arm == 0 and twist == 0:  # nothing the contract keeps apart: identical to round-off
            assert err <= 1e-7 * fmax


REFUSE = """
import sys, math
sys.path.insert(0, {law!r})
from stickslip_yade import stickslip_engines, stickslip_material, stickslip_runner, insert_stickslip
from yade import *
from yade import utils, geom
mat = O.materials.append(stickslip_material(1e4, 0.5))
O.bodies.append(geom.facetBox((0, 0, 0), (0.05, 0.05, 0.05), material=mat))
for k in range(3):
    O.bodies.append(utils.sphere((0.012 * k - 0.012, 0, 0), 0.005, material=mat))
law = dict(ks=8e3, nu_s=0.0, mu_s=0.5, mu_k=0.45)
loop = lambda ig2: InteractionLoop(ig2, [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()])
own = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]),
       loop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom()]), NewtonIntegrator(gravity=(0, 0, -9.81))]
if case == "no_facet_functor":  # the issue's case: spheres would fall through the facet box
    O.engines = own[:2] + [loop([Ig2_Sphere_Sphere_ScGeom()]), stickslip_runner(**law), own[3]]
elif case == "no_facet_bound":
    O.engines = [own[0], InsertionSortCollider([Bo1_Sphere_Aabb()])] + own[2:3] + [stickslip_runner(**law), own[3]]
elif case == "runner_after_newton":
    O.engines = own + [stickslip_runner(**law)]
elif case == "other_law2":
    O.engines = own[:2] + [InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom()],
                                           [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]),
                           stickslip_runner(**law), own[3]]
elif case == "friction_material":
    fr = O.materials.append(ViscElMat(kn=2e4, cn=1.0, ks=0, cs=0, frictionAngle=0.5, density=2600))
    for y in (0.02, 0.03 - 1e-6):  # (YADE's Ip2 takes the smaller friction angle of the two)
        O.bodies.append(utils.sphere((0, y, 0), 0.005, material=fr))
    O.engines = insert_stickslip(own, **law)
elif case == "unsupported_shape":
    O.bodies.append(utils.polyhedron([(0, 0, 0.02), (0.01, 0, 0.02), (0, 0.01, 0.02), (0, 0, 0.03)], material=mat))
    O.engines = stickslip_engines(**law)
elif case == "engine_added_later":
    O.engines = stickslip_engines(**law)
    O.dt = 1e-5
    for _ in range(10):
        O.step()
    O.engines = O.engines[:2] + [loop([Ig2_Sphere_Sphere_ScGeom()])] + O.engines[3:]
elif case == "fine":
    O.engines = insert_stickslip(own, **law)
O.dt = 1e-5
try:
    for _ in range(300):
        O.step()
    error = None
except RuntimeError:
    error = stickslip_law.error
"""


REFUSALS = [
    ("no_facet_functor", ["Facet", "no Ig2 functor for Facet-Sphere", "pass through"]),
    ("no_facet_bound", ["Facet", "no Bo1_Facet_Aabb"]),
    ("runner_after_newton", ["after the InteractionLoop and before NewtonIntegrator"]),
    ("other_law2", ["Law2_ScGeom_FrictPhys_CundallStrack", "Law2_ScGeom_ViscElPhys_Basic only"]),
    ("friction_material", ["tan(frictionAngle) = 0.546", "own tangential force"]),
    ("unsupported_shape", ["is a Polyhedra", "handles Sphere, Facet, Wall, Box"]),
    ("engine_added_later", ["no Ig2 functor for Facet-Sphere"]),
    ("fine", None),
]


@pytest.mark.parametrize("case,words", REFUSALS)
def test_what_the_law_cannot_handle_is_refused_naming_it(case, words):
    """Each case in a scene of its own (the batch resets the scene between them), the
    refusal at the first step that meets it."""
    errors = batch("refusals", REFUSE.format(law=str(LAW)), [{"case": c} for c, _ in REFUSALS], "error")
    error = errors[json.dumps({"case": case})]
    if words is None:
        assert error is None
        return
    assert error is not None and error.startswith("stick-slip law: "), error
    for w in words:
        assert w in error, error


# ---------------------------------------------------------------- YADE's shipped examples
def derive(example, replacements, steps, law, checks, before=r"NewtonIntegrator\(", backend="python"):
    """The installed example with the law swapped in: its text with `replacements`
    (regex, replacement) applied, the GUI left out, the law's runner put before
    NewtonIntegrator (backend "cpp": the example's engine list given to insert_stickslip, as
    a user of the compiled law would), then `steps` steps and a report of what the test
    checks."""
    text = (EXAMPLES / example).read_text()
    text = re.sub(r"^.*\bqt\b.*$", "", text, flags=re.M)  # no GUI (qt.View, qt.Renderer, imports)
    text = re.sub(r"^from __future__ import .*$", "", text, flags=re.M)  # Python 3 has them all
    text = re.sub(r"^(\s*)import gts,\s*", r"\1import ", text, flags=re.M)  # gts is not installed
    for pattern, repl in replacements:
        text, n = re.subn(pattern, repl, text, flags=re.M)
        assert n, f"{example}: {pattern!r} not found: the example changed"
    if backend == "python":
        text, n = re.subn(f"({before})", f"stickslip_runner({law}), \\1", text, flags=re.M)
        assert n == 1, f"{example}: one NewtonIntegrator expected in O.engines"
    head = (f"import sys, json\nsys.path.insert(0, {str(LAW)!r})\n"
            f"from stickslip_yade import stickslip_runner, stickslip_material, insert_stickslip\n")
    swap = f"O.engines = insert_stickslip(O.engines, {law}, backend='cpp')\n" if backend == "cpp" else ""
    tail = swap + f"""
import math as _m, builtins as _b  # (examples do `from numpy import *`, which shadows sum and all)
_n = len(O.bodies)
_e0 = _b.sum(b.state.mass * 10.0 * (b.state.pos[{checks['up']}] - {checks['bottom']}) for b in O.bodies if b.dynamic)
_ek, _most, _slips = [], 0, 0
for _k in range({steps}):
    O.step()
    _slips += int(stickslip_law.n_slipped)  # (contacts that slipped in the step)
    if _k % 50 == 0:
        _most = max(_most, stickslip_law.n_contacts())
        _ek.append(_b.sum(0.5 * b.state.mass * b.state.vel.squaredNorm() for b in O.bodies if b.dynamic))
_pos = [list(b.state.pos) for b in O.bodies if b is not None and b.dynamic and not b.isClump]
print("RESULT " + json.dumps({{"n0": _n, "n": len([b for b in O.bodies if b is not None]), "pos": _pos,
      "ek": _ek, "e0": _e0, "slips": _slips, "contacts": _most,
      "finite": _b.all(_m.isfinite(x) for p in _pos for x in p), "iter": O.iter}}))
"""
    return head + text + tail


@pytest.mark.parametrize("backend", ["python", "cpp"])
@pytest.mark.parametrize("example", ["baraban", "clump-inbox",  # 9 s, 5 s on the Python law; 3 s, 1 s compiled
                                     pytest.param("periodicSandPile", marks=pytest.mark.slow)])  # 35 s, 13 s
def test_shipped_examples_run_with_the_law(tmp_path, example, backend):
    """Variants of three of Debian's YADE examples, on the Python law and on the compiled
    one (the example's own engine list through insert_stickslip): a drum of facets turned by a
    RotationEngine (baraban/baraban.py), clumps and spheres falling into a facet box
    (clumps/clump-inbox-viscoelastic.py), spheres piling up on a box in a periodic cell, with
    contacts across the boundary (PeriodicBoundaries/periodicSandPile.py). The ViscEl
    examples keep their normal law (tc, en: frictionAngle = 0, so YADE adds no friction of
    its own); the sand pile's FrictMat becomes a stickslip_material of the same normal
    stiffness, kn = E r = 100 N/m, and its time stepper a fixed dt (0.1 sqrt(m/kn)); the law
    gets the examples' friction coefficient (tan 35 deg, tan 30 deg), mu_k = 0.9 mu_s.
    Checked: no error, no lost, escaped or non-finite body, slips (over 100 contact-steps that
    slipped in the run; contacts at zero or negative overlap, which YADE keeps with facets,
    are no contacts for the law and do not count: in clump-inbox they were 32 000 of the
    32 300 slips the law counted before issue 25), and
    kinetic energy below what the bodies started with plus the potential energy of their
    fall to the container's bottom."""
    if not EXAMPLES.is_dir():
        skip_engine("yade", "YADE's examples are not installed (/usr/share/doc/yade/examples)")
    launcher = "yade"
    if backend == "cpp":  # the compiled law: YADE started by its launcher
        skip_engine("yade_cpp")
        from stickslip.adapters.yade_cpp import LAUNCHER as launcher
    mu35 = math.tan(math.radians(35))
    law = f"ks=5e5, nu_s=0.0, mu_s={mu35:.6f}, mu_k={0.9 * mu35:.6f}"
    if example == "baraban":
        stl = EXAMPLES / "baraban" / "baraban.stl"
        text = derive("baraban/baraban.py", [(r"frictionAngle=frictionAngle", "frictionAngle=0"),
                                             (r"'baraban\.stl'", repr(str(stl)))], 5000, law, {"up": 1, "bottom": -5.0},
                      backend=backend)
        inside = lambda p: math.hypot(p[0], p[1]) <= 5.03  # noqa: E731 -- the drum's facets reach 5.02 m from its axis
    elif example == "clump-inbox":
        text = derive("clumps/clump-inbox-viscoelastic.py", [(r"frictionAngle=frictionAngle", "frictionAngle=0")],
                      16000, law, {"up": 2, "bottom": -1.0}, backend=backend)
        inside = lambda p: max(abs(p[0]), abs(p[1])) <= 1.0 and p[2] >= -1.0  # noqa: E731 -- the box, open on top
    else:
        mu30 = math.tan(math.radians(30))
        text = derive("PeriodicBoundaries/periodicSandPile.py", [
            (r"FrictMat\(density=1, young=1e5, poisson=0.3, frictionAngle=radians\(30\), label='boxMat'\)",
             "stickslip_material(100.0, 0.0, density=1, label='boxMat')"),
            (r"FrictMat\(density=1000, young=1e4, poisson=0.3, frictionAngle=radians\(30\), label='sphereMat'\)",
             "stickslip_material(100.0, 0.0, density=1000, label='sphereMat')"),
            (r"\[Ip2_FrictMat_FrictMat_FrictPhys\(\)\], \[Law2_ScGeom_FrictPhys_CundallStrack\(\)\]",
             "[Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]"),
            (r"^\s*GlobalStiffnessTimeStepper\(.*$", ""),
            (r"^O\.dt = 0\.2 \* PWaveTimeStep\(\)", "O.dt = 4e-4"),
        ], 3000, f"ks=25.0, nu_s=0.0, mu_s={mu30:.6f}, mu_k={0.9 * mu30:.6f}", {"up": 1, "bottom": 0.6},
            before=r"^\s*newton\s*$", backend=backend)
        # On the box, in the cell: x, z are periodic (any value); y too, with period 3*0.6 m
        # (a few spheres end one period down, also in the native example: 6 of 2000).
        inside = lambda p: p[1] % 1.8 >= 0.6 - 0.01  # noqa: E731
    script = tmp_path / "variant.py"
    script.write_text(text)
    r = yade(tmp_path, script, timeout=1200, launcher=launcher)
    assert r["n"] == r["n0"] and r["finite"] and all(inside(p) for p in r["pos"])
    assert r["contacts"] > 10 and r["slips"] > 100
    assert max(r["ek"]) <= r["e0"] + r["ek"][0]


SHEAR = """
import sys, json
sys.path.insert(0, {law!r})
from stickslip_yade import stickslip_engines, stickslip_material
from yade import O, Vector3, utils, Matrix3
mat = O.materials.append(stickslip_material(1e4, 1.0))
O.periodic = True
O.cell.setBox(0.1, 0.1, 0.1)
a = O.bodies.append(utils.sphere((0.05, 0.005, 0.05), 0.01, material=mat))
b = O.bodies.append(utils.sphere((0.05, 0.1 - 0.015 + 1e-4, 0.05), 0.01, material=mat))  # touches a across y
for i in (a, b):
    O.bodies[i].state.blockedDOFs = "xyzXYZ"  # they follow the cell's mean motion only
O.engines = stickslip_engines(ks=5e3, nu_s=0.0, mu_s=0.5, mu_k=0.45, check=True)
O.dt = 1e-5
O.cell.velGrad = Matrix3(0, 0.1, 0.02, 0, 0, 0, 0, 0, 0)  # simple shear of the cell
log = []
for _ in range(400):
    st = [O.bodies[i].state for i in (a, b)]
    kin = [list(s.pos) + list(s.angVel) for s in st]  # x(t), w(t - dt/2): what the law sees in the step
    O.step()
    H = O.cell.hSize  # YADE turns the cell at the start of a step: this is the cell the law saw
    kin.append([H[i, j] for i in range(3) for j in range(3)])
    got = stickslip_law.contact(a, b)
    log.append([kin, None if got is None else [list(got[1]), got[2]]])
print("RESULT " + json.dumps(log))
"""


def test_periodic_homogeneous_shear_loads_the_spring_with_the_image_motion(tmp_path):
    """Two spheres touching across a periodic boundary while the cell shears: the spring
    must follow the displacement of b's image (x_b + hSize @ cellDist, as positions and the
    cell evolve) relative to a, plus the spins' share (YADE spins bodies with the mean
    flow), step by step (leapfrog: a step's displacement over dt is the velocity the law
    saw). Recomputed here from positions, cell and spins, independently of the velocities
    the law uses: equal to round-off."""
    script = tmp_path / "shear.py"
    script.write_text(SHEAR.format(law=str(LAW)))
    log = yade(tmp_path, script)
    ks, r, dt = 5e3, 0.01, 1e-5
    cell = np.array([0, -1, 0])  # b's image is one period down in y
    D, prev, worst, fmax = np.zeros(3), None, 0.0, 0.0
    for kin, got in log:
        xa, wa, xb, wb = (np.array(kin[0][:3]), np.array(kin[0][3:]), np.array(kin[1][:3]), np.array(kin[1][3:]))
        H = np.array(kin[2]).reshape(3, 3)
        img = xb + H @ cell
        d = img - xa
        n = d / np.linalg.norm(d)
        if prev is not None:
            c = r - 0.5 * (2 * r - np.linalg.norm(d))  # lever arm to mid-overlap (docs/law.md step 1)
            step_rel = (xa - prev[0]) - (img - prev[1]) + dt * np.cross(c * wa + c * wb, n)
            if D.any():  # turned into the tangent plane keeping its length (docs/law.md step 3)
                L = np.linalg.norm(D)
                D = D - (D @ n) * n
                D *= L / np.linalg.norm(D)
            D = D + step_rel - (step_rel @ n) * n
            F = -ks * D
            assert got is not None and not got[1]  # it sticks: no slip within this run
            worst = max(worst, np.abs(np.array(got[0]) - F).max())
            fmax = max(fmax, np.abs(F).max())
        prev = (xa, img)
    # The spring grew to a good share of mu*Fn (Fn ~ Kn*1e-4 = 1 N) and matches.
    assert fmax > 0.01 and worst <= 1e-9 * fmax, (worst, fmax)
