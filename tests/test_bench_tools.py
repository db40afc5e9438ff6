# SPDX-License-Identifier: GPL-2.0-or-later
"""The benchmark's measuring tools (issue 32): the interval of a ratio measured in
interleaved rounds, and the reading of callgrind's profiles. Cost: ~0.3 s in all."""
import math
from pathlib import Path

import numpy as np
import pytest

from stickslip.bench import callgrind
from stickslip.bench.ratio_interval import ratio_interval


def test_ratio_interval_covers_the_true_ratio_95_times_in_100():
    """2000 simulated benchmarks of 8 rounds: times with a common per-round disturbance
    (cancels in the ratio) and independent log-normal scatter (sd 0.05) around a true
    ratio 1.03. A 95 % interval must cover 1.03 in 95 % of them: the binomial scatter of
    that share over 2000 trials is sqrt(0.95*0.05/2000) = 0.0049, so [0.935, 0.965] is
    +-3 sd. A normal (z) interval on 8 rounds covers ~92 % and fails this; so does an
    interval from the times' spread instead of the paired log-ratios."""
    rng = np.random.default_rng(32)
    true, n, trials = 1.03, 8, 2000
    covered = 0
    for _ in range(trials):
        common = rng.uniform(0.7, 1.4, n)  # the machine's state in each round, shared by A and B
        a = 5e-3 * common * np.exp(rng.normal(0.0, 0.05, n))
        b = 5e-3 * true * common * np.exp(rng.normal(0.0, 0.05, n))
        mid, low, high = ratio_interval(list(zip(a, b)))
        assert low < mid < high
        covered += low <= true <= high
    assert 0.935 <= covered / trials <= 0.965


def test_ratio_interval_is_the_geometric_mean_and_inverts():
    pairs = [(1.0, 1.1), (2.0, 2.0), (1.0, 0.95)]
    mid, low, high = ratio_interval(pairs)
    # (1.1 * 1.0 * 0.95)^(1/3), to round-off (a few ulps of the logs' sum)
    assert mid == pytest.approx((1.1 * 0.95) ** (1 / 3), rel=1e-14)
    inv = ratio_interval([(b, a) for a, b in pairs])
    assert inv[0] == pytest.approx(1 / mid, rel=1e-14)
    assert inv[1] == pytest.approx(1 / high, rel=1e-14) and inv[2] == pytest.approx(1 / low, rel=1e-14)
    one = ratio_interval([(1.0, 1.2)])
    assert one[0] == pytest.approx(1.2, rel=1e-15) and math.isnan(one[1]) and math.isnan(one[2])


# A profile as callgrind writes it (names compressed to (id) after their first use): main
# costs 100 itself and calls f (inclusive 70: f's own 50 and g's 20, called from f).
PROFILE = """\
# callgrind format
version: 1
positions: line
events: Ir
summary: 170

ob=(1) /bin/prog
fl=(1) prog.c
fn=(1) main
3 60
cfn=(2) f
calls=1 10
4 70
5 40

fn=(2)
10 30
cfn=(3) g(int)
calls=2 20
11 20
+1 20

fn=(3)
20 20
"""


def test_callgrind_self_costs_leave_out_what_a_function_calls(tmp_path):
    p = tmp_path / "callgrind.out.1.1"
    p.write_text(PROFILE)
    assert callgrind.total(p) == 170
    costs = callgrind.self_costs(p)
    assert costs == {"main": 100, "f": 50, "g(int)": 20}
    assert sum(costs.values()) == callgrind.total(p)


def test_callgrind_total_refuses_a_file_without_summary(tmp_path):
    p = tmp_path / "not-a-profile"
    p.write_text("events: Ir\n")
    with pytest.raises(RuntimeError, match="no summary"):
        callgrind.total(p)


