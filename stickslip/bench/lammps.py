# SPDX-License-Identifier: GPL-2.0-or-later
"""LAMMPS rows for `stickslip bench`: what `pair_style gran/hooke/stickslip` costs against
stock `gran/hooke/history`, and how it scales on 2 processes.

The scene is Debian's examples/pour/in.pour: its first run (3000 grains poured onto a floor
wall, 25 000 steps) is made once with the stock styles and kept as a data file under
build/lammps_bench/; every timed run reads it and runs in.pour's second part, the chute
(gravity tilted 26 degrees: the pile flows, about a third of the contact-steps slide). Both
the pair style and the floor wall are swapped: stock gran/hooke/history + wall/gran, or
gran/hooke/stickslip + wall/gran/stickslip. in.pour's material (Kn 2000, Kt 2/7 Kn,
gamma_n 50, xmu = mu_s 0.5) with dampflag 1 (a tangential dashpot, gamma_t = gamma_n/2, in
every configuration: without it the law's two resets are the same), and the law's own
settings: mu_k = 0.45 < mu_s (the kinetic drop that makes it a stick-slip law; the LIGGGHTS
benchmark's 0.45/0.5) and reset spring (docs/law.md's default, the paper's eq. 8), in both
slip timings; the other rules (history rotation, lever arm, mass damping) are stock's, the
engine's geometry shared by both styles.

1. Overhead, timed: in each round the three configurations (stock, step, exact) run one
   after the other as separate processes, the order turning from round to round; each run
   reads the data, runs WARM untimed steps (the contacts' history builds up again after
   read_data), then STEPS timed steps. The time is the on-CPU time of the LAMMPS process
   over the timed steps alone, read from /proc/PID/schedstat by a probe that the input
   script runs (`shell`) before and after them. Each round's ratio divides two runs made
   seconds apart; the figure is the geometric mean over the rounds with a 95 % interval
   (stickslip/bench/ratio_interval.py). The CPU the rest of the machine used during each run is
   recorded; rounds in which it exceeded NOISY cores are reported apart, and the ratio uses
   the quiet rounds when there are at least 3 (a busy second core slows a run through the
   shared caches even when the run keeps its core).
2. Overhead, counted: callgrind's instructions over CALLGRIND_STEPS steps after the same
   warm-up (not instrumented), in the whole time step (LAMMPS' Verlet::run), in the pair
   style's own functions and in the wall's; the same binaries and input give the same
   counts whatever the machine's load. (The exact timing's out-of-line functions are
   counted with the pair style: the wall calls them too, for its few contacts.)
3. MPI: the step configuration on 1 and on 2 processes (`mpirun -np 2`), LAMMPS' "Loop
   time" of the timed steps, medians of `reps` runs each alternating 1, 2, 2, 1, ...;
   speed-up = T1 / T2.

Cost on the 2-core machine, idle: ~15 s once for the pour; ~4 s a round (10 by default);
~1 min of callgrind (two at a time); ~5 s per MPI repetition.

    python -m stickslip.bench.lammps [--rounds 10] [--reps 3] [--no-callgrind] [--callgrind-steps 200]
"""
from __future__ import annotations

import argparse
import concurrent.futures
import math
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..adapters.lammps import BUILD
from ..adapters.lammps_family import serial_mpi_env
from . import callgrind
from .data_cache import cached_data
from .proc_probe import probe_script
from .ratio_interval import ratio_interval

ROOT = Path(__file__).resolve().parents[2]
LAUNCHER = BUILD / "lmp-stickslip"
EXAMPLE = Path("/usr/share/lammps/examples/pour/in.pour")
CACHE = ROOT / "build" / "lammps_bench"

WARM = 200  # untimed steps after read_data (the history builds up again)
STEPS = 1000  # timed steps (~0.7 s on one idle core)
ROUNDS = 10
NOISY = 0.3  # cores used by other processes during a run above which its round is not quiet
CALLGRIND_STEPS = 200
TARGET = {"step": 1.02, "exact": 1.05}  # issue 30: at most this many times stock's cost

