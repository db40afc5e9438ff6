#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The pull request's description for LAMMPS, written from this repository and the tree the
patch is for, in the sections of LAMMPS' form for a new feature.

  tools/lammps_pr.py LAMMPS_DIR [--build BUILD] [-o FILE]

LAMMPS_DIR is the tree tools/lammps_patch.py writes the patch for (its layout is stated in
the implementation notes). With --build (a LAMMPS build of that tree with the patch applied
and its test programs, as ./run.sh setup makes build/lammps_2026), LAMMPS' granular tests and
the sub-model's cases are run first (tools/lammps_unittest.py run) and their counts reported;
without it, the section lists the commands and says they were not run. The comparison with
linear_history/static is the sub-model's page's (its section "Beside linear_history/static");
the authors, their affiliation and e-mail, and the LGPL answer are left to the submitter.
"""
from __future__ import annotations

import argparse
import platform
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parent.parent))

import lammps_patch as lp  # noqa: E402

REPO = lp.REPO
PAGE = REPO / "lammps_plugin" / "doc" / "gran_sub_mod_tangential_stick_slip.md"
FIGURE = "docs/img/stick_slip_vs_static_dynamic.png"
TITLE = "[New Feature] tangential stick_slip: stick-slip friction (Khellaf and Mansouri, 2024) for granular models"
LEFT = "_left to the submitter_"

# the new-feature form's checklist, in its order (ticked by the submitter after submitting)
CHECKLIST = (
    "the feature is complete",
    "the licensing information is complete",
    "the corresponding author's information is complete",
    "the source follows LAMMPS' formatting rules",
    "documentation is added or updated",
    "the documentation builds with LAMMPS' documentation tools",
    "the feature works with the conventional (make) build",
    "the feature works with the CMake build",
    "a package README is added or updated",
    "one or more example inputs are included",
)


def comparison():
    """The three sentences of the sub-model's page on the two laws (the last paragraph of its
    section "Beside linear_history/static"), after a line saying what was run."""
    text = PAGE.read_text()
    start = text.index("## Beside linear_history/static")
    section = text[start:text.index("\n## ", start + 3)]
    said = section.strip().split("\n\n")[-1].replace("\n", " ")
    from stickslip import scene

    c = scene.load("drag").contact
    return ("Both models on the paper's drag case (a disk dragged at constant speed over a floor), with "
            f"mu_{{t,static}} = mu_{{t,s}} = {c.mu_s:g} and mu_{{t,dynamic}} = mu_{{t,k}} = {c.mu_k:g} (the figure attached: "
            f"{FIGURE} of the sub-model's repository, made by its tools/static_dynamic_figure.py): {said} "
            "Both are wanted: linear_history/static gives a contact that breaks loose and then slides at "
            "the dynamic coefficient; stick_slip gives the stick-slip oscillation itself, the stick phases, "
            "slip events and force drops that the paper's model builds from a static and a kinetic "
            "coefficient, with the kinetic one as the mean of the saw-tooth.")


def tests_run(build):
    """The lines of the section on tests: each check and its result, or its command."""
    checks = [
        ("LAMMPS' granular tests (ctest -R ^DEM), with the sub-model's yaml cases among them", "lammps_unittest"),
        ("LAMMPS' linear_history and mindlin cases with stick_slip/total at mu_k = mu_s", "lammps_unittest"),
        ("test_pair_style on the sub-model's pair case (newton on and off, restart, data file; "
         "its single() test skipped, see the notes)", "lammps_unittest"),
    ]
    if build is None:
        lines = [f"- {what}: `tools/lammps_unittest.py run BUILD` (not run for this description)" for what, _ in checks]
    else:
        import lammps_unittest

        summary, ok = lammps_unittest.run(Path(build))
        lines = [f"- {line}" for line in summary if not line.startswith(" ")]
        lines.append(f"- all passed: {'yes' if ok else 'no'}")
    lines += [
        "- the documentation: LAMMPS' Sphinx configuration builds the changed page (html and spelling) with "
        "no warning the unchanged page lacks, and `make char_check role_check` rules (`tools/lammps_docs.py`)",
        "- the example on 1 and 4 processes prints its committed logs (default and 64-bit id builds)",
        "- this repository's tests of the sub-model (pytest): the law's one-contact contract to the ulp, the "
        "paper's drag, tilt and tray within round-off of a reference solver on 1 and 2 processes, "
        "linear_history and mindlin runs bit for bit at mu_k = mu_s, restarts, the single() values",
    ]
    return lines


def description(tree, build=None):
    """The pull request's description (markdown) for the tree LAMMPS_DIR."""
    tree = Path(tree)
    how, where = lp.layout(tree)
    registration = ("GranSubModStyle lines in the sub-model's header, which the build's style scan collects"
                    if how == "style header" else
                    "an #include and a row per keyword in src/GRANULAR/gran_sub_mod_register.cpp's table "
                    "(the header carries no GranSubModStyle line)")
    pages = ("doc/src/pair_granular.rst" if where == "one page" else
             "doc/src/pair_granular.rst (the list, single() values, restriction) and "
             "doc/src/granular_tangential_models.rst (the model's section and reference)")
    keywords = ", ".join(f"`{k}`" for k, _ in lp.style_lines(lp.HEADER.read_text()))
    notes = [
        f"- Registration, as this tree does it: {registration}.",
        f"- Documentation: {pages}, with `.. versionadded:: TBD`; the coefficients written mu_{{t,s}} and "
        "mu_{t,k} (the page's items before write mu_s for the sliding coefficient); the authors' names in "
        "false_positives.txt where the list's order puts them.",
        "- Code: the sub-model (gran_sub_mod_tangential_stick_slip.h/.cpp) and the model's core "
        "(stick_slip_core.h: the slip, the drop to Fmin and the reset of the spring, and exact slip timing, "
        "plain doubles in and out), both in LAMMPS_NS::Granular_NS. The sub-model uses "
        "GranularModel::synchronized_verlet, nx_unrotated and GranSubMod::rotate_rescale_vec directly, and "
        "rescales a force by Fscrit / |F| as linear_history does; the headers define no macro. Named "
        "constants: EPSILON (as linear_history's) and STICK_MARGIN, the relative margin below the threshold "
        "under which exact timing skips a sticking contact's start force (round-off of the bound).",
        "- The record's slip count (/record) is the number of time steps in which the contact slipped "
        "(several slips within one step of /exact count once), as the documentation says.",
        "- Correctness: with mu_k = mu_s and /total the sub-model performs linear_history's operations (with "
        "k_t NULL, mindlin's), so LAMMPS' own linear_history and mindlin cases pass with it in their place.",
        "- Citation: a CiteMe reminder of the paper, as Developer_cite.rst says for a feature that implements a "
        "published method: a file-scope string whose first line names the model and gives the DOI, then the "
        "BibTeX entry, added in the constructor when citeme is on; the example's logs show it.",
        "- single(): pair granular's single() reports the sub-model's record (/record) or the force the model "
        "would apply with no time passing. LAMMPS' pair-style tester cannot call it: its single() test builds "
        "two atoms with atom_style full (or ellipsoid), which has no radius, and pair granular refuses such an "
        "atom style; the yaml case skips it and this repository's tests check single() through "
        "compute pair/local.",
        "- Tests added: unittest/granular/dem04-stick-slip-drag-3d.yaml and its /exact twin (a sphere dragged "
        "on a floor, torques from the model's saw-tooth), unittest/force-styles/tests/"
        "atomic-pair-granular_stick_slip.yaml with its inputs in.granular_stick_slip and "
        "data.granular_stick_slip; each yaml has its date_generated.",
        "- Example: examples/granular/in.stick_slip, 320 spheres settling on a floor under a tilting gravity, "
        "with logs on 1 and 4 processes (log.4Jul26.stick_slip.g++.1, .4): the 4-process log shows the bed "
        "split over a 2 by 2 by 1 grid, and its thermo output agrees with the 1-process log to the printed digits.",
        f"- Tested on {platform.system()} {platform.machine()} with g++ and OpenMPI, 1, 2 and 4 processes, "
        "the CMake build.",
    ]
    out = [
        f"# {TITLE}", "",
        "**Summary**", "",
        f"A tangential sub-model for pair granular and the granular wall fixes, {keywords}: the stick-slip "
        "friction model of Khellaf and Mansouri (2024), a spring and a dashpot in series with a slider whose "
        "static threshold mu_{t,s} Fn is higher than the force it keeps after a slip, (2 mu_{t,k} - mu_{t,s}) Fn, "
        "so that slow sliding saw-tooths about mu_{t,k} Fn. Suffixes choose the reset of the spring (/total), "
        "exact slip timing within the step (/exact) and a per-contact record (/record). With documentation, "
        "an example and unit tests.", "",
        "**Related Issues**", "", "None.", "",
        "**Author(s)**", "", f"{LEFT}: name, affiliation and a long-lived e-mail address of the corresponding "
        "author.", "",
        "**Licensing**", "",
        "My contribution may be licensed as GPL v2 (default LAMMPS license): yes (its files are "
        "GPL-2.0-or-later)",
        f"My contribution may be licensed as LGPL (for use as a library with proprietary software): {LEFT}", "",
        "**Backward Compatibility**", "",
        "Not affected: the pull request adds files and new keywords; existing inputs give the same results.", "",
        "**Beside linear_history/static**", "",
        comparison(), "",
        "**Implementation Notes**", "", *notes, "",
        "**Tests run**", "", *tests_run(build), "",
        "## Post Submission Checklist", "",
        *[f"- [ ] {item}" for item in CHECKLIST], "",
        "## Further Information, Files, and Links", "",
        "Khellaf, A., & Mansouri, M. (2024). Development of the stick-slip friction model for discrete elements "
        "modeling. Technology Audit and Production Reserves, 4(1(78)), 17-25. "
        "doi:10.15587/2706-5448.2024.310428", "",
    ]
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tree", type=Path, help="the LAMMPS tree the patch is for (or its files that --reads names)")
    ap.add_argument("--build", type=Path, help="a build of the patched tree with its test programs: run the tests")
    ap.add_argument("-o", "--output", type=Path, help="write the description here (default: standard output)")
    a = ap.parse_args(argv)
    if not a.tree.is_dir():
        ap.error(f"{a.tree} is not a folder: give a LAMMPS tree")
    if a.build is not None and not (a.build / "build" / "test_pair_style").is_file():
        ap.error(f"--build {a.build}: no build/test_pair_style in it (a build with LAMMPS' test programs)")
    try:
        text = description(a.tree, a.build)
    except lp.Refused as e:
        print(e, file=sys.stderr)
        return 2
    if a.output:
        a.output.write_text(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
