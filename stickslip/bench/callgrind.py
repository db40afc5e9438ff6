# SPDX-License-Identifier: GPL-2.0-or-later
"""Instruction counts from valgrind's callgrind: a cost figure that the machine's load
does not move (the same binary on the same input executes the same instructions).

`count` runs a command under callgrind collecting only inside one function (LIGGGHTS'
`Verlet::run`, the time-step loop) and writing a profile each time that function returns,
so that every `run` command of an input script gets its own count; `self_costs` reads a
profile's instructions per function (not counting the functions it calls), which
attributes the count to the pair loop, the contact models, the integrator, ...

A warm-up before the counted steps need not be instrumented: with `on_request`, callgrind
starts without instrumentation (the program runs several times faster) and the input
script switches it on by running ON_SCRIPT (LIGGGHTS: `shell ./callgrind_on.sh`) before
the steps to count. The script returns once callgrind has confirmed, and the program
waits for it, so the count is the same as with instrumentation from the start (measured:
4 054 880 202 instructions either way for 100 steps of the benchmark pour).
"""
from __future__ import annotations

import collections
import re
import shutil
import subprocess
from pathlib import Path

VERLET_RUN = "LAMMPS_NS::Verlet::run(int)"

# Switches instrumentation on in the ancestor process that runs under callgrind (a program's
# `system` call runs this through sh, and the program waits for it).
ON_SCRIPT = """\
#!/bin/sh
p=$PPID
while [ "$p" -gt 1 ]; do
  if callgrind_control -i on "$p" 2>/dev/null | grep -q OK; then exit 0; fi
  read -r line < /proc/$p/stat
  set -- ${line##*) }
  p=$2
done
echo "callgrind_on.sh: no ancestor runs under callgrind" >&2
exit 1
"""


def available():
    return shutil.which("valgrind") is not None


def count(cmd, cwd, function=VERLET_RUN, env=None, timeout=7200, on_request=False, options=()):
    """Run `cmd` in `cwd` under callgrind; returns the profiles written at each return from
    `function`, in order (one per call), as paths. `on_request`: no instrumentation until
    the program runs ./callgrind_on.sh (written into `cwd`). `options`: more callgrind
    options (e.g. --dump-instr=yes for instruction_counts)."""
    cwd = Path(cwd)
    for old in cwd.glob("callgrind.out.*"):
        old.unlink()
    vg = ["valgrind", "--tool=callgrind", "--collect-atstart=no", f"--toggle-collect={function}",
          f"--dump-after={function}", "--callgrind-out-file=callgrind.out.%p"]
    vg += list(options)
    if on_request:
        (cwd / "callgrind_on.sh").write_text(ON_SCRIPT)
        (cwd / "callgrind_on.sh").chmod(0o755)
        vg.append("--instr-atstart=no")
    with open(cwd / "callgrind.txt", "w") as out:
        p = subprocess.run(vg + [str(c) for c in cmd], cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env,
                           timeout=timeout)
    if p.returncode != 0:
        tail = (cwd / "callgrind.txt").read_text(errors="replace").strip().splitlines()[-1:] or ["no output"]
        raise RuntimeError(f"callgrind run failed (exit {p.returncode}) in {cwd}: {tail[0]}")
    # callgrind.out.PID.N, N = 1, 2, ...: the profile after the N-th return from `function`
    parts = sorted(cwd.glob("callgrind.out.*.*"), key=lambda f: int(f.name.rsplit(".", 1)[1]))
    if on_request and not parts:
        raise RuntimeError(f"callgrind counted nothing in {cwd}: did the program run ./callgrind_on.sh?")
    return parts


def total(profile):
    """All instructions counted in a profile (its `summary:` line)."""
    return event_totals(profile)["Ir"]


# A time model from callgrind's simulation of the caches and the branch predictors
# (--cache-sim=yes --branch-sim=yes), for what an instruction count does not show: an
# instruction costs a cycle, a miss of the first-level caches SIM_L1 more, of the last level
# SIM_LL, a mispredicted branch SIM_MISPREDICT (round figures for a current x86 core; the
# counts are printed beside it, for a reader to weigh otherwise).
SIMULATION = ("--cache-sim=yes", "--branch-sim=yes")
SIM_L1, SIM_LL, SIM_MISPREDICT = 10, 100, 15


