# SPDX-License-Identifier: GPL-2.0-or-later
"""Variants of the LIGGGHTS plugin for the benchmark's analysis, made in the build that needs
them: the law's files (liggghts_plugin/tangential_model_stick_slip.h and its core,
law_core/stick_slip_core.h) carry no hook for them. A variant's headers are
written into its build folder and put first on the plugin's include path (CMakeLists.txt's
STICK_SLIP_HEADERS), in place of the law's:

- control: `tangential stick_slip` is LIGGGHTS' own `tangential history` (its class from
  Debian's header, unchanged), compiled into the plugin as the law is: timed against the
  stock model in Debian's library it shows what the plugin's build and place cost without
  any of the law's arithmetic (`python -m stickslip.bench.liggghts --control`);
- paths: the law and its core with a counter on each path (liggghts_plugin/
  stick_slip_path_counts.h: the counts, written when the program ends), for
  stickslip.bench.liggghts_paths.

    python -m stickslip.bench.liggghts_variants control|paths    (build it; prints the launcher)
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAW = ROOT / "liggghts_plugin" / "tangential_model_stick_slip.h"
CORE = ROOT / "law_core" / "stick_slip_core.h"
BUILDS = {"control": ROOT / "build" / "liggghts_control", "paths": ROOT / "build" / "liggghts_plugin_paths"}

CLASS = "template<>\nclass TangentialModel<TANGENTIAL_STICK_SLIP> : public TangentialModelBase\n{"
CONTROL_CLASS = """template<>
class TangentialModel<TANGENTIAL_STICK_SLIP> : public TangentialModel<TANGENTIAL_HISTORY>
{
public:
  // the benchmark's control: stock tangential history under the law's name (settings that
  // only stick_slip has are refused)
  TangentialModel(LAMMPS * lmp, IContactHistorySetup * hsetup, class ContactModelBase * c) :
    TangentialModel<TANGENTIAL_HISTORY>(lmp, hsetup, c) {}
};
"""

# (path, file, a line of it, where the counting statement goes: before or after that line,
# the statement). The paths' names are those of liggghts_plugin/stick_slip_path_counts.h.
COUNTS = (
    ("CALL_*", LAW, "const bool energy = !PLAIN && update_history && energy_books;", "after",
     "STICK_SLIP_COUNTING(true);\nif (!update_history) STICK_SLIP_COUNT(CALL_NO_UPDATE);\n"
     "else if (sidata.is_wall) STICK_SLIP_COUNT(CALL_WALL);\nelse STICK_SLIP_COUNT(CALL_PAIR);\n"
     "STICK_SLIP_COUNTING(update_history);"),
    ("STAMP_FRESH", LAW, "if (fresh) D[0] = D[1] = D[2] = 0.0;", "after", "if (fresh) STICK_SLIP_COUNT(STAMP_FRESH);"),
    ("TURN_NONE", LAW, "if (dn != 0.0) {", "before", "if (dn == 0.0) STICK_SLIP_COUNT(TURN_NONE);"),
    ("TURN_*", LAW, "if (!(x < 1e-6)) {", "before",
     "if (x < 1e-6) STICK_SLIP_COUNT(TURN_SERIES); else STICK_SLIP_COUNT(TURN_SQRT);"),
    ("STEP_SLIP", LAW, "const double fmin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]) * fn;",
     "before", "STICK_SLIP_COUNT(STEP_SLIP);"),
    ("STEP_STICK", LAW, "FOR_XYZ(k) hist[k] = D[k];", "before", "if (!exact && !slip) STICK_SLIP_COUNT(STEP_STICK);"),
    ("EXACT_START_OVER", CORE, "stick = 1.0;", "before", "if (start_slips) STICK_SLIP_COUNT(EXACT_START_OVER);"),
    ("EXACT_NO_SLIP", CORE, "if (STICK_SLIP_UNLIKELY(step_slips(end_slips, start_slips))) {", "before",
     "if (!step_slips(end_slips, start_slips)) STICK_SLIP_COUNT(EXACT_NO_SLIP);"),
    ("EXACT_E4_START", CORE, "const double a = fmin / std::sqrt(vs2), aks = a / ks;", "before",
     "STICK_SLIP_COUNT(EXACT_E4_START);"),
    ("EXACT_GENERAL", CORE, "const double f0[3] = {F0[0], F0[1], F0[2]}, v[3] = {vs[0], vs[1], vs[2]};", "before",
     "STICK_SLIP_COUNT(EXACT_GENERAL);"),
    ("GEN_E1", CORE, "if (!(T > 0.0)) {", "after", "STICK_SLIP_COUNT(GEN_E1);"),
    ("GEN_STICK_TO_END", CORE, "if (!(theta + dtheta <= 1.0)) {", "after", "STICK_SLIP_COUNT(GEN_STICK_TO_END);"),
    ("GEN_SLIP", CORE, "slips++;", "after", "STICK_SLIP_COUNT(GEN_SLIP);"),
    ("GEN_E4", CORE, "if (kept > 0.0 && dot(F, F) >= T * T) {", "after", "STICK_SLIP_COUNT(GEN_E4);"),
    ("GEN_E5", CORE, "if (rate == 0.0) {", "after", "STICK_SLIP_COUNT(GEN_E5);"),
    ("GEN_E6", CORE, "if (flow_law && along >= 0.0) {", "after", "STICK_SLIP_COUNT(GEN_E6);"),
    ("GEN_E7", CORE, "if ((std::sqrt(dot(q, q)) <= SETTLED * T && along > 0.0) || slips >= MAX_EXPLICIT_SLIPS) {",
     "after", "STICK_SLIP_COUNT(GEN_E7);"),
)


def _line_of(text, anchor, name, file):
    """The index of the one line of `text` that holds `anchor` (whitespace runs alike)."""
    rx = re.compile(r"\s+".join(map(re.escape, anchor.split())))
    hits = [i for i, line in enumerate(text.splitlines()) if rx.search(line)]
    if len(hits) != 1:
        raise RuntimeError(f"liggghts_variants: path {name}: '{anchor}' is on {len(hits)} lines of {file.name}, "
                           "not one (the law changed: update COUNTS)")
    return hits[0]


def counted(file):
    """`file` (the law or its core) with its paths' counting statements."""
    lines = file.read_text().splitlines()
    inserts = []
    for name, f, anchor, where, statement in COUNTS:
        if f == file:
            i = _line_of("\n".join(lines), anchor, name, file)
            inserts.append((i + (where == "after"), statement))
    for i, statement in sorted(inserts, reverse=True):
        lines[i:i] = statement.splitlines()
    return '#include "stick_slip_path_counts.h"\n' + "\n".join(lines) + "\n"


