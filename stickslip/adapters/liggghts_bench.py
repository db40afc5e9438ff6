"""LIGGGHTS rows for `stickslip bench`: what the stick_slip plugin costs, and how it scales.

All figures come from one call, measured side by side on the same 3D packing of
20 800 settled spheres (created once, cached under build/liggghts_bench/):

1. plugin overhead: the same input script with `tangential stick_slip` (slips tested at
   the end of the step, and with `exact_slip_timing on`) and with LIGGGHTS' stock
   `tangential history` (hooke/stiffness, pair and floor), run alternately by the
   plugin's launcher; time = LIGGGHTS' own "Loop time" of a fixed number of steps after
   a short warm-up. Memory: history values per contact
   (read from `compute pair/gran/local id history`'s column count) and the peak
   RSS of each run.
2. MPI speed-up: the stick_slip script on 1 process (launcher) and on 2
   (`mpirun -np 2` launcher), speed-up = T1/T2, and the contact statistics of both
   (`compute contact/atom` summed: pair contacts, mean coordination) to show they agree.

Every time is a median over `reps` repetitions; the runs of one repetition follow
each other (A, B, C, then C, B, A, ...) so slow drifts of the machine cancel. The
timings need an otherwise idle machine: each run measures the CPU the rest of the
machine used meanwhile (/proc/stat), a run disturbed by more than NOISY cores is
re-run (within a budget of 2 x reps re-runs), and the worst remaining figure is a row.

Cost on the 2-core reference machine: ~4.5 min for benchmark(3) with the packing cached,
~2 min more to make it (40 000 steps on 2 processes).

    python -m stickslip.adapters.liggghts_bench [--reps 3]
"""
from __future__ import annotations

import argparse
import hashlib
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .liggghts import BUILD, LAUNCHER

CACHE = BUILD.parent / "liggghts_bench"

STEPS = 3000  # timed steps per run (~20 s on one core of the reference machine)
WARM = 200  # untimed steps first: contact histories build up again after read_data
SETTLE = 40000  # steps of the one-off pour (0.2 s of gravity settling)

# One material for every run: soft spheres (r = 0.8-1.0 mm, kn = 2000 N/m), dt ~ T_c/30.
MATERIAL = """\
fix m1 all property/global kn peratomtypepair 1 2000
fix m2 all property/global kt peratomtypepair 1 1600
fix m3 all property/global gamman_abs peratomtypepair 1 0.1
fix m4 all property/global gammat_abs peratomtypepair 1 0.05
fix m5 all property/global coefficientFriction peratomtypepair 1 0.5
fix m6 all property/global coefficientKineticFriction peratomtypepair 1 0.45
"""

HEADER = """\
atom_style sphere
atom_modify map array
boundary p p f
newton off
communicate single vel yes
units si
processors * * 1
"""

# 40 x 40 x 13 spheres on a loose lattice (random diameters 1.6-2.0 mm, shifted
# sideways at random) fall onto the floor of a box periodic in x and y and settle.
MAKE_PACKING = HEADER + """\
region box block 0 0.088 0 0.088 0 0.040 units box
create_box 1 box
neighbor 0.0003 bin
neigh_modify delay 0
""" + MATERIAL + """\
pair_style gran model hooke/stiffness tangential history absolute_damping on limitForce on
pair_coeff * *
timestep 5e-6
region fill block 0 0.088 0 0.088 0.0011 0.0287 units box
lattice sc 0.0022 origin 0.5 0.5 0.5
create_atoms 1 region fill
variable d atom 0.0016+0.0004*random(0,1,15485863)
set type 1 diameter v_d density 2600
displace_atoms all random 0.0002 0.0002 0.0 49979687 units box
fix floor all wall/gran model hooke/stiffness tangential history primitive type 1 zplane 0.0 absolute_damping on limitForce on
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
compute ke all ke
thermo_style custom step atoms c_ke
thermo 5000
run {settle}
write_data {out}
"""

# The timed script: identical for all configurations but for ${tang} and ${extra}.
TIMED = HEADER + """\
read_data {data}
neighbor 0.0003 bin
neigh_modify delay 0
""" + MATERIAL + """\
pair_style gran model hooke/stiffness tangential ${{tang}} absolute_damping on limitForce on ${{extra}}
pair_coeff * *
timestep 5e-6
fix floor all wall/gran model hooke/stiffness tangential ${{tang}} primitive type 1 zplane 0.0 absolute_damping on limitForce on ${{extra}}
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
compute c all contact/atom
compute cs all reduce sum c_c
thermo_style custom step atoms c_cs
thermo {warm}
run {warm}
thermo {steps}
run {steps}
"""