def test_callgrind_simulated_reads_the_events_by_name_and_weighs_them(tmp_path):
    """The summary's events are read by the names of the `events:` line (their order is
    callgrind's, not fixed here), and the time model is instructions + 10 first-level misses
    + 100 last-level ones + 15 mispredicted branches: a profile with one of each kind."""
    p = tmp_path / "callgrind.out.1.1"
    p.write_text("# callgrind format\nevents: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw Bc Bcm Bi Bim\n"
                 "fn=(1) main\n1 1000 400 200 1 2 3 4 5 6 90 7 10 8\n"
                 "summary: 1000 400 200 1 2 3 4 5 6 90 7 10 8\n")
    sim = callgrind.simulated(callgrind.event_totals(p))
    assert sim == {"instructions": 1000, "l1_misses": 6, "ll_misses": 15, "mispredicts": 15,
                   "cycles": 1000 + 10 * 6 + 100 * 15 + 15 * 15}
    plain = tmp_path / "callgrind.out.2.1"
    plain.write_text("events: Ir\nsummary: 170\n")  # no simulation: every miss is 0
    assert callgrind.simulated(callgrind.event_totals(plain))["cycles"] == 170


# The same with one cost line per instruction (--dump-instr=yes: address, line, Ir), as the
# path analysis reads it: f's instructions at 0x10, 0x14 (ran 5 times each), 0x18 (ran 2
# times), the call at 0x1c (its line carries g's inclusive cost, not a run count).
PROFILE_INSTR = """\
# callgrind format
version: 1
positions: instr line
events: Ir
summary: 31

fn=(1) f
0x10 3 5
+4 3 5
+4 4 2
cfn=(2) g
calls=2 0x40 7
+4 5 10
* 5 2
fn=(2)
0x40 7 7
"""


def test_callgrind_instruction_counts_read_each_instructions_runs(tmp_path):
    p = tmp_path / "callgrind.out.1.1"
    p.write_text(PROFILE_INSTR)
    runs = callgrind.instruction_counts(p, lambda f: f == "f")
    assert dict(runs) == {"f": {0x10: 5, 0x14: 5, 0x18: 2, 0x1C: 2}}


# With --dump-line=yes too (positions: instr line), and source files: f's code from a.cpp
# with lines of b.h inlined (fi=), back to a.cpp (fe=); b.h's name first written at a call
# (cfi=), as callgrind does; g (in b.h) is called from f, its call cost line is skipped.
PROFILE_LINES = """\
# callgrind format
version: 1
positions: instr line
events: Ir
summary: 22

fl=(1) /usr/src/a.cpp
fn=(1) f
0x10 3 5
cfi=(2) /usr/src/b.h
cfn=(2) g
calls=2 0x40 7
+4 4 8
+4 * 1
fi=(2)
+4 10 5
+4 11 2
fe=(1)
+4 5 2
fl=(2)
fn=(2)
0x40 7 7
"""


def test_callgrind_instruction_lines_name_each_instructions_function_file_and_line(tmp_path):
    """Costs 0.01 s. Each instruction's file follows fl/fi/fe (not a call's cfi), the
    function's name may be first written at a call (cfn), and a call's inclusive cost is
    not a run count."""
    p = tmp_path / "callgrind.out.1.1"
    p.write_text(PROFILE_LINES)
    got = callgrind.instruction_lines(p, lambda f: True)
    assert got == {0x10: ("f", "/usr/src/a.cpp", 3, 5), 0x18: ("f", "/usr/src/a.cpp", 4, 1),
                   0x1C: ("f", "/usr/src/b.h", 10, 5), 0x20: ("f", "/usr/src/b.h", 11, 2),
                   0x24: ("f", "/usr/src/a.cpp", 5, 2), 0x40: ("g", "/usr/src/b.h", 7, 7)}
    assert set(callgrind.instruction_lines(p, lambda f: f.endswith(".h"))) == {0x1C, 0x20, 0x40}


