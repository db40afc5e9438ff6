# SPDX-License-Identifier: GPL-2.0-or-later
"""Independent runs on every core, with one progress bar.

A task is (cost, function, args): a module-level function and picklable arguments;
cost is the task's estimated seconds (runner.cost), the same unit for every kind of task.
`run_all` runs the costliest first (so the last ones to finish are short), on
`workers()` processes, and returns the results in the tasks' order. A task that raises
returns its exception instead, so one failing engine does not lose the others' runs.
"""
from __future__ import annotations

import os
import resource
import sys
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait


def workers() -> int:
    """Processes to use: every core, or STICKSLIP_JOBS if set (1 = in this process)."""
    n = os.cpu_count() or 1
    try:
        return max(1, int(os.environ.get("STICKSLIP_JOBS", n)))
    except ValueError:
        return n


def _cpu_seconds():
    """CPU time of this process and of the processes it waited for (engines it started)."""
    me, engines = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + engines.ru_utime + engines.ru_stime


def _call(fn, args):
    """fn(*args) and the CPU seconds it took."""
    start = _cpu_seconds()
    try:
        result = fn(*args)
    except Exception as e:  # returned, not raised: the caller decides what a failure means
        result = e
    return result, _cpu_seconds() - start


def run_all(tasks, label="runs", progress=True, cpu_log=None, n_workers=None):
    """The tasks' results in their order. cpu_log: a list to which (task, CPU seconds) is
    appended for every task (what `stickslip bench --report` reports). n_workers: processes
    (default: workers())."""
    n_workers = n_workers or workers()
    order = sorted(range(len(tasks)), key=lambda k: -tasks[k][0])
    results = [None] * len(tasks)
    cpu = [0.0] * len(tasks)
    bar = _Bar(label, len(tasks), progress)
    if n_workers == 1 or len(tasks) == 1:
        for k in order:
            results[k], cpu[k] = _call(*tasks[k][1:])
            bar.done()
    else:
        with ProcessPoolExecutor(max_workers=n_workers) as pool:
            pending = {pool.submit(_call, *tasks[k][1:]): k for k in order}
            while pending:
                finished, _ = wait(pending, timeout=1.0, return_when=FIRST_COMPLETED)
                for f in finished:
                    k = pending.pop(f)
                    results[k], cpu[k] = f.result()
                    bar.done()
                bar.tick()
    bar.close()
    if cpu_log is not None:
        cpu_log += zip(tasks, cpu)
    return results


class _Bar:
    """Tasks done out of total. On a terminal a bar whose elapsed time moves even while a
    long run works; elsewhere (logs, CI) one line per finished task."""

    def __init__(self, label, total, enabled):
        self.label, self.total, self.n, self.t = label, total, 0, None
        self.enabled = enabled
        self.start = time.perf_counter()
        if enabled and sys.stderr.isatty():
            from tqdm import tqdm

            self.t = tqdm(total=total, desc=label, unit="run", file=sys.stderr, leave=False)

    def done(self):
        self.n += 1
        if self.t is not None:
            self.t.update(1)
        elif self.enabled:
            sys.stderr.write(f"{self.label}: {self.n}/{self.total} runs done "
                             f"({time.perf_counter() - self.start:.0f} s)\n")

    def tick(self):
        if self.t is not None:
            self.t.refresh()

    def close(self):
        if self.t is not None:
            self.t.close()
