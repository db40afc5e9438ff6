# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model as LAMMPS would merge it (tools/lammps_patch.py): its files read like LAMMPS'
own; the patch applies to a clean LAMMPS 4 Jul 2026 tree and puts its passages where they
belong; the user's page (lammps_plugin/doc/) says what LAMMPS' page says; the example's
committed logs are what the example prints, on 1 and 4 processes, default and BIGBIG builds.

The tree, the builds and the clean source come from `./run.sh setup` with
STICKSLIP_SOURCE_BUILDS=lammps-2026 (BIGBIG: lammps-2026-bigbig; CI builds both); the tests
that need them skip without, and fail as root when the set-up was asked for them."""
import os
import re
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

from conftest import as_root, lammps_release_launcher
from lammps_runs import MPI_ENV
from stickslip.adapters import lammps_granular, source_build_asked

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

import lammps_patch as lp  # noqa: E402

GRANULAR = ROOT / "lammps_plugin" / "granular"
SUB_MODEL = sorted(GRANULAR.iterdir())
PAGE = ROOT / "lammps_plugin" / "doc" / "gran_sub_mod_tangential_stick_slip.md"
EXAMPLE = ROOT / "lammps_plugin" / "patch" / "examples" / "in.stick_slip"
TOP = ROOT / "build" / "lammps_2026"


def clean_source(tmp_path, paths):
    """`paths` of the clean 4 Jul 2026 tree, from Debian's source archive ./run.sh fetched."""
    lammps_release_launcher("lammps-2026")
    archive = next((TOP / "download").glob("lammps_*.orig.tar.*"))
    with tarfile.open(archive) as tar:
        for p in paths:
            member = tar.getmember(p)
            target = tmp_path / p
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(tar.extractfile(member).read())
    return tmp_path


# ------------------------------------------------------------------ LAMMPS' form


def test_the_files_read_like_lammps_own():
    """Each file: LAMMPS' banner, ASCII only, lines of at most 100 characters, code in
    LAMMPS_NS alone (no namespace of the project's), no start-up line and no header that is
    not the sub-model's; the .cpp names its contributing authors and cites the paper through
    CiteMe with its DOI."""
    for f in SUB_MODEL:
        text = f.read_text()
        assert text.isascii(), f.name
        long = [i + 1 for i, line in enumerate(text.splitlines()) if len(line) > 100]
        assert not long, (f.name, long)
        assert "LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator" in text.split("\n", 3)[1], f.name
        assert "This software is distributed under\n   the GNU General Public License." in text, f.name
        names = set(re.findall(r"\bnamespace\s+(\w+)\s*\{", text))
        assert names <= {"LAMMPS_NS", "Granular_NS"}, (f.name, names)
        includes = set(re.findall(r'#include "([^"]+)"', text))
        assert not {i for i in includes if "stickslip" in i or "version" in i}, (f.name, includes)
        assert "logmesg" not in text and "STICKSLIP" not in text, f.name
    cpp = (GRANULAR / "gran_sub_mod_tangential_stick_slip.cpp").read_text()
    assert "Contributing author" in cpp
    assert "citeme->add(cite_stick_slip)" in cpp and "10.15587/2706-5448.2024.310428" in cpp


def test_clang_format_with_lammps_style():
    """clang-format with LAMMPS' src/.clang-format (from the 4 Jul 2026 tree) changes nothing."""
    style = TOP / "source" / "src" / ".clang-format"
    if not style.is_file():
        lammps_release_launcher("lammps-2026")
        pytest.fail(f"{style} missing")
    if shutil.which("clang-format") is None:
        if as_root() and source_build_asked("lammps-2026"):
            pytest.fail("clang-format missing (./run.sh setup installs it with lammps-2026)")
        pytest.skip("clang-format missing")
    for f in SUB_MODEL:
        if f.suffix in (".h", ".cpp"):
            got = subprocess.run(["clang-format", f"--style=file:{style}", str(f)], capture_output=True, text=True)
            assert got.returncode == 0 and got.stdout == f.read_text(), f"clang-format would change {f.name}"


