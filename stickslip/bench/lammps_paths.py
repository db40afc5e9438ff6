# SPDX-License-Identifier: GPL-2.0-or-later
"""Where the LAMMPS plugin's instructions go per contact-step, on lammps_bench's chute
(issue 30 item 5), next to stock gran/hooke/history + wall/gran on the same steps.

callgrind counts how often each instruction ran (--dump-instr=yes) over the benchmark's
window (its warm-up, then STEPS steps). An instruction of the contact loop ran as often as
the path it belongs to, so the instructions are grouped by their run count: a group is
one path (every neighbour, a touching contact, a slip, E4 at the step's start, each
branch of exact_slips, ...). Our groups are named from the source: the plugin is built a
second time with debug information (-g, which changes no instruction: checked here by
comparing the two builds' disassembly), each instruction carries its file and line, and
a group is named after the marker statements (MARKERS) that have instructions in it.
Stock's library has no line information: its groups are listed with their counts, which
name them well enough (every neighbour, every touching contact, the slip branch, ...).
A pair contact's common path ("touching") holds the law's sticking arithmetic, and in the
exact timing E0's test of the step's start.

Cost: the -g build once (~20 s on 2 cores), then ~1 min (three callgrind runs, two at a time).

    python -m stickslip.bench.lammps_paths [--steps 500]
"""
from __future__ import annotations

import argparse
import collections
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from ..adapters.text_dumps import id_ranges
from . import callgrind
from . import lammps as bench

SOURCE = bench.ROOT / "lammps_plugin"
LINES_BUILD = bench.ROOT / "build" / "lammps_plugin_lines"
STEPS = 500

# file -> {statement: the path its instructions belong to}
MARKERS = {
    "pair_gran_hooke_stickslip.cpp": {
        "const double radi = radius[i];": "every grain i",
        "const int j = jlist[jj] & NEIGHMASK;": "every neighbour",
        "touch[jj] = 0;": "apart",
        "touch[jj] = 1;": "touching",
        "torque[j][0] -= cj * tor1;": "j owned (its force and torque)",
    },
    "fix_wall_gran_stickslip.cpp": {
        "if (!(mask[i] & bit)) continue;": "every grain",
        "for (int m = 0; m < dnum; m++) hist[i][m] = 0.0;": "apart",
        "double meff = rmass[i];": "touching",
    },
    "stick_slip_law.h": {
        "const double ratio = stickslip::StickSlipCore::drop_to(fs, c.kin * fnabs, std::sqrt(sum),":
            "step: slip (reset to Fmin)",
    },
    "../law_core/stick_slip_core.h": {
        "for (int i = 0; i < 3; i++) F0[i] = F[i] + ksdt * vs[i];": "exact: every evaluation (E0)",
        "if (start_slips && T > 0.0 && !total": "exact: a slip in the step (E4 tested)",
        "F[i] = -a * vs[i];": "exact: E4 at the step's start (slides)",
        "stick = exact_general(f0, v, T, fmin, ratio, ks, nu_s, dt, total, applied, spring);": "exact: general case",
        "const double speed = std::sqrt(dot(vs, vs));": "exact_slips: every call",
        "applied[k] = 0.0;": "E1 (Fn = 0)",
        "const double f = dot(F, u), F2 = dot(F, F);": "E2 (next slip sought)",
        "for (int k = 0; k < 3; k++) applied[k] = trial[k] = F[k] + (rate * rest) * u[k];": "sticks to the step's end",
        "slips++;": "E3 (a slip)",
        "trial[k] = (fmin + kept) * u[k];": "E4 after a slip",
        "plastic_flow(F, u, rate * rest / T, T);": "E6 (plastic flow)",
        "const double fu = dot(F, u);": "E5/E6/E7 tests",
        "const double n = std::floor(rest / L);": "E7 (closed form)",
    },
}
LAW_FILES = re.compile(r"(lammps_plugin/(stick_slip_law\.h|wall_contact\.h|pair_gran_hooke_stickslip\.cpp|"
                       r"fix_wall_gran_stickslip\.cpp)|law_core/stick_slip_core\.h)$")
STOCK = re.compile(r"PairGranHookeHistory::compute|FixWallGran::(post_force|hooke_history)")


def _lines_build():
    """The plugin built again with -g into LINES_BUILD; refuses if its code differs."""
    flags = "-O3 -DNDEBUG -g"  # CMake's Release flags (-O3 -DNDEBUG) and debug information
    if not (LINES_BUILD / "CMakeCache.txt").is_file():
        subprocess.run(["cmake", "-S", str(SOURCE), "-B", str(LINES_BUILD), "-DCMAKE_BUILD_TYPE=Release",
                        f"-DCMAKE_CXX_FLAGS_RELEASE={flags}",
                        f"-DLAMMPS_HEADERS={bench.ROOT / 'build' / 'lammps_headers' / 'src'}"],
                       check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", str(LINES_BUILD), "-j", str(os.cpu_count() or 1)], check=True,
                   stdout=subprocess.DEVNULL)
    if _code(LINES_BUILD) != _code(bench.LAUNCHER.parent):
        raise RuntimeError(f"{LINES_BUILD} has other instructions than {bench.LAUNCHER.parent}: rebuild both "
                           "(./run.sh setup, then delete the -g build)")
    return LINES_BUILD / "lmp-stickslip"


def _code(build):
    """The library's instructions without addresses (the disassembly's text)."""
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", str(build / "libstickslip_lammps.so")],
                         check=True, capture_output=True, text=True).stdout
    return [re.sub(r"^\s*[0-9a-f]+:\s*|\s[0-9a-f]+ <[^>]*>|#.*$", "", ln) for ln in out.splitlines()[3:]]


