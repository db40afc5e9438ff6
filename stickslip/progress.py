# SPDX-License-Identifier: GPL-2.0-or-later
"""A progress bar for long runs (tqdm on stderr), or nothing when disabled."""
from __future__ import annotations

import contextlib
import sys


@contextlib.contextmanager
def bar(label, total, enabled=True):
    """Yields update(done, total) for engines to call now and then."""
    if not enabled:
        yield None
        return
    from tqdm import tqdm

    with tqdm(total=total, desc=label, unit="step", file=sys.stderr, leave=False,
              mininterval=0.5, unit_scale=True) as t:
        def update(done, total_=None):
            t.update(max(0, done - t.n))

        yield update