# ------------------------------------------------------------------ the patch


def test_the_patch_applies_to_a_clean_tree(tmp_path):
    """git apply --check and patch --dry-run on the clean tree's files it changes; applied,
    pair_granular.rst holds each passage once, the list's item 7 right after item 6, the
    sub-model's description before the section's end, the reference last, ASCII only; the
    false positives keep their order."""
    tree = clean_source(tmp_path / "lammps", lp.CHANGED)
    patch = tmp_path / "stick_slip.patch"
    patch.write_text(lp.patch(tree))
    for cmd in (["git", "apply", "--check", str(patch)], ["patch", "-p1", "--dry-run", "-s", "-i", str(patch)]):
        got = subprocess.run(cmd, cwd=tree, capture_output=True, text=True)
        assert got.returncode == 0, (cmd, got.stdout, got.stderr)
    subprocess.run(["patch", "-p1", "-s", "-i", str(patch)], cwd=tree, check=True)
    page = (tree / lp.PAGE).read_text()
    assert page.isascii()
    for name, _ in lp.ANCHORS:
        assert page.count((ROOT / "lammps_plugin" / "patch" / "doc" / name).read_text()) == 1, name
    lines = page.splitlines()
    six = next(i for i, x in enumerate(lines) if x.startswith("6. *mindlin_rescale/force*"))
    assert lines[six + 1].startswith("7. *stick_slip*")
    assert page.rstrip().endswith("https://doi.org/10.15587/2706-5448.2024.310428")
    model = page.index("For *tangential stick_slip*")
    assert page.index("The *mindlin_rescale/force* option") < model < page.index("\n----------\n", model)
    words = (tree / lp.SPELLING).read_text().splitlines()
    for w in lp.SPELLING_WORDS:
        i = words.index(w)
        assert words[i - 1].lower() <= w.lower() <= words[i + 1].lower(), w


def test_a_changed_file_that_does_not_match_is_refused(tmp_path):
    """A tree whose page has lost a place the patch needs: one line naming the page and the
    place, not a patch that would not apply."""
    (tmp_path / "doc" / "src").mkdir(parents=True)
    (tmp_path / "doc" / "utils" / "sphinx-config").mkdir(parents=True)
    (tmp_path / lp.PAGE).write_text("a page without its list\n")
    (tmp_path / lp.SPELLING).write_text("Aa\n")
    with pytest.raises(SystemExit, match="pair_granular.rst: the place of pair_granular.list.rst"):
        lp.patch(tmp_path)


# ------------------------------------------------------------------ the two pages agree


def test_the_user_page_says_what_lammps_page_says():
    """The names, the coefficients' ranges (as the C++ refuses them), the default, the DOI,
    the restrictions and the tested releases: on the user's page as on LAMMPS' page (the
    patch's passages) and in the code."""
    md = PAGE.read_text()
    rst = "".join((ROOT / "lammps_plugin" / "patch" / "doc" / n).read_text() for n, _ in lp.ANCHORS)
    header = (GRANULAR / "gran_sub_mod_tangential_stick_slip.h").read_text()
    cpp = (GRANULAR / "gran_sub_mod_tangential_stick_slip.cpp").read_text()
    names = re.findall(r"GranSubModStyle\(([^,]+),", header)
    assert len(names) == 8 and all(f"`{n}`" in md for n in names)
    assert all(f"/{o}" in rst for o in ("total", "exact", "record"))
    for rule_md, rule_rst, rule_cpp in (("μs/2 ≤ mu_k ≤ μs", r"\mu_s/2 \le \mu_k \le \mu_s", "[mu_s/2, mu_s]"),
                                        ("`mu_s` = static friction coefficient μs, > 0", r"\mu_s", "mu_s = {} is outside its allowed range: > 0"),
                                        ("≥ 0: the tangential dashpot", "x_{\\gamma,t}", "x_gamma,t = {} is outside its allowed range: >= 0"),
                                        ("stiffness (force/distance units), > 0; or `NULL`", "NULL", "> 0, or NULL")):
        assert rule_md in md and rule_rst in rst and rule_cpp in cpp, rule_md
    doi = "10.15587/2706-5448.2024.310428"
    assert doi in md and doi in rst and doi in cpp
    for restriction in ("atom_style sphere", "comm_modify vel yes", "synchronized_verlet"):
        assert restriction in md, restriction
    assert "synchronized_verlet" in rst and "allow_synchronization" in cpp
    tested = [v for v, _ in lammps_granular.RELEASES.values()]
    assert f"Tested releases: **{tested[0]}** and **{tested[1]}**." in md
    readme = (ROOT / "README.md").read_text()
    assert all(v in readme for v in tested) and "2Aug2023" not in readme + md


