# SPDX-License-Identifier: GPL-2.0-or-later
"""LIGGGHTS rows for `stickslip bench`: what the stick_slip plugin costs, and how it scales.

All figures come from one call, measured on the same 3D packing of 20 800 settled spheres
(~45 600 grain pair contacts; created once, cached under build/liggghts_bench/):

1. plugin overhead against LIGGGHTS' stock `tangential history` (hooke/stiffness, pair and
   floor; the stock model from Debian's library, stick_slip in both slip timings from the
   plugin; all run by the plugin's launcher), two ways:
   - time, interleaved chunk by chunk: in each round the three configurations run side by
     side as three processes, each stopped by a shell probe after its warm-up and after
     every chunk of CHUNK steps; the benchmark lets one process go at a time, so a block
     (the same chunk of each configuration, ~0.25 s each) is timed within a second, and
     the order turns from block to block (A B C, B C A, C A B). A chunk's time is the
     on-CPU time of LIGGGHTS' thread (/proc/PID/schedstat), and the probe also reads the
     CPU the rest of the machine used meanwhile (/proc/stat). On this project's 2-core
     virtual machine a busy second core slows a run by 20-90 % (measured: two runs side
     by side took 1.5-1.9x their time alone), so a block counts as quiet only when other
     processes used less than NOISY cores during each of its chunks; the figures use the
     quiet blocks (all blocks, said so, when fewer than two are quiet), and more rounds run
     while there are fewer than MIN_QUIET_BLOCKS. A ratio is the geometric mean of the
     rounds' ratios (each the geometric mean of its blocks'), with a 95 % interval over
     rounds (stickslip/bench/ratio_interval.py): each round starts new processes, and processes
     differ (memory placement) by more than blocks of one process do;
   - instructions, counted by callgrind over CALLGRIND_STEPS steps after the same warm-up
     (the same binaries and input: the count does not depend on the machine's load), in
     total and in the tangential model alone, per configuration and as ratios.
   Memory: history values per contact (read from `compute pair/gran/local id history`'s
   column count) and the peak RSS of each run.
2. MPI speed-up: the stick_slip script on 1 process (launcher) and on 2
   (`mpirun -np 2` launcher), speed-up = T1/T2 (LIGGGHTS' "Loop time", medians of `reps`
   runs alternating 1, 2, 2, 1, ...), and the contact statistics of both
   (`compute contact/atom` summed: pair contacts, mean coordination) to show they agree.

Cost on the 2-core machine, idle: ~40 s per round (5 by default), ~1 min of callgrind
(two at a time; the warm-up runs uninstrumented), ~30 s per MPI repetition; ~2.5 min more to make the packing (40 000
steps on 2 processes). On a busy machine everything is slower, and the rounds added for
want of quiet blocks (up to 3 x) add to it.

    python -m stickslip.bench.liggghts [--rounds 5] [--reps 3] [--no-callgrind] [--baseline LAUNCHER]
        [--control [LAUNCHER]] [--stamp-cost]

--control: the control build (liggghts_variants.py: stock history compiled into the plugin in
the law's place; built into build/liggghts_control, or give its launcher) joins the rounds, so that the law is also compared with stock's
arithmetic built as the plugin is; --stamp-cost: stick_slip without its stamp joins them.
"""
from __future__ import annotations

import argparse
import concurrent.futures
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from . import callgrind
from . import liggghts_rounds
from . import liggghts_runs
from .ratio_interval import ratio_interval

ROUNDS = 5  # rounds of the overhead comparison by default (~40 s each on the idle machine)
MIN_QUIET_BLOCKS = 60  # quiet blocks wanted: more rounds (up to 3 x ROUNDS) until there are
CALLGRIND_STEPS = 100  # steps counted by callgrind (after WARM; ~0.3 s a step under callgrind)
MPI_STEPS = 2000  # timed steps of the MPI runs