def test_liggghts_bench_round_ratios_are_each_rounds_geometric_mean_of_quiet_blocks():
    """liggghts_bench takes the round as the interval's unit: per round the geometric mean
    of its quiet blocks' ratios (a noisy block left out, a round without a quiet one left
    out). Two rounds of made-up chunks, the ratios worked out by hand."""
    from stickslip.bench import liggghts_rounds as lb

    def run(cpus, foreign):
        return {"chunks": [{"cpu": c * lb.CHUNK, "foreign": f} for c, f in zip(cpus, foreign)]}
    n = lb.CHUNKS
    quiet, noisy = [0.0] * n, [lb.NOISY * 2] * n
    # round 1: ratios 2 and 8 alternating (geometric mean 4), one noisy block of ratio 100
    a1 = [1.0] * n
    b1 = [2.0 if k % 2 == 0 else 8.0 for k in range(n)]
    b1[5], f1 = 100.0, quiet.copy()
    f1[5] = lb.NOISY * 2
    round1 = {"history": run(a1, f1), "stick_slip": run(b1, quiet)}
    round2 = {"history": run([1.0] * n, noisy), "stick_slip": run([3.0] * n, quiet)}  # no quiet block
    round3 = {"history": run([2.0] * n, quiet), "stick_slip": run([3.0] * n, quiet)}
    got = lb.round_ratios([round1, round2, round3], "stick_slip", "history", quiet_only=True)
    # round 1 without block 5: 19 blocks of 8 and 20 of 2 -> exp((19 ln 8 + 20 ln 2)/39)
    assert got[0] == pytest.approx(math.exp((19 * math.log(8) + 20 * math.log(2)) / 39), rel=1e-12)
    assert got[1:] == [pytest.approx(1.5, rel=1e-12)] and len(got) == 2
    every = lb.round_ratios([round1, round2, round3], "stick_slip", "history", quiet_only=False)
    assert len(every) == 3 and every[1] == pytest.approx(3.0, rel=1e-12)