# ------------------------------------------------------------------ the example


def thermo(text):
    """The thermo table of a LAMMPS log or screen output: its header line to 'Loop time'."""
    start = text.index("\n   Step ")
    return text[start:text.index("\nLoop time", start)]


@pytest.mark.parametrize("build", ["build", "bigbig"])
def test_the_examples_logs_are_its_runs(tmp_path, build):
    """examples/granular/in.stick_slip on 1 and 4 processes prints the thermo table of its
    committed logs (log.4Jul26.stick_slip.g++.1 and .4), on the default build and on the
    BIGBIG one; its friction ratio stays in [2 mu_k - mu_s, mu_s] = [0.4, 0.5] after the
    loading and the slips count up."""
    lmp = lammps_release_launcher("lammps-2026")
    exe = TOP / build / "lmp" if build == "bigbig" else lmp
    if not exe.is_file():
        if as_root() and source_build_asked("lammps-2026-bigbig"):
            pytest.fail(f"{exe} missing")
        pytest.skip(f"engine missing: lammps_granular: {exe} missing (STICKSLIP_SOURCE_BUILDS=lammps-2026-bigbig)")
    for n in (1, 4):
        cmd = [str(exe), "-in", str(EXAMPLE), "-log", "none", "-echo", "screen", "-nocite"]
        if n > 1:
            cmd = ["mpirun", "-np", str(n), "--oversubscribe"] + cmd
        got = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, env=dict(os.environ, **MPI_ENV))
        assert got.returncode == 0, got.stdout[-2000:] + got.stderr[-2000:]
        log = (EXAMPLE.parent / f"log.4Jul26.stick_slip.g++.{n}").read_text()
        assert thermo(got.stdout) == thermo(log), n
    rows = [line.split() for line in thermo(log).splitlines()[2:]]
    ratio, slips = [float(r[1]) for r in rows], [float(r[2]) for r in rows]
    assert all(0.4 - 1e-12 <= r <= 0.5 + 1e-12 for r in ratio[len(ratio) // 2:]) and slips[-1] >= 5


@pytest.mark.long
def test_the_documentation_builds_without_a_new_warning():
    """tools/lammps_docs.py on the patched 4 Jul 2026 tree: LAMMPS' Sphinx configuration
    builds pair_granular.rst (html and spelling) with no warning and no misspelt word that
    the unpatched page lacks, ASCII only, roles as LAMMPS writes them (the tool's docstring)."""
    lammps_release_launcher("lammps-2026")
    sys.path.insert(0, str(ROOT / "tools"))
    import lammps_docs

    venv = lammps_docs.VENV
    if not (venv / "bin" / "python").is_file():
        pytest.fail(f"{venv} missing (./run.sh setup makes it with lammps-2026)")
    lines, ok = lammps_docs.check(TOP / "source", TOP / "pristine", venv)
    print("\n".join(lines))
    assert ok, "\n".join(lines)
