# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for DEM-Engine (PyPI `deme`, Project Chrono's GPU DEM) with the force model of
deme_model/ (the law in deme_model/stick_slip.cu, attached by deme_model/stickslip_deme.py).

Runs in this process on the GPU: one DEMSolver per scene, the law with the linear normal
force (the paper's Table 2), the scene's slip timing and reset, and its record on (each
body's last contact kept in owner wildcards, read after every output row). DEM-Engine is
3D: 2D scenes run as "equivalent spheres" (docs/law.md, 2D: a sphere of the disk's mass per
unit thickness, motion held in the xy-plane by a prescribed vz = 0), rotation off as a
prescribed zero spin, imposed velocity components as prescribed ones. Walls are analytical
planes: fixed, or turned about their pivot with the angle of each step prescribed (pyref's,
Scene.rotation_steps and rotation_rate) and its rate as the plane's spin.

The engine takes positions and radii as float and subtracts its box's corner from a position
in float. Its frame is centred on the first wall's pivot (origin); grains sit on the
positions it holds exactly (float_step: 2^-23 of the box's half edge); and each wall is moved
along its normal by a few nanometres at most (wall_shift) so that the grain nearest to it has
the scene's overlap with its float radius. The paper's overlaps are 1e-5 of a radius: placed
as given, Fn would start 3 % low in the drag and 7 % high in the tilt, and ring.

What differs from the CPU engines (deme_model/README.md): float arithmetic, positions kept
on the engine's grid (its box / 2^37 per axis), the first step loads the spring (no set-up
evaluation: row 0 has zero contact forces, as LIGGGHTS'), the velocity reported is the
step's (v(t + dt/2)), and sums of many contact forces in an order that changes from run to
run (a one-grain scene has one contact: none). Supported: stick_slip scenes whose recorded
contacts are each the only contact of their first grain at a time (the record is per body),
fixed or turning plane walls, no output.stats, output.slip_stats, output.energy, turning
gravity, or spin in 2D.
"""
from __future__ import annotations

import importlib
import importlib.util
import math
import time

import numpy as np

from .. import columns, law_options, shipped
from . import RunResult

NAME = "deme"
GRAIN_FAMILY0 = 1  # grain k is family 1 + k
WALL_FAMILY0 = 200  # wall k is family 200 + k
MAX_GRAINS = GRAIN_FAMILY0 + WALL_FAMILY0 - 2 - 1  # (families are 8-bit; the engine keeps 255)


def helper():
    """deme_model/stickslip_deme.py: in a checkout loaded from its file (the folder is not a
    package); a wheel installs it as a module of its own."""
    path = shipped.CHECKOUT / "deme_model" / "stickslip_deme.py"
    if not path.is_file():
        return importlib.import_module("stickslip_deme")
    spec = importlib.util.spec_from_file_location("stickslip_deme", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _import_deme():
    import deme

    return deme


def available():
    if importlib.util.find_spec("deme") is None:
        return "PyPI package `deme` not installed (pip install -e '.[gpu]' brings deme[cuda12])"
    import ctypes

    try:
        ctypes.CDLL("libcuda.so.1")
    except OSError:
        return "no CUDA driver (libcuda.so.1 not found): DEM-Engine runs on an NVIDIA GPU only"
    try:
        _import_deme()
    except Exception as e:  # (the wheel's CUDA libraries, a driver too old, ...)
        return f"`import deme` fails: {str(e).splitlines()[0] if str(e) else type(e).__name__}"
    model = helper().MODEL_FILE
    if not model.is_file():
        return f"{model} missing"
    return None


def check_scene(scene):
    """ValueError, one line, for what this adapter does not run."""
    scene.refuse_unsupported("DEM-Engine")
    if scene.contact.law != "stick_slip":
        raise ValueError(f"the DEM-Engine force model implements stick_slip only, not {scene.contact.law}")
    out = scene.output
    for flag in ("energy", "stats", "slip_stats"):
        if getattr(out, flag):
            raise ValueError(f"output.{flag}: the DEM-Engine adapter does not record these columns")
    if scene.gravity_rate or scene.gravity_spinup[1]:
        raise ValueError("turning gravity: not supported by the DEM-Engine adapter")
    if scene.dimension == 2 and scene.effects["rotation"]:
        raise ValueError("effects.rotation in 2D: the equivalent sphere would need a disk's inertia; "
                         "the DEM-Engine adapter runs 2D scenes without rotation only")
    if len(scene.grains) > MAX_GRAINS:
        raise ValueError(f"{len(scene.grains)} grains: the DEM-Engine adapter gives each grain a family, "
                         f"at most {MAX_GRAINS}")
    for w in scene.walls:
        if np.any(w.velocity != 0):
            raise ValueError(f"wall {w.name}: a translating wall is not supported by the DEM-Engine adapter")
    firsts = [a for a, _ in out.contacts]
    if len(set(firsts)) != len(firsts) or any(a not in {g.name for g in scene.grains} for a in firsts):
        raise ValueError("output.contacts: the DEM-Engine record keeps one contact per grain; each recorded "
                         "contact must start with a grain of its own")


def _expr(x):
    return repr(float(x))


def _pivot(w):
    """The point a wall turns about: its pivot, or its own point if it does not turn."""
    return w.rotation.pivot if w.rotation is not None else w.point


def _unit_normal(w):
    return w.normal / np.linalg.norm(w.normal)


def origin(scene):
    """The scene point at the engine's origin, the centre of its box: the first wall's pivot
    (its point if it does not turn), else the first grain's centre."""
    if scene.walls:
        w = scene.walls[0]
        return np.array(_pivot(w))
    return np.array(scene.grains[0].position)


def domain(scene):
    """A cube centred on the engine's origin, in engine coordinates (scene minus origin), its
    edge a power of 2 at least 4x the grains' distance from the origin and reach: its corner,
    which the engine keeps as float, is then exact, and grid positions are exact binary
    fractions. (lo, hi) per axis."""
    o = origin(scene)
    dist = max(float(np.max(np.abs(g.position - o))) for g in scene.grains)
    reach = max(float(np.linalg.norm(g.velocity)) * scene.duration + 10 * g.radius for g in scene.grains)
    half = 2.0 ** math.ceil(math.log2(max(4 * (dist + reach), 1e-3)))
    return [(-half, half)] * 3


def float_step(scene):
    """The spacing of the positions the engine takes exactly: AddClumps, SetInitPos and a
    tracker's SetPos subtract the box's corner in float (position - corner, both float), so a
    position is held exactly only on multiples of 2^-23 of the box's half edge (the drag's:
    1.5e-8 m, half its static overlap); elsewhere it moves by up to half of that."""
    return domain(scene)[0][1] * 2.0 ** -23


def _snap(scene, x):
    step = float_step(scene)
    return np.round(np.asarray(x, float) / step) * step


def engine_position(scene, g):
    """A grain's centre in engine coordinates, on the float_step grid (where the engine holds
    it exactly): within float_step/2 of the scene's, a difference wall_shift takes up."""
    return [float(v) for v in _snap(scene, g.position - origin(scene))]


def wall_shift(scene, w):
    """How far along its normal the engine's plane is moved from the scene's so that the grain
    nearest to it has the scene's overlap with the engine's float radius and its centre on the
    grid: the paper's overlaps are 1e-5 of a radius, close to float's 2^-24 of one. Without
    it the drag's overlap would be 3.2 % smaller (its centre 0.95 nm higher on the grid, its
    float radius 0.1 nm larger), up to 28 % for a centre half a float_step away, and the
    grain would ring. s = (r - float(r)) + (c_engine - c) . n, c in engine coordinates. (The
    centre's move along the wall stays: a few nm, which changes no force on a plane.)"""
    n = _unit_normal(w)
    o, p = origin(scene), w.point
    g = min(scene.grains, key=lambda g: abs(float((g.position - p) @ n) - g.radius))
    c = g.position - o
    return (g.radius - float(np.float32(g.radius))) + float((np.array(engine_position(scene, g)) - c) @ n)


def wall_placement(scene, w):
    """A wall's owner (engine coordinates, on the float_step grid) and its plane's point
    relative to the owner: the pivot's remainder from the grid, the plane's offset from its
    pivot and wall_shift along the normal (float, small: exact to ~1e-15 m). The first wall's
    pivot is the origin, on the grid: it turns about its pivot exactly; another turning wall
    would turn about a point up to float_step/2 from its pivot."""
    n = _unit_normal(w)
    pivot = _pivot(w)
    pivot_e = pivot - origin(scene)
    owner = _snap(scene, pivot_e)
    rel = (pivot_e - owner) + (w.point - pivot) + wall_shift(scene, w) * n
    return [float(v) for v in owner], [float(v) for v in rel]


def turning_prescription(scene, w):
    """The turning wall's quaternion code and spin (expressions of the engine's t, the time at
    the start of the step whose end they set). The engine evaluates them after its force
    step k (1-based) for step k + 1, which pyref calls step k (its step 0 is the set-up):
    angle rate dt min(k, steps turning) = rate min(t + dt, stop time), spin while k <= steps
    turning, i.e. t < (steps - 1/2) dt."""
    rot, dt = w.rotation, scene.dt
    n, rate = scene.rotation_steps(w), scene.rotation_rate(w)
    a = rot.axis / np.linalg.norm(rot.axis)
    angle = f"(({_expr(rate)}) * fmin((double)t + {_expr(dt)}, {_expr(n * dt)}))"
    quat = (f"double ss_a = {angle}; double ss_s = sin(0.5 * ss_a); "
            f"return make_float4((float)({_expr(a[0])} * ss_s), (float)({_expr(a[1])} * ss_s), "
            f"(float)({_expr(a[2])} * ss_s), (float)cos(0.5 * ss_a));")
    turning = f"((double)t < {_expr((n - 0.5) * dt)})"
    spin = [f"({turning} ? {_expr(rate * c)} : 0.0)" for c in a]
    return quat, spin


def new_solver(deme):
    """A solver on the first GPU, quiet but for errors (DEM-Engine 3 takes the list of
    devices; earlier versions a count)."""
    try:
        solver = deme.DEMSolver([0])
    except TypeError:
        solver = deme.DEMSolver()
    solver.SetVerbosity("ERROR")
    return solver


def wall_angle(scene, w, step):
    """A wall's angle after `step` steps (0 for a fixed one): rate dt min(step, steps turning)."""
    if w.rotation is None:
        return 0.0
    return scene.rotation_rate(w) * scene.dt * min(step, scene.rotation_steps(w))


def build(scene, deme):
    """The solver for a checked scene, not yet initialised: (solver, {grain name: (tracker,
    family)}). The force model: stickslip_deme.attach(normal="hooke", record=True)."""
    ss = helper()
    c, eff = scene.contact, scene.effects
    p = c.law_params(eff)
    solver = new_solver(deme)
    ss.attach(solver, normal="hooke",
              **law_options.arguments("deme", reset=c.reset, slip_timing=c.slip_timing, record="yes"))
    mat = solver.LoadMaterial({"kn": p.kn, "nu_n": p.nu_n, "ks": p.ks, "nu_s": p.nu_s, "mu": p.mu_s, "mu_k": p.mu_k})
    box = domain(scene)
    solver.InstructBoxDomainDimension(*box)
    solver.InstructBoxDomainBoundingBC("none", mat)
    g3 = [float(v) for v in scene.gravity[:3]] if eff["gravity"] else [0.0, 0.0, 0.0]
    solver.SetGravitationalAcceleration(g3)
    grains = {}
    for k, g in enumerate(scene.grains):
        fam = GRAIN_FAMILY0 + k
        template = solver.LoadSphereType(scene.grain_mass(g), g.radius, mat)
        batch = solver.AddClumps(template, [engine_position(scene, g)])
        batch.SetVel([[float(v) for v in g.velocity]])
        batch.SetFamily(fam)
        if g.fixed:
            solver.SetFamilyFixed(fam)
        else:
            vel = [(_expr(g.velocity[i]) if a in g.imposed else "none") for i, a in enumerate("xyz")]
            if scene.dimension == 2:
                vel[2] = "0"
            if any(v != "none" for v in vel):
                solver.SetFamilyPrescribedLinVel(fam, *vel, False)
            if not eff["rotation"]:
                solver.SetFamilyPrescribedAngVel(fam, "0", "0", "0", False)  # the paper's no rolling
        grains[g.name] = (solver.Track(batch), fam)
    for k, w in enumerate(scene.walls):
        fam = WALL_FAMILY0 + k
        obj = solver.AddExternalObject()
        owner, rel = wall_placement(scene, w)
        obj.AddPlane(rel, [float(v) for v in w.normal], mat)
        obj.SetInitPos(owner)
        obj.SetMass(1.0)
        obj.SetFamily(fam)
        if w.rotation is None:
            solver.SetFamilyFixed(fam)
        else:
            quat, spin = turning_prescription(scene, w)
            solver.SetFamilyPrescribedPosition(fam, *[_expr(v) for v in owner])
            solver.SetFamilyPrescribedQuaternion(fam, quat)
            solver.SetFamilyPrescribedAngVel(fam, *spin)
    solver.SetTimeStepSize(scene.dt)
    solver.SetIntegrator("centered_difference")  # v(t + dt/2) = v + dt a, x += dt v(t + dt/2): leapfrog
    return solver, grains


def steps_duration(n, dt):
    """The duration to ask DoDynamics for n steps: the engine steps while its elapsed time,
    summed in its float time step (float(dt) differs from dt by up to 2^-24 relatively), is
    below the duration, so n dt may give n + 1 steps; (n - 1/2) dt gives n."""
    return (n - 0.5) * dt


def _record(solver, fam, ss):
    return ss.read_record(solver, fam)


def run(scene, out_dir, progress=None):
    check_scene(scene)
    deme = _import_deme()
    ss = helper()
    t0 = time.perf_counter()
    solver, grains = build(scene, deme)
    solver.Initialize()  # (compiles the kernels: minutes on a cold cache, deme_model/README.md)
    o = origin(scene)[:scene.dimension]
    t_init = time.perf_counter() - t0
    out, d, dt, every = scene.output, scene.dimension, scene.dt, scene.output.every
    rows = scene.steps // every
    t = np.arange(rows + 1) * every * dt
    x = np.zeros((rows + 1, len(out.grains), d))
    v = np.zeros_like(x)
    fn = np.zeros((rows + 1, len(out.contacts)))
    ft = np.zeros((rows + 1, len(out.contacts), d))
    slips = np.zeros((rows + 1, len(out.contacts)), dtype=int)
    last_count = np.zeros(len(out.contacts))
    # the recorded walls' angles: as prescribed (turning_prescription), pyref's of each step
    turning = [next(w for w in scene.walls if w.name == name) for name in out.walls]
    angle = np.array([[wall_angle(scene, w, r * every) for w in turning] for r in range(rows + 1)]).reshape(
        rows + 1, len(turning))

    def sample(r, step):
        for i, name in enumerate(out.grains):
            tracker, _ = grains[name]
            x[r, i] = np.asarray(tracker.Pos(), float)[:d] + o  # (engine frame to the scene's)
            v[r, i] = np.asarray(tracker.Vel(), float)[:d]
        for i, (a, _) in enumerate(out.contacts):
            if r == 0:
                continue  # no force evaluated yet (row 0: zero contact forces)
            rec = _record(solver, grains[a][1], ss)
            # evaluated in the last step (it began at (step - 1) dt): else not touching
            if rec["t"] >= (step - 1.5) * dt:
                fn[r, i] = rec["fn"]
                ft[r, i] = [rec["fx"], rec["fy"], rec["fz"]][:d]
                count = rec["slips"]
                slips[r, i] = count - last_count[i] if count >= last_count[i] else count  # (made again)
                last_count[i] = count
            else:
                last_count[i] = 0.0

    t1 = time.perf_counter()
    sample(0, 0)
    for r in range(1, rows + 1):
        solver.DoDynamicsThenSync(steps_duration(every, dt))
        sample(r, r * every)
        if progress is not None and (r % max(1, rows // 200) == 0 or r == rows):
            progress(r * every, scene.steps)
    wall = time.perf_counter() - t1
    for arr in (x, v, fn, ft):
        if not np.isfinite(arr).all():
            raise RuntimeError("DEM-Engine: a non-finite position, velocity or contact force")
    rec = _Recording(t, x, v, fn, ft, slips, angle)
    notes = [f"DEM-Engine: {t_init:.0f} s to initialise (JIT compile), {wall:.1f} s to run; float arithmetic"]
    return RunResult(columns.frame(scene, rec), scene.steps, wall, notes)


class _Recording:
    """The fields columns.frame reads (pyref.Recording's names)."""

    def __init__(self, t, x, v, fn, ft, slips, angle):
        self.t, self.x, self.v, self.fn, self.ft, self.slips, self.angle = t, x, v, fn, ft, slips, angle