STOCK_ARGS = "2000.0 NULL 50.0 NULL 0.5 1"
LAW = "mu_k 0.45 reset spring"
WALL = "zplane 0.0 2000.0"  # in.pour's floor
CONFIGS = {  # the pair style, and the floor wall's fix arguments
    "stock": (f"gran/hooke/history {STOCK_ARGS}", f"wall/gran hooke/history {STOCK_ARGS} {WALL}"),
    "step": (f"gran/hooke/stickslip {STOCK_ARGS} {LAW}",
             f"wall/gran/stickslip hooke/history {STOCK_ARGS} {WALL} {LAW}"),
    "exact": (f"gran/hooke/stickslip {STOCK_ARGS} {LAW} slip_timing exact",
              f"wall/gran/stickslip hooke/history {STOCK_ARGS} {WALL} {LAW} slip_timing exact"),
}
LABEL = {"stock": "stock gran/hooke/history", "step": "gran/hooke/stickslip, step timing",
         "exact": "gran/hooke/stickslip, slip_timing exact"}
PAIR_FUNCTIONS = ("PairGranHookeHistory::compute", "PairGranHookeStickSlip::", "exact_slips", "exact_general")
WALL_FUNCTIONS = ("FixWallGran::", "FixWallGranStickSlip::")  # stock's post_force and hooke_history; ours

# in.pour's settings around its chute run, both LAMMPS benchmarks' timed scene (chute_script)
CHUTE = """\
{units}atom_style sphere
boundary p p fm
newton off
comm_modify vel yes
read_data {data}
neighbor 0.2 bin
neigh_modify delay 0
{pair}
timestep 0.001
fix 1 all nve/sphere
fix 2 all gravity 1.0 chute 26.0
{wall}
compute c all contact/atom
compute cs all reduce sum c_c
thermo_style custom step atoms c_cs
thermo_modify norm no
thermo {warm}
run {warm}
{before}
thermo {steps}
run {steps} pre no post no
{after}"""


def chute_script(data, pair, wall, warm, steps, before="", after="", units=""):
    """The chute's input on the grains of `data`: `pair` the pair style's lines, `wall` the
    floor's fix line, WARM untimed steps then `steps` timed ones with `before` and `after`
    around them; `units` a first line (LAMMPS' default units: none)."""
    return CHUTE.format(units=units, data=data, pair=pair, wall=wall, warm=warm, steps=steps, before=before,
                        after=after)


# Appends the on-CPU time (ns) of the LAMMPS process that runs it through `shell` (its
# nearest ancestor named lmp-stickslip) to probe.log. Shell built-ins only.
PROBE = probe_script("lmp-stickslip)", 'read -r s < /proc/$p/schedstat\necho "${s%% *}" >> probe.log')

LOOP = re.compile(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms")
CPU_USE = re.compile(r"([\d.]+)% CPU use with")


def _env(folder, nproc=1):
    env = dict(os.environ, OMP_NUM_THREADS="1")
    env.pop("LD_PRELOAD", None)
    if nproc == 1:
        env.update(serial_mpi_env(folder))  # no Open MPI daemon for a serial run
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def _check():
    if not LAUNCHER.is_file():
        raise RuntimeError(f"LAMMPS plugin not built: {LAUNCHER} missing (./run.sh setup)")
    if not EXAMPLE.is_file():
        raise RuntimeError(f"{EXAMPLE} missing (apt-get install lammps-examples)")


def _busy_seconds():
    """CPU time all cores have spent busy so far (Linux), in seconds."""
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    return (sum(v) - v[3] - (v[4] if len(v) > 4 else 0)) / os.sysconf("SC_CLK_TCK")


def _children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run(cmd, cwd, nproc=1, timeout=3600):
    """Run a command; returns (stdout, the CPU the rest of the machine used meanwhile, in
    cores: all cores' busy time less the command's own, over its wall time)."""
    b0, c0, t0 = _busy_seconds(), _children_cpu(), time.monotonic()
    p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace",
                       env=_env(cwd, nproc), timeout=timeout)
    wall = time.monotonic() - t0
    own = _children_cpu() - c0  # (mpirun's ranks are its children: counted too)
    foreign = max(0.0, (_busy_seconds() - b0 - own) / wall) if wall > 0 else math.inf
    if p.returncode != 0 or "ERROR" in p.stdout:
        lines = p.stdout.strip().splitlines() or ["no output"]
        why = next((x.strip() for x in lines if "ERROR" in x), lines[-1].strip())
        raise RuntimeError(f"{' '.join(map(str, cmd[:4]))} ... failed (exit {p.returncode}) in {cwd}: {why}")
    return p.stdout, foreign


