#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model stick_slip as a patch to LAMMPS' tree: everything a pull request would change.

  tools/lammps_patch.py LAMMPS_DIR [-o FILE]    the unified diff against the tree LAMMPS_DIR
  tools/lammps_patch.py LAMMPS_DIR --files      the tree's paths the patch adds or changes
  tools/lammps_patch.py --changed               the tree's paths the patch changes (not adds)
  tools/lammps_patch.py --example-logs LMP      run the example with LMP on 1 and 4 processes: its logs

LAMMPS_DIR is a clean LAMMPS tree (4 Jul 2026: Debian sid's lammps_20260704+dfsg source), or
only the files the patch changes from one (CHANGED). `git apply` or `patch -p1` in LAMMPS' top
folder applies it. What it holds (ADDED: the tree's path <- this repository's file):
- src/GRANULAR/: the sub-model's files, lammps_plugin/granular/, and the law's core,
  law_core/stick_slip_core.h, in LAMMPS' form (lammps_form: LAMMPS' banner, LAMMPS_NS);
- doc/src/pair_granular.rst: the sub-model in the tangential list, its description and
  equations, its extra single() values, its restriction and the paper's reference (the
  passages in lammps_plugin/patch/doc/, each put at a place of the page found by ANCHORS);
  doc/utils/sphinx-config/false_positives.txt: the authors' names for the spelling check;
- examples/granular/: in.stick_slip and its logs on 1 and 4 processes;
- unittest/: the sub-model's yaml cases (lammps_plugin/unittest/, tools/lammps_unittest.py).
"""
from __future__ import annotations

import argparse
import difflib
import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PLUGIN = REPO / "lammps_plugin"
PAGE = "doc/src/pair_granular.rst"
SPELLING = "doc/utils/sphinx-config/false_positives.txt"
SPELLING_WORDS = ("Khellaf", "Mansouri")
# the patch's passages of pair_granular.rst: (fragment, [regex of the line after which it
# goes | (regex of a line, regex of the first later line before which it goes)])
ANCHORS = (
    ("pair_granular.list.rst", r"^6\. \*mindlin_rescale/force\* :"),
    ("pair_granular.model.rst", (r"^The \*mindlin_rescale/force\* option", r"^----------$")),
    ("pair_granular.single.rst", r"as \*p1\*, \*p2\*, \.\.\., \*p12\*"),
    ("pair_granular.restrictions.rst", r"command so that velocities are stored by ghost atoms\.$"),
    ("pair_granular.reference.rst", None),  # at the end
)


CORE = REPO / "law_core" / "stick_slip_core.h"
BANNER = """\
/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   Copyright (2003) Sandia Corporation.  Under the terms of Contract
   DE-AC04-94AL85000 with Sandia Corporation, the U.S. Government retains
   certain rights in this software.  This software is distributed under
   the GNU General Public License.

   See the README file in the top-level LAMMPS directory.
------------------------------------------------------------------------- */

/* ----------------------------------------------------------------------
   Contributing authors: the stickslip developers
   The engine-free core of the stick-slip friction model of Khellaf and
   Mansouri (2024), equations numbered as in the paper: plain doubles in
   and out, for one contact and one step. The tangential sub-model
   stick_slip turns the spring into its tangent plane, builds the trial
   force and, in step timing, tests the slip as linear_history does (so
   that, at mu_k = mu_s, it gives that model's results bit for bit); the
   rest of the law is here.
------------------------------------------------------------------------- */
"""
# the sub-model's line that names the core's namespace in this repository (gone in LAMMPS' form)
CORE_USING = "using stickslip::StickSlipCore;"


def lammps_form(path, text):
    """A file as the patch adds it to LAMMPS' tree: the law's core with LAMMPS' banner in
    LAMMPS_NS (law_core/ keeps it engine-neutral for LIGGGHTS and YADE), the sub-model without
    the line that reaches for the core's own namespace."""
    if path == CORE:
        body = text[text.index("#ifndef STICKSLIP_STICK_SLIP_CORE_H"):]
        body = body.replace("STICKSLIP_STICK_SLIP_CORE_H", "LMP_STICK_SLIP_CORE_H")
        body = body.replace("namespace stickslip {", "namespace LAMMPS_NS {")
        return BANNER + "\n" + body.replace("}    // namespace stickslip", "}    // namespace LAMMPS_NS")
    return "".join(line for line in text.splitlines(keepends=True) if CORE_USING not in line)


def added():
    """{path in LAMMPS' tree: file of this repository} of the files the patch adds."""
    files = {f"src/GRANULAR/{f.name}": f for f in sorted((PLUGIN / "granular").iterdir())}
    files["src/GRANULAR/stick_slip_core.h"] = CORE
    files.update({f"examples/granular/{f.name}": f for f in sorted((PLUGIN / "patch" / "examples").iterdir())})
    for part in ("granular", "force-styles"):
        files.update({f"unittest/{part}/tests/{f.name}": f for f in sorted((PLUGIN / "unittest" / part).iterdir())
                      if f.suffix != ".skeleton"})
    return files