OVERHEAD = ("history", "stick_slip", "stick_slip_exact")
# --stamp-cost: stick_slip without the fourth history value (the stamp by which a grain pair
# that opened and touched again between neighbour-list builds restarts from a zero spring)
STAMPLESS = "stick_slip_keep"
TARGET = {"stick_slip": 1.02, "stick_slip_exact": 1.05}  # at most this many times history's cost

LAST_ROUNDS = []  # the overhead runs behind the last benchmark() figures: per round, {config: run}
LAST_MPI = {}  # processes -> the MPI runs behind the last benchmark() figures
LAST_COUNTS = {}  # config -> callgrind figures of the last benchmark()


def instruction_counts(data, work, configs, steps=CALLGRIND_STEPS):
    """Callgrind's counts over `steps` steps after WARM, per configuration ({name: (tangential
    key, launcher)}), two at a time: instructions per step, and those of the tangential model
    (TangentialModel<id> and the stick_slip helpers; self costs) per step."""
    def one(name):
        tang, launcher = configs[name]
        d = work / f"{name}-callgrind"
        d.mkdir(exist_ok=True)
        # instrumentation switched on after the warm-up: only the counted `run` is profiled
        liggghts_runs.write_timed(d, data, "shell ./callgrind_on.sh\n" + liggghts_runs.single(steps))
        parts = callgrind.count(liggghts_runs.command(tang, launcher=launcher), d, env=liggghts_runs.env(),
                                on_request=True)
        if len(parts) != 1:
            raise RuntimeError(f"callgrind wrote {len(parts)} profiles in {d}, expected one (the counted run)")
        costs = callgrind.self_costs(parts[0])
        law = sum(v for f, v in costs.items()
                  if "ContactModels::TangentialModel<" in f or "ContactModels::StickSlip::" in f)
        text = (d / "callgrind.txt").read_text(errors="replace")
        atoms = int(liggghts_runs.LOOP.findall(text)[-1][3])
        return {"per_step": callgrind.total(parts[0]) / steps, "law_per_step": law / steps,
                "contacts": liggghts_runs.contacts_at(text, liggghts_runs.WARM + steps, atoms)}
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, os.cpu_count() or 1)) as ex:
        return dict(zip(configs, ex.map(one, configs)))


def _timed(data, tang, nproc, work):
    """One MPI-comparison run: LIGGGHTS' "Loop time" per step, pair contacts, atoms, peak RSS."""
    d = work / f"{tang}-np{nproc}"
    d.mkdir(exist_ok=True)
    liggghts_runs.write_timed(d, data, liggghts_runs.single(MPI_STEPS))
    info = {}
    text, rss = liggghts_runs.run(liggghts_runs.command(tang, nproc), d, info=info)
    loops = liggghts_runs.LOOP.findall(text)
    if len(loops) < 2:
        raise RuntimeError(f"no 'Loop time' line for the timed run ({tang}, {nproc} procs)")
    seconds, procs, steps, atoms = float(loops[-1][0]), int(loops[-1][1]), int(loops[-1][2]), int(loops[-1][3])
    contacts = liggghts_runs.contacts_at(text, liggghts_runs.WARM + MPI_STEPS, atoms)
    return {"s_per_step": seconds / steps, "procs": procs, "atoms": atoms, "contacts": contacts,
            "coordination": 2 * contacts / atoms, "rss_mib": rss, "foreign_cores": info.get("foreign_cores")}