def _pour():
    """in.pour's first run (3000 grains poured, stock styles) as a data file; made once."""
    script = EXAMPLE.read_text()
    runs = list(re.finditer(r"^run\s+25000\s*$", script, flags=re.M))
    if len(runs) != 2:
        raise RuntimeError(f"{EXAMPLE} changed: expected two `run 25000` lines")
    script = script[:runs[0].end()] + "\nwrite_data pour.data\n"

    def make(tmp):
        (tmp / "in.pour").write_text(script)
        _run([str(LAUNCHER), "-in", "in.pour", "-log", "none", "-echo", "none", "-nocite"], tmp)
        return tmp / "pour.data"
    return cached_data(CACHE, "pour", script, make)


def _command(config, nproc=1):
    pair, wall = CONFIGS[config]
    cmd = [str(LAUNCHER), "-in", "in.timed", "-log", "none", "-echo", "none", "-nocite", "-var", "pair", pair,
           "-var", "wall", wall]
    return (["mpirun", "-np", str(nproc)] + cmd) if nproc > 1 else cmd


def _script(data, steps, before="", after=""):
    """The timed input; ${pair} and ${wall} (_command's -var) choose the styles."""
    return chute_script(data, "pair_style ${pair}\npair_coeff * *", "fix zlower all ${wall}", WARM, steps, before,
                        after)


def _folder(work, name):
    d = Path(work) / name
    d.mkdir(parents=True, exist_ok=True)
    return d


def timed_run(d, script, cmd, probe=PROBE):
    """Run `cmd` in folder d on the input `script` (written as in.timed), which runs
    `shell ./probe.sh` right before and right after its timed steps: (the engine's on-CPU
    seconds between the two, its output, the other processes' CPU during the run in cores).
    `probe`: the probe for the engine's process name (proc_probe.py)."""
    (d / "probe.sh").write_text(probe)
    (d / "probe.sh").chmod(0o755)
    (d / "probe.log").unlink(missing_ok=True)
    (d / "in.timed").write_text(script)
    out, foreign = _run(cmd, d)
    marks = [int(x) for x in (d / "probe.log").read_text().split()]
    if len(marks) != 2:
        raise RuntimeError(f"{len(marks)} probe marks in {d} (expected 2)")
    return (marks[1] - marks[0]) * 1e-9, out, foreign


def _timed(data, config, work):
    """One overhead run: on-CPU seconds of the timed steps, pair contacts at their end, and
    the other processes' CPU during the run (cores)."""
    d = _folder(work, f"timed-{config}")
    cpu, out, foreign = timed_run(d, _script(data, STEPS, "shell ./probe.sh", "shell ./probe.sh"), _command(config))
    return {"cpu": cpu, "contacts": _contacts(out, WARM + STEPS), "foreign": foreign,
            "atoms": int(LOOP.findall(out)[-1][3])}


