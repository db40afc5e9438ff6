#!/usr/bin/env python3
"""DEM-Engine on a GPU, in one run (tools/gpu_check.sh sets up `deme` and calls this):

  contract   every row of tests/law_contract.py on the engine, side by side in one solver
             (the force model's sweep: each row's coefficients, timing and reset per owner;
             positions, velocities and spins prescribed per family as the rows state them),
             against the hand-worked values (law_contract.compare, float) and the CPU
             shim's values (tests/deme_shim.py) for the same row
  drag, tilt the paper's cases through the adapter (stickslip/adapters/deme.py) against pyref,
             with bounds derived for float and the engine's start (see BOUNDS)
  bench      a bed of >= 500 000 spheres settling in a box: the stick-slip model (Hertz-Mindlin
             normal force) and the engine's own frictional Hertz-Mindlin, same bed, same
             steps, alternated in one process; the ratio per round and its spread (with
             --control also the engine's model against itself in two solvers: an A/A pair)
  spread     pyref's tilt with float-sized changes of its inputs: how far the final speed
             moves (the tilt's bound, BOUNDS)

    python3 tools/deme_gpu_check.py [--out DIR] [--deadline S] [--bench-grid N] [--rounds R]
    python3 tools/deme_gpu_check.py --part NAME --out DIR      (one part; what the above runs)

The parts run as parallel processes (each solver's JIT compile is minutes of one CPU core
on a cold cache: in parallel they overlap), each with its own DEME_JIT_CACHE_DIR under
--cache (the bench's two solvers share one: a second process compiles the stock model
while the bench compiles the stick-slip one, and the bench waits for it, so that both
compiles overlap). The bench times its rounds after the other GPU parts have finished.
Each part writes its JSON and log under --work; the summary is printed and written to
DIR/summary.txt, with every part's results (DIR/results.json) and logs (DIR/parts.log).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

PARTS = ("contract", "drag", "tilt", "bench", "warm_stock", "spread")
GPU_PARTS = ("contract", "drag", "tilt")  # the bench waits for these before it times
F32_EPS = 2.0 ** -23


# ---------------------------------------------------------------- contract rows on the engine
def segment_spans(case):
    """[(first step, last step, segment)] of a case, steps 1-based."""
    spans, first = [], 1
    for seg in case.segments:
        spans.append((first, first + seg.steps - 1, seg))
        first += seg.steps
    return spans


def _r(x):
    return repr(float(x))


def row_prescription(case, body, base):
    """Expressions of the engine's t (float, the time at the start of the step whose end they
    set) for body 0 (grain i) or 1 (grain j) of a contract row placed at `base`: (position,
    velocity, spin), each 3 strings. The engine's force step k (1-based) sees the initial state
    for k = 1, else the prescription evaluated at t = (k - 2) dt; it must give
    contract_runners._state of step k. A segment [a, b] then holds while t < (b - 3/2) dt; in
    a turn the step in the segment is k - a + 1 = t/dt + 3 - a."""
    import contract_runners as runners
    import law_contract as lc

    dt = lc.DT
    spans = segment_spans(case)
    pos, vel, spin = [[], [], []], [[], [], []], [[], [], []]
    start = runners.rest_positions(case, case.segments[0].delta)
    for a, b, seg in spans:
        if seg.omega:
            s = start[body]
            ang = f"({_r(seg.omega * dt)} * ((double)t / {_r(dt)} + {3 - a}.0))"
            x = [f"({_r(base[0])} + cos({ang}) * {_r(s[0])} - sin({ang}) * {_r(s[1])})",
                 f"({_r(base[1])} + sin({ang}) * {_r(s[0])} + cos({ang}) * {_r(s[1])})", _r(base[2] + s[2])]
            # v = omega z x (x - base)
            v = [f"(-{_r(seg.omega)} * (sin({ang}) * {_r(s[0])} + cos({ang}) * {_r(s[1])}))",
                 f"({_r(seg.omega)} * (cos({ang}) * {_r(s[0])} - sin({ang}) * {_r(s[1])}))", "0.0"]
            w = ["0.0", "0.0", _r(seg.omega)]
        else:
            xs, vs, _ = runners._state(case, seg, 1, start)
            x = [_r(base[i] + xs[body][i]) for i in range(3)]
            v = [_r(vs[body][i]) for i in range(3)]
            w = ["0.0", "0.0", "0.0"]
            start = runners.rest_positions(case, seg.delta)
        for lst, e in ((pos, x), (vel, v), (spin, w)):
            for i in range(3):
                lst[i].append((b, e[i]))
        if seg.omega:  # (a turn is a case's last segment; the next would start from its end)
            break

    def piecewise(pieces):
        expr = pieces[-1][1]
        for b, e in reversed(pieces[:-1]):
            expr = f"(((double)t < {_r((b - 1.5) * dt)}) ? {e} : {expr})"
        return expr
    return [piecewise(p) for p in pos], [piecewise(p) for p in vel], [piecewise(p) for p in spin]


def row_layout(cases):
    """Where each row sits: wall rows on the floor z = 0 in a grid 4 m apart, pair rows in a
    grid at z = 2 (the floor is an infinite plane: 1.5 m below them)."""
    out = []
    for k, case in enumerate(cases):
        z = 0.0 if case.geometry == "wall" else 2.0
        out.append((4.0 * (k % 8) - 14.0, 4.0 * (k // 8) - 14.0, z))
    return out


def run_contract(args, log):
    import numpy as np
    import contract_runners as runners
    import law_contract as lc
    import deme_shim
    from stickslip.adapters import deme as adapter

    deme = adapter._import_deme()
    ss = adapter.helper()
    cases = [deme_shim.float_case(c) for c in lc.CASES]
    bases = row_layout(cases)
    solver = adapter.new_solver(deme)
    ss.attach(solver, normal="hooke", sweep=True, record=True)
    mat = solver.LoadMaterial({"kn": lc.KN, "ks": lc.KS})
    solver.InstructBoxDomainDimension((-32.0, 32.0), (-32.0, 32.0), (-32.0, 32.0))
    solver.InstructBoxDomainBoundingBC("none", mat)
    solver.SetGravitationalAcceleration([0.0, 0.0, 0.0])
    sphere = solver.LoadSphereType(1000.0 * 4 / 3 * math.pi * lc.R ** 3, lc.R, mat)
    trackers, families = [], []
    for k, (case, base) in enumerate(zip(cases, bases)):
        x0 = runners.rest_positions(case, case.segments[0].delta)
        v0 = np.zeros_like(x0)
        v0[0] = case.segments[0].velocity
        bodies = []
        for body in range(len(x0)):
            fam = 1 + 2 * k + body
            batch = solver.AddClumps(sphere, [[float(base[i] + x0[body][i]) for i in range(3)]])
            batch.SetVel([[float(v) for v in v0[body]]])
            batch.SetFamily(fam)
            solver.SetFamilyExtraMargin(fam, 0.125)  # (a row's grains stay listed while 1/16 apart)
            moves = body == 0 or any(s.omega for s in case.segments)
            if moves:
                pos, vel, spin = row_prescription(case, body, base)
                solver.SetFamilyPrescribedPosition(fam, *pos)
                solver.SetFamilyPrescribedLinVel(fam, *vel)
                solver.SetFamilyPrescribedAngVel(fam, *spin)
            else:
                solver.SetFamilyFixed(fam)
            bodies.append(solver.Track(batch))
        trackers.append(bodies[0])
        families.append([1 + 2 * k + b for b in range(len(x0))])
    floor = solver.AddExternalObject()
    floor.AddPlane([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], mat)
    floor.SetMass(1.0)
    floor.SetFamily(250)
    solver.SetFamilyFixed(250)
    solver.SetTimeStepSize(lc.DT)
    solver.SetIntegrator("centered_difference")
    solver.SetMaxVelocity(80.0)
    t0 = time.perf_counter()
    solver.Initialize()
    t_init = time.perf_counter() - t0
    log(f"contract: initialised in {t_init:.0f} s")
    for case, fams in zip(cases, families):
        for fam in fams:
            ss.set_family_coefficients(solver, fam, mu_s=case.mu_s, mu_k=case.mu_k, nu_n=case.nu_n, nu_s=case.nu_s,
                                       slip_timing=case.timing, reset=case.reset)
    owner = [int(tr.GetOwnerID()) for tr in trackers]
    steps = max(c.steps for c in cases)
    traces = [runners._empty(c.steps) for c in cases]
    names = ss.RECORD_WILDCARDS
    t1 = time.perf_counter()
    for k in range(steps):
        solver.DoDynamicsThenSync(adapter.steps_duration(1, lc.DT))
        vals = {n: solver.GetAllOwnerWildcardValue(n) for n in names}
        for c, case in enumerate(cases):
            if k >= case.steps:
                continue
            o = owner[c]
            if vals["ss_rec_t"][o] < (k - 0.5) * lc.DT:
                continue  # not evaluated in this step (it began at k dt): apart
            tr = traces[c]
            tr["fn"][k] = vals["ss_rec_fn"][o]
            tr["F"][k] = [vals[n][o] for n in ("ss_rec_fx", "ss_rec_fy", "ss_rec_fz")]
            tr["D"][k] = [vals[n][o] for n in ("ss_rec_dx", "ss_rec_dy", "ss_rec_dz")]
            tr["slips"][k] = int(vals["ss_rec_slips"][o])
    log(f"contract: {steps} steps in {time.perf_counter() - t1:.1f} s")
    results = []
    for case, tr in zip(cases, traces):
        results.append(judge_row(case, tr))
    return {"init_s": t_init, "rows": results}


def normals(case):
    """The law's normal (i to j) at each step of a row, from its prescribed states."""
    import numpy as np
    import contract_runners as runners

    out, start, k = np.zeros((case.steps, 3)), runners.rest_positions(case, case.segments[0].delta), 0
    for seg in case.segments:
        begin = start
        for s in range(1, seg.steps + 1):
            x, _, _ = runners._state(case, seg, s, begin)
            if case.geometry == "wall":
                out[k] = (0.0, 0.0, -1.0)
            else:
                d = x[1] - x[0]
                out[k] = d / np.linalg.norm(d)
            k += 1
        start = x
    return out


