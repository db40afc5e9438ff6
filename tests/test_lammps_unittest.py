# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model in LAMMPS' own tests (tools/lammps_unittest.py): its yaml cases as the tool
writes them, their values pyref's; the stock cases turned into the sub-model; and, where the
LAMMPS 4 Jul 2026 build has its test programs (STICKSLIP_SOURCE_BUILDS=lammps-2026; CI
builds them), LAMMPS' granular tests, the turned cases and the sub-model's own, run."""
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import lammps_release_launcher

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

import lammps_unittest as lu  # noqa: E402


@pytest.mark.parametrize("timing", sorted(lu.DRAG_FILES))
def test_the_drag_cases_are_what_pyref_gives(timing):
    """The committed yaml is the tool's output from pyref's law (write it again with
    `tools/lammps_unittest.py write`), with the date its values were generated as LAMMPS
    writes it (ctime), and its segments end on steps that slip and on steps that stick,
    before the first slip and over several cycles."""
    path = lu.CASES / "granular" / lu.DRAG_FILES[timing]
    date = lu.date_generated(path.read_text())
    assert date is not None and time.strptime(date, "%a %b %d %H:%M:%S %Y")
    assert path.read_text() == lu.drag_case(timing, date)
    ends = np.cumsum(lu.SEGMENTS)
    force, slipped = lu.drag_series(timing, ends[-1], slips=True)
    d = lu.DRAG
    threshold = d["mu_s"] * d["kn"] * d["overlap"]
    assert np.abs(force[:, 0]).max() <= threshold
    at_ends = slipped[ends - 1]
    assert ends[0] < np.argmax(slipped) + 1 and at_ends.any() and not at_ends.all()
    assert slipped.sum() >= 10  # several cycles of the saw-tooth


def test_stock_cases_are_turned_into_the_sub_model():
    """linear_history and mindlin (a number or a variable each) become stick_slip/total with
    mu_k = mu_s; other tangential sub-models and texts without them are left alone."""
    text = ("pair_coeff: * * hooke ${k} 0.5 tangential linear_history ${kt} ${gt} ${xmu} damping mass_velocity\n"
            "  fix w all wall/gran granular hertz/material 1e5 0.3 0.3 tangential mindlin NULL 1.0 0.4 zplane 0 NULL\n")
    assert lu.with_stick_slip(text) == (
        "pair_coeff: * * hooke ${k} 0.5 tangential stick_slip/total ${kt} ${gt} ${xmu} ${xmu} damping mass_velocity\n"
        "  fix w all wall/gran granular hertz/material 1e5 0.3 0.3 tangential stick_slip/total NULL 1.0 0.4 0.4 "
        "zplane 0 NULL\n")
    for other in ("tangential mindlin_rescale NULL 1.0 0.4 x", "tangential linear_nohistory 1.0 0.4 x",
                  "tangential mindlin/force NULL 1.0 0.4 x", "tangential linear_history_classic 1 2 3 x"):
        assert lu.with_stick_slip(other) is None, other


def test_the_pair_case_files_are_the_tools():
    """The pair granular case's input, data and skeleton are what the tool writes, and the
    committed case (reference values added by LAMMPS' tester) keeps the skeleton's settings."""
    styles = lu.CASES / "force-styles"
    assert (styles / lu.PAIR_INPUT_FILE).read_text() == lu.PAIR_INPUT
    assert (styles / lu.PAIR_DATA).read_text() == lu.pair_data()
    assert lu.PAIR_DATA in lu.PAIR_INPUT and f"input_file: {lu.PAIR_INPUT_FILE}\n" in lu.pair_skeleton()
    assert (styles / lu.PAIR_SKELETON).read_text() == lu.pair_skeleton()
    case = (styles / lu.PAIR_CASE).read_text()
    for coeff in lu.PAIR_COEFFS:
        assert f"  {coeff}\n" in case
    for key in ("init_forces", "run_forces", "init_stress", "run_stress"):
        assert f"\n{key}: " in case


@pytest.mark.long
def test_lammps_own_tests_pass_with_the_sub_model():
    """ctest's granular tests (LAMMPS' and the sub-model's), LAMMPS' linear_history and
    mindlin cases with stick_slip/total, and test_pair_style on the pair case, on the
    LAMMPS 4 Jul 2026 build with its test programs."""
    lmp = lammps_release_launcher("lammps-2026")
    build = lmp.parent.parent
    if not (build / "build" / "test_pair_style").is_file():
        pytest.fail(f"{build}/build has no test programs (./run.sh setup builds them with lammps-2026)")
    lines, ok = lu.run(build)
    print("\n".join(lines))
    assert ok, "\n".join(lines)


def test_the_pair_case_slips_and_sticks(tmp_path):
    """What LAMMPS' pair-style tester checks is the law at work: over its 4 steps (fix nve,
    as the tester runs) some of the pair case's contacts slip and some stick, in each of its
    three type pairs (the same coefficients with /record: pair/local p17, the slips)."""
    lmp = lammps_release_launcher("lammps-2026")
    from lammps_runs import read_dump, run_lammps

    styles = lu.CASES / "force-styles"
    (tmp_path / lu.PAIR_DATA).write_text((styles / lu.PAIR_DATA).read_text())
    coeffs = [c.replace("stick_slip ", "stick_slip/record ").replace("stick_slip/total/exact ",
                                                                      "stick_slip/total/exact/record ")
              for c in lu.PAIR_COEFFS]
    script = (lu.PAIR_INPUT + "".join(f"pair_coeff {c}\n" for c in coeffs) + "fix 1 all nve\n"
              "compute pl all pair/local p17 cutoff radius\ncompute t all property/local ptype1 ptype2 cutoff radius\n"
              "dump d all local 4 dump.slips c_t[1] c_t[2] c_pl\nrun 4\n")
    run_lammps(tmp_path, "pair", script, exe=lmp)
    rows = read_dump(tmp_path / "dump.slips")[4]
    for types in ((1, 1), (2, 2), (1, 2)):
        mine = [r[2] for r in rows if sorted(r[:2]) == list(types)]
        slipped = sum(s > 0 for s in mine)
        print(f"types {types}: {len(mine)} contacts, {slipped} slipped in 4 steps")
        assert 0 < slipped < len(mine), types
