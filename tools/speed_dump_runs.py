# SPDX-License-Identifier: GPL-2.0-or-later
"""What the speed-dump scripts (liggghts_speed_dumps.py, lammps_speed_dumps.py) share: run
each case's input script in its own folder of OUT, two at a time, print one line per case,
and exit with status 1 if any failed."""
import concurrent.futures
import subprocess
import sys


def run_cases(cases, out, command, env):
    """cases: {name: input script}; command: the engine's command line, without the script."""
    def run(name):
        d = out / name
        d.mkdir(exist_ok=True)
        (d / "in.x").write_text(cases[name])
        p = subprocess.run(command + ["-in", "in.x"], cwd=d, env=env, capture_output=True, text=True)
        if p.returncode or "ERROR" in p.stdout:
            return f"{name}: FAILED {p.stdout[-300:]}"
        return f"{name}: ok, {(d / 'dump.out').stat().st_size} bytes"

    failed = 0
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        for r in pool.map(run, cases):
            print(r, flush=True)
            failed += "FAILED" in r
    sys.exit(1 if failed else 0)