def _contacts(out, step):
    """Pair contacts at `step` (thermo: step atoms c_cs; contact/atom counts each pair twice)."""
    rows = [ln.split() for ln in out.splitlines() if re.match(rf"\s*{step}\s+\d+\s+\S+\s*$", ln)]
    if not rows:
        raise RuntimeError(f"no thermo line for step {step}")
    return float(rows[-1][2]) / 2


def _counted(data, config, work, steps=CALLGRIND_STEPS):
    """callgrind: instructions in the whole time step, in the pair style and in the wall, over
    `steps` steps."""
    d = _folder(work, f"callgrind-{config}")
    k = counted_run(d, _script(data, steps, "shell ./callgrind_on.sh"), _command(config),
                    {"pair": PAIR_FUNCTIONS, "wall": WALL_FUNCTIONS})
    return dict(k, steps=steps)


def counted_run(d, script, cmd, groups, options=()):
    """callgrind on `cmd` in folder d, counting the steps after `script`'s (in.timed's)
    `shell ./callgrind_on.sh`: {"total": the whole time step's instructions (Verlet::run),
    and for each name of `groups` the own instructions of the functions whose names hold
    one of its patterns}; with options=callgrind.SIMULATION also "simulated": the step's
    callgrind.simulated figures."""
    (d / "in.timed").write_text(script)
    profile = callgrind.count(cmd, d, env=_env(d), on_request=True, options=options)[-1]
    costs = callgrind.self_costs(profile)
    out = {name: sum(v for fn, v in costs.items() if any(p in fn for p in patterns))
           for name, patterns in groups.items()}
    out["total"] = callgrind.total(profile)
    if options:
        out["simulated"] = callgrind.simulated(callgrind.event_totals(profile))
    return out


def _mpi(data, nproc, work):
    d = _folder(work, f"mpi-{nproc}")
    (d / "in.timed").write_text(_script(data, STEPS))
    out, foreign = _run(_command("step", nproc), d, nproc)
    loop = LOOP.findall(out)[-1]
    # LAMMPS' "% CPU use": the ranks' CPU time over their wall time; below 100 % the ranks
    # waited for a core (other processes) or for each other
    return {"loop": float(loop[0]), "contacts": _contacts(out, WARM + STEPS), "foreign": foreign,
            "cpu_use": float(CPU_USE.findall(out)[-1])}


def measure(rounds=ROUNDS, reps=3, counts=True, callgrind_steps=CALLGRIND_STEPS):
    """Every figure of the benchmark (a dict; rows() turns it into bench rows)."""
    _check()
    data = _pour()
    order = list(CONFIGS)
    res = {"rounds": [], "counts": {}, "mpi": {1: [], 2: []}}
    with tempfile.TemporaryDirectory(prefix="lammps_bench-") as work:
        for r in range(rounds):
            turn = order[r % 3:] + order[:r % 3]
            res["rounds"].append({c: _timed(data, c, work) for c in turn})
        if counts and callgrind.available():
            with concurrent.futures.ThreadPoolExecutor(2) as pool:
                jobs = {c: pool.submit(_counted, data, c, work, callgrind_steps) for c in order}
                res["counts"] = {c: j.result() for c, j in jobs.items()}
        for k in range(reps):
            for nproc in ((1, 2) if k % 2 == 0 else (2, 1)):
                res["mpi"][nproc].append(_mpi(data, nproc, work))
    return res


def quiet_rounds(rounds):
    """The rounds a ratio is taken over: those in which no run saw the other processes use
    more than NOISY cores, if there are at least 3, else all; and the words that say which."""
    quiet = [r for r in rounds if all(x["foreign"] <= NOISY for x in r.values())]
    if len(quiet) >= 3:
        return quiet, f"the {len(quiet)} quiet rounds of {len(rounds)}"
    return rounds, f"{len(rounds)} rounds, {len(quiet)} of them quiet"


