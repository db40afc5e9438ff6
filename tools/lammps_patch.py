#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model stick_slip as a patch to the LAMMPS tree it is given: everything a pull
request would change, written for that tree.

  tools/lammps_patch.py LAMMPS_DIR [-o FILE]   the unified diff against the tree LAMMPS_DIR
  tools/lammps_patch.py LAMMPS_DIR --layout    how that tree registers sub-models, and its pages
  tools/lammps_patch.py LAMMPS_DIR --files     the tree's paths the patch adds or changes
  tools/lammps_patch.py LAMMPS_DIR --reads     the tree's paths the patch reads: those it
                                               changes and those that show the tree's layout
  tools/lammps_patch.py --example-logs LMP     run the example with LMP on 1 and 4 processes: its logs

LAMMPS_DIR is a clean LAMMPS tree, or only its files that --reads names (a copy of them is
enough to write the patch). `git apply` or `patch -p1` in LAMMPS' top folder applies it.
The tree's layout decides what the patch writes (layout):
- registration: a build that generates the sub-models' style header from GranSubModStyle
  lines in the headers of src/GRANULAR/ (LAMMPS 4 Jul 2026), or the checked-in table
  src/GRANULAR/gran_sub_mod_register.cpp (an #include of each header, a row
  { "keyword", &creator<Class>, TANGENTIAL } for each keyword), which the patch extends;
- pages: the tangential models on doc/src/pair_granular.rst (one page), or on
  doc/src/granular_tangential_models.rst beside it (split pages).
A tree with neither of a pair stops the tool with one line naming what it looked for.
What the patch holds (the tree's path <- this repository's file):
- src/GRANULAR/: the sub-model, lammps_plugin/granular/, and the law's core,
  law_core/stick_slip_core.h, in LAMMPS' form (tools/lammps_form.py);
- the documentation: the sub-model in the tangential list, its description, its extra
  single() values, its restriction and the paper's reference (lammps_plugin/patch/doc/, each
  passage put at a place found on the page); the authors' names in the spelling check's
  word list (doc/utils/sphinx-config/false_positives.txt), each where the list's order puts it;