def _place(lines, anchor, name):
    """The index in `lines` where the fragment `name` goes (one match, or an error naming it)."""
    if anchor is None:
        return len(lines)
    first, before = (anchor, None) if isinstance(anchor, str) else anchor
    hits = [i for i, line in enumerate(lines) if re.search(first, line)]
    if len(hits) != 1:
        raise SystemExit(f"lammps_patch: {PAGE}: the place of {name} ({first!r}) is found {len(hits)} times, not once")
    if before is None:
        return hits[0] + 1
    for i in range(hits[0] + 1, len(lines)):
        if re.search(before, lines[i]):
            return i
    raise SystemExit(f"lammps_patch: {PAGE}: no {before!r} after {first!r} (the place of {name})")


def changed_page(text):
    """pair_granular.rst with the patch's passages, each set apart by blank lines."""
    lines = text.splitlines(keepends=True)
    places = [(_place(lines, anchor, name), name) for name, anchor in ANCHORS]
    for at, name in sorted(places, reverse=True):
        fragment = (PLUGIN / "patch" / "doc" / name).read_text()
        if name == "pair_granular.list.rst":  # (an item of the list: no blank line before it)
            block = fragment
        else:
            block = (("\n" if at and lines[at - 1].strip() else "") + fragment
                     + ("\n" if at < len(lines) and lines[at].strip() else ""))
        lines[at:at] = [block]
    return "".join(lines)


def changed_spelling(text):
    """false_positives.txt with the authors' names, in its (case-insensitive) order."""
    words = text.splitlines()
    for w in SPELLING_WORDS:
        if w not in words:
            at = next((i for i, x in enumerate(words) if x.lower() > w.lower()), len(words))
            words.insert(at, w)
    return "\n".join(words) + "\n"


CHANGED = {PAGE: changed_page, SPELLING: changed_spelling}


def _diff(path, old, new):
    """One file's part of a git-style unified diff (old None: a new file)."""
    a, b = (old or "").splitlines(keepends=True), new.splitlines(keepends=True)
    head = [f"diff --git a/{path} b/{path}\n"] + (["new file mode 100644\n"] if old is None else [])
    body = list(difflib.unified_diff(a, b, "/dev/null" if old is None else f"a/{path}", f"b/{path}"))
    if b and not b[-1].endswith("\n"):
        raise SystemExit(f"lammps_patch: {path} does not end with a newline")
    return "".join(head + body)


def patch(tree):
    """The unified diff of the patch against the LAMMPS tree `tree`."""
    parts = []
    for path, change in CHANGED.items():
        original = tree / path
        if not original.is_file():
            raise SystemExit(f"lammps_patch: {original} missing: give a clean LAMMPS tree (4 Jul 2026)")
        text = original.read_text()
        parts.append(_diff(path, text, change(text)))
    for path, source in added().items():
        if (tree / path).exists():
            raise SystemExit(f"lammps_patch: {tree / path} exists: give a clean LAMMPS tree (the patch adds it)")
        parts.append(_diff(path, None, lammps_form(source, source.read_text())))
    return "".join(parts)


EXAMPLE = PLUGIN / "patch" / "examples" / "in.stick_slip"
LOG_DATE = "4Jul26"  # the LAMMPS release the logs come from, as LAMMPS names its example logs


def example_logs(lmp):
    """examples/granular's logs of in.stick_slip, as LAMMPS ships them (log.DATE.NAME.g++.N),
    run by `lmp` on 1 and 4 processes in the example's folder."""
    import os
    import subprocess

    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for n in (1, 4):
        log = f"log.{LOG_DATE}.stick_slip.g++.{n}"
        cmd = [str(Path(lmp).resolve()), "-in", EXAMPLE.name, "-log", log, "-echo", "both", "-nocite"]
        if n > 1:
            cmd = ["mpirun", "-np", str(n), "--oversubscribe"] + cmd
        subprocess.run(cmd, cwd=EXAMPLE.parent, check=True, capture_output=True, env=env)
        print(f"wrote {(EXAMPLE.parent / log).relative_to(REPO)}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tree", type=Path, nargs="?", help="a clean LAMMPS tree (or the files of it the patch changes)")
    ap.add_argument("-o", "--output", type=Path, help="write the patch here (default: standard output)")
    ap.add_argument("--files", action="store_true", help="list the paths the patch adds or changes")
    ap.add_argument("--changed", action="store_true", help="list the paths the patch changes")
    ap.add_argument("--example-logs", type=Path, metavar="LMP", help="write the example's logs, run with LMP")
    a = ap.parse_args(argv)
    if a.example_logs:
        example_logs(a.example_logs)
        return 0
    if a.changed:
        print("\n".join(CHANGED))
        return 0
    if a.tree is None:
        ap.error("give the LAMMPS tree")
    if a.files:
        print("\n".join(list(CHANGED) + list(added())))
        return 0
    text = patch(a.tree)
    if a.output:
        a.output.write_text(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
