# SPDX-License-Identifier: GPL-2.0-or-later
"""Modern LAMMPS rows for `stickslip bench`: what the tangential sub-model
`stick_slip` of `pair_style granular` costs against LAMMPS' own `linear_history` (the same
numeric Ks) and `mindlin` (Ks NULL on both: Mindlin's 8 G* a), on a settled bed of 10 368
spheres, in both slip timings.

The bed, made once and cached under build/lammps_2025_bench/ (named by the hash of the
script that makes it, data_cache.py): 24 x 24 x 18 spheres on a simple-cubic lattice of
spacing 1.2, jittered by up to 0.1, diameters uniform in 0.9-1.1, density 1 (LJ units), in
a box periodic in x and y, fall under gravity 1 onto a floor wall (`fix wall/gran granular
... zplane`) and settle with stock linear_history until the kinetic energy per grain
(translation + rotation), checked every 2500 steps after the first 10 000, is below KE_MAX =
1e-6 (~1e-6 m g d for a grain of d = 1): 20 000 steps, ~1 min of one core, once. It lies
~11.5 deep (packing fraction ~0.59), with 24 888 pair contacts (2.40 per grain: the
coordination number of frictional spheres, 4.8) and ~660 grains on the floor.

Every configuration: hertz/material E 1e5, restitution 0.5 (`damping coeff_restitution`),
Poisson 0.3; tangential damping x = 1.0; mu_s 0.5; the law's mu_k 0.45 (Fmin = 0.4 Fn) with
the paper's reset (no /total: at a slip the spring alone is reset to carry Fmin), step
timing (`stick_slip`) and exact (`stick_slip/exact`). The pair and the floor wall have the
same model and are swapped together: each configuration's script differs from its stock's
in the tangential words alone.

The timed scene is lammps.py's (in.pour's chute): gravity tilted 26 degrees, the bed shears
over the frictional floor and dilates: 12.7 % of the pair contact-steps of the timed steps
slip in the step timing with Ks (12.5 % with NULL; the law's slip count with /record,
measured once), ~23 300 pair contacts at their end.

1. Time: in each round the six configurations run one after the other as separate
   processes, the order turning from round to round; each reads the bed, runs WARM untimed
   steps (the contacts' history builds up again after read_data), then STEPS timed ones.
   The time is the process' on-CPU time over the timed steps alone (a /proc/PID/schedstat
   probe that the input script runs with `shell`; lammps.timed_run). Each round's ratio
   divides two runs made seconds apart; the figure is the geometric mean over the rounds
   with a 95 % interval (ratio_interval.py), over the quiet rounds when there are at least
   3 (lammps.quiet_rounds: the rest of the machine used at most NOISY cores in every run).
2. Instructions (callgrind, load-independent): over CALLGRIND_STEPS steps after the same
   warm-up (not instrumented), in the whole time step (Verlet::run), in the contact model
   (pair granular, the wall fix, GranularModel and its sub-models) and in the tangential
   sub-model alone (with the exact timing's out-of-line function).
3. With --simulate, what the instruction count does not show: callgrind's simulation of
   the caches and branch predictors over the same window (callgrind.SIMULATION), each
   configuration's first-level and last-level cache misses and mispredicted branches per
   step against its stock's, and a time model from them (callgrind.simulated: a cycle an
   instruction, 10 more a first-level miss, 100 a last-level one, 15 a mispredicted
   branch), for a machine whose load leaves the time's interval too wide to tell 5 %.

Cost on the 2-core machine: ~1 min of one core once for the bed; ~27 s a round (six runs:
~2.7 s timed, ~1.5 s of start and warm-up; 10 rounds by default), ~1.5 min of callgrind
(two at a time): ~6 min in all (measured at load 2-4; the other processes' load slows it);
--simulate makes callgrind's pass ~2 min longer. (`stickslip bench` takes these rows; its `reps` has no use here: no MPI part.)

    python -m stickslip.bench.lammps_granular [--release lammps-2026] [--rounds 10] [--steps 800] [--no-callgrind]
                                              [--callgrind-steps 100] [--simulate]
"""
from __future__ import annotations

