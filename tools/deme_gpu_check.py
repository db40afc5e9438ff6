#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""DEM-Engine on a GPU, in one run (tools/gpu_check.sh sets up `deme` and calls this):

  contract   every row of stickslip/contract/cases.py on the engine, side by side in one solver
             (the force model's sweep: each row's coefficients, timing and reset per owner;
             positions, velocities and spins prescribed per family as the rows state them),
             against the hand-worked values (cases.compare, float) and the CPU
             shim's values (stickslip/contract/deme_shim.py) for the same row (tools/deme_gpu_contract.py)
  drag, tilt the paper's cases through the adapter (stickslip/adapters/deme.py) against pyref,
             with bounds derived for float and the engine's start (see BOUNDS)
  bench      a bed of >= 500 000 spheres settling in a box: the stick-slip model (Hertz-Mindlin
             normal force) and the engine's own frictional Hertz-Mindlin, same bed, same
             steps, alternated in one process; the ratio per round and its spread (with
             --control also the engine's model against itself in two solvers: an A/A pair;
             tools/deme_gpu_bench.py)
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
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from deme_fn_ring import fn_spread, ring_of  # noqa: E402
from deme_gpu_bench import bench_lines, run_bench, run_warm_stock  # noqa: E402
from deme_gpu_contract import run_contract  # noqa: E402
from deme_gpu_parts import wait_json  # noqa: E402

PARTS = ("contract", "drag", "tilt", "bench", "warm_stock", "spread")
F32_EPS = 2.0 ** -23
WORK = Path(tempfile.gettempdir()) / "gpu_check"  # the parts' files and the JIT cache, by default


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


# ---------------------------------------------------------------- orchestration
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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--part", choices=PARTS)
    ap.add_argument("--parts", nargs="+", choices=PARTS, default=list(PARTS))
    ap.add_argument("--out", default=os.environ.get("OUT", "gpu_check_out"),
                    help="where summary.txt, results.json and parts.log go (default $OUT)")
    ap.add_argument("--work", default=str(WORK / "parts"), help="the parts' files")
    ap.add_argument("--cache", default=str(WORK / "jit"))
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