- examples/granular/: in.stick_slip and its logs on 1 and 4 processes;
- unittest/: the sub-model's yaml cases (lammps_plugin/unittest/, tools/lammps_unittest.py).
"""
from __future__ import annotations

import argparse
import difflib
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from lammps_form import CORE, HEADER, lammps_form, style_lines  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
PLUGIN = REPO / "lammps_plugin"
DOC = PLUGIN / "patch" / "doc"
PAGE = "doc/src/pair_granular.rst"
TANGENTIAL_PAGE = "doc/src/granular_tangential_models.rst"  # split pages
SPELLING = "doc/utils/sphinx-config/false_positives.txt"
SPELLING_WORDS = ("Khellaf", "Mansouri")
REGISTER = "src/GRANULAR/gran_sub_mod_register.cpp"  # the table of sub-models
STYLE_SOURCE = "src/GRANULAR/gran_sub_mod_tangential.h"  # GranSubModStyle lines, where the build scans them
LABEL = "stick_slip_tangential_model"  # the model's section on split pages
TABLE_ROW = re.compile(r'^(\s*)\{\s*"([^"]+)",(\s*)&creator<(\w+)>,(\s*)(\w+)\s*\},?\s*$')
TABLE_INCLUDE = re.compile(r'^#include "(gran_sub_mod\w*\.h)"$')


class Refused(SystemExit):
    """A tree the patch cannot be written for: one line saying what was looked for and where
    (the command exits 2, as for a bad argument)."""


def _stop(message):
    raise Refused(f"lammps_patch: {message}")


# ------------------------------------------------------------------ the tree's layout


def registration(tree):
    """'table' (src/GRANULAR/gran_sub_mod_register.cpp) or 'style header' (GranSubModStyle
    lines that the build collects), or a stop naming what was looked for."""
    table = tree / REGISTER
    if table.is_file():
        rows = [TABLE_ROW.match(line) for line in table.read_text().splitlines()]
        if not any(r and r[6] == "TANGENTIAL" for r in rows):
            _stop(f"{table}: no row {{ \"keyword\", &creator<Class>, TANGENTIAL }} in its table")
        return "table"
    source = tree / STYLE_SOURCE
    if source.is_file() and "GranSubModStyle(" in source.read_text():
        return "style header"
    _stop(f"{tree}: no way to register a sub-model found: looked for {REGISTER} (a table of sub-models) "
          f"and for GranSubModStyle lines in {STYLE_SOURCE} (a generated style header)")


def pages(tree):
    """'split' (granular_tangential_models.rst beside pair_granular.rst) or 'one page', or a
    stop naming what was looked for."""
    if not (tree / PAGE).is_file():
        _stop(f"{tree}: no {PAGE}: looked for it (and for {TANGENTIAL_PAGE} beside it, on split pages)")
    return "split" if (tree / TANGENTIAL_PAGE).is_file() else "one page"


def layout(tree):
    return registration(tree), pages(tree)


# ------------------------------------------------------------------ the documentation


def _fragment(name):
    return (DOC / f"{name}.rst").read_text()


def _after(pattern, name):
    """A place: the line after the one line that matches `pattern`."""
    def place(lines, page):
        hits = [i for i, line in enumerate(lines) if re.search(pattern, line)]
        if len(hits) != 1:
            _stop(f"{page}: the place of the {name} ({pattern!r}) is found {len(hits)} times, not once")
        return hits[0] + 1
    return place


def _before(first, then, name):
    """A place: before the first line matching `then` after the one line matching `first`."""
    def place(lines, page):
        start = _after(first, name)(lines, page)
        for i in range(start, len(lines)):
            if re.search(then, lines[i]):
                return i
        _stop(f"{page}: no {then!r} after {first!r} (the place of the {name})")
    return place


def _at_end(lines, page):
    return len(lines)


def _before_references(lines, page):
    """Before the page's References heading, or at its end if it has none."""
    for i in range(len(lines) - 1):
        if lines[i].strip() == "References" and re.fullmatch(r'"+\s*', lines[i + 1]):
            return i
    return len(lines)


TANGENTIAL_ITEM = re.compile(r"^(\d+)\. (.*?) : .*x_\{\\gamma,t\}")


def _item(lines, page):
    """The tangential list's item for the model, after its last item (the numbered items that
    take x_{gamma,t}), numbered one more and naming the model as the others do (*name* or a
    :ref: to its section): (place, text)."""
    hits = [(i, m) for i, line in enumerate(lines) if (m := TANGENTIAL_ITEM.match(line))]
    if not hits:
        _stop(f"{page}: no tangential list found (numbered items with x_{{gamma,t}})")
    at, last = hits[-1]
    while at + 1 < len(lines) and lines[at + 1].startswith("   ") and lines[at + 1].strip():
        at += 1  # the last item's continuation lines
    name = f":ref:`stick_slip <{LABEL}>`" if last[2].startswith(":ref:") else "*stick_slip*"
    return at + 1, f"{int(last[1]) + 1}. {name} : {_fragment('item')}"


def _section(text):
    """The model's passage as a section of the split tangential page."""
    title = "*stick_slip* tangential model"
    return f".. _{LABEL}:\n\n{title}\n{'-' * len(title)}\n\n{text}"


def passages(where):
    """{page: [(place, text)]} of the documentation for the page layout `where`."""
    single = (_after(r"as \*p1\*, \*p2\*, \.\.\., \*p12\*", "single() values"), _fragment("single"))
    restriction = (_after(r"command so that velocities are stored by ghost atoms\.$", "restriction"),
                   _fragment("restrictions"))
    if where == "one page":
        model = (_before(r"^The \*mindlin_rescale/force\* option", r"^----------$", "model's description"),
                 _fragment("model"))
        return {PAGE: [_item, model, single, restriction, (_at_end, _fragment("reference"))]}
    return {PAGE: [_item, single, restriction],
            TANGENTIAL_PAGE: [(_before_references, _section(_fragment("model"))), (_at_end, _fragment("reference"))]}