def rows(res):
    """Rows for bench.csv/bench.md."""
    out = []
    rounds = res["rounds"]
    used, which = quiet_rounds(rounds)
    atoms = rounds[0]["stock"]["atoms"]
    tag = f"in.pour's chute, {atoms} grains, {STEPS} steps, 1 process"
    for c in CONFIGS:
        t = statistics.median(r[c]["cpu"] for r in used) / STEPS
        k = statistics.median(r[c]["contacts"] for r in used)
        out.append({"benchmark": "lammps", "case": f"{LABEL[c]}: on-CPU s per step ({tag}; median of {which})",
                    "contacts": round(k), "seconds_per_step": t, "contact_steps_per_s": k / t, "value": t})
    for c in ("step", "exact"):
        ratio, lo, hi = ratio_interval([(r["stock"]["cpu"], r[c]["cpu"]) for r in used])
        out.append({"benchmark": "lammps", "case": f"{LABEL[c]} / stock, time (geometric mean of {which}, "
                                                  f"95 % interval {lo:.3f}-{hi:.3f}; target <= {TARGET[c]})",
                    "value": ratio})
    counts = res["counts"]
    if counts:
        n = counts["stock"]["steps"]
        for c in CONFIGS:
            k = counts[c]
            out.append({"benchmark": "lammps", "case": f"{LABEL[c]}: instructions per step, whole step / pair style / "
                                                      f"wall (callgrind, {n} steps)",
                        "value": f"{k['total'] / n:.4g} / {k['pair'] / n:.4g} / {k['wall'] / n:.4g}"})
        s = counts["stock"]
        for c in ("step", "exact"):
            k = counts[c]
            out.append({"benchmark": "lammps", "case": f"{LABEL[c]} / stock, instructions: whole step / pair style / "
                                                      f"pair style + wall (target <= {TARGET[c]})",
                        "value": f"{k['total'] / s['total']:.4f} / {k['pair'] / s['pair']:.4f} / "
                                 f"{(k['pair'] + k['wall']) / (s['pair'] + s['wall']):.4f}"})
    t1 = statistics.median(x["loop"] for x in res["mpi"][1])
    t2 = statistics.median(x["loop"] for x in res["mpi"][2])
    n = len(res["mpi"][1])
    busy = max(x["foreign"] for x in res["mpi"][1] + res["mpi"][2])
    use = statistics.median(x["cpu_use"] for x in res["mpi"][2])
    # (2 processes need both cores: other processes' load slows them far more than 1, and
    # Open MPI's ranks spin while they wait for each other)
    out.append({"benchmark": "lammps", "case": f"{LABEL['step']}: MPI speed-up, 2 processes (Loop time of {STEPS} "
                                              f"steps, median of {n}: 1 process {t1:.3f} s, 2 processes {t2:.3f} s; "
                                              f"2 processes' CPU use {use:.0f} %; other processes used up to "
                                              f"{busy:.1f} cores meanwhile)",
                "value": t1 / t2})
    k1 = statistics.median(x["contacts"] for x in res["mpi"][1])
    k2 = statistics.median(x["contacts"] for x in res["mpi"][2])
    out.append({"benchmark": "lammps", "case": "pair contacts at the end, 1 / 2 processes", "value": f"{k1:.0f} / {k2:.0f}"})
    return out


def benchmark(reps=3):
    """Rows for `stickslip bench` (see the module docstring)."""
    return rows(measure(ROUNDS, reps))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=ROUNDS)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--no-callgrind", action="store_true")
    ap.add_argument("--callgrind-steps", type=int, default=CALLGRIND_STEPS, help="steps counted by callgrind")
    a = ap.parse_args(argv)
    if a.callgrind_steps < 1:
        ap.error("--callgrind-steps must be >= 1")
    try:
        res = measure(a.rounds, a.reps, counts=not a.no_callgrind, callgrind_steps=a.callgrind_steps)
    except RuntimeError as e:
        print(f"lammps_bench: {e}", file=sys.stderr)
        return 1
    for r in rows(res):
        print(f"{r['case']}: {r['value'] if isinstance(r['value'], str) else format(r['value'], '.4g')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