import argparse
import concurrent.futures
import math
import statistics
import sys
import tempfile
import time

from ..adapters import lammps_granular
from . import callgrind
from . import lammps as base
from .data_cache import cached_data
from .proc_probe import probe_script
from .ratio_interval import ratio_interval

CACHE = base.ROOT / "build" / "lammps_2025_bench"

BED = (24, 24, 18)  # grains along x, y (lattice sites, periodic) and layers: 10 368
KE_MAX = 1e-6  # settled: kinetic energy per grain below this (LJ units)
WARM = 200  # untimed steps after read_data
STEPS = 800  # timed steps (~2.7 s on one core)
ROUNDS = 10
CALLGRIND_STEPS = 100

NORMAL = "hertz/material 1e5 0.5 0.3 damping coeff_restitution"
KS, X, MU_S, MU_K = "2000.0", "1.0", "0.5", "0.45"
TANGENTIAL = {  # a configuration: its tangential sub-model's words (pair and wall alike)
    "linear_history": f"linear_history {KS} {X} {MU_S}",
    "ks_step": f"stick_slip {KS} {X} {MU_S} {MU_K}",
    "ks_exact": f"stick_slip/exact {KS} {X} {MU_S} {MU_K}",
    "mindlin": f"mindlin NULL {X} {MU_S}",
    "null_step": f"stick_slip NULL {X} {MU_S} {MU_K}",
    "null_exact": f"stick_slip/exact NULL {X} {MU_S} {MU_K}",
}
STOCK = {"ks_step": "linear_history", "ks_exact": "linear_history", "null_step": "mindlin", "null_exact": "mindlin"}
TARGET = {"ks_step": 1.02, "ks_exact": 1.05, "null_step": 1.02, "null_exact": 1.05}
# callgrind: own instructions of the functions whose names hold one of the patterns
GROUPS = {"model": ("PairGranular::", "FixWallGran", "GranularModel::", "GranSubMod", "StickSlipCore::"),
          "tangential": ("GranSubModTangential", "StickSlipCore::")}

SETTLE = """\
units lj
atom_style sphere
boundary p p fm
newton off
comm_modify vel yes
lattice sc {density!r}
region box block 0 {nx} 0 {ny} 0 {zhi}
create_box 1 box
region fill block 0 {nx} 0 {ny} 0.5 {top}
create_atoms 1 region fill
variable d atom 0.9+0.2*random(0,1,4711)
set group all diameter v_d
set group all density 1.0
displace_atoms all random 0.1 0.1 0.1 4712 units box
velocity all create 0.1 4713 dist gaussian
neighbor 0.2 bin
neigh_modify delay 0
pair_style granular
pair_coeff * * {model}
timestep 0.001
fix 1 all nve/sphere
fix 2 all gravity 1.0 vector 0 0 -1
fix floor all wall/gran granular {model} zplane 0.0 NULL
compute ke all ke
compute rke all erotate/sphere
variable kpg equal (c_ke+c_rke)/atoms
thermo_style custom step atoms v_kpg
thermo 2500
run 10000
variable chunk loop 40
label settle
run 2500
if "${{kpg}} < {ke_max!r}" then "jump SELF settled"
next chunk
jump SELF settle
print "ERROR: the bed has not settled (kinetic energy per grain ${{kpg}})"
quit 1
label settled
write_data bed.data
"""

# on-CPU time (ns) of the LAMMPS process (named lmp) that runs it through `shell`, appended to probe.log
PROBE = probe_script("lmp)", 'read -r s < /proc/$p/schedstat\necho "${s%% *}" >> probe.log')


def model(config):
    """The granular model's words of a configuration (pair_coeff's and the wall's)."""
    return f"{NORMAL} tangential {TANGENTIAL[config]}"