def changed_page(text, page, parts):
    """A page with the patch's passages (parts: [(place, text) or a function giving both]),
    each set apart by blank lines, a list's item without."""
    lines = text.splitlines(keepends=True)
    found = []
    for part in parts:
        if callable(part):
            at, block = part(lines, page)
            found.append((at, block))
            continue
        place, fragment = part
        at = place(lines, page)
        found.append((at, ("\n" if at and lines[at - 1].strip() else "") + fragment
                      + ("\n" if at < len(lines) and lines[at].strip() else "")))
    for at, block in sorted(found, key=lambda x: x[0], reverse=True):
        lines[at:at] = [block]
    return "".join(lines)


def spelling_place(words, word):
    """Where `word` goes in the word list: the place that leaves the most words in order
    around it, case ignored (the list is sorted so, but for a few words out of place)."""
    key = word.lower()
    before = [0]  # words before each place that sort at or below `word`
    for w in words:
        before.append(before[-1] + (w.lower() <= key))
    after_total = sum(w.lower() > key for w in words)
    best, at, above = -1, 0, 0
    for i in range(len(words) + 1):
        score = before[i] + after_total - above
        if score > best:
            best, at = score, i
        if i < len(words):
            above += words[i].lower() > key
    return at


def changed_spelling(text):
    """false_positives.txt with the authors' names, each where the list's order puts it."""
    words = text.splitlines()
    for w in SPELLING_WORDS:
        if w not in words:
            words.insert(spelling_place(words, w), w)
    return "\n".join(words) + "\n"


# ------------------------------------------------------------------ the registration table


def changed_register(text):
    """gran_sub_mod_register.cpp with the sub-model's header among its includes (in their
    alphabetical order) and a row per keyword after the table's last TANGENTIAL row, in its
    columns."""
    lines = text.splitlines(keepends=True)
    mine = HEADER.name
    includes = [(i, m[1]) for i, line in enumerate(lines) if (m := TABLE_INCLUDE.match(line.rstrip("\n")))]
    if not includes:
        _stop(f"{REGISTER}: no #include \"gran_sub_mod_....h\" to put the sub-model's header beside")
    at = next((i for i, name in includes if name > mine), includes[-1][0] + 1)
    rows = [(i, m) for i, line in enumerate(lines) if (m := TABLE_ROW.match(line.rstrip("\n")))]
    tangential = [(i, m) for i, m in rows if m[6] == "TANGENTIAL"]
    last, m = tangential[-1]
    # the table's columns, or wider where a keyword or class of ours needs it (our rows
    # aligned among themselves; the table's own rows are left as they are)
    indent, ours = m[1], style_lines(HEADER.read_text())
    keys = [f'{indent}{{ "{keyword}",' for keyword, _ in ours]
    name_col = max([lines[last].index("&creator")] + [len(k) + 1 for k in keys])
    creators = [" " * (name_col - len(k)) + f"&creator<{cls}>," for k, (_, cls) in zip(keys, ours)]
    type_col = max([lines[last].index(m[6])] + [len(k) + len(c) + 1 for k, c in zip(keys, creators)])
    new = [k + c + " " * (type_col - len(k) - len(c)) + "TANGENTIAL },\n" for k, c in zip(keys, creators)]
    if not lines[last].rstrip().endswith(","):  # the table's last row: ours end it now
        lines[last] = lines[last].rstrip()[:-1].rstrip() + " },\n"
        new[-1] = new[-1].replace("},\n", "}\n")
    lines[last + 1:last + 1] = new
    lines[at:at] = [f'#include "{mine}"\n']
    return "".join(lines)


# ------------------------------------------------------------------ the patch


def changes(tree):
    """{path in the tree: function of its text} of the files the patch changes there."""
    how, where = layout(tree)
    out = {path: (lambda text, path=path, parts=parts: changed_page(text, path, parts))
           for path, parts in passages(where).items()}
    out[SPELLING] = changed_spelling
    if how == "table":
        out[REGISTER] = changed_register
    return out


