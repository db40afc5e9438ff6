"""Instruction counts from valgrind's callgrind: a cost figure that the machine's load
does not move (the same binary on the same input executes the same instructions).

`count` runs a command under callgrind collecting only inside one function (LIGGGHTS'
`Verlet::run`, the time-step loop) and writing a profile each time that function returns,
so that every `run` command of an input script gets its own count; `self_costs` reads a
profile's instructions per function (not counting the functions it calls), which
attributes the count to the pair loop, the contact models, the integrator, ...
"""
from __future__ import annotations

import collections
import re
import shutil
import subprocess
from pathlib import Path

VERLET_RUN = "LAMMPS_NS::Verlet::run(int)"


def available():
    return shutil.which("valgrind") is not None


def count(cmd, cwd, function=VERLET_RUN, env=None, timeout=7200):
    """Run `cmd` in `cwd` under callgrind; returns the profiles written at each return from
    `function`, in order (one per call), as paths."""
    cwd = Path(cwd)
    for old in cwd.glob("callgrind.out.*"):
        old.unlink()
    vg = ["valgrind", "--tool=callgrind", "--collect-atstart=no", f"--toggle-collect={function}",
          f"--dump-after={function}", "--callgrind-out-file=callgrind.out.%p"]
    with open(cwd / "callgrind.txt", "w") as out:
        p = subprocess.run(vg + [str(c) for c in cmd], cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env,
                           timeout=timeout)
    if p.returncode != 0:
        tail = (cwd / "callgrind.txt").read_text(errors="replace").strip().splitlines()[-1:] or ["no output"]
        raise RuntimeError(f"callgrind run failed (exit {p.returncode}) in {cwd}: {tail[0]}")
    # callgrind.out.PID.N, N = 1, 2, ...: the profile after the N-th return from `function`
    parts = sorted(cwd.glob("callgrind.out.*.*"), key=lambda f: int(f.name.rsplit(".", 1)[1]))
    return parts


def total(profile):
    """All instructions counted in a profile (its `summary:` line)."""
    with open(profile) as f:
        for line in f:
            if line.startswith(("summary:", "totals:")):
                return int(line.split()[1])
    raise RuntimeError(f"{profile}: no summary line (not a callgrind profile?)")


_NAME = re.compile(r"(c?fn)=\((\d+)\)(?: (.*))?")


def self_costs(profile):
    """Instructions per function in a profile, each function's own (what it calls excluded)."""
    names, costs = {}, collections.Counter()
    fn, call_cost_follows = None, False
    with open(profile) as f:
        for line in f:
            m = _NAME.match(line)
            if m:
                # a name is written in full the first time, as (id) afterwards
                if m.group(3):
                    names[m.group(2)] = m.group(3)
                if m.group(1) == "fn":
                    fn = names.get(m.group(2), m.group(2))
                continue
            if line.startswith("calls="):
                call_cost_follows = True  # the next cost line is the call's inclusive cost
                continue
            if fn is not None and line[:1] in "0123456789+-*":
                if call_cost_follows:
                    call_cost_follows = False
                    continue
                fields = line.split()
                if len(fields) >= 2:
                    costs[fn] += int(fields[1])
    return costs