def label(config):
    return f"tangential {TANGENTIAL[config].split()[0]} (Ks {TANGENTIAL[config].split()[1]})"


def launcher(release=None):
    """The lmp to time: a release of lammps_granular.RELEASES, or the newest built."""
    if release is None:
        return lammps_granular.LAUNCHER
    why = lammps_granular.release_missing(release)
    if why:
        raise RuntimeError(why)
    return lammps_granular.built()[release]


def _check(lmp):
    if not lmp.is_file():
        raise RuntimeError(f"LAMMPS not built: {lmp} missing (STICKSLIP_SOURCE_BUILDS="
                           f"{','.join(lammps_granular.RELEASES)} ./run.sh setup)")


def bed(size=BED, cache=CACHE, lmp=None):
    """The settled bed's data file (made once, kept in `cache`); size: grains along x, y and layers."""
    nx, ny, layers = size
    spacing = 1.2
    script = SETTLE.format(density=1 / spacing ** 3, nx=nx, ny=ny, top=layers + 0.5,
                           zhi=layers + 3, model=model("linear_history"), ke_max=KE_MAX)

    def make(tmp):
        (tmp / "in.settle").write_text(script)
        base._run(_command("in.settle", lmp), tmp)
        return tmp / "bed.data"
    return cached_data(cache, f"bed-{nx}x{ny}x{layers}", script, make)


def bed_facts(data):
    """{grains, kinetic energy per grain (translation + rotation), steps it took to settle}
    read from the data file."""
    mass, ke, section, steps = {}, 0.0, None, None
    with open(data) as f:
        for line in f:
            if steps is None and "timestep =" in line:
                steps = int(line.split("timestep =")[1].split(",")[0])
            words = line.split()
            if words and words[0][0].isalpha():  # a section's title (Atoms # sphere, Velocities)
                section = words[0]
                continue
            if len(words) < 7 or not words[0].isdigit():
                continue
            if section == "Atoms":  # id type diameter density x y z ...
                d, rho = float(words[2]), float(words[3])
                mass[words[0]] = (rho * math.pi * d ** 3 / 6, d)
            elif section == "Velocities":  # id vx vy vz wx wy wz
                m, d = mass[words[0]]
                v = [float(x) for x in words[1:7]]
                ke += 0.5 * m * sum(x * x for x in v[:3]) + 0.5 * (0.1 * m * d * d) * sum(x * x for x in v[3:])
    return {"grains": len(mass), "ke_per_grain": ke / len(mass), "settle_steps": steps}


def _command(infile="in.timed", lmp=None):
    return [str(lmp or lammps_granular.LAUNCHER), "-in", infile, "-log", "none", "-echo", "none", "-nocite"]


def script(data, config, steps=STEPS, warm=WARM, before="", after=""):
    """The input of one configuration's run on the bed `data`."""
    # lammps.py's chute on the bed; the model written into the script, pair and wall alike
    m = model(config)
    return base.chute_script(data, f"pair_style granular\npair_coeff * * {m}",
                             f"fix floor all wall/gran granular {m} zplane 0.0 NULL", warm, steps, before, after,
                             units="units lj\n")


def _timed(data, config, work, steps, warm, lmp):
    """One run: on-CPU seconds of the timed steps, pair contacts at their start (step 0) and
    end, the other processes' CPU during the run (cores)."""
    d = base._folder(work, f"timed-{config}")
    cpu, out, foreign = base.timed_run(d, script(data, config, steps, warm, "shell ./probe.sh", "shell ./probe.sh"),
                                       _command(lmp=lmp), PROBE)
    return {"cpu": cpu, "contacts0": base._contacts(out, 0), "contacts": base._contacts(out, warm + steps),
            "foreign": foreign, "atoms": int(base.LOOP.findall(out)[-1][3])}


def _counted(data, config, work, steps, warm, lmp, options=()):
    d = base._folder(work, f"callgrind-{config}")
    k = base.counted_run(d, script(data, config, steps, warm, "shell ./callgrind_on.sh"), _command(lmp=lmp), GROUPS,
                         options)
    return dict(k, steps=steps)