def judge_row(case, trace):
    """A row's verdict: the law's hand values (float ulps), the CPU shim's trace (the largest
    difference in float ulps of the row's largest force or spring), and, if it fails, whether
    the engine's trace matches one step earlier or later (a misplaced prescription)."""
    import numpy as np
    import deme_shim
    import law_contract as lc

    trace["n"] = normals(case)
    out = {"row": case.name}
    try:
        lc.compare(case, trace, dtype=np.float32)
        out["contract"] = "pass"
    except AssertionError as e:
        out["contract"] = "FAIL " + str(e)[:300]
        for shift in (-1, 1):
            moved = {q: (np.roll(v, shift, axis=0) if v is not None else None) for q, v in trace.items()}
            try:
                lc.compare(case, moved, dtype=np.float32)
                out["contract"] += f" (matches shifted by {shift} step)"
            except AssertionError:
                pass
    try:
        cpu = deme_shim.run_case(case, sweep=True)
        scale = max(np.nanmax(np.abs(cpu["F"])), np.nanmax(np.abs(cpu["D"])), 1e-30)
        worst = 0.0
        for q in ("F", "D", "fn"):
            a, b = np.asarray(trace[q], float), np.asarray(cpu[q], float)
            both = np.isfinite(a) & np.isfinite(b)
            if (np.isfinite(a) != np.isfinite(b)).any():
                worst = math.inf
            if both.any():
                worst = max(worst, float(np.max(np.abs(a[both] - b[both]))) / (scale * F32_EPS))
        same_slips = bool(np.array_equal(trace["slips"], cpu["slips"]))
        out["vs_cpu_ulps"] = worst
        out["vs_cpu_slips_equal"] = same_slips
    except Exception as e:  # (no compiler on the machine, ...)
        out["vs_cpu_ulps"] = None
        out["vs_cpu_error"] = f"{type(e).__name__}: {e}"[:200]
    return out