def event_totals(profile):
    """{event: count} of a profile's summary line (Ir; with SIMULATION also I1mr D1mr D1mw
    ILmr DLmr DLmw Bc Bcm Bi Bim ...), as its `events:` line names them."""
    names = None
    with open(profile) as f:
        for line in f:
            if line.startswith("events:"):
                names = line.split()[1:]
            elif line.startswith(("summary:", "totals:")) and names:
                return dict(zip(names, (int(x) for x in line.split()[1:])))
    raise RuntimeError(f"{profile}: no summary line under an events line (not a callgrind profile?)")


def simulated(events):
    """What the simulation found, from event_totals: {instructions, l1_misses, ll_misses,
    mispredicts, cycles} (cycles: the model above)."""
    e = collections.Counter(events)
    l1 = e["I1mr"] + e["D1mr"] + e["D1mw"]
    ll = e["ILmr"] + e["DLmr"] + e["DLmw"]
    bad = e["Bcm"] + e["Bim"]
    return {"instructions": e["Ir"], "l1_misses": l1, "ll_misses": ll, "mispredicts": bad,
            "cycles": e["Ir"] + SIM_L1 * l1 + SIM_LL * ll + SIM_MISPREDICT * bad}


_NAME = re.compile(r"(c?fn)=\((\d+)\)(?: (.*))?")
_FILE = re.compile(r"(c?fl|c?fi|fe)=\((\d+)\)(?: (.*))?")


def _position(previous, text):
    """A cost line's address or line number: profiles compress them as +n / -n relative to
    the previous one, * the same, or write them in full."""
    return (previous + int(text[1:], 0) if text[0] == "+" else previous - int(text[1:], 0) if text[0] == "-"
            else previous if text == "*" else int(text, 0))


def _cost_lines(profile):
    """Each cost line of a profile, as (function, source file, fields, call): the function
    (fn=) and file (fl=, or fi=/fe= for code inlined into it, until the next fn=) it belongs
    to, its whitespace-separated fields (positions compressed as _position reads them, then
    the costs), and whether it is a call's inclusive cost (the line after calls=), which is
    not the function's own. Names are written in full the first time, as (id) afterwards,
    in one table per kind that calls (cfn=, cfi=, cfl=) fill too."""
    functions, files = {}, {}
    fn = file = fn_file = None
    call = False
    with open(profile) as f:
        for line in f:
            m = _FILE.match(line)
            if m:
                if m.group(3):
                    files[m.group(2)] = m.group(3)
                if not m.group(1).startswith("c"):  # a call's file names the callee: nothing changes here
                    file = files.get(m.group(2), m.group(2))
                    if m.group(1) == "fl":
                        fn_file = file
                continue
            m = _NAME.match(line)
            if m:
                if m.group(3) and m.group(3).strip():
                    functions[m.group(2)] = m.group(3).strip()
                if m.group(1) == "fn":
                    fn, file = functions.get(m.group(2), m.group(2)), fn_file
                continue
            if line.startswith("calls="):
                call = True
            elif line[:1] in "0123456789+-*":
                yield fn, file, line.split(), call
                call = False


def self_costs(profile):
    """Instructions per function in a profile, each function's own (what it calls excluded)."""
    costs = collections.Counter()
    for fn, _, fields, call in _cost_lines(profile):
        if fn is not None and not call and len(fields) >= 2:
            costs[fn] += int(fields[1])
    return costs


def instruction_counts(profile, want):
    """{function: {address: times run}} for the functions whose name `want` accepts, from a
    profile written with --dump-instr=yes (each cost line: address, line, instructions; an
    instruction's count is how often it ran)."""
    runs = collections.defaultdict(collections.Counter)
    address = 0
    for fn, _, fields, call in _cost_lines(profile):
        address = _position(address, fields[0])
        # a call's inclusive cost sits at the call's address: not this instruction's runs
        if not call and fn is not None and len(fields) >= 3 and want(fn):
            runs[fn][address] += int(fields[2])
    return runs


def instruction_lines(profile, want):
    """{address: (function, source file, line, times run)} for the instructions whose source file
    `want` accepts, from a profile written with --dump-instr=yes --dump-line=yes of a
    program built with debug information (each cost line: address, line, instructions).
    The file is the function's, or that of code inlined into it (_cost_lines)."""
    runs = {}
    address = line_no = 0
    for fn, file, fields, call in _cost_lines(profile):
        address = _position(address, fields[0])
        line_no = _position(line_no, fields[1])
        if not call and len(fields) >= 3 and file is not None and want(file):
            old = runs.get(address, (fn, file, line_no, 0))
            runs[address] = (fn, file, line_no, old[3] + int(fields[2]))
    return runs
