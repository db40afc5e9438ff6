#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The patch's documentation built with LAMMPS' own tooling, against the pages it changes.

  tools/lammps_docs.py TREE PRISTINE [--venv DIR]

TREE is a LAMMPS tree with tools/lammps_patch.py's patch applied (./run.sh setup's 4 Jul 2026
tree, build/lammps_2026/source), PRISTINE the unpatched copies of the files the patch changes
(build/lammps_2026/pristine). The pages the patch changes (doc/src/pair_granular.rst, and
granular_tangential_models.rst in a tree whose tangential models have a page of their own:
tools/lammps_patch.py) are built twice, as LAMMPS has them and as the patch leaves them, by
LAMMPS' Sphinx configuration (doc/utils/sphinx-config/conf.py.in, configured as doc/Makefile
does) and its extensions, in a source folder of those pages, a Manual page whose toctree holds
them, and a titled stub for each page they link to (the whole manual, 1000 pages and
doxygen's API, is not read): the html builder and the spelling builder (`make html`, `make
spelling`) with LAMMPS' own word list (the patched false_positives.txt). Every warning and
every misspelt word of the patched pages must be one of the unpatched pages': the patch adds
none. Then LAMMPS' `make char_check` and `make role_check` rules on the patched pages: ASCII
only, roles written as LAMMPS writes them.

The Python packages are LAMMPS' doc/utils/requirements.txt from PyPI, in a virtual
environment of their own (--venv; ./run.sh setup makes build/lammps_docs/venv), with one
change: the sphinx-fortran fork LAMMPS takes from GitHub (not reachable here) is PyPI's
sphinx-fortran. The spelling builder needs libenchant-2 and an en_US dictionary (Debian's
libenchant-2-2 and hunspell-en-us).
"""
from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
VENV = REPO / "build" / "lammps_docs" / "venv"
sys.path.insert(0, str(Path(__file__).resolve().parent))

import lammps_patch  # noqa: E402


def requirements(tree):
    """LAMMPS' documentation requirements, the GitHub fork of sphinx-fortran as PyPI's."""
    lines = (tree / "doc" / "utils" / "requirements.txt").read_text().splitlines()
    return ["sphinx-fortran" if "sphinx-fortran" in x else x for x in lines if x.strip()]


def configure(tree, out):
    """doc/Makefile's conf.py rule: conf.py.in with the tree's folders."""
    doc = tree / "doc"
    text = (doc / "utils" / "sphinx-config" / "conf.py.in").read_text()
    for key, value in (("@DOXYGEN_XML_DIR@", doc / "doxygen" / "xml"), ("@LAMMPS_SOURCE_DIR@", tree / "src"),
                       ("@LAMMPS_PYTHON_DIR@", tree / "python"), ("@LAMMPS_DOC_DIR@", doc)):
        text = text.replace(key, str(value))
    config = out / "config"
    shutil.copytree(doc / "utils" / "sphinx-config", config, ignore=shutil.ignore_patterns("conf.py*"))
    (config / "conf.py").write_text(text)
    return config


def source_folder(pages, words, out):
    """The pages ({name: text}), a Manual holding them, a stub for each page they link to,
    the word list."""
    out.mkdir(parents=True)
    for name, text in pages.items():
        (out / f"{name}.rst").write_text(text)
    linked = sorted(set(re.findall(r":doc:`(?:[^`<]*<)?([^`<>]+?)>?`", "".join(pages.values()), re.S)) - set(pages))
    for name in linked:
        (out / f"{name}.rst").write_text(f"{name}\n{'=' * len(name)}\n\nA stub of the page.\n")
    toc = "\n".join(f"   {n}" for n in list(pages) + linked)
    (out / "Manual.rst").write_text(f"Manual\n======\n\n.. toctree::\n   :maxdepth: 1\n\n{toc}\n")
    (out / "false_positives.txt").write_text(words)


def build(python, config, src, builder, out, pages):
    """One sphinx-build; returns its warnings about the pages, line numbers left out (the patch
    moves them), and for the spelling builder the misspelt words."""
    log = out / f"{builder}.log"
    proc = subprocess.run([str(python), "-m", "sphinx", "-E", "-q", "-b", builder, "-c", str(config),
                           "-d", str(out / f"doctrees-{builder}"), "-w", str(log), str(src),
                           str(out / builder)], capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"lammps_docs: sphinx-build -b {builder} failed:\n{proc.stderr[-3000:]}")
    found = set()
    for line in log.read_text().splitlines():
        if any(f"{name}.rst" in line for name in pages):
            found.add(re.sub(rf"{re.escape(str(src))}/|:\d+:", "", line).strip())
    if builder == "spelling":
        for f in (out / builder).rglob("*.spelling"):
            found |= {f"misspelt: {m}" for m in re.findall(r"\((\S+)\)", f.read_text())}
    return found


def ascii_and_roles(text):
    """doc/Makefile's char_check and role_check on one page: the lines they would print."""
    bad = [f"non-ASCII: {x}" for x in text.splitlines() if re.search(r"[^ -~]", x)]
    for rule in (r" :[a-z]+`", r" `[^`]+<[a-z][^`]+`[^_]", r":(ref|doc):[^`]", r"(ref|doc)`[^`]",
                 r"^ *\.\. [a-z0-9]+:(\s+.*|)$"):
        bad += [f"role: {x}" for x in text.splitlines() if re.search(rule, x)]
    return bad


def check(tree, pristine, venv=VENV):
    """Returns (lines to print, whether the patch adds no warning and no misspelling)."""
    tree, pristine, venv = Path(tree).resolve(), Path(pristine).resolve(), Path(venv).resolve()
    python = venv / "bin" / "python"
    if not python.is_file():
        return [f"lammps_docs: {python} missing (./run.sh setup with lammps-2026 makes it)"], False
    paths = [p for p in lammps_patch.changes(pristine) if p.endswith(".rst")]
    spelling = lammps_patch.SPELLING
    texts = {name: {Path(p).stem: (top / p).read_text() for p in paths} for name, top in
             (("pristine", pristine), ("patched", tree))}
    words = {"pristine": (pristine / spelling).read_text(), "patched": (tree / spelling).read_text()}
    lines, ok = [], True
    shown = ", ".join(f"{Path(p).stem}.rst" for p in paths)
    with tempfile.TemporaryDirectory(prefix="lammps_docs-") as tmp:
        tmp = Path(tmp)
        config = configure(tree, tmp)
        found = {}
        for name in ("pristine", "patched"):
            source_folder(texts[name], words[name], tmp / name / "src")
            found[name] = {b: build(python, config, tmp / name / "src", b, tmp / name, texts[name])
                           for b in ("html", "spelling")}
        for b in ("html", "spelling"):
            new = found["patched"][b] - found["pristine"][b]
            lines.append(f"make {b} on {shown}: {len(found['patched'][b])} warnings with the patch, "
                         f"{len(found['pristine'][b])} without; new: {len(new)}")
            lines += [f"  {x}" for x in sorted(new)]
            ok &= not new
    bad = [x for text in texts["patched"].values() for x in ascii_and_roles(text)]
    lines.append(f"char_check and role_check on {shown}: {len(bad)} lines")
    lines += [f"  {x}" for x in bad]
    return lines, ok and not bad


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tree", type=Path, help="the patched LAMMPS tree")
    ap.add_argument("pristine", type=Path, nargs="?", help="the unpatched copies of the files the patch changes")
    ap.add_argument("--venv", type=Path, default=VENV, help="the virtual environment with LAMMPS' doc packages")
    ap.add_argument("--requirements", action="store_true", help="print the packages to install, and stop")
    a = ap.parse_args(argv)
    if a.requirements:
        print("\n".join(requirements(a.tree)))
        return 0
    if a.pristine is None:
        ap.error("give the unpatched copies (PRISTINE)")
    lines, ok = check(a.tree, a.pristine, a.venv)
    print("\n".join(lines))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