def measure(rounds=ROUNDS, counts=True, callgrind_steps=CALLGRIND_STEPS, size=BED, steps=STEPS, warm=WARM,
            cache=CACHE, log=None, release=None, simulate=False):
    """Every figure of the benchmark (a dict; rows() turns it into bench rows). `log`: a
    function told of each finished round; release: the LAMMPS release to time (a word of
    lammps_granular.RELEASES; None: the newest built); simulate: also callgrind's cache
    and branch simulation (the docstring's 3.)."""
    lmp = launcher(release)
    _check(lmp)
    t0 = time.monotonic()
    data = bed(size, cache, lmp)
    res = {"bed": bed_facts(data), "bed_s": time.monotonic() - t0, "steps": steps, "rounds": [], "counts": {},
           "release": release or next(r for r, x in lammps_granular.built().items() if x == lmp)}
    order = list(TANGENTIAL)
    with tempfile.TemporaryDirectory(prefix="lammps_granular_bench-") as work:
        for r in range(rounds):
            turn = order[r % len(order):] + order[:r % len(order)]
            res["rounds"].append({c: _timed(data, c, work, steps, warm, lmp) for c in turn})
            if log:
                log(f"round {r + 1}/{rounds}: "
                    + ", ".join(f"{c} {x['cpu']:.3f} s" for c, x in res["rounds"][-1].items()))
        t1 = time.monotonic()
        if (counts or simulate) and callgrind.available():
            # one callgrind pass: the simulation leaves the instruction counts as they are
            options = callgrind.SIMULATION if simulate else ()
            with concurrent.futures.ThreadPoolExecutor(2) as pool:
                jobs = {c: pool.submit(_counted, data, c, work, callgrind_steps, warm, lmp, options) for c in order}
                res["counts"] = {c: j.result() for c, j in jobs.items()}
        res["callgrind_s"] = time.monotonic() - t1
    res["rounds_s"] = t1 - t0 - res["bed_s"]
    return res