def _profile(config, steps, launcher, work):
    d = work / config
    d.mkdir()
    (d / "in.timed").write_text(bench._script(bench._pour(), steps, "shell ./callgrind_on.sh"))
    cmd = bench._command(config)
    cmd[0] = str(launcher)
    return callgrind.count(cmd, d, env=bench._env(d), on_request=True,
                           options=["--dump-instr=yes", "--dump-line=yes"])[-1]


def marker_lines():
    """{(file, line): path name} of MARKERS in the current source; refuses a missing one."""
    out = {}
    for name, marks in MARKERS.items():
        source = (SOURCE / name).read_text().splitlines()
        for statement, path in marks.items():
            lines = [k + 1 for k, text in enumerate(source) if statement in text]
            if len(lines) != 1:
                raise RuntimeError(f"marker of '{path}' found {len(lines)} times in lammps_plugin/{name}: {statement}")
            out[(Path(name).name, lines[0])] = path  # (the profile names a file without its folder)
    return out


def our_groups(runs, markers):
    """[(times run, instructions, name)] of the plugin's instructions, most first. The pair
    style's loop, the wall's and the out-of-line exact-timing functions (called by both) are
    grouped apart, as the law is inlined into both loops. A marker names the group of its
    part that holds most of its line's instructions (the compiler may hoist a part of a line
    onto a more frequent path)."""
    groups = collections.defaultdict(list)
    for fn, file, line, n in runs.values():
        part = "pair" if "PairGranHookeStickSlip" in fn else "wall" if "FixWallGran" in fn else "law"
        groups[(part, n)].append((Path(file).name, line))
    names = collections.defaultdict(list)
    for fl, path in markers.items():
        for part in ("pair", "wall", "law"):
            held = {key: lines.count(fl) for key, lines in groups.items() if key[0] == part and fl in lines}
            if held:
                names[max(held, key=lambda key: (held[key], key[1]))].append(path)
    out = []
    for (part, n), lines in groups.items():
        where = collections.defaultdict(list)
        for f, ln in sorted(set(lines)):
            where[f].append(ln)
        text = " = ".join(sorted(names[(part, n)])) if names[(part, n)] else \
            "(" + "; ".join(f"{f}:{id_ranges(v, through='-', sep=',')}" for f, v in where.items()) + ")"
        out.append((n, len(lines), f"{part}: {text}"))
    return sorted(out, key=lambda g: -g[0] * g[1])


def stock_groups(profile):
    """[(times run, instructions, function)] of stock's pair compute and wall."""
    runs = callgrind.instruction_counts(profile, lambda f: bool(STOCK.search(f)))
    out = []
    for fn, per in runs.items():
        for n, k in collections.Counter(per.values()).items():
            out.append((n, k, fn.split("(")[0].replace("LAMMPS_NS::", "")))
    return sorted(out, key=lambda g: -g[0] * g[1])


def _print(title, rows, per, share=0.002):
    """rows as a table: per = touching pair contact-steps (the unit of the last columns)."""
    total = sum(n * k for n, k, _ in rows)
    print(f"\n{title}: {total:.4g} instructions, {total / per:.1f} per touching pair contact-step ({per})")
    print(f"  {'times run':>10} {'/touching':>9} {'instr.':>6} {'per contact-step':>16}  path")
    for n, k, name in rows:
        if n * k >= share * total:
            print(f"  {n:>10} {n / per:>9.4f} {k:>6} {n * k / per:>16.2f}  {name}")
    rest = sum(n * k for n, k, _ in rows if n * k < share * total)
    print(f"  {'':>10} {'':>9} {'':>6} {rest / per:>16.2f}  (groups below {share:.1%} each)")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m stickslip.bench.lammps_paths",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=STEPS, help="steps counted after the benchmark's warm-up")
    a = ap.parse_args(argv)
    if a.steps < 1:
        ap.error("--steps must be >= 1")
    try:
        bench._check()
        if not callgrind.available():
            raise RuntimeError("valgrind not installed (apt-get install valgrind)")
        launcher = _lines_build()
        markers = marker_lines()
        with tempfile.TemporaryDirectory(prefix="lammps_paths-") as work, \
                concurrent.futures.ThreadPoolExecutor(2) as pool:
            jobs = {c: pool.submit(_profile, c, a.steps, launcher, Path(work)) for c in bench.CONFIGS}
            profiles = {c: j.result() for c, j in jobs.items()}
            stock = stock_groups(profiles["stock"])
            ours = {c: our_groups(callgrind.instruction_lines(profiles[c], lambda f: bool(LAW_FILES.search(f))),
                                  markers) for c in ("step", "exact")}
    except (RuntimeError, subprocess.CalledProcessError) as e:
        print(f"lammps_paths: {e}", file=sys.stderr)
        return 1
    print(f"lammps_bench's chute, steps {bench.WARM}-{bench.WARM + a.steps} (1 process)")
    # stock's touching contacts: of the pair groups that ran less often than every neighbour,
    # the one with the most instructions (the contact's arithmetic; apart ones only clear)
    pair = [g for g in stock if "compute" in g[2]]
    every = max(n for n, _, _ in pair)
    _print(bench.LABEL["stock"], stock, max((g for g in pair if g[0] < every), key=lambda g: g[1])[0])
    for c, rows in ours.items():
        touching = next(n for n, _, name in rows if "touching" in name)
        _print(bench.LABEL[c], rows, touching)
    return 0


if __name__ == "__main__":
    sys.exit(main())