# Two overlapping spheres, one step, and a local dump of `id history` with K columns:
# LIGGGHTS refuses a column beyond the compute's count, so the largest K that runs
# is 3 (id) + the number of history values per contact.
HISTORY_PROBE = """\
atom_style sphere
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
neighbor 0.0003 bin
""" + MATERIAL + """\
pair_style gran model hooke/stiffness tangential {tang} absolute_damping on limitForce on {extra}
pair_coeff * *
timestep 5e-6
create_atoms 1 single 0 0 0 units box
create_atoms 1 single 0.0019 0 0 units box
set atom * diameter 0.002 density 2600
fix integr all nve/sphere
compute pl all pair/gran/local id history
dump d all local 1 {dump} {columns}
run 1
"""

# each configuration: the tangential model, and a setting appended to the pair and wall
# lines (fix wall/gran takes the settings last; "limitForce on" repeats one already there)
TANGENTIAL = {"history": ("history", "limitForce on"), "stick_slip": ("stick_slip", "limitForce on"),
              "stick_slip_exact": ("stick_slip", "exact_slip_timing on")}

NOISY = 0.1  # cores used by other processes during a run above which it is re-run (within a budget)
LAST_RUNS = {}  # (tangential model, processes) -> the runs behind the last benchmark() figures
DISCARDED = []  # runs re-done because the machine was busy

LOOP = re.compile(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms")
MEMORY = re.compile(r"Memory usage per processor = (\S+) Mbytes")


def _env():
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def _check():
    if not LAUNCHER.is_file():
        raise RuntimeError(f"LIGGGHTS plugin launcher not built: {LAUNCHER} missing "
                           "(cmake -S liggghts_plugin -B build/liggghts_plugin && cmake --build build/liggghts_plugin)")
    if shutil.which("mpirun") is None:
        raise RuntimeError("mpirun not on PATH (apt-get install openmpi-bin): needed for the MPI speed-up")


def _busy_jiffies():
    """CPU time (all cores, in clock ticks) the machine has spent busy so far (Linux; else None)."""
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    return sum(v) - v[3] - (v[4] if len(v) > 4 else 0)  # all but idle and iowait


def _vm_hwm_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1])
    except OSError:
        pass
    return 0.0


def _run(args, cwd, timeout=3600, info=None):
    """Run a LIGGGHTS command line; returns (stdout, peak RSS of the process in MiB).
    `info`, a dict, receives `foreign_cores`: the CPU the rest of the machine used meanwhile,
    in cores (busy time of all cores minus this run's own, over the wall time)."""
    b0, w0 = _busy_jiffies(), time.monotonic()
    with open(cwd / "stdout.txt", "w+", errors="replace") as out:
        p = subprocess.Popen(args, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=_env(), text=True)
        t0 = time.monotonic()
        hwm = 0.0
        while True:
            # peak RSS from /proc (VmHWM, KiB): ru_maxrss would also count the memory of this
            # Python process, which the child shares between fork and exec
            hwm = max(hwm, _vm_hwm_kib(p.pid))
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - t0 > timeout:
                p.kill()
                pid, status, usage = os.wait4(p.pid, 0)
                break
            time.sleep(0.05)
        p.returncode = os.waitstatus_to_exitcode(status)
        b1, wall = _busy_jiffies(), time.monotonic() - w0
        if info is not None and b0 is not None and b1 is not None and wall > 0:
            # rusage of mpirun includes its ranks (its waited-for children)
            own = usage.ru_utime + usage.ru_stime
            info["foreign_cores"] = max(0.0, ((b1 - b0) / os.sysconf("SC_CLK_TCK") - own) / wall)
        out.seek(0)
        text = out.read()
    if p.returncode != 0:
        lines = text.strip().splitlines() or ["no output"]
        why = next((x.strip() for x in lines if "ERROR" in x), lines[-1].strip())
        raise RuntimeError(f"{' '.join(map(str, args[:3]))} ... failed (exit {p.returncode}) in {cwd}: {why}")
    return text, hwm / 1024.0


def _packing():
    """The settled packing as a data file; built once (on 2 processes), reused afterwards."""
    script = MAKE_PACKING.format(settle=SETTLE, out="{out}")
    key = hashlib.sha1(script.encode()).hexdigest()[:12]
    data = CACHE / f"packing-{key}.data"
    if data.is_file():
        return data
    CACHE.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=CACHE) as tmp:
        tmp = Path(tmp)
        (tmp / "in.packing").write_text(script.format(out="packing.data"))
        _run(["mpirun", "-np", "2", str(LAUNCHER), "-in", "in.packing", "-log", "log.packing"], tmp)
        os.replace(tmp / "packing.data", data)
    return data