def benchmark(reps=3, rounds=ROUNDS, counts=True, baseline=None, stamp_cost=False, control=None):
    """Rows for `stickslip bench` (see the module docstring). `baseline`: another build's
    launcher, whose stick_slip (both timings) joins the rounds and the counts, for A/B
    comparisons of two builds. `stamp_cost`: stick_slip without its stamp joins them too.
    `control`: the launcher of the control build (liggghts_variants.py),
    whose `stick_slip` is stock history compiled into the plugin."""
    liggghts_runs.check()
    reps, rounds = max(1, int(reps)), max(1, int(rounds))
    data = liggghts_runs.packing()
    configs = {name: (name, liggghts_runs.LAUNCHER) for name in OVERHEAD}
    if baseline is not None:
        configs.update({f"{name}@baseline": (name, Path(baseline)) for name in OVERHEAD[1:]})
    if stamp_cost:
        configs[STAMPLESS] = (STAMPLESS, liggghts_runs.LAUNCHER)
    if control is not None:
        configs["control"] = ("stick_slip", Path(control))
    rows = []
    with tempfile.TemporaryDirectory(prefix="liggghts_bench-") as work:
        work = Path(work)
        hist = {"history": liggghts_runs.history_values("history", "", work),
                "stick_slip": liggghts_runs.history_values("stick_slip", "", work),
                "stick_slip_record": liggghts_runs.history_values("stick_slip", "stick_slip_record on", work)}
        if counts and callgrind.available():
            LAST_COUNTS.clear()
            LAST_COUNTS.update(instruction_counts(data, work, configs))
        LAST_ROUNDS[:] = liggghts_rounds.overhead_rounds(data, work, rounds, configs)
        # a busy machine leaves few quiet blocks: more rounds, within a limit
        while len(liggghts_rounds.blocks(LAST_ROUNDS, True)) < MIN_QUIET_BLOCKS and len(LAST_ROUNDS) < 3 * rounds:
            LAST_ROUNDS.extend(liggghts_rounds.overhead_rounds(data, work, 1, configs))
        mpi = {1: [], 2: []}
        for r in range(reps):
            for nproc in ((1, 2) if r % 2 == 0 else (2, 1)):
                mpi[nproc].append(_timed(data, "stick_slip", nproc, work))
        LAST_MPI.clear()
        LAST_MPI.update(mpi)
    runs = LAST_ROUNDS
    atoms = runs[0]["history"]["atoms"]
    quiet, every = liggghts_rounds.blocks(runs, True), liggghts_rounds.blocks(runs, False)
    blocks = quiet if len(quiet) >= 2 else every
    which = f"{len(quiet)} quiet blocks" if blocks is quiet else f"all {len(every)} blocks (machine busy)"
    tag = f"{atoms} spheres, median of {which} of {liggghts_rounds.CHUNK} steps, {len(runs)} rounds"
    for name in configs:
        t = statistics.median(b[name] for b in blocks)
        k = statistics.median(r[name]["contacts"] for r in runs)
        rows.append({"benchmark": "liggghts", "case": f"overhead: {_label(name)}, CPU s per step (1 process; {tag})",
                     "contacts": round(k), "seconds_per_step": t, "contact_steps_per_s": k / t, "value": t})
    ratios = [(name, "history") for name in configs if name != "history"]
    ratios.append(("stick_slip_exact", "stick_slip"))
    if stamp_cost:
        ratios.append(("stick_slip", STAMPLESS))
    if control is not None:  # (control / history is already among the ratios to history above)
        ratios += [("stick_slip", "control"), ("stick_slip_exact", "control")]
    if baseline is not None:
        ratios += [(name, f"{name}@baseline") for name in OVERHEAD[1:]]
    for num, den in ratios:
        target = f" (target <= {TARGET[num]})" if den == "history" and num in TARGET else ""
        # the interval's unit is the round: each round starts new processes, whose ratio
        # differs from the last round's by more than their blocks' scatter says (measured
        # 2026-11-25: rounds at 1.118-1.163, blocks' interval +-0.013), so blocks treated as
        # independent understate the uncertainty; their interval is printed for comparison
        per_round = liggghts_rounds.round_ratios(runs, num, den, blocks is quiet)
        mid, low, high = ratio_interval([(1.0, x) for x in per_round])
        rows.append({"benchmark": "liggghts", "case": f"overhead: time {_label(num)} / {_label(den)}{target}, "
                     f"geometric mean over {len(per_round)} rounds (each: its {'quiet ' if blocks is quiet else ''}"
                     f"blocks), 95 % interval over rounds", "value": mid, "ci_low": low, "ci_high": high})
        mid, low, high = ratio_interval([(b[den], b[num]) for b in blocks])
        rows.append({"benchmark": "liggghts", "case": f"overhead: time {_label(num)} / {_label(den)}, over {which} "
                     f"taken as independent (within-round scatter only), 95 % interval",
                     "value": mid, "ci_low": low, "ci_high": high})
    if LAST_COUNTS:
        for name in configs:
            c = LAST_COUNTS[name]
            rows.append({"benchmark": "liggghts", "case": f"instructions per step, {_label(name)} "
                         f"(callgrind, {CALLGRIND_STEPS} steps after {liggghts_runs.WARM})",
                         "contacts": round(c["contacts"]),
                         "value": c["per_step"]})
            rows.append({"benchmark": "liggghts", "case": f"instructions in the tangential model per pair "
                         f"contact-step (wall contacts' calls included), {_label(name)}", "value":
                         c["law_per_step"] / c["contacts"]})
        for num, den in ratios:
            rows.append({"benchmark": "liggghts", "case": f"instructions: {_label(num)} / {_label(den)}",
                         "value": LAST_COUNTS[num]["per_step"] / LAST_COUNTS[den]["per_step"]})
    for key, label in (("history", "stock tangential history"), ("stick_slip", "tangential stick_slip"),
                       ("stick_slip_record", "stick_slip with stick_slip_record on")):
        rows.append({"benchmark": "liggghts", "case": f"memory: history values per contact, {label}",
                     "value": float(hist[key])})
    for name in ("history", "stick_slip"):
        rows.append({"benchmark": "liggghts", "case": f"memory: peak RSS of the run, MiB, {_label(name)}",
                     "value": statistics.median(r[name]["rss_mib"] for r in runs)})
        if runs[0][name]["liggghts_mib"] is not None:
            rows.append({"benchmark": "liggghts", "case": f"memory: LIGGGHTS' estimate per process, MiB, "
                         f"{_label(name)}", "value": runs[0][name]["liggghts_mib"]})
    t1, t2 = (statistics.median(x["s_per_step"] for x in mpi[n]) for n in (1, 2))
    mtag = f"{atoms} spheres, {MPI_STEPS} steps, wall time, median of {reps}"
    for n, t, label in ((1, t1, "1 process (launcher)"), (2, t2, "2 processes (mpirun -np 2)")):
        k = statistics.median(x["contacts"] for x in mpi[n])
        rows.append({"benchmark": "liggghts", "case": f"MPI: stick_slip, {label}, s per step ({mtag})",
                     "contacts": round(k), "seconds_per_step": t, "contact_steps_per_s": k / t, "value": t})
    rows.append({"benchmark": "liggghts", "case": "MPI: speed-up T1/T2 on 2 processes (target >= 1.6)",
                 "value": t1 / t2})
    for n, label in ((1, "1 process"), (2, "2 processes")):
        rows.append({"benchmark": "liggghts",
                     "case": f"MPI: mean coordination (pair contacts per sphere, contact/atom) at the end, {label}",
                     "contacts": round(statistics.median(x["contacts"] for x in mpi[n])),
                     "value": statistics.median(x["coordination"] for x in mpi[n])})
    k1, k2 = (statistics.median(x["contacts"] for x in mpi[n]) for n in (1, 2))
    rows.append({"benchmark": "liggghts", "case": "MPI: relative difference in pair contacts, 2 vs 1 process",
                 "value": (k2 - k1) / k1})
    # how busy the machine was: the overhead figures use quiet blocks when there are any; the
    # MPI runs (wall time, both cores) are only as good as the machine was idle
    chunks = [c for r in runs for g in r.values() for c in g["chunks"]]
    rows.append({"benchmark": "liggghts", "case": f"machine: CPU used by other processes during the overhead "
                 f"chunks, cores (median; {os.cpu_count()} cores; quiet: below {liggghts_rounds.NOISY})",
                 "value": statistics.median(c["foreign"] for c in chunks)})
    foreign = [x["foreign_cores"] for n in mpi for x in mpi[n] if x["foreign_cores"] is not None]
    if foreign:
        rows.append({"benchmark": "liggghts", "case": "machine: CPU used by other processes during the MPI runs, "
                     f"cores (max; {os.cpu_count()} cores)", "value": max(foreign)})
    return rows


