# SPDX-License-Identifier: GPL-2.0-or-later
"""Where the stick_slip plugin's cost goes per contact-step, on the benchmark pour of
liggghts_bench (issue 32), next to stock `tangential history` on the same contacts:

1. how often each path through the law runs: an analysis build of the plugin counts them
   (liggghts_variants.py: the law and its core with a counter on each path, into
   build/liggghts_plugin_paths; never the default); the count over the benchmark's callgrind window (steps WARM to
   WARM + STEPS) is the count of a run to the window's end less that of a run to its start;
2. how many instructions each path executes: callgrind profiles the default build over
   the same steps with one count per instruction (--dump-instr=yes). An instruction of the
   law ran as often as the paths it belongs to ran, so the instructions are grouped by
   their execution count and each group is named after the path (or the paths' union)
   that ran exactly that often. Stock history (Debian's library, no debug information)
   has the same kind of groups: every call, pair contacts, and its stick and slip
   branches, told apart by their counts (they add up to the calls).

Cost: the analysis build once (~3-5 min on 2 cores), then ~2 min.

    python -m stickslip.bench.liggghts_paths [--steps 100]
"""
from __future__ import annotations

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from ..adapters.liggghts import BUILD, LAUNCHER
from . import callgrind, liggghts_runs, liggghts_variants
from .liggghts import CALLGRIND_STEPS

LAW = re.compile(r"ContactModels::TangentialModel<\d+>::(surfacesIntersect|law<)|StickSlipCore::")


def _analysis_build():
    """The plugin with the path counters (liggghts_variants: built once, again when the law changes)."""
    return liggghts_variants.build("paths")


def path_counts(tang, steps, work):
    """{path: runs} over the window, from the analysis build (two runs, subtracted)."""
    launcher = _analysis_build()
    got = []
    for n in (0, steps):
        d = work / f"paths-{tang}-{n}"
        d.mkdir(exist_ok=True)
        liggghts_runs.write_timed(d, liggghts_runs.packing(), liggghts_runs.single(n) if n else "")
        env = dict(liggghts_runs.env(), STICK_SLIP_PATH_COUNTS=str(d / "paths.txt"))
        subprocess.run(liggghts_runs.command(tang, launcher=launcher), cwd=d, env=env, check=True,
                       stdout=subprocess.DEVNULL)
        got.append({k: int(v) for k, v in (ln.split() for ln in (d / "paths.txt").read_text().splitlines())})
    return {k: got[1][k] - got[0][k] for k in got[1]}


def instruction_runs(tang, steps, work, launcher=LAUNCHER):
    """{function: {address: times run}} for the law's functions, callgrind over the window."""
    d = work / f"instr-{tang}"
    d.mkdir(exist_ok=True)
    liggghts_runs.write_timed(d, liggghts_runs.packing(), "shell ./callgrind_on.sh\n" + liggghts_runs.single(steps))
    parts = callgrind.count(liggghts_runs.command(tang, launcher=launcher), d, env=liggghts_runs.env(),
                            on_request=True, options=["--dump-instr=yes"])
    return callgrind.instruction_counts(parts[0], lambda f: bool(LAW.search(f)))


def _groups(runs):
    """{times run: instructions that ran that often}, over all the law's functions."""
    g = collections.Counter()
    for per_address in runs.values():
        for n in per_address.values():
            g[n] += 1
    return g


def _names(p):
    """Path counts and their unions that an instruction group may match, by name."""
    calls = p["CALL_PAIR"] + p["CALL_WALL"]
    names = {"every call": calls, "pair contacts": p["CALL_PAIR"], "wall contacts": p["CALL_WALL"],
             "not new": calls - p["STAMP_FRESH"], "pair contacts not new": p["CALL_PAIR"] - p["STAMP_FRESH"],
             "turn (D off the plane)": p["TURN_SERIES"] + p["TURN_SQRT"]}
    if p["EXACT_NO_SLIP"]:  # (the exact timing's unions; in the step timing they are all 0 or every call)
        names.update({"exact: a slip in the step": p["EXACT_E4_START"] + p["EXACT_GENERAL"],
                      "exact: not over at the start": calls - p["EXACT_START_OVER"],
                      "exact: over at the start, Fn > 0": p["EXACT_START_OVER"] - p["GEN_E1"]})
    names.update({k: v for k, v in p.items() if not k.startswith("CALL")})
    return names


def attribute(groups, names):
    """[(times run, instructions, the name(s) of what ran that often)], most instructions first."""
    out = []
    for n, k in sorted(groups.items(), key=lambda nk: -nk[0] * nk[1]):
        match = [name for name, c in names.items() if c == n and c > 0]
        out.append((n, k, " = ".join(match) if match else "?"))
    return out


def stock_attribution(groups, walls):
    """Stock history's groups: every call (the most frequent), pair and wall contacts (the
    floor's contacts are the same in every run of the benchmark), and the two branches
    that add up to the calls (stick the larger: the benchmark's contacts mostly stick)."""
    calls = max(groups)
    named = {calls: "every call", walls: "wall contacts", calls - walls: "pair contacts"}
    for a in groups:
        if a not in named and calls - a in groups and a > calls - a:
            named[a], named[calls - a] = "stick", "slip"
    return [(n, k, named.get(n, "?")) for n, k in sorted(groups.items(), key=lambda nk: -nk[0] * nk[1])]


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m stickslip.bench.liggghts_paths", description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=CALLGRIND_STEPS, help="steps of the window after the warm-up")
    ap.add_argument("--launcher", type=Path, default=LAUNCHER,
                    help="the build whose instructions are counted (default: the plugin's build; the paths are "
                         "counted by the analysis build of this source, the same for any build that gives the "
                         "same results)")
    a = ap.parse_args(argv)
    if a.steps < 1:
        ap.error("--steps must be >= 1")
    liggghts_runs.check()
    if not callgrind.available():
        sys.stderr.write("liggghts_paths: valgrind not installed (apt-get install valgrind)\n")
        return 1
    with tempfile.TemporaryDirectory(prefix="liggghts_paths-") as work:
        work = Path(work)
        for tang in ("stick_slip", "stick_slip_exact"):
            p = path_counts(tang, a.steps, work)
            calls = p["CALL_PAIR"] + p["CALL_WALL"]
            rows = attribute(_groups(instruction_runs(tang, a.steps, work, a.launcher.resolve())), _names(p))
            warm = liggghts_runs.WARM
            print(f"\n{liggghts_runs.LABEL[tang]}: steps {warm}-{warm + a.steps}, {calls} law calls "
                  f"({p['CALL_PAIR']} pair, {p['CALL_WALL']} wall)")
            print("  paths, runs per call:  " + ", ".join(f"{k} {v / calls:.4%}" for k, v in p.items()
                                                            if v and not k.startswith("CALL")))
            _print(rows, calls)
        groups = _groups(instruction_runs("history", a.steps, work))
        print(f"\n{liggghts_runs.LABEL['history']} (its own trajectory: its counts differ a little)")
        _print(stock_attribution(groups, p["CALL_WALL"]), max(groups))
    return 0


def _print(rows, calls):
    print(f"  {'times run':>10} {'instructions':>12}  {'per call':>8}  ran on")
    for n, k, name in rows:
        print(f"  {n:>10} {k:>12}  {n * k / calls:8.2f}  {name}")
    print(f"  {'':>10} {'':>12}  {sum(n * k for n, k, _ in rows) / calls:8.2f}  in all, per call")


if __name__ == "__main__":
    sys.exit(main())
