#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Dumps for checking that a speed change of the LIGGGHTS plugin changes no output digit
(issue 32): the benchmark's packing (liggghts_bench, 100 + 300 steps, every grain-grain
and floor contact) in all 8 compiled modes of the law (exact_slip_timing off/on x
history_rotation keep_length/project x stick_slip_record off/on), with slip_reset_total,
without the stamp (history_on_separation keep) and with the energy books; and the plugin's
example in.pour3d (400 spheres into a box of 5 primitive walls, 20 000 steps of the fall)
in both slip timings. Every dump at %.17g (id x v f omega; with the record also the
per-contact record of compute pair/gran/local). Made with one build into OUT; compare two
OUTs byte for byte with `diff -r OLD NEW` (14 cases, 18 dump files). ~20 s on 2 cores.

    .venv/bin/python tools/liggghts_speed_dumps.py BUILD_DIR OUT_DIR
    (BUILD_DIR: a folder with liggghts-stickslip, e.g. build/liggghts_plugin or a copy of it)
"""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from stickslip.bench import liggghts_runs as b  # noqa: E402
from speed_dump_runs import run_cases  # noqa: E402

if len(sys.argv) != 3:
    sys.exit(__doc__)
build, out = Path(sys.argv[1]).resolve(), Path(sys.argv[2])
out.mkdir(parents=True, exist_ok=True)
exe = str(build / "liggghts-stickslip")


def f17(n):
    return " ".join(["%.17g"] * n)


DUMP = ('dump d all custom {every} dump.out id x y z vx vy vz fx fy fz omegax omegay omegaz\n'
        'dump_modify d sort id format "%d {fmt}"\n').replace("{fmt}", f17(12))
# with stick_slip_record on: id1 id2 periodic flag and the 3 + 5 history values
REC = ('compute pl all pair/gran/local id history\n'
       'dump l all local {every} dump.local c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5] c_pl[6] c_pl[7] c_pl[8] '
       'c_pl[9] c_pl[10] c_pl[11]\n'
       'dump_modify l format "{fmt}"\n').replace("{fmt}", f17(11))


def packing(extra, rec=False, pair_only=""):
    """The benchmark's timed script, 100 steps then 300 with dumps every 100; `pair_only`
    settings for the grain pairs alone (LIGGGHTS' normal model crashes on a primitive wall
    with computeElasticPotential on, stock history's as ours)."""
    t = b.TIMED.format(data=b.packing(), warm=100, timed=DUMP.format(every=100) + "run 300\n")
    if rec:  # (LIGGGHTS wants the compute before the first run)
        t = t.replace("compute c all contact/atom", REC.format(every=100) + "compute c all contact/atom")
    pair = "tangential ${tang} absolute_damping on limitForce on ${extra}\npair_coeff"
    if t.count(pair) != 1:
        sys.exit("liggghts_bench's pair_style line changed: this script's edits no longer apply")
    t = t.replace(pair, pair.replace("${extra}", "${extra} " + pair_only))
    return t.replace("${tang}", "stick_slip").replace("${extra}", extra)


def pour(extra):
    s = (ROOT / "liggghts_plugin/examples/in.pour3d").read_text()
    head, sep, _ = s.partition("run             ${steps}")
    if not sep or s.count("absolute_damping on limitForce on") != 2:
        sys.exit("liggghts_plugin/examples/in.pour3d changed: this script's edits no longer apply")
    head = head.replace("absolute_damping on limitForce on", "absolute_damping on limitForce on " + extra)
    return head + DUMP.format(every=5000) + "run 20000\n"


cases = {}
for exact in ("off", "on"):
    for rot in ("keep_length", "project"):
        for rec in ("off", "on"):
            cases[f"pack-exact_{exact}-{rot}-rec_{rec}"] = packing(
                f"exact_slip_timing {exact} history_rotation {rot} stick_slip_record {rec}", rec == "on")
cases["pack-reset_total-exact"] = packing("slip_reset_total on exact_slip_timing on")
cases["pack-keep_separated"] = packing("history_on_separation keep")
ENERGY = "computeElasticPotential on heating_tangential_history on"
cases["pack-energy-exact"] = packing("exact_slip_timing on", pair_only=ENERGY)
cases["pack-energy"] = packing("", pair_only=ENERGY)
cases["pour-step"] = pour("exact_slip_timing off")
cases["pour-exact"] = pour("exact_slip_timing on")


run_cases(cases, out, [exe, "-log", "none", "-echo", "none"], b.env())
