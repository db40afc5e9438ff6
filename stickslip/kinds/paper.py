# SPDX-License-Identifier: GPL-2.0-or-later
"""The paper's statements beside the runs' figures: each kind lists what its section of the
paper says that can be checked (or not), and how the runs' summary figures check it.

A Statement's `value` reads the figure from one run's summary; `check` says whether it
matches the paper (None: the statement cannot be checked from a run). `why` explains,
in one sentence per slip timing ("step", "exact", or "" for both), a difference.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable


@dataclass
class Statement:
    section: str  # e.g. "§3.1"
    text: str  # what the paper says
    value: Callable[[dict], object] | None  # the figure, from a run's summary
    check: Callable[[object], bool] | None  # matches the paper?
    law: str = "stick_slip"  # the run it is judged on
    why: dict = field(default_factory=dict)  # slip timing ("" = any) -> sentence, where it differs
    how: str = ""  # how the statement is read (tolerance and its reason)


def rows(statements, runs, fmt):
    """Table rows: (section, text, how, {(timing, engine): value}, {timing: verdict}, why)."""
    out = []
    for st in statements:
        values, verdicts = {}, {}
        for (law, timing, eng), (sc, summary, df) in sorted(runs.items()):
            if law != st.law:
                continue
            v = st.value(summary) if st.value else None
            values[(timing, eng)] = fmt(v)
            if st.check is None or v is None:
                verdict = "cannot be checked"
            else:
                verdict = "matches" if st.check(v) else "differs"
            # one verdict per timing: "differs" if any engine differs
            if verdicts.get(timing) != "differs":
                verdicts[timing] = verdict
        why = "; ".join(f"{t + ': ' if t else ''}{w}" for t, w in st.why.items() if not t or t in verdicts)
        out.append((st.section, st.text, st.how, values, verdicts, why))
    return out


def near(target, rel):
    return lambda v: v is not None and abs(v - target) <= rel * abs(target)