# ---------------------------------------------------------------- the paper's cases
# Bounds of DEM-Engine against pyref on the paper's one-grain cases (one contact: no
# reordered sums). The engine starts without pyref's set-up evaluation, so its spring is one
# step's load ahead (Ks V dt) and its slips may come one step apart; it reports v(t + dt/2)
# (a dt/2 apart from pyref's v(t)); float rounds Fn, F and the threshold at 2^-24
# relatively; positions sit on a grid of box/2^37 (deme.domain: the drag's 0.25 m box,
# 1.8e-12 m, 7e-5 of its static overlap; the adapter places the grain so that its overlap
# is the scene's, stickslip/adapters/deme.py). On a plane the force model takes the grain's
# distance in double along the normal made unit (deme_model/stick_slip.cu, step 0), not the
# engine's float distance (steps of ulp(r), 0.9 % of the drag's overlap and 0.3 % of the
# tilt's) along its float normal. What stays is the plane's float orientation: a turning
# plate's quaternion is cast to float each step, so its normal points ~2e-8 rad off, anew each
# step, and the plate moves under the grain's foot by that times the foot's distance from the
# pivot (2 mm at the tilt's end); the normal oscillator, damped little (restitution 0.96),
# rings with it. float_ring measures that ring on the CPU emulation of the engine's geometry.
def emulated(sc):
    """The scene's run on the engine's float geometry with the model's own distance, emulated
    on the CPU (tools/deme_plane_emulation.py, the force model through its shim), recorded as
    the scene is (its output.every): its timeseries."""
    import deme_plane_emulation as emulation
    from stickslip import columns

    return columns.frame(sc, emulation.emulate(sc, model_distance=True))


def ring_of(spread):
    """How far Fn strays relatively before the first slip, from fn_spread's figures:
    max |Fn / (W cos beta) - 1|."""
    return max(1.0 - spread["min"], spread["max"] - 1.0)


def float_ring(sc):
    """Fn's ring on the emulated float geometry (emulated, ring_of), pyref's own start
    included (3.7e-4 on both cases): the drag's fixed plane has an exact normal, pyref's
    ring; the tilt's turning one rings by ~0.3 %."""
    return ring_of(fn_spread(sc, emulated(sc)))


def drag_bounds(sc, e):
    """The drag's: one step's load (inc) and the grid (2e-4, with a margin of 2) as before,
    and Fn a relative e (float_ring) from pyref's: |Fs|/Fn after a slip (Fmin set on the Fn of
    the slip, read on the next) by mu_s e; the threshold mu_s Fn, so the first slip, by
    mu_s Fn e / (Ks V); the period (2 (mu_s - mu_k) Fn / (Ks V)) by e of itself. The mean Fn
    stays pyref's: the grain rocks about its rest."""
    p = sc.contact
    g = sc.grains[0]
    speed = float(abs(g.velocity[0]))
    fn = sc.grain_mass(g) * 9.81
    inc = p.ks * speed * sc.dt / fn  # one step's load, in |Fs|/Fn
    grid = 2e-4  # the overlap's grid (7e-5) and float, with a margin of 2
    first = p.mu_s * fn * e / (p.ks * speed)
    period = 2 * (p.mu_s - p.mu_k) * fn / (p.ks * speed) * e
    return {"fs_fn_max": inc + grid, "fs_fn_min": inc + grid + p.mu_s * e, "fs_fn_mean": inc + grid + p.mu_s * e,
            "fn_mean_N": grid * fn, "first_slip_s": 2 * sc.dt + first, "slip_period_s": 2 * sc.dt + period,
            "slip_count": 1}