def control():
    """The law's header with its class replaced by the control's."""
    text = LAW.read_text()
    start = text.index(CLASS)
    end = text.index("\n};\n", start) + len("\n};\n")
    return text[:start] + CONTROL_CLASS + text[end:]


def headers(kind):
    """{file name: text} of a variant's headers."""
    if kind == "control":
        return {LAW.name: control()}
    return {LAW.name: counted(LAW), CORE.name: counted(CORE)}


def build(kind):
    """The variant's plugin (built once, again when the law changes); its launcher."""
    out = BUILDS[kind]
    folder = out / "headers"
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in headers(kind).items():
        path = folder / name
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
    if not (out / "CMakeCache.txt").is_file():
        extra = ["-DSTICK_SLIP_PATH_COUNTS=ON"] if kind == "paths" else []
        subprocess.run(["cmake", "-S", str(ROOT / "liggghts_plugin"), "-B", str(out), "-DCMAKE_BUILD_TYPE=Release",
                        f"-DSTICK_SLIP_HEADERS={folder}", *extra], check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", str(out), "-j", str(os.cpu_count() or 1)], check=True,
                   stdout=subprocess.DEVNULL)
    return out / "liggghts-stickslip"


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1 or argv[0] not in BUILDS:
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    print(build(argv[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
