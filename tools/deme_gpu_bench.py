# SPDX-License-Identifier: GPL-2.0-or-later
"""The GPU check's bench part (tools/deme_gpu_check.py): a bed of >= 500 000 spheres settling
in a box, the stick-slip model (Hertz-Mindlin normal force) against the engine's own
frictional Hertz-Mindlin, same bed, same steps, alternated in one process; the ratio per
round, its spread and the engine's own statistics, and the summary's lines for them."""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

from deme_gpu_parts import wait_json, wait_parts

GPU_PARTS = ("contract", "drag", "tilt")  # the bench waits for these before it times


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