def compare_case(name, args, log):
    from stickslip import analysis, columns
    from stickslip import scene as scene_mod
    from stickslip.adapters import deme as adapter
    from pyref import Simulation

    sc = scene_mod.load(name)
    if name == "tilt":
        sc.output.every = args.tilt_every  # (the engine is read back once a row: ~20 ms a call)
    t0 = time.perf_counter()
    res = adapter.run(sc, Path(args.work) / name)
    t_run = time.perf_counter() - t0
    df = res.timeseries
    df.to_csv(Path(args.work) / f"{name}_deme.csv.gz", index=False)
    ref = columns.frame(sc, Simulation(sc).run())
    s_d, s_p = analysis.summarise(sc, df), analysis.summarise(sc, ref)
    log(f"{name}: DEM-Engine {t_run:.0f} s with its initialisation ({res.notes[0]})")
    t0 = time.perf_counter()
    try:
        emu = emulated(sc)
        f_e, s_e = fn_spread(sc, emu), analysis.summarise(sc, emu)
        ring = ring_of(f_e)
        log(f"{name}: Fn's ring on the emulated float geometry {ring:.3g} ({time.perf_counter() - t0:.0f} s, CPU)")
    except Exception as e:  # (the CPU shim neither carried nor built: the ring's bounds nan, their rows OUT)
        f_e, ring, s_e = {}, math.nan, {}
        log(f"{name}: no emulated float geometry, so no bounds that take Fn's ring: {type(e).__name__}: {e}"[:400])
    if name == "drag":
        bounds = drag_bounds(sc, ring)
    else:
        spread = wait_json(Path(args.work) / "spread.json", args.t0 + args.deadline - 20 - time.time())
        bounds = tilt_bounds(sc, spread, s_p, ring)
    rows = []
    for key, bound in bounds.items():
        a, b = s_d.get(key), s_p.get(key)
        ok = a is not None and b is not None and abs(a - b) <= bound
        rows.append({"quantity": key, "deme": a, "pyref": b, "diff": None if a is None or b is None else a - b,
                     "bound": bound, "ok": bool(ok), "emulated": s_e.get(key)})
    return {"wall_s": t_run, "notes": res.notes, "rows": rows, "float_ring": ring, "deme_summary": _plain(s_d),
            "pyref_summary": _plain(s_p),
            "fn": {"deme": fn_spread(sc, df), "emulated": f_e, "pyref": fn_spread(sc, ref)}}


def sticking_fn_over_weight(sc, df):
    """The recorded contact's Fn while it sticks before the first slip (rows 1 on), over the
    weight's normal share W cos(angle) (the tilt's plate turns): (times, ratios)."""
    import numpy as np

    c = "-".join(sc.output.contacts[0])
    fn = df[f"{c}_fn"].to_numpy()
    first = np.flatnonzero(df[f"{c}_slip"].to_numpy() > 0)
    end = first[0] if len(first) else len(fn)
    angle = df[f"{sc.output.walls[0]}_angle"].to_numpy() if sc.output.walls else np.zeros(len(fn))
    w = sc.grain_mass(sc.grains[0]) * 9.81 * np.cos(angle)
    return df["t"].to_numpy()[1:end], (fn / w)[1:end]


def fn_spread(sc, df):
    """sticking_fn_over_weight's first value, least and most: how far the start rings."""
    _, rel = sticking_fn_over_weight(sc, df)
    return {"first": float(rel[0]), "min": float(rel.min()), "max": float(rel.max())} if len(rel) else {}


def tilt_bounds(sc, spread, ref, ring):
    """The tilt (read every `every` steps): the first slip in the same row or the next (two
    steps apart at most: the spring one step's load ahead, the threshold's float rounding,
    well under a step's turn of the plate); and Fn a relative `ring` (float_ring) from
    pyref's: the slip, where mu_s Fn first falls to the load, at tan(beta) = mu_s (1 +- ring),
    so by mu_s ring in tan(beta) and mu_s ring / (d tan/dt >= the plate's rate) in time. The
    final speed within
      3 x pyref's own spread under float-sized input changes (part spread: the stick-slip
          phase is a sequence of slips a rounding could move),
      + g dt/2 (the engine reports v(t + dt/2), pyref v(t)),
      + the float rounding of the velocity's sum over the steps after the first slip
          (2^-24 |v| a step at worst),
      + the first slip's bound in time times the steady sliding's acceleration (the grain
          slides that much longer or shorter).
    The start's differences (the engine's first step loads the spring) end at the first slip,
    which resets the spring (eq. 8)."""
    dt, every = sc.dt, sc.output.every
    w = sc.walls[0]
    tan_rate = sc.rotation_rate(w) / math.cos(w.rotation.stop_angle) ** 2  # d tan(beta)/dt at most, 1/s
    e = sc.contact.mu_s * ring
    t_first = every * dt + e / sc.rotation_rate(w) + 1e-12
    v_spread = spread.get("final_speed_spread", math.nan) if spread else math.nan
    t1, v1 = ref.get("t_first_slip_s") or 0.0, abs(ref.get("final_speed_mps") or 0.0)
    sliding = (sc.duration - t1) / dt * 2 ** -24 * v1
    accel = ref.get("accel_steady_expected_mps2") or 0.0
    speed = (3 * v_spread if math.isfinite(v_spread) else 0.0) + 9.81 * dt / 2 + sliding + accel * t_first
    return {"t_first_slip_s": t_first, "tan_beta_first_slip": every * dt * tan_rate + e + 1e-9,
            "final_speed_mps": speed}


def run_spread(args, log):
    """pyref's tilt and four runs with one input changed by a float rounding: mu_s and kn by
    2^-23 relative up and down, and the grain's start by the engine's grid step
    (0.5 m / 2^37). The largest change of the final speed is the tilt's spread."""
    from concurrent.futures import ProcessPoolExecutor

    changes = [None, ("mu_s", 1 + F32_EPS), ("mu_s", 1 - F32_EPS), ("kn", 1 + F32_EPS), ("y0", 0.5 / 2 ** 37)]
    with ProcessPoolExecutor(len(changes)) as pool:
        speeds = list(pool.map(_tilt_final_speed, changes))
    spread = max(abs(v - speeds[0]) for v in speeds[1:])
    log(f"spread: pyref tilt final speed {speeds[0]:.6f} m/s, changed inputs move it by up to {spread:.2e}")
    return {"final_speeds": speeds, "changes": [str(c) for c in changes], "final_speed_spread": spread}


