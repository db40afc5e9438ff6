# SPDX-License-Identifier: GPL-2.0-or-later
"""Time, interleaved chunk by chunk (stickslip/bench/liggghts.py): in each round every
configuration runs as its own LIGGGHTS process, stopped by a shell probe after its warm-up
and after every chunk of CHUNK steps; one process goes at a time, so a block (the same chunk
of each configuration) is timed within a second, and the order turns from block to block.
A chunk's time is the on-CPU time of LIGGGHTS' thread; a block is quiet when the rest of
the machine used less than NOISY cores during each of its chunks."""
from __future__ import annotations

import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from . import liggghts_runs
from .proc_probe import probe_script

CHUNK = 50  # steps per timed chunk (~0.25 s on one idle core)
CHUNKS = 40  # timed chunks per run (steps WARM to WARM + 2000)
NOISY = 0.1  # cores used by other processes during a chunk above which its block is not quiet

# The probe between chunks: appends to probe.log the on-CPU and run-queue wait time (ns) of
# LIGGGHTS' main thread (/proc/PID/schedstat; `shell` runs it from LIGGGHTS through sh, so
# it looks for the launcher among its ancestors), the uptime (s) and the machine's CPU line
# (/proc/stat), then waits until the benchmark writes a line into go.fifo. Shell built-ins
# only: the probe itself should cost next to nothing.
PROBE = probe_script("liggghts-stick", """
read -r s < /proc/$p/schedstat; read -r u < /proc/uptime; read -r c < /proc/stat
echo "$s | $u | $c" >> probe.log
read -r go < go.fifo
read -r s < /proc/$p/schedstat; read -r u < /proc/uptime; read -r c < /proc/stat
echo "$s | $u | $c" >> probe.log
""")


def _chunked(chunks, chunk):
    """The timed part of an overhead run: chunks of `chunk` steps, a probe before each and
    after the last (`pre no`: the chunks continue the same run, no re-setup between them)."""
    return f"thermo {chunk}\nshell ./probe.sh\n" + f"run {chunk} pre no post no\nshell ./probe.sh\n" * chunks


def _probe_chunks(log):
    """Per chunk between two probes: on-CPU and run-queue wait time of LIGGGHTS' thread (s),
    wall time (s) and the CPU the rest of the machine used meanwhile (cores)."""
    tick = os.sysconf("SC_CLK_TCK")
    marks = []
    for line in Path(log).read_text().splitlines():
        sched, up, cpu = line.split("|")
        run_ns, wait_ns = (int(x) for x in sched.split()[:2])
        ticks = [int(x) for x in cpu.split()[1:]]
        busy = sum(ticks) - ticks[3] - (ticks[4] if len(ticks) > 4 else 0)  # all but idle and iowait
        marks.append((run_ns * 1e-9, wait_ns * 1e-9, float(up.split()[0]), busy / tick))
    # each probe writes a mark when the run reaches it and another when it is let go: a
    # chunk runs from one probe's second mark to the next probe's first (the time the run
    # waited at a probe, while the other configurations ran, is not the chunk's)
    chunks = []
    for a, b in zip(marks[1::2], marks[2::2]):
        own, wall = b[0] - a[0], b[2] - a[2]
        # uptime and /proc/stat count in 1/100 s: a 0.5 s chunk reads other processes' CPU to ~0.04 cores
        foreign = max(0.0, (b[3] - a[3] - own) / wall) if wall > 0 else math.inf
        chunks.append({"cpu": own, "wait": b[1] - a[1], "wall": wall, "foreign": foreign})
    return chunks