def rows(res):
    """Rows for bench.csv/bench.md."""
    out = []
    rounds, b = res["rounds"], res["bed"]
    used, which = base.quiet_rounds(rounds)
    first = rounds[0]["linear_history"]
    tag = f"LAMMPS {res['release']}, settled bed's chute, {first['atoms']} grains, {res['steps']} steps, 1 process"
    out.append({"benchmark": "lammps_granular", "case": f"the bed: grains / pair contacts per grain at read_data / "
                                                        f"kinetic energy per grain (LJ) / steps it settled in",
                "value": f"{b['grains']} / {first['contacts0'] / first['atoms']:.2f} / {b['ke_per_grain']:.2g} / "
                         f"{b['settle_steps']}"})
    for c in TANGENTIAL:
        t = statistics.median(r[c]["cpu"] for r in used) / res["steps"]
        k = statistics.median(r[c]["contacts"] for r in used)
        out.append({"benchmark": "lammps_granular", "case": f"{label(c)}: on-CPU s per step ({tag}; median of {which})",
                    "contacts": round(k), "seconds_per_step": t, "contact_steps_per_s": k / t, "value": t})
    busy = [r for r in rounds if not any(r is q for q in used)]  # left out of the figure: reported apart
    for c, stock in STOCK.items():
        ratio, lo, hi = ratio_interval([(r[stock]["cpu"], r[c]["cpu"]) for r in used])
        out.append({"benchmark": "lammps_granular",
                    "case": f"{label(c)} / {label(stock)}, time (geometric mean of {which}, 95 % interval "
                            f"{lo:.3f}-{hi:.3f}; target <= {TARGET[c]})", "value": ratio, "ci_low": lo, "ci_high": hi})
        if busy:
            ratio, lo, hi = ratio_interval([(r[stock]["cpu"], r[c]["cpu"]) for r in busy])
            out.append({"benchmark": "lammps_granular",
                        "case": f"{label(c)} / {label(stock)}, time in the {len(busy)} busy rounds left out (geometric "
                                f"mean, 95 % interval {lo:.3f}-{hi:.3f})", "value": ratio, "ci_low": lo, "ci_high": hi})
    counts = res["counts"]
    if counts:
        for c in TANGENTIAL:
            k, n = counts[c], counts[c]["steps"]
            out.append({"benchmark": "lammps_granular",
                        "case": f"{label(c)}: instructions per step, whole step / contact model / tangential "
                                f"sub-model (callgrind, {n} steps)",
                        "value": f"{k['total'] / n:.4g} / {k['model'] / n:.4g} / {k['tangential'] / n:.4g}"})
        for c, stock in STOCK.items():
            k, s = counts[c], counts[stock]
            out.append({"benchmark": "lammps_granular",
                        "case": f"{label(c)} / {label(stock)}, instructions: whole step / contact model / "
                                f"tangential sub-model (target <= {TARGET[c]})",
                        "value": f"{k['total'] / s['total']:.4f} / {k['model'] / s['model']:.4f} / "
                                 f"{k['tangential'] / s['tangential']:.4f}"})
    sim = counts if counts and "simulated" in next(iter(counts.values())) else None
    if sim:
        keys = ("instructions", "l1_misses", "ll_misses", "mispredicts", "cycles")
        for c in TANGENTIAL:
            k, n = sim[c]["simulated"], sim[c]["steps"]
            out.append({"benchmark": "lammps_granular",
                        "case": f"{label(c)}: per step, whole step, simulated (callgrind --cache-sim --branch-sim, "
                                f"{n} steps): instructions / L1 misses / LL misses / mispredicted branches / "
                                f"modelled cycles", "value": " / ".join(f"{k[x] / n:.4g}" for x in keys)})
        for c, stock in STOCK.items():
            k, s = sim[c]["simulated"], sim[stock]["simulated"]
            out.append({"benchmark": "lammps_granular",
                        "case": f"{label(c)} / {label(stock)}, simulated, whole step: instructions / L1 misses / "
                                f"LL misses / mispredicted branches / modelled cycles (target <= {TARGET[c]})",
                        "value": " / ".join(f"{k[x] / s[x]:.4f}" if s[x] else "-" for x in keys)})
    return out


def benchmark(reps=3):
    """Rows for `stickslip bench` (see the module docstring; no repetitions: rounds)."""
    return rows(measure(ROUNDS))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m stickslip.bench.lammps_granular", description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=ROUNDS)
    ap.add_argument("--steps", type=int, default=STEPS, help="timed steps per run")
    ap.add_argument("--no-callgrind", action="store_true")
    ap.add_argument("--callgrind-steps", type=int, default=CALLGRIND_STEPS, help="steps counted by callgrind")
    ap.add_argument("--release", choices=list(lammps_granular.RELEASES), help="the LAMMPS to time (default: the newest built)")
    ap.add_argument("--simulate", action="store_true",
                    help="also callgrind's cache and branch simulation and its time model (~2 min)")
    a = ap.parse_args(argv)
    if a.rounds < 1 or a.steps < 1 or a.callgrind_steps < 1:
        ap.error("--rounds, --steps and --callgrind-steps must be >= 1")
    try:
        res = measure(a.rounds, not a.no_callgrind, a.callgrind_steps, steps=a.steps,
                      log=lambda text: print(text, file=sys.stderr, flush=True), release=a.release,
                      simulate=a.simulate)
    except RuntimeError as e:
        print(f"lammps_granular_bench: {e}", file=sys.stderr)
        return 1
    for r in rows(res):
        print(f"{r['case']}: {r['value'] if isinstance(r['value'], str) else format(r['value'], '.4g')}")
    print(f"cost: bed {res['bed_s']:.0f} s (0 when cached), rounds {res['rounds_s']:.0f} s, "
          f"callgrind {res['callgrind_s']:.0f} s (wall)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