def _tilt_final_speed(change):
    from stickslip import columns, analysis
    from stickslip import scene as scene_mod
    from pyref import Simulation

    sc = scene_mod.load("tilt")
    if change is not None:
        what, f = change
        if what == "y0":
            sc.grains[0].position[1] += f
        else:
            setattr(sc.contact, what, getattr(sc.contact, what) * f)
    df = columns.frame(sc, Simulation(sc).run())
    return float(analysis.summarise(sc, df)["final_speed_mps"])


# ---------------------------------------------------------------- the bench
def bed(grid):
    """A lattice of grid^3 spheres (r 1 mm, 1 % gaps) in a box open at the top."""
    r = 1e-3
    step = 2.02 * r
    span = grid * step
    xs = [(i + 0.5) * step - span / 2 for i in range(grid)]
    pts = [[x, y, (k + 0.5) * step + 1e-4] for k in range(grid) for y in xs for x in xs]
    return r, span, pts


def bench_solver(deme, kind, grid, dt, cd_freq=0):
    """One solver of the bench: kind "stickslip" (the force model, Hertz-Mindlin normal force,
    mu 0.5, mu_k 0.45) or "stock" (the engine's frictional Hertz-Mindlin, mu 0.5). cd_freq 0:
    the engine's own scheduling of contact detection (adaptive); N > 0: detection every N
    steps and the engine's first bin size kept, for both (DisableAdaptiveUpdateFreq,
    DisableAdaptiveBinSize), which leaves the force model's cost alone."""
    from stickslip.adapters import deme as adapter

    ss = adapter.helper()
    solver = adapter.new_solver(deme)
    props = {"E": 1e8, "nu": 0.3, "CoR": 0.9, "mu": 0.5}
    if kind == "stickslip":
        ss.attach(solver, normal="hertz")
        props["mu_k"] = 0.45
    else:
        solver.UseFrictionalHertzianModel()
        props["Crr"] = 0.0
    mat = solver.LoadMaterial(props)
    r, span, pts = bed(grid)
    half = span / 2 + 4 * r
    solver.InstructBoxDomainDimension((-half, half), (-half, half), (0.0, 2 * span + 8 * r))
    solver.InstructBoxDomainBoundingBC("top_open", mat)
    sphere = solver.LoadSphereType(2600 * 4 / 3 * math.pi * r ** 3, r, mat)
    solver.AddClumps(sphere, pts)
    solver.SetGravitationalAcceleration([0.0, 0.0, -9.81])
    solver.SetTimeStepSize(dt)
    solver.SetMaxVelocity(2.0)
    if cd_freq > 0:
        solver.SetCDUpdateFreq(cd_freq)
        solver.DisableAdaptiveUpdateFreq()
        # (an adaptive bin size hill-climbs on detection's wall time from a random start: the
        # two solvers' bins climbed to 0.0029 m and 0.0040 m, and their integration times parted)
        solver.DisableAdaptiveBinSize()
    return solver, len(pts)


def run_warm_stock(args, log):
    """Compiles the bench's stock solver into the shared cache, then leaves (marker file)."""
    from stickslip.adapters import deme as adapter

    deme = adapter._import_deme()
    solver, n = bench_solver(deme, "stock", args.bench_grid, 2e-6)
    t0 = time.perf_counter()
    solver.Initialize()
    log(f"warm_stock: stock model compiled in {time.perf_counter() - t0:.0f} s")
    return {"init_s": time.perf_counter() - t0}


def printed(call):
    """What a call of the engine prints (C printf, on file descriptor 1), as text."""
    import ctypes
    import tempfile

    sys.stdout.flush()
    libc = ctypes.CDLL(None)
    with tempfile.TemporaryFile(mode="w+") as tmp:
        saved = os.dup(1)
        os.dup2(tmp.fileno(), 1)
        try:
            call()
        finally:
            libc.fflush(None)
            os.dup2(saved, 1)
            os.close(saved)
        tmp.seek(0)
        return tmp.read()


def engine_stats(text):
    """The engine's own statistics (ShowThreadCollaborationStats, ShowTimingStats) as numbers:
    {"Number of updates kinematic gets": 40.0, ..., "dT: Calculate contact forces": 1.2, ...}
    (timers in seconds, each thread's under its prefix)."""
    import re

    stats, thread = {}, ""
    for line in text.splitlines():
        if "kT TIMING" in line:
            thread = "kT: "
        elif "dT TIMING" in line:
            thread = "dT: "
        m = re.match(r"\s*([^:~]+):\s*([-+0-9.eE]+)", line)
        if m:
            stats[thread + m.group(1).strip()] = float(m.group(2))
    return stats


# The bench's pairs of solvers: (label, kind) of the model timed, then of the one it is
# divided by. CONTROL is an A/A pair: the engine's model against itself in a second solver,
# so that its ratios' spread is what the engine's own scheduling gives two equal solvers.
PAIR = (("stickslip", "stickslip"), ("stock", "stock"))
CONTROL = (("stock_a", "stock"), ("stock_b", "stock"))
SHOWN = {"stickslip": "stick-slip", "stock": "stock", "stock_a": "stock (a)", "stock_b": "stock (b)"}