def reads(tree):
    """The tree's paths the patch reads: those it changes, and those that show its layout."""
    how, _ = layout(tree)
    return list(changes(tree)) + ([] if how == "table" else [STYLE_SOURCE])


def added():
    """{path in LAMMPS' tree: file of this repository} of the files the patch adds."""
    files = {f"src/GRANULAR/{f.name}": f for f in sorted((PLUGIN / "granular").iterdir())}
    files["src/GRANULAR/stick_slip_core.h"] = CORE
    files.update({f"examples/granular/{f.name}": f for f in sorted((PLUGIN / "patch" / "examples").iterdir())})
    for part in ("granular", "force-styles"):
        files.update({f"unittest/{part}/tests/{f.name}": f for f in sorted((PLUGIN / "unittest" / part).iterdir())
                      if f.suffix != ".skeleton"})
    return files


def _diff(path, old, new):
    """One file's part of a git-style unified diff (old None: a new file)."""
    a, b = (old or "").splitlines(keepends=True), new.splitlines(keepends=True)
    head = [f"diff --git a/{path} b/{path}\n"] + (["new file mode 100644\n"] if old is None else [])
    body = list(difflib.unified_diff(a, b, "/dev/null" if old is None else f"a/{path}", f"b/{path}"))
    if b and not b[-1].endswith("\n"):
        _stop(f"{path} does not end with a newline")
    return "".join(head + body)


def patch(tree):
    """The unified diff of the patch against the LAMMPS tree `tree`."""
    tree = Path(tree)
    how, _ = layout(tree)
    parts = []
    for path, change in changes(tree).items():
        original = tree / path
        if not original.is_file():
            _stop(f"{original} missing: give a clean LAMMPS tree")
        text = original.read_text()
        parts.append(_diff(path, text, change(text)))
    for path, source in added().items():
        if (tree / path).exists():
            _stop(f"{tree / path} exists: give a clean LAMMPS tree (the patch adds it)")
        parts.append(_diff(path, None, lammps_form(source, source.read_text(), how == "style header")))
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
        cmd = [str(Path(lmp).resolve()), "-in", EXAMPLE.name, "-log", log, "-echo", "both"]
        if n > 1:
            cmd = ["mpirun", "-np", str(n), "--oversubscribe"] + cmd
        subprocess.run(cmd, cwd=EXAMPLE.parent, check=True, capture_output=True, env=env)
        (EXAMPLE.parent / "log.cite").unlink(missing_ok=True)
        print(f"wrote {(EXAMPLE.parent / log).relative_to(REPO)}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tree", type=Path, nargs="?", help="a clean LAMMPS tree (or its files that --reads names)")
    ap.add_argument("-o", "--output", type=Path, help="write the patch here (default: standard output)")
    what = ap.add_mutually_exclusive_group()
    what.add_argument("--layout", action="store_true", help="print the tree's layout")
    what.add_argument("--files", action="store_true", help="list the paths the patch adds or changes")
    what.add_argument("--reads", action="store_true", help="list the paths the patch reads")
    what.add_argument("--example-logs", type=Path, metavar="LMP", help="write the example's logs, run with LMP")
    a = ap.parse_args(argv)
    if a.example_logs:
        example_logs(a.example_logs)
        return 0
    if a.tree is None:
        ap.error("give the LAMMPS tree")
    if not a.tree.is_dir():
        ap.error(f"{a.tree} is not a folder: give a LAMMPS tree")
    try:
        return _run(a)
    except Refused as e:
        print(e, file=sys.stderr)
        return 2


def _run(a):
    if a.layout:
        how, where = layout(a.tree)
        print(f"registration: {how}\npages: {where}")
    elif a.files or a.reads:
        print("\n".join(reads(a.tree) if a.reads else list(changes(a.tree)) + list(added())))
    else:
        text = patch(a.tree)
        if a.output:
            a.output.write_text(text)
        else:
            sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