def _label(name):
    base, _, build = name.partition("@")
    return liggghts_runs.LABEL[base] + (f" ({build} build)" if build else "")


# What the two-process figure says about more machines; written under the table of bench.md.
SCALING_NOTE = """\
LIGGGHTS beyond one machine: the box is cut into one sub-domain per MPI process
(`processors`); a process owns the grains inside its sub-domain, keeps ghost copies of the
grains within one neighbour cutoff of its faces, and a contact's history moves with its
grain. Per step a process computes ~N/P grains and exchanges only the ghost layer with
its neighbouring sub-domains, ~(N/P)^(2/3) grains in 3D. So the speed-up stays close to P
while each process keeps many grains (thousands) and the grains fill the box evenly; with
fewer grains per process the halo exchange's latency over the network dominates.
LIGGGHTS-PUBLIC 3.8 has no dynamic load balancing: for a pour that fills part of the box,
choose a `processors` grid that cuts only where grains are (e.g. `processors * * 1`
for a layer)."""


def _table(rows):
    lines = [f"{'case':<120} {'contacts':>9} {'value':>12}  95 % interval"]
    for r in rows:
        c = "" if r.get("contacts") is None else str(r["contacts"])
        ci = f"  [{r['ci_low']:.4f}, {r['ci_high']:.4f}]" if r.get("ci_low") is not None else ""
        lines.append(f"{r['case']:<120} {c:>9} {r['value']:>12.5g}{ci}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m stickslip.bench.liggghts",
                                 description="LIGGGHTS stick_slip plugin: overhead vs stock history (time in "
                                             "interleaved rounds, callgrind instructions), MPI speed-up.")
    ap.add_argument("--rounds", type=int, default=ROUNDS,
                    help=f"overhead rounds (default {ROUNDS}; more, up to 3x, while quiet blocks are < {MIN_QUIET_BLOCKS})")
    ap.add_argument("--reps", type=int, default=3, help="MPI repetitions (median quoted)")
    ap.add_argument("--no-callgrind", action="store_true", help="skip the instruction counts")
    ap.add_argument("--baseline", type=Path, help="another build's liggghts-stickslip, compared in the same rounds")
    ap.add_argument("--control", type=Path, nargs="?", const=True,
                    help="the control build's liggghts-stickslip (liggghts_variants.py: stock history compiled in "
                         "the plugin; without a value it is built), in the same rounds")
    ap.add_argument("--stamp-cost", action="store_true",
                    help="also run stick_slip with history_on_separation keep (no stamp history value)")
    a = ap.parse_args(argv)
    if a.rounds < 1 or a.reps < 1:
        ap.error("--rounds and --reps must be >= 1")
    if a.control is True:
        from . import liggghts_variants

        a.control = liggghts_variants.build("control")
    for opt, path in (("--baseline", a.baseline), ("--control", a.control)):
        if path is not None and not path.is_file():
            ap.error(f"{opt} {path}: no such file (a built liggghts-stickslip)")
    t0 = time.perf_counter()
    try:
        rows = benchmark(a.reps, a.rounds, counts=not a.no_callgrind,
                         baseline=a.baseline.resolve() if a.baseline else None, stamp_cost=a.stamp_cost,
                         control=a.control.resolve() if a.control else None)
    except RuntimeError as e:
        sys.stderr.write(f"liggghts_bench: {e}\n")
        return 1
    print(_table(rows))
    print(f"\nblocks (CPU ms per step of each configuration's chunk; other processes' CPU, cores, "
          f"over the block; * quiet):")
    for i, got in enumerate(LAST_ROUNDS):
        for k in range(liggghts_rounds.CHUNKS):
            worst = max(g["chunks"][k]["foreign"] for g in got.values())
            cpu = " ".join(f"{g['chunks'][k]['cpu'] / liggghts_rounds.CHUNK * 1e3:8.3f}" for g in got.values())
            print(f"  {i + 1}.{k + 1:<3}" + cpu
                  + f"  {worst:5.2f}{' *' if liggghts_rounds.quiet_block(got, k) else ''}")
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