def _bench_pair(args, deme, log, cd_freq, wait, pair=PAIR):
    """The two solvers of `pair` on the same bed: initialise, settle, then `rounds` blocks of
    each, alternated; block times, contacts, the engine's update frequency after each block and
    its own statistics over the rounds. The ratio is the first's time over the second's."""
    from stickslip.adapters import deme as adapter
    from stickslip.bench.ratio_interval import ratio_interval
    import statistics

    dt, steps = 2e-6, args.bench_steps
    (a, _), (b, _) = pair
    out = {"spheres": args.bench_grid ** 3, "dt": dt, "steps_per_block": steps, "settle_steps": args.settle_steps,
           "cd_freq": cd_freq or "adaptive", "pair": [a, b], "init_s": {}}
    solvers = {}
    for label, kind in pair:
        if kind == "stock" and "stock_cache_warmed" not in out:  # the pair's first stock solver
            if "warm_stock" in args.parts:
                # (the stock model's compile, warm_stock, runs beside the first's: wait for it,
                # but leave time for a cold compile here and the rounds)
                wait_json(Path(args.work) / "warm_stock.json", args.t0 + args.deadline - 200 - time.time())
            out["stock_cache_warmed"] = (Path(args.work) / "warm_stock.json").is_file()
        solvers[label], _ = bench_solver(deme, kind, args.bench_grid, dt, cd_freq)
        t0 = time.perf_counter()
        solvers[label].Initialize()
        out["init_s"][label] = time.perf_counter() - t0
        log(f"bench ({out['cd_freq']}): {SHOWN[label]} initialised in {out['init_s'][label]:.0f} s")
    for s in solvers.values():  # settle (the bed falls the 1 % gaps and starts its contacts)
        s.DoDynamicsThenSync(adapter.steps_duration(args.settle_steps, dt))
    out["gpu_to_itself"] = wait()
    for s in solvers.values():
        s.ClearTimingStats()
        s.ClearThreadCollaborationStats()
    times, contacts, freq, bins = ({a: [], b: []} for _ in range(4))
    for rnd in range(args.rounds):
        for label in ((a, b) if rnd % 2 == 0 else (b, a)):
            s = solvers[label]
            t0 = time.perf_counter()
            s.DoDynamicsThenSync(adapter.steps_duration(steps, dt))
            times[label].append(time.perf_counter() - t0)
            contacts[label].append(int(s.GetNumContacts()))
            freq[label].append(float(s.GetUpdateFreq()))
            # (its adaptive bin size, on unless disabled, hill-climbs on detection's wall time
            # from a random start: one of the states that can set a solver's cost apart)
            bins[label].append(float(s.GetBinSize()))
        log(f"bench ({out['cd_freq']}): round {rnd + 1}: {SHOWN[a]} {times[a][-1]:.3f} s, "
            f"{SHOWN[b]} {times[b][-1]:.3f} s")
    out["engine_stats"], out["engine_text"] = {}, {}
    for label, s in solvers.items():
        text = printed(lambda: (s.ShowThreadCollaborationStats(), s.ShowTimingStats()))
        out["engine_text"][label], out["engine_stats"][label] = text, engine_stats(text)
    ratios = [x / y for x, y in zip(times[a], times[b])]
    # the geometric mean of the rounds' ratios and its 95 % interval over rounds (the CPU
    # engines' benchmarks do the same: stickslip/bench/ratio_interval.py)
    out["ratio_geomean"], out["ratio_low"], out["ratio_high"] = ratio_interval(list(zip(times[b], times[a])))
    out.update(times=times, contacts=contacts, update_freq=freq, bin_size=bins, ratios=ratios,
               ratio_mean=statistics.mean(ratios), ratio_min=min(ratios), ratio_max=max(ratios),
               ms_per_step={k: [1e3 * t / steps for t in v] for k, v in times.items()})
    return out


def run_bench(args, log):
    """The bench with the engine's scheduling of contact detection, then (--cd-freq N) with
    detection every N steps for both models, then (--control) the A/A pair with the engine's
    scheduling, one pair of solvers after the other."""
    import gc
    from stickslip.adapters import deme as adapter

    deme = adapter._import_deme()
    others = [p for p in GPU_PARTS if p in args.parts]
    pairs = 1 + (args.cd_freq > 0) + args.control
    out = _bench_pair(args, deme, log, 0, lambda: wait_parts(
        args, others, args.t0 + args.deadline - 30 - 8 * args.rounds * pairs - time.time()))
    if args.cd_freq > 0:
        gc.collect()
        out["fixed_cd"] = _bench_pair(args, deme, log, args.cd_freq, lambda: wait_parts(args, others, 0))
    if args.control:
        gc.collect()
        out["control"] = _bench_pair(args, deme, log, 0, lambda: wait_parts(args, others, 0), pair=CONTROL)
    return out


# ---------------------------------------------------------------- orchestration
def wait_json(path, timeout):
    """The JSON a part wrote, waiting up to `timeout` s for it (None if it never came)."""
    end = time.time() + timeout
    while time.time() < end:
        if path.is_file():
            try:
                return json.loads(path.read_text())
            except json.JSONDecodeError:
                pass
        time.sleep(1.0)
    return None


def wait_parts(args, parts, timeout):
    """True once every part of `parts` has ended (its .done marker), False at the timeout
    (looked at once at least)."""
    end = time.time() + timeout
    while True:
        if all((Path(args.work) / f"{p}.done").exists() for p in parts):
            return True
        if time.time() >= end:
            return False
        time.sleep(1.0)