class _Paused:
    """One LIGGGHTS run of the overhead comparison: CHUNKS chunks of CHUNK steps after WARM,
    stopped at each probe until told to go on, so that the driver decides which
    configuration runs when (the others wait, blocked, using no CPU)."""

    def __init__(self, data, tang, launcher, d):
        d.mkdir(exist_ok=True)
        self.d = d
        liggghts_runs.write_timed(d, data, _chunked(CHUNKS, CHUNK))
        (d / "probe.sh").write_text(PROBE)
        (d / "probe.sh").chmod(0o755)
        for f in ("probe.log", "go.fifo"):
            (d / f).unlink(missing_ok=True)
        os.mkfifo(d / "go.fifo")
        self.out = open(d / "stdout.txt", "w+", errors="replace")
        self.p = subprocess.Popen(liggghts_runs.command(tang, launcher=launcher), cwd=d, stdout=self.out,
                                  stderr=subprocess.STDOUT, env=liggghts_runs.env(), text=True)
        self.probes = 0

    def wait(self, timeout=3600):
        """Until the run has reached its next probe (and stopped there)."""
        t0 = time.monotonic()
        log = self.d / "probe.log"
        while not (log.is_file() and len(log.read_text().splitlines()) > 2 * self.probes):
            if self.p.poll() is not None:
                self._fail()
            if time.monotonic() - t0 > timeout:
                self.p.kill()
                raise RuntimeError(f"no probe within {timeout} s in {self.d}")
            time.sleep(0.01)  # (polling costs ~1 % of a core, counted as other processes' CPU)
        self.probes += 1

    def go(self):
        with open(self.d / "go.fifo", "w") as f:
            f.write("go\n")

    def finish(self):
        """Let the run end; its chunks (_probe_chunks), contacts, atoms and peak memory."""
        rss = liggghts_runs.vm_hwm_kib(self.p.pid) / 1024.0
        self.go()
        if self.p.wait() != 0:
            self._fail()
        self.out.seek(0)
        text = self.out.read()
        self.out.close()
        chunks = _probe_chunks(self.d / "probe.log")
        if len(chunks) != CHUNKS:
            raise RuntimeError(f"{len(chunks)} of {CHUNKS} chunks timed in {self.d}")
        atoms = int(liggghts_runs.LOOP.findall(text)[-1][3])
        mem = liggghts_runs.MEMORY.findall(text)
        contacts = liggghts_runs.contacts_at(text, liggghts_runs.WARM + CHUNKS * CHUNK, atoms)
        return {"chunks": chunks, "atoms": atoms, "contacts": contacts,
                "rss_mib": rss, "liggghts_mib": float(mem[-1]) if mem else None}

    def _fail(self):
        self.p.kill()
        self.p.wait()
        self.out.seek(0)
        lines = self.out.read().strip().splitlines() or ["no output"]
        why = next((x.strip() for x in lines if "ERROR" in x), lines[-1].strip())
        raise RuntimeError(f"LIGGGHTS failed in {self.d}: {why} (the chunk probe needs /bin/sh and Linux's /proc)")


def overhead_rounds(data, work, rounds, configs):
    """`rounds` rounds; in each, one run per configuration ({name: (tangential key, launcher)}),
    all started and stopped at their first probe, then advanced chunk by chunk in turn: a
    block of chunks is the same chunk of every configuration, one right after the other
    (~0.5 s each), and the order turns by one from block to block (A B C, B C A, C A B, ...)
    so that each configuration takes each place equally often. Returns, per round,
    {name: run} (_Paused.finish)."""
    names = list(configs)
    out = []
    for r in range(rounds):
        runs = {}
        try:
            for name in names:  # one at a time: set-ups and warm-ups do not overlap
                tang, launcher = configs[name]
                runs[name] = _Paused(data, tang, launcher, work / f"{name}-round{r}")
                runs[name].wait()
            for k in range(CHUNKS):
                j = (r * CHUNKS + k) % len(names)
                for name in names[j:] + names[:j]:
                    runs[name].go()
                    runs[name].wait()
            got = {name: runs[name].finish() for name in names}
        finally:
            for run in runs.values():
                if run.p.poll() is None:
                    run.p.kill()
                    run.p.wait()
        out.append(got)
        quiet = sum(quiet_block(got, k) for k in range(CHUNKS))
        print(f"  round {r + 1}/{rounds}: {quiet}/{CHUNKS} quiet blocks; other processes "
              f"{statistics.fmean(c['foreign'] for g in got.values() for c in g['chunks']):.2f} cores", file=sys.stderr,
              flush=True)
    return out


def quiet_block(got, k):
    return all(g["chunks"][k]["foreign"] <= NOISY for g in got.values())


def round_ratios(rounds_, num, den, quiet_only):
    """Per round, the geometric mean of its blocks' time ratios num/den (quiet blocks only:
    rounds without one are left out)."""
    out = []
    for got in rounds_:
        logs = [math.log(b[num] / b[den]) for b in blocks([got], quiet_only)]
        if logs:
            out.append(math.exp(statistics.fmean(logs)))
    return out


def blocks(rounds_, quiet_only):
    """The blocks (one chunk of each configuration, {name: CPU s per step}), all or quiet only."""
    return [{n: g["chunks"][k]["cpu"] / CHUNK for n, g in got.items()} for got in rounds_ for k in range(CHUNKS)
            if not quiet_only or quiet_block(got, k)]
