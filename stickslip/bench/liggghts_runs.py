# SPDX-License-Identifier: GPL-2.0-or-later
"""The LIGGGHTS benchmark's runs (stickslip/bench/liggghts.py): the settled packing (made once,
cached under build/liggghts_bench/), the input script of every configuration of the
tangential model, and running one (the plugin's launcher, alone or under mpirun) with what
its output says (atoms, contacts, history values per contact, peak memory)."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import time

from ..adapters.liggghts import BUILD, LAUNCHER
from .data_cache import cached_data

CACHE = BUILD.parent / "liggghts_bench"

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

# The timed script: identical for all configurations but for ${tang} and ${extra}; {timed}
# is the timed part (chunks with probes between them, or one run for callgrind or MPI).
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
{timed}"""


def single(steps):
    return f"thermo {steps}\nrun {steps}\n"


def write_timed(d, data, timed):
    """The timed script into d/in.timed: the packing `data`, the warm-up, then `timed`."""
    (d / "in.timed").write_text(TIMED.format(data=data, warm=WARM, timed=timed))


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
              "stick_slip_exact": ("stick_slip", "exact_slip_timing on"),
              "stick_slip_keep": ("stick_slip", "history_on_separation keep")}
LABEL = {"history": "stock tangential history", "stick_slip": "tangential stick_slip",
         "stick_slip_exact": "tangential stick_slip exact_slip_timing on",
         "stick_slip_keep": "tangential stick_slip history_on_separation keep (no stamp)",
         "control": "stock history compiled in the plugin (control build)"}

LOOP = re.compile(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms")
MEMORY = re.compile(r"Memory usage per processor = (\S+) Mbytes")


def env():
    """The runs' environment: no preloaded library, and mpirun allowed as root."""
    out = dict(os.environ)
    out.pop("LD_PRELOAD", None)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        out.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return out


def check():
    if not LAUNCHER.is_file():
        raise RuntimeError(f"LIGGGHTS plugin launcher not built: {LAUNCHER} missing "
                           "(cmake -S liggghts_plugin -B build/liggghts_plugin && cmake --build build/liggghts_plugin)")
    if shutil.which("mpirun") is None:
        raise RuntimeError("mpirun not on PATH (apt-get install openmpi-bin): needed for the MPI speed-up")


def busy_jiffies():
    """CPU time (all cores, in clock ticks) the machine has spent busy so far (Linux; else None)."""
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    return sum(v) - v[3] - (v[4] if len(v) > 4 else 0)  # all but idle and iowait


def vm_hwm_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1])
    except OSError:
        pass
    return 0.0


def run(args, cwd, timeout=3600, info=None):
    """Run a LIGGGHTS command line; returns (stdout, peak RSS of the process in MiB).
    `info`, a dict, receives `foreign_cores`: the CPU the rest of the machine used meanwhile,
    in cores (busy time of all cores minus this run's own, over the wall time)."""
    b0, w0 = busy_jiffies(), time.monotonic()
    with open(cwd / "stdout.txt", "w+", errors="replace") as out:
        p = subprocess.Popen(args, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env(), text=True)
        t0 = time.monotonic()
        hwm = 0.0
        while True:
            # peak RSS from /proc (VmHWM, KiB): ru_maxrss would also count the memory of this
            # Python process, which the child shares between fork and exec
            hwm = max(hwm, vm_hwm_kib(p.pid))
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - t0 > timeout:
                p.kill()
                pid, status, usage = os.wait4(p.pid, 0)
                break
            time.sleep(0.05)
        p.returncode = os.waitstatus_to_exitcode(status)
        b1, wall = busy_jiffies(), time.monotonic() - w0
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


def packing():
    """The settled packing as a data file; built once (on 2 processes), reused afterwards."""
    script = MAKE_PACKING.format(settle=SETTLE, out="{out}")

    def make(tmp):
        (tmp / "in.packing").write_text(script.format(out="packing.data"))
        run(["mpirun", "-np", "2", str(LAUNCHER), "-in", "in.packing", "-log", "log.packing"], tmp)
        return tmp / "packing.data"
    return cached_data(CACHE, "packing", script, make)


def history_values(tang, extra, work):
    """Number of contact-history values per contact, as LIGGGHTS reports it."""
    d = work / f"probe-{tang}{'-rec' if extra else ''}"
    d.mkdir(exist_ok=True)
    best = None
    for k in range(4, 21):
        cols = " ".join(f"c_pl[{i}]" for i in range(1, k + 1))
        (d / "in.probe").write_text(HISTORY_PROBE.format(tang=tang, extra=extra, dump="dump.probe", columns=cols))
        try:
            run([str(LAUNCHER), "-in", "in.probe", "-log", "none"], d, timeout=120)
        except RuntimeError as e:
            if "out-of-range" in str(e):
                break
            raise
        best = k
    if best is None:
        raise RuntimeError(f"could not read the history size of tangential {tang}")
    return best - 3


def command(tang, nproc=1, launcher=LAUNCHER):
    model, extra = TANGENTIAL[tang]
    cmd = [str(launcher), "-in", "in.timed", "-log", "none", "-var", "tang", model, "-var", "extra", extra]
    return ["mpirun", "-np", str(nproc)] + cmd if nproc > 1 else cmd


def contacts_at(text, step, atoms):
    """Pair contacts at `step` from its thermo line (step atoms c_cs; contact/atom summed
    counts each pair contact twice)."""
    last = [ln.split() for ln in text.splitlines() if re.match(rf"\s*{step}\s+{atoms}\s", ln)]
    if not last:
        raise RuntimeError(f"no thermo line for step {step}")
    return float(last[-1][2]) / 2