def _plain(d):
    return {k: (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v) for k, v in d.items()
            if isinstance(v, (int, float, str, type(None), bool))}


RUNNERS = {"contract": run_contract, "drag": lambda a, log: compare_case("drag", a, log),
           "tilt": lambda a, log: compare_case("tilt", a, log), "bench": run_bench, "warm_stock": run_warm_stock,
           "spread": run_spread}


def run_part(args):
    out = Path(args.work)
    out.mkdir(parents=True, exist_ok=True)

    def log(msg):
        print(f"[{time.strftime('%H:%M:%S')}] {msg}", flush=True)
    try:
        result = RUNNERS[args.part](args, log)
        result["ok"] = True
    except Exception as e:
        traceback.print_exc()
        result = {"ok": False, "error": f"{type(e).__name__}: {e}"[:2000]}
    (out / f"{args.part}.json").write_text(json.dumps(result, indent=1, default=str))
    return 0


def orchestrate(args):
    out = Path(args.work)
    out.mkdir(parents=True, exist_ok=True)
    # (an earlier run's files in the same work folder would pass for this run's)
    for old in list(out.glob("*.done")) + list(out.glob("*.json")) + list(out.glob("*_deme.csv.gz")):
        old.unlink()
    t_start = args.t0 = time.time()
    procs = {}
    for part in args.parts:
        env = dict(os.environ)
        cache = Path(args.cache) / ("bench" if part in ("bench", "warm_stock") else part)
        cache.mkdir(parents=True, exist_ok=True)
        env["DEME_JIT_CACHE_DIR"] = str(cache)
        logf = open(out / f"{part}.log", "w")
        cmd = [sys.executable, __file__, "--part", part, "--work", str(out), "--deadline", str(args.deadline),
               "--bench-grid", str(args.bench_grid), "--rounds", str(args.rounds), "--t0", repr(t_start),
               "--tilt-every", str(args.tilt_every), "--bench-steps", str(args.bench_steps),
               "--settle-steps", str(args.settle_steps), "--cd-freq", str(args.cd_freq),
               *(["--control"] if args.control else []), "--parts", *args.parts]
        procs[part] = (subprocess.Popen(cmd, stdout=logf, stderr=subprocess.STDOUT, env=env), logf)
        print(f"started {part}", flush=True)
    pending = set(procs)
    while pending and time.time() - t_start < args.deadline:
        for part in sorted(pending):
            p, logf = procs[part]
            if p.poll() is not None:
                pending.discard(part)
                logf.close()
                (out / f"{part}.done").touch()
                print(f"[{time.time() - t_start:5.0f} s] {part} ended (exit {p.returncode})", flush=True)
        time.sleep(1.0)
    for part in pending:  # past the deadline: stop it, keep what it wrote
        procs[part][0].kill()
        procs[part][1].close()
        print(f"[{time.time() - t_start:5.0f} s] {part} stopped at the deadline", flush=True)
    text = summary(args, time.time() - t_start)
    print(text, flush=True)
    final = Path(args.out)
    final.mkdir(parents=True, exist_ok=True)
    (final / "summary.txt").write_text(text)
    merged = {p: (json.loads((out / f"{p}.json").read_text()) if (out / f"{p}.json").is_file() else None)
              for p in args.parts}
    (final / "results.json").write_text(json.dumps(merged, indent=1, default=str))
    for name in ("drag", "tilt"):  # the engine's time series, for a look after
        if (out / f"{name}_deme.csv.gz").is_file():
            shutil.copy(out / f"{name}_deme.csv.gz", final)
    with open(final / "parts.log", "w") as f:
        for p in args.parts:
            f.write(f"==== {p}\n" + ((out / f"{p}.log").read_text() if (out / f"{p}.log").is_file() else "") + "\n")
    return 0


def summary(args, elapsed):
    out = Path(args.work)
    res = {p: (json.loads((out / f"{p}.json").read_text()) if (out / f"{p}.json").is_file() else None)
           for p in args.parts}
    lines = [f"== DEM-Engine GPU check ({elapsed:.0f} s) =="]
    c = res.get("contract")
    if c and c.get("ok"):
        rows = c["rows"]
        passed = [r for r in rows if r["contract"] == "pass"]
        lines.append(f"contract on the GPU: {len(passed)} of {len(rows)} rows pass (float ulps); "
                     f"initialise {c['init_s']:.0f} s")
        for r in rows:
            cpu = r.get("vs_cpu_ulps")
            cpu_s = "n/a" if cpu is None else ("inf" if cpu == math.inf else f"{cpu:.1f}")
            lines.append(f"  {r['row']:52s} {r['contract'][:90]:12s} vs CPU shim: {cpu_s} ulps, "
                         f"slips {'equal' if r.get('vs_cpu_slips_equal') else 'DIFFER'}")
    elif "contract" in res:
        lines.append(f"contract: {'no result' if not c else c.get('error')}")
    for name in ("drag", "tilt"):
        d = res.get(name)
        if d and d.get("ok"):
            lines.append(f"{name} against pyref (DEM-Engine run {d['wall_s']:.0f} s with its initialisation):")
            for r in d["rows"]:
                lines.append(f"  {r['quantity']:22s} deme {r['deme']!s:>22.22} pyref {r['pyref']!s:>22.22} "
                             f"diff {r['diff']!s:>11.11} bound {r['bound']:.3g} {'ok' if r['ok'] else 'OUT'} "
                             f"(emulated {r.get('emulated')!s:.10})")
            for who, f in (d.get("fn") or {}).items():
                if f:
                    lines.append(f"  Fn / (W cos angle) before the first slip, {who}: first {f['first']:.6f}, "
                                 f"min {f['min']:.6f}, max {f['max']:.6f}")
        elif name in res:
            lines.append(f"{name}: {'no result' if not d else d.get('error')}")
    s = res.get("spread")
    if s and s.get("ok"):
        lines.append(f"tilt spread (pyref, float-sized input changes): {s['final_speed_spread']:.3g} m/s "
                     f"(final speeds {', '.join(f'{v:.6f}' for v in s['final_speeds'])})")
    b = res.get("bench")
    if b and b.get("ok"):
        lines += bench_lines(b)
        for more in ("fixed_cd", "control"):
            if b.get(more):
                lines += bench_lines(b[more])
    elif "bench" in res:
        lines.append(f"bench: {'no result' if not b else b.get('error')}")
    w = res.get("warm_stock")
    if w and not w.get("ok"):
        lines.append(f"warm_stock: {w.get('error')}")
    return "\n".join(lines) + "\n"


