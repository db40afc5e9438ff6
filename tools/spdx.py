#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The license's SPDX line in every source file, as the engines mark theirs.

    .venv/bin/python tools/spdx.py            # add it to every source file git tracks that lacks it
    .venv/bin/python tools/spdx.py FILE ...   # to these files only
    .venv/bin/python tools/spdx.py --check    # list the tracked source files without it; exit 1 if any

Source files: *.py, *.sh, *.cpp, *.h, *.cu, CMakeLists.txt, run.sh and .ci/run, but the files of
lammps_plugin/granular/ (the LAMMPS sub-model, in LAMMPS' form for LAMMPS' tree: LAMMPS' banner
states their license, as LAMMPS' contribution rules ask, and --check requires it). Where the
line goes: Python and shell, a comment after the shebang and coding lines; C, C++ and CUDA,
the first line of the top comment (after an editor's mode line; a `/*` comment's text moves
to the next line; a file that starts otherwise gets a `//` line); CMake, the first line.
"""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TAG = "SPDX-License-Identifier: GPL-2.0-or-later"
HASH_COMMENTS = (".py", ".sh")
C_LIKE = (".cpp", ".h", ".cu")
SCRIPTS = ("run.sh", ".ci/run")  # shell scripts without a suffix


def is_source(relative: str) -> bool:
    return (relative.endswith(HASH_COMMENTS + C_LIKE) or relative in SCRIPTS
            or relative.rsplit("/", 1)[-1] == "CMakeLists.txt")


def tracked_sources() -> list[str]:
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [f for f in out.splitlines() if is_source(f) and (ROOT / f).is_file()]


LAMMPS_FORM = "lammps_plugin/granular/"
LAMMPS_BANNER = "This software is distributed under\n   the GNU General Public License."


def has_tag(text: str, relative: str = "") -> bool:
    # near the top, where the engines put it (a later mention, e.g. in this file's code, does not count)
    if relative.startswith(LAMMPS_FORM):
        return LAMMPS_BANNER in "\n".join(text.splitlines()[:12])
    return any(TAG in line for line in text.splitlines()[:5])


def with_tag(relative: str, text: str) -> str:
    """The file's text with the SPDX line put in."""
    if relative.endswith(C_LIKE):
        if not text.startswith("/*"):
            return f"// {TAG}\n" + text
        first, _, rest = text.partition("\n")
        if "-*-" in first:  # an editor's mode line stays the first line
            return f"{first}\n   {TAG}\n{rest}"
        body = text[2:].lstrip(" ")
        return f"/* {TAG}" + ("" if body.startswith("\n") else "\n   ") + body
    lines = text.splitlines(keepends=True)
    at = 0  # after a shebang and a coding line (PEP 263: line 1 or 2)
    if lines and lines[0].startswith("#!"):
        at = 1
    if len(lines) > at and re.match(r"^[ \t\f]*#.*?coding[:=]", lines[at]):
        at += 1
    return "".join(lines[:at]) + f"# {TAG}\n" + "".join(lines[at:])


def main(argv: list[str]) -> int:
    if argv == ["--check"]:
        missing = [f for f in tracked_sources() if not has_tag((ROOT / f).read_text(), f)]
        print("\n".join(missing) or "every tracked source file has the SPDX line")
        return 1 if missing else 0
    files = [str(Path(f).resolve().relative_to(ROOT)) for f in argv] or tracked_sources()
    for relative in files:
        path = ROOT / relative
        text = path.read_text()
        if not has_tag(text, relative) and not relative.startswith(LAMMPS_FORM):
            path.write_text(with_tag(relative, text))
            print(f"spdx: {relative}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
