#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Dumps for checking that a speed change of the LAMMPS plugin changes no output digit:
in.pour (pour 6000 + chute 2000 steps, dampflag 1 unless said) in all 8 compiled modes
(slip_timing step/exact x history_rotation project/keep_length x record no/yes, mu_k 0.45
reset spring), with the stock arguments (dampflag 0 and 1), the law's settings, reset total,
no dashpot, and lammps_bench's chute (100 + 300 steps: step, exact, exact keep_length
record); every dump at %.17g (x v f omega; with record also compute pair/local and the
wall's record columns). Made with one build into OUT; compare two OUTs byte for byte with
`diff -r OLD NEW` (21 dump files). ~10-20 s on 2 cores (Release build).

    .venv/bin/python tools/lammps_speed_dumps.py BUILD_DIR OUT_DIR
    (BUILD_DIR: a folder with lmp-stickslip, e.g. build/lammps_plugin or a copy of it)
"""
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from stickslip.bench import lammps as b  # noqa: E402
from speed_dump_runs import run_cases  # noqa: E402

if len(sys.argv) != 3:
    sys.exit(__doc__)
build, out = Path(sys.argv[1]).resolve(), Path(sys.argv[2])
out.mkdir(parents=True, exist_ok=True)
exe = str(build / "lmp-stickslip")
DUMP = ("dump d all custom {every} dump.out id x y z vx vy vz fx fy fz omegax omegay omegaz{extra}\n"
        "dump_modify d sort id format float %.17g\n")
REC = ("compute pl all pair/local p1 p2 p3 p4 p11 p12 p13\n"
       "dump l all local {every} dump.local c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5] c_pl[6] c_pl[7]\n"
       "dump_modify l format float %.17g\n")
SRC = Path("/usr/share/lammps/examples/pour/in.pour").read_text()

def pour(kw, damp):
    s = SRC.replace("50.0 NULL 0.5 0", f"50.0 NULL 0.5 {damp}")
    s = s.replace("gran/hooke/history", "gran/hooke/stickslip").replace("wall/gran hooke/history", "wall/gran/stickslip hooke/history")
    s = re.sub(r"^(pair_style.*)$", lambda m: m.group(1) + " " + kw, s, flags=re.M)
    s = s.replace("zplane 0.0 2000.0", "zplane 0.0 2000.0 " + kw)
    rec = "record yes" in kw
    extra = " f_zlower[9] f_zlower[10] f_zlower[11] f_zlower[12] f_zlower[13] f_zlower[14]" if rec else ""
    runs = list(re.finditer(r"^run\s+25000$", s, flags=re.M))
    if len(runs) != 2 or s.count("stickslip") != 2 or s.count(" 0.5 ") != 2:
        sys.exit("examples/pour/in.pour changed: this script's edits no longer apply")
    head = s[:runs[0].start()] + DUMP.format(every=1000, extra=extra) + (REC.format(every=1000) if rec else "")
    return head + "run 6000" + s[runs[0].end():runs[1].start()] + "run 2000" + s[runs[1].end():]

def bench(kw):
    # (a dump defined between runs needs the second run's set-up: no `pre no`)
    t = b.TIMED.format(data=b._pour(), warm=100, steps=300, before=DUMP.format(every=100, extra=""),
                       after="").replace("run 300 pre no post no", "run 300")
    law = "2000.0 NULL 50.0 NULL 0.5 1 " + kw
    return (t.replace("${pair}", f"gran/hooke/stickslip {law}")
             .replace("${wall}", f"wall/gran/stickslip hooke/history 2000.0 NULL 50.0 NULL 0.5 1 zplane 0.0 2000.0 {kw}"))

cases = {}
for timing in ("step", "exact"):
    for rot in ("project", "keep_length"):
        for rec in ("no", "yes"):
            kw = f"mu_k 0.45 reset spring slip_timing {timing} history_rotation {rot} record {rec}"
            cases[f"pour-{timing}-{rot}-{rec}"] = pour(kw, 1)
cases["pour-stockargs"] = pour("", 0)
cases["pour-stockargs-damped"] = pour("", 1)
cases["pour-law"] = pour("mu_k 0.45 slip_timing exact history_rotation keep_length lever_arm contact damping absolute reset spring", 1)
cases["pour-total-exact"] = pour("mu_k 0.45 reset total slip_timing exact", 1)
cases["pour-nodash-exact"] = pour("mu_k 0.45 reset spring slip_timing exact", 0)
cases["pour-mus-exact"] = pour("slip_timing exact history_rotation keep_length", 0)
cases["bench-step"] = bench("mu_k 0.45 reset spring")
cases["bench-exact"] = bench("mu_k 0.45 reset spring slip_timing exact")
cases["bench-exact-keep"] = bench("mu_k 0.45 reset spring slip_timing exact history_rotation keep_length record yes")

run_cases(cases, out, [exe, "-log", "none", "-echo", "none", "-nocite"], b._env())