def _history_values(tang, extra, work):
    """Number of contact-history values per contact, as LIGGGHTS reports it."""
    d = work / f"probe-{tang}{'-rec' if extra else ''}"
    d.mkdir(exist_ok=True)
    best = None
    for k in range(4, 21):
        cols = " ".join(f"c_pl[{i}]" for i in range(1, k + 1))
        (d / "in.probe").write_text(HISTORY_PROBE.format(tang=tang, extra=extra, dump="dump.probe", columns=cols))
        try:
            _run([str(LAUNCHER), "-in", "in.probe", "-log", "none"], d, timeout=120)
        except RuntimeError as e:
            if "out-of-range" in str(e):
                break
            raise
        best = k
    if best is None:
        raise RuntimeError(f"could not read the history size of tangential {tang}")
    return best - 3


def _timed(data, tang, nproc, work):
    """One timed run: seconds per step, pair contacts, atoms, peak RSS (MiB), LIGGGHTS' memory estimate."""
    d = work / f"{tang}-np{nproc}"
    d.mkdir(exist_ok=True)
    (d / "in.timed").write_text(TIMED.format(data=data, warm=WARM, steps=STEPS))
    model, extra = TANGENTIAL[tang]
    cmd = [str(LAUNCHER), "-in", "in.timed", "-log", "none", "-var", "tang", model, "-var", "extra", extra]
    if nproc > 1:
        cmd = ["mpirun", "-np", str(nproc)] + cmd
    info = {}
    text, rss = _run(cmd, d, info=info)
    loops = LOOP.findall(text)
    if len(loops) < 2:
        raise RuntimeError(f"no 'Loop time' line for the timed run ({tang}, {nproc} procs)")
    seconds, procs, steps, atoms = float(loops[-1][0]), int(loops[-1][1]), int(loops[-1][2]), int(loops[-1][3])
    # the thermo line of the last step: step atoms c_cs (contact/atom summed = 2 x pair contacts)
    last = [ln.split() for ln in text.splitlines() if re.match(rf"\s*{WARM + STEPS}\s+{atoms}\s", ln)]
    contact_sum = float(last[-1][2])
    mem = MEMORY.findall(text)
    return {"s_per_step": seconds / steps, "procs": procs, "atoms": atoms, "contacts": contact_sum / 2,
            "coordination": contact_sum / atoms, "rss_mib": rss, "liggghts_mib": float(mem[-1]) if mem else None,
            "foreign_cores": info.get("foreign_cores")}