STATS_SHOWN = ("Number of updates kinematic gets", "Average steps per dynamic update",
               "Average steps contact detection lags behind",
               "Number of times dynamic held back", "kT total active time", "dT total active time",
               "dT: Calculate contact forces", "dT: Wait for kT update", "dT: Integration")


def bench_lines(b):
    """The summary's lines for one pair of bench solvers."""
    a, c = b["pair"]
    na, nc = SHOWN[a], SHOWN[c]
    lines = [f"bench (contact detection: {b.get('cd_freq', 'adaptive')}): {b['spheres']} spheres, "
             f"{b['steps_per_block']} steps a block, dt {b['dt']:g}; initialise "
             + ", ".join(f"{SHOWN[k]} {v:.0f} s" for k, v in b["init_s"].items())
             + f" (stock's cache warmed by the other process: {b['stock_cache_warmed']}); "
             f"GPU to itself: {b['gpu_to_itself']}",
             f"  ms per step: {na} {', '.join(f'{v:.3f}' for v in b['ms_per_step'][a])}; "
             f"{nc} {', '.join(f'{v:.3f}' for v in b['ms_per_step'][c])}",
             f"  contacts: {na} {b['contacts'][a]}, {nc} {b['contacts'][c]}"]
    if b.get("update_freq"):
        lines.append(f"  engine's update frequency after each block: {na} {b['update_freq'][a]}, "
                     f"{nc} {b['update_freq'][c]}")
    if b.get("bin_size"):
        sizes = {k: ", ".join(f"{v:.4g}" for v in b["bin_size"][k]) for k in (a, c)}
        lines.append(f"  engine's bin size after each block (m): {na} {sizes[a]}; {nc} {sizes[c]}")
    for label, st in (b.get("engine_stats") or {}).items():
        shown = [f"{k} {st[k]:.4g}" for k in STATS_SHOWN if k in st]
        lines.append(f"  engine's own statistics over the rounds, {SHOWN[label]}: "
                     + ("; ".join(shown) or "none printed"))
    what = ("target <= 1.05" if [a, c] == [p[0] for p in PAIR]
            else "A/A control: the same model in two solvers, 1 but for the engine's own scheduling")
    lines.append(f"  {na} / {nc} per round: {', '.join(f'{r:.3f}' for r in b['ratios'])}; mean "
                 f"{b['ratio_mean']:.3f}, range {b['ratio_min']:.3f}-{b['ratio_max']:.3f}; geometric mean "
                 f"{b['ratio_geomean']:.3f} (95 % over rounds {b['ratio_low']:.3f}-{b['ratio_high']:.3f}; "
                 f"{what})")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--part", choices=PARTS)
    ap.add_argument("--parts", nargs="+", choices=PARTS, default=list(PARTS))
    ap.add_argument("--out", default=os.environ.get("OUT", "gpu_check_out"),
                    help="where summary.txt, results.json and parts.log go (default $OUT)")
    ap.add_argument("--work", default="/tmp/gpu_check/parts", help="the parts' files")
    ap.add_argument("--cache", default="/tmp/gpu_check/jit")
    ap.add_argument("--t0", type=float, default=None, help="(parts: the check's start, epoch s)")
    ap.add_argument("--deadline", type=float, default=380.0, help="seconds for everything (default 380)")
    ap.add_argument("--bench-grid", type=int, default=80, help="spheres per lattice edge (default 80: 512 000)")
    ap.add_argument("--rounds", type=int, default=5, help="bench rounds, each one block of each model")
    ap.add_argument("--bench-steps", type=int, default=2000, help="steps a bench block (default 2000)")
    ap.add_argument("--settle-steps", type=int, default=2000,
                    help="steps each bench solver runs before the rounds (default 2000)")
    ap.add_argument("--tilt-every", type=int, default=25, help="the tilt's rows, in steps (default 25)")
    ap.add_argument("--cd-freq", type=int, default=0,
                    help="N > 0: the bench again with contact detection every N steps for both models")
    ap.add_argument("--control", action="store_true",
                    help="the bench's A/A control too: the engine's model against itself in a second solver")
    args = ap.parse_args(argv)
    Path(args.work).mkdir(parents=True, exist_ok=True)
    if args.t0 is None:
        args.t0 = time.time()
    if args.part:
        return run_part(args)
    return orchestrate(args)


if __name__ == "__main__":
    sys.exit(main())
