# SPDX-License-Identifier: GPL-2.0-or-later
"""The GPU check's contract part (tools/deme_gpu_check.py): every row of stickslip/contract/cases.py
on DEM-Engine side by side in one solver (the force model's sweep: each row's coefficients,
timing and reset per owner; positions, velocities and spins prescribed per family as the
rows state them), judged against the hand-worked values (cases.compare, float) and
the CPU shim's values (stickslip/contract/deme_shim.py) for the same row."""
from __future__ import annotations

import math
import time

F32_EPS = 2.0 ** -23


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
    cases.state of step k. A segment [a, b] then holds while t < (b - 3/2) dt; in
    a turn the step in the segment is k - a + 1 = t/dt + 3 - a."""
    from stickslip.contract import cases as lc

    dt = lc.DT
    spans = segment_spans(case)
    pos, vel, spin = [[], [], []], [[], [], []], [[], [], []]
    start = lc.rest_positions(case, case.segments[0].delta)
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
            xs, vs, _ = lc.state(case, seg, 1, start)
            x = [_r(base[i] + xs[body][i]) for i in range(3)]
            v = [_r(vs[body][i]) for i in range(3)]
            w = ["0.0", "0.0", "0.0"]
            start = lc.rest_positions(case, seg.delta)
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
    from stickslip.adapters import deme as adapter
    from stickslip.contract import cases as lc, deme_shim

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
        x0 = lc.rest_positions(case, case.segments[0].delta)
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
    traces = [lc.empty_trace(c.steps) for c in cases]
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
    from stickslip.contract import cases as lc

    out, start, k = np.zeros((case.steps, 3)), lc.rest_positions(case, case.segments[0].delta), 0
    for seg in case.segments:
        begin = start
        for s in range(1, seg.steps + 1):
            x, _, _ = lc.state(case, seg, s, begin)
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
    from stickslip.contract import cases as lc, deme_shim

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
