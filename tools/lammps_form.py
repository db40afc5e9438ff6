# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model's C++ files in LAMMPS' own form: what tools/lammps_patch.py adds to a tree.

This repository keeps one source of each file: the law's core, law_core/stick_slip_core.h,
engine-neutral (LIGGGHTS, LAMMPS 2021's styles and YADE include it too), and the sub-model,
lammps_plugin/granular/, which a user copies as it is into LAMMPS 4 Feb 2025 or 4 Jul 2026
(the sub-model asks the release it is compiled in what it has). A LAMMPS tree takes them
written for that tree alone (lammps_form):
- the core: LAMMPS' banner and a comment about LAMMPS, in LAMMPS_NS::Granular_NS, without
  the macros for inlining and branch hints (LAMMPS' own sub-models give the compiler none:
  the core's functions are plain inline members there);
- the sub-model: the members of the current GranularModel and GranSubMod used directly
  (synchronized_verlet, nx_unrotated, rotate_rescale_vec, allow_synchronization, a force
  rescaled by Fscrit / |F|, as linear_history and mindlin use them) instead of the helpers
  that ask the release; its header's GranSubModStyle lines only for a tree whose build
  generates the style header from them (with_style_lines).
Each change names the text it replaces: a source that no longer has it stops the tool with
one line, instead of a LAMMPS form that silently keeps it.
"""
from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
CORE = REPO / "law_core" / "stick_slip_core.h"
SUB_MODEL = REPO / "lammps_plugin" / "granular" / "gran_sub_mod_tangential_stick_slip.cpp"
HEADER = SUB_MODEL.with_suffix(".h")
COLUMNS = 100  # LAMMPS' src/.clang-format ColumnLimit

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
   The core of the stick-slip friction model of Khellaf and Mansouri
   (2024), equations numbered as in the paper: plain doubles in and out,
   for one contact and one step. Its host is the tangential sub-model
   stick_slip (gran_sub_mod_tangential_stick_slip.cpp), which turns the
   spring into its tangent plane, builds the trial force and, in step
   timing, tests the slip as linear_history does; the rest of the model
   is here.
------------------------------------------------------------------------- */
"""

# the sub-model's line that names the core's namespace in this repository (the core is in
# Granular_NS in LAMMPS' form, which the sub-model already uses)
CORE_USING = "using stickslip::StickSlipCore;"

# ------------------------------------------------------------------ the core

CORE_MACROS = re.compile(r"#if defined\(__GNUC__\)\n#define STICK_SLIP_ALWAYS_INLINE .*?#endif\n\n", re.S)
# (text in the core, its LAMMPS form): every one must be found
CORE_TEXT = (
    ("STICKSLIP_STICK_SLIP_CORE_H", "LMP_STICK_SLIP_CORE_H"),
    ("namespace stickslip {", "namespace LAMMPS_NS::Granular_NS {"),
    ("}    // namespace stickslip", "}    // namespace LAMMPS_NS::Granular_NS"),
    # the branch hint and the comments about it and about the functions kept out of line
    ("    // (most steps stick: the slipping code is laid out of the sticking path)\n", ""),
    ("if (STICK_SLIP_UNLIKELY(step_slips(end_slips, start_slips))) {",
     "if (step_slips(end_slips, start_slips)) {"),
    ("    // the general case, out of line on copies (an address taken here would keep the common\n"
     "    // path's vectors in memory, and values live across a call would leave the registers)\n",
     "    // the general case, a function of its own, on copies (an address taken here would keep\n"
     "    // the common path's vectors in memory)\n"),
    ("\n     Out of line: it runs only in steps that slip. */", " */"),
)
INLINING = re.compile(r"STICK_SLIP_(?:ALWAYS_INLINE|NOINLINE) ")


def _stop(message):
    raise SystemExit(f"lammps_form: {message}")


def _replace(text, pairs, name):
    for old, new in pairs:
        if old not in text:
            _stop(f"{name} has no {old.strip()!r} (its LAMMPS form replaces it)")
        text = text.replace(old, new)
    return text


TEMPLATE_LINE = re.compile(r"^ *template <[^>]*>$")


def reflow(declaration):
    """A declaration (its lines from the one that names the function, or its template line,
    to the one that closes its parameter list) on one line, or wrapped at 100 columns with
    each continuation aligned after the opening parenthesis, as LAMMPS' clang-format style
    lays it out."""
    first, *rest = declaration.split("\n")
    joined = first + "".join(" " + line.strip() for line in rest)
    if len(joined) <= COLUMNS:
        return joined
    if TEMPLATE_LINE.match(first):
        return first + "\n" + reflow("\n".join(rest))
    open_at = joined.index("(") + 1
    parts = joined[open_at:].split(", ")
    lines, line = [], joined[:open_at] + parts[0]
    for i, part in enumerate(parts[1:], 1):
        tail = "" if i == len(parts) - 1 else ","
        if len(line) + 2 + len(part) + len(tail) <= COLUMNS:
            line += ", " + part
        else:
            lines.append(line + ",")
            line = " " * open_at + part
    return "\n".join(lines + [line])


def _drop_inlining(text):
    """The core without its inlining macros, each declaration laid out again."""
    while (m := INLINING.search(text)) is not None:
        text = text[:m.start()] + text[m.end():]
        start = text.rindex("\n", 0, m.start()) + 1
        above = text.rfind("\n", 0, start - 1) + 1
        if TEMPLATE_LINE.match(text[above:start - 1]):
            start = above
        depth, i = 0, text.index("(", m.start())
        while True:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            if depth == 0:
                break
            i += 1
        end = text.index("\n", i)
        text = text[:start] + reflow(text[start:end]) + text[end:]
    return text


def core_form(text):
    """law_core/stick_slip_core.h as LAMMPS' tree takes it."""
    start = text.find("#ifndef STICKSLIP_STICK_SLIP_CORE_H")
    if start < 0:
        _stop(f"{CORE.name} has no include guard STICKSLIP_STICK_SLIP_CORE_H")
    body, macros = CORE_MACROS.subn("", text[start:])
    if macros != 1:
        _stop(f"{CORE.name}: its block of macros (#if defined(__GNUC__) ... #endif) is not found once")
    body = _drop_inlining(_replace(body, CORE_TEXT, CORE.name))
    left = sorted(set(re.findall(r"\bSTICK_SLIP_\w+", body)))
    if left:
        _stop(f"{CORE.name}: {', '.join(left)} left in its LAMMPS form")
    return BANNER + "\n" + body


# ------------------------------------------------------------------ the sub-model

# the helpers that ask the release, from their comment to the end of their namespace
RELEASE_HELPERS = re.compile(r"/\* -{70}\n   The host release\..*?\n}    // namespace\n\n", re.S)
# (text in the sub-model, its LAMMPS form): every one must be found
SUB_MODEL_TEXT = (
    ("#include <type_traits>\n#include <utility>\n", ""),
    (CORE_USING + "    // (the law's core; tools/lammps_patch.py puts it in Granular_NS)\n", ""),
    ("set_allow_synchronization(this, !exact_timing);", "allow_synchronization = !exact_timing;"),
    ("const int sync = synchronized(gm);", "const int sync = gm->synchronized_verlet == 1;"),
    ("full_step_normal(gm)", "gm->nx_unrotated"),
    ("rotate_rescale(this, ", "rotate_rescale_vec("),
    ("(rescaled as the host's stock does)", "(rescaled as linear_history does)"),
)
# step timing's drop rescaled by the release's own arithmetic: Fscrit / |F| in LAMMPS' tree
RELEASE_RATIO = re.compile(r"\[this\]\(double fmin, double mag\) \{\s*return rescale_factor\(gm, fmin, mag\);\s*\}")


def sub_model_form(text):
    """gran_sub_mod_tangential_stick_slip.cpp as LAMMPS' tree takes it."""
    text, helpers = RELEASE_HELPERS.subn("", text)
    if helpers != 1:
        _stop(f"{SUB_MODEL.name}: its helpers that ask the release (\"The host release.\") are not found once")
    text = _replace(text, SUB_MODEL_TEXT, SUB_MODEL.name)
    text, ratio = RELEASE_RATIO.subn("StickSlipCore::stock_ratio", text)
    if ratio != 1:
        _stop(f"{SUB_MODEL.name}: step timing's drop_to with rescale_factor is not found once")
    left = sorted(set(re.findall(r"\b(?:Has[A-Z]\w+|synchronized|full_step_normal|set_allow_synchronization|"
                                 r"rotate_rescale|rescale_factor|stickslip)\b(?=\s*[(<:])", text)))
    if left:
        _stop(f"{SUB_MODEL.name}: {', '.join(left)} left in its LAMMPS form")
    return text


STYLE_LINES = re.compile(r"#ifdef GRAN_SUB_MOD_CLASS\n.*?#else\n\n", re.S)


def header_form(text, with_style_lines):
    """The sub-model's header, with its GranSubModStyle lines or (a tree that registers
    sub-models in a table) without them and the #ifdef around the class."""
    if with_style_lines:
        return text
    body, n = STYLE_LINES.subn("", text)
    if n != 1 or not body.endswith("#endif\n#endif\n"):
        _stop(f"{HEADER.name}: its GranSubModStyle block (#ifdef GRAN_SUB_MOD_CLASS ... #else) is not found once")
    return body[:-len("#endif\n")]


def style_lines(text):
    """(keyword, class) of the header's GranSubModStyle lines."""
    return re.findall(r"GranSubModStyle\(([^,]+),(\w+),TANGENTIAL\);", text)


def lammps_form(path, text, with_style_lines=True):
    """A file of this repository as the patch adds it to a LAMMPS tree (others unchanged)."""
    path = Path(path)
    if path == CORE:
        return core_form(text)
    if path == SUB_MODEL:
        return sub_model_form(text)
    if path == HEADER:
        return header_form(text, with_style_lines)
    return text
