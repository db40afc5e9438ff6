# SPDX-License-Identifier: GPL-2.0-or-later
"""How long 1 and 2 ranks agree on a flowing pile (issue 30, item 4), stock against ours.

LAMMPS is not rank-independent on a pile: a grain's force is a sum over its contacts in the
order of the rank's neighbour list, and the ranks' lists (ghost atoms, the pairs computed
on both sides of a rank boundary with newton off) give another order, so 1 and 2 ranks
part by round-off once grains press on several neighbours, and the pile's chaos grows it.
Our pair style sums in stock's order (with stock's arguments it is stock bit for bit,
test_lammps_dropin.py), so it must part no sooner than stock with the law's settings too.
The few-grain scenes, where that order cannot differ, are identical on 1 and 2 ranks
(test_lammps_plugin.py::test_ranks_and_newton_do_not_change_a_few_grain_scene).

Measured (examples/pour/in.pour as shipped, 3000 grains poured, then the chute; positions
dumped every 1000 steps, the largest difference between 1 and 2 ranks, periodic images
folded):

| step | stock | ours, mu_k 0.45 reset spring |
|---|---|---|
| 5000 | 0 | 0 |
| 6000 | 4.7e-15 | 2.1e-15 |
| 8000 | 2.0e-11 | 1.2e-11 |
| 10000 | 7.2e-6 | 6.5e-9 |
| 12000 | 0.091 | 0.0079 |
| 14000 | 1.04 | 0.64 |
| 50000 | 9.2 | 8.1 (the grains have flowed apart: chaos) |
"""
import re

import numpy as np
import pytest

from conftest import needs_engine
from lammps_runs import EXAMPLES, STOCK, read_dump, rename_to_stickslip, run_lammps

pytestmark = needs_engine("lammps")  # LAMMPS installed and the plugin built (the adapter's check)

LAW = "mu_k 0.45 reset spring"
DUMP = "dump d all custom 1000 dump.out id x y z\ndump_modify d sort id format float %.17g\n"
BOX = 20.0  # in.pour's box is periodic in x and y with this side


def pour(styles):
    s = (EXAMPLES / "pour" / "in.pour").read_text()
    first = re.search(r"^run\s+25000", s, flags=re.M)
    assert first, "examples/pour/in.pour changed"
    s = s[:first.start()] + DUMP + s[first.start():]
    if styles == "stock":
        return s
    s = rename_to_stickslip(s)
    s, k1 = re.subn(r"(gran/hooke/stickslip 2000\.0 NULL 50\.0 NULL 0\.5 0)", rf"\1 {LAW}", s)
    s, k2 = re.subn(r"(zplane 0\.0 2000\.0)", rf"\1 {LAW}", s)
    assert (k1, k2) == (1, 1), "examples/pour/in.pour changed"
    return s


def divergence(folder):
    """Largest |x1 - x2| over the grains at each dump step (periodic images folded)."""
    one, two = read_dump(folder / "1" / "dump.out"), read_dump(folder / "2" / "dump.out")
    out = {}
    for step in sorted(one):
        a, b = one[step], two[step]
        assert np.array_equal(a[:, 0], b[:, 0]), f"step {step}: different grains on 1 and 2 ranks"
        d = a[:, 1:4] - b[:, 1:4]
        d[:, :2] -= np.round(d[:, :2] / BOX) * BOX
        out[step] = np.abs(d).max() if len(a) else 0.0
    return out


def first_above(div, level):
    return next((s for s, d in div.items() if d > level), None)


@pytest.mark.slow
def test_ours_parts_between_ranks_no_sooner_than_stock(tmp_path):
    """The whole in.pour on 1 and 2 ranks, stock and ours with the law's settings: the first
    dump where 1 and 2 ranks differ at all, and where they differ by more than 1e-3 (a
    thousandth of a grain diameter), must come no sooner for ours. ~6 min on the shared
    machine (the 2-rank runs ~130 s each), ~2 min idle."""
    div = {}
    for styles in ("stock", "ours"):
        for np_ in (1, 2):
            run_lammps(tmp_path / styles / str(np_), "pour", pour(styles), exe=STOCK if styles == "stock" else None,
                       np_=np_, timeout=1800)
        div[styles] = divergence(tmp_path / styles)
        print(styles, {s: f"{d:.2g}" for s, d in div[styles].items()})
    for level in (0.0, 1e-3):
        stock, ours = first_above(div["stock"], level), first_above(div["ours"], level)
        assert stock is not None, f"stock's 1 and 2 ranks never differ by more than {level}: nothing measured"
        assert ours is None or ours >= stock, (level, ours, stock)