def test_lammps_granular_bench_swaps_only_the_tangential_words_and_divides_each_law_by_its_stock(tmp_path):
    """Issue 49 item 5's benchmark (stickslip/bench/lammps_granular.py), its plumbing on a
    tiny bed (48 grains settled, 2 rounds of 20 + 50 steps; 13 LAMMPS 2025 runs: ~1 s of
    CPU, a few seconds of wall time). Each law configuration's input is its stock's but for the tangential
    words, on the pair and the floor wall alike, with the stock's Ks (or NULL), x and mu_s;
    the order turns from round to round; the rows divide each law's time by its own stock's
    (geometric mean over the rounds, over the quiet ones when there are 3), and its
    instructions likewise."""
    from conftest import skip_engine

    skip_engine("lammps_granular")
    from stickslip.bench import lammps_granular as lg

    data = tmp_path / "bed.data"
    assert set(lg.STOCK.values()) == {"linear_history", "mindlin"} and lg.NORMAL.startswith("hertz/material ")
    for c, stock in lg.STOCK.items():
        law, ref = lg.TANGENTIAL[c].split(), lg.TANGENTIAL[stock].split()
        assert law[0] == ("stick_slip/exact" if c.endswith("exact") else "stick_slip")  # no /total: the paper's reset
        assert law[1:4] == ref[1:4] and (law[1] == "NULL") == (stock == "mindlin")
        assert float(lg.MU_K) < float(lg.MU_S) and law[3:] == [lg.MU_S, lg.MU_K]
        text = lg.script(data, c)
        where = [ln.split()[:2] + ln.split(" tangential ")[1].split()[:5] for ln in text.splitlines()
                 if " tangential " in ln]
        assert where == [["pair_coeff", "*"] + law, ["fix", "floor"] + law]
        assert text.replace(lg.TANGENTIAL[c], "T") == lg.script(data, stock).replace(lg.TANGENTIAL[stock], "T")

    res = lg.measure(2, counts=False, size=(4, 4, 3), steps=50, warm=20, cache=tmp_path)
    bed = lg.bed((4, 4, 3), tmp_path)
    assert [p.name for p in tmp_path.glob("*.data")] == [bed.name]  # made once, then read from the cache
    assert res["bed"]["grains"] == 48 and res["bed"]["ke_per_grain"] < lg.KE_MAX
    order = list(lg.TANGENTIAL)
    assert [list(r) for r in res["rounds"]] == [order, order[1:] + order[:1]]
    for r in res["rounds"]:
        for x in r.values():
            assert 0.0 < x["cpu"] < 5.0 and x["atoms"] == 48 and x["contacts0"] > 0

    def row(c, what):
        return next(r for r in lg.rows(res) if r["case"].startswith(f"{lg.label(c)} / ") and what in r["case"])
    for c, stock in lg.STOCK.items():
        logs = [math.log(r[c]["cpu"] / r[stock]["cpu"]) for r in res["rounds"]]
        got = row(c, "time")
        assert got["value"] == pytest.approx(math.exp(sum(logs) / 2), rel=1e-12)
        assert got["ci_low"] < got["value"] < got["ci_high"]

    # made-up rounds: each law costs 1.01 / 1.04 times its stock, whose two differ by 2x; a
    # 5th round, noisy, gives 3x and is left out (4 quiet rounds)
    factor = {"linear_history": 1.0, "ks_step": 1.01, "ks_exact": 1.04, "mindlin": 2.0, "null_step": 2.02,
              "null_exact": 2.08}
    made = [{c: dict(res["rounds"][0][c], cpu=f * s, foreign=0.0) for c, f in factor.items()} for s in (1, 2, 3, 5)]
    made.append({c: dict(x, cpu=x["cpu"] * (3.0 if c in lg.STOCK else 1.0), foreign=1.0) for c, x in made[0].items()})
    counts = {c: {"total": 1000 * f, "model": 100 * f, "tangential": 10 * f, "steps": 10} for c, f in factor.items()}
    res = dict(res, rounds=made, counts=counts)
    for c, stock in lg.STOCK.items():
        expect = factor[c] / factor[stock]
        assert row(c, "time")["value"] == pytest.approx(expect, rel=1e-12)
        assert "the 4 quiet rounds of 5" in row(c, "time")["case"]
        assert row(c, "busy rounds")["value"] == pytest.approx(3 * expect, rel=1e-12)
        assert row(c, "instructions")["value"] == " / ".join([f"{expect:.4f}"] * 3)


def test_the_analysis_builds_find_their_places_in_the_law():
    """The LIGGGHTS analysis variants are made from the law's files as they read now: each
    path's counter finds its one line (law or core) and the control replaces the law's class;
    the LAMMPS path markers find theirs. A law edited without them fails here."""
    from stickslip.bench import lammps_paths, liggghts_variants as lv

    counted = lv.headers("paths")
    for name, file, anchor, where, statement in lv.COUNTS:
        assert statement.splitlines()[0] in counted[file.name], name
    assert all(t.startswith('#include "stick_slip_path_counts.h"') for t in counted.values())
    control = lv.headers("control")[lv.LAW.name]
    assert lv.CONTROL_CLASS in control and "StickSlipCore::" not in control
    assert len(lammps_paths.marker_lines()) == sum(len(m) for m in lammps_paths.MARKERS.values())


def test_the_lammps_path_markers_name_the_profile_s_lines():
    """A marker names the group that runs its line, whatever folder its file is in (the
    profile names a file by its path; the core lies in law_core/): one made-up profile line
    per marker, each alone in its group, comes back named (the core's path from lammps_plugin/
    is ../law_core/)."""
    from stickslip.bench import lammps_paths

    markers = lammps_paths.marker_lines()
    where = {Path(name).name: name for name in lammps_paths.MARKERS}  # file -> its path in lammps_plugin/
    runs = {k: ("PairGranHookeStickSlip::contacts", f"/src/lammps_plugin/{where[f]}", line, 10 + k)
            for k, (f, line) in enumerate(markers)}
    named = {name for _, _, name in lammps_paths.our_groups(runs, markers)}
    assert named == {f"pair: {path}" for path in markers.values()}
