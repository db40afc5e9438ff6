# SPDX-License-Identifier: GPL-2.0-or-later
"""The ratio of two costs measured in interleaved rounds, with its confidence interval.

Each round times configuration A and configuration B one right after the other, so the
two share that moment's machine (load, caches, clock); the round's ratio b/a cancels what
is common to both. Ratios of times combine multiplicatively, so the figure is the
geometric mean of the rounds' ratios, and its interval is Student's t interval on the
rounds' log-ratios (mean +- t * s / sqrt(n), n - 1 degrees of freedom), mapped back by exp.
This assumes the rounds' log-ratios are independent draws around one value: rounds must
not share a disturbance that favours one side (the benchmark alternates the order of the
configurations from round to round for that reason).
"""
from __future__ import annotations

import functools
import math
import statistics

from scipy import stats


@functools.lru_cache(maxsize=None)
def _t_quantile(p, dof):
    return float(stats.t.ppf(p, dof))


def ratio_interval(pairs, level=0.95):
    """(ratio, low, high) for the rounds' (a, b) times: the geometric mean of b/a and its
    `level` confidence interval; low = high = nan with fewer than two rounds."""
    logs = [math.log(b / a) for a, b in pairs]
    if not logs:
        raise ValueError("ratio_interval: no rounds")
    centre = statistics.fmean(logs)
    if len(logs) < 2:
        return math.exp(centre), math.nan, math.nan
    half = _t_quantile(0.5 + level / 2, len(logs) - 1) * statistics.stdev(logs) / math.sqrt(len(logs))
    return math.exp(centre), math.exp(centre - half), math.exp(centre + half)