def benchmark(reps=3):
    """Rows for `stickslip bench` (see the module docstring)."""
    _check()
    reps = max(1, int(reps))
    DISCARDED.clear()
    data = _packing()
    configs = [("history", 1), ("stick_slip", 1), ("stick_slip", 2), ("stick_slip_exact", 1)]
    runs = {c: [] for c in configs}
    with tempfile.TemporaryDirectory(prefix="liggghts_bench-") as work:
        work = Path(work)
        hist = {"history": _history_values("history", "", work),
                "stick_slip": _history_values("stick_slip", "", work),
                "stick_slip_record": _history_values("stick_slip", "stick_slip_record on", work)}
        retries = 2 * reps  # budget for re-running runs disturbed by other processes
        for r in range(reps):
            for c in (configs if r % 2 == 0 else configs[::-1]):
                while True:
                    got = _timed(data, c[0], c[1], work)
                    busy = got["foreign_cores"] or 0.0
                    if busy <= NOISY or retries <= 0:
                        break
                    retries -= 1
                    DISCARDED.append((c, got))
                runs[c].append(got)
        LAST_RUNS.clear()
        LAST_RUNS.update(runs)

    def med(c, key):
        return statistics.median(x[key] for x in runs[c])

    A, B, M, E = configs
    n = runs[B][0]["atoms"]
    tag = f"{n} spheres, {STEPS} steps, median of {reps}"
    rows = []
    for c, label in ((A, "stock tangential history"), (B, "tangential stick_slip"),
                     (E, "tangential stick_slip exact_slip_timing on")):
        t, k = med(c, "s_per_step"), med(c, "contacts")
        rows.append({"benchmark": "liggghts", "case": f"overhead: {label}, s per step (1 process; {tag})",
                     "contacts": round(k), "seconds_per_step": t, "contact_steps_per_s": k / t, "value": t})
    ratio = med(B, "s_per_step") / med(A, "s_per_step")
    paired = statistics.median(b["s_per_step"] / a["s_per_step"] for a, b in zip(runs[A], runs[B]))
    rows.append({"benchmark": "liggghts", "case": "overhead: wall-time ratio stick_slip / history (target <= 1.05)",
                 "value": ratio})
    rows.append({"benchmark": "liggghts", "case": "overhead: median of the per-repetition ratios stick_slip / history",
                 "value": paired})
    rows.append({"benchmark": "liggghts", "case": "overhead: wall-time ratio stick_slip exact_slip_timing on / history "
                 "(target <= 1.05)", "value": med(E, "s_per_step") / med(A, "s_per_step")})
    rows.append({"benchmark": "liggghts", "case": "overhead: median of the per-repetition ratios stick_slip exact / history",
                 "value": statistics.median(e["s_per_step"] / a["s_per_step"] for a, e in zip(runs[A], runs[E]))})
    for key, label in (("history", "stock tangential history"), ("stick_slip", "tangential stick_slip"),
                       ("stick_slip_record", "stick_slip with stick_slip_record on")):
        rows.append({"benchmark": "liggghts", "case": f"memory: history values per contact, {label}",
                     "value": float(hist[key])})
    for c, label in ((A, "stock tangential history"), (B, "tangential stick_slip")):
        rows.append({"benchmark": "liggghts", "case": f"memory: peak RSS of the run, MiB, {label}",
                     "value": med(c, "rss_mib")})
        if runs[c][0]["liggghts_mib"] is not None:
            rows.append({"benchmark": "liggghts", "case": f"memory: LIGGGHTS' estimate per process, MiB, {label}",
                         "value": runs[c][0]["liggghts_mib"]})
    t1, t2 = med(B, "s_per_step"), med(M, "s_per_step")
    for c, t, label in ((B, t1, "1 process (launcher)"), (M, t2, "2 processes (mpirun -np 2)")):
        k = med(c, "contacts")
        rows.append({"benchmark": "liggghts", "case": f"MPI: stick_slip, {label}, s per step ({tag})",
                     "contacts": round(k), "seconds_per_step": t, "contact_steps_per_s": k / t, "value": t})
    rows.append({"benchmark": "liggghts", "case": "MPI: speed-up T1/T2 on 2 processes (target >= 1.6)",
                 "value": t1 / t2})
    for c, label in ((B, "1 process"), (M, "2 processes")):
        rows.append({"benchmark": "liggghts",
                     "case": f"MPI: mean coordination (pair contacts per sphere, contact/atom) at the end, {label}",
                     "contacts": round(med(c, "contacts")), "value": med(c, "coordination")})
    k1, k2 = med(B, "contacts"), med(M, "contacts")
    rows.append({"benchmark": "liggghts", "case": "MPI: relative difference in pair contacts, 2 vs 1 process",
                 "value": (k2 - k1) / k1})
    # Timings mean something only on an otherwise idle machine: say how busy it was
    # (runs above NOISY were re-run while the retry budget lasted).
    foreign = [x["foreign_cores"] for c in configs for x in runs[c] if x["foreign_cores"] is not None]
    if foreign:
        rows.append({"benchmark": "liggghts", "case": "machine: CPU used by other processes during the kept runs, "
                     f"cores (max; {os.cpu_count()} cores; figures are unreliable above ~{NOISY})",
                     "value": max(foreign)})
    return rows


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
    lines = [f"{'case':<100} {'contacts':>9} {'value':>12}"]
    for r in rows:
        c = "" if r.get("contacts") is None else str(r["contacts"])
        lines.append(f"{r['case']:<100} {c:>9} {r['value']:>12.5g}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m stickslip.adapters.liggghts_bench",
                                 description="LIGGGHTS stick_slip plugin: overhead vs stock history, MPI speed-up.")
    ap.add_argument("--reps", type=int, default=3, help="repetitions per figure (median quoted)")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    try:
        rows = benchmark(a.reps)
    except RuntimeError as e:
        sys.stderr.write(f"liggghts_bench: {e}\n")
        return 1
    print(_table(rows))
    print("\nruns (s per step, other processes' CPU in cores):")
    for (tang, nproc), got in LAST_RUNS.items():
        print(f"  {tang:<16} np={nproc}: " + ", ".join(f"{x['s_per_step']:.5f} ({x['foreign_cores'] or 0:.2f})" for x in got))
    if DISCARDED:
        print(f"  re-run because the machine was busy: {len(DISCARDED)} run(s)")
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
