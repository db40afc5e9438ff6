# SPDX-License-Identifier: GPL-2.0-or-later
"""The documentation holds: every relative link and anchor of every *.md resolves, user pages
carry no dates, work-session talk or links outside the repository (dated measurements live in
the history sections of docs/performance.md and docs/testing.md), every page speaks
impersonally (no first person, issue numbers or notebook phrases), no tracked file names a
machine's own folders, the suite's test counts the pages state are the suite's, and
every example input the docs call runnable runs on its engine (short: a few thousand steps).

The YADE example (yade_law/example_drag.py) is run by tests/test_yade_law.py; `stickslip run`
by tests/test_cli_studies.py.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import skip_engine
from stickslip.adapters import lammps as lammps_adapter
from stickslip.adapters import liggghts as liggghts_adapter
from stickslip.adapters.lammps_family import serial_mpi_env

ROOT = Path(__file__).resolve().parent.parent
HISTORY_PAGES = ("docs/performance.md", "docs/testing.md")  # dates allowed in their "## History"


def markdown_files():
    """Every *.md of the repository that git tracks or would track (not build outputs)."""
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "*.md"], cwd=ROOT,
                         capture_output=True, text=True, check=True).stdout.split()
    return sorted(ROOT / p for p in out)


FENCE = re.compile(r"^\s*(```|~~~)")
LINK = re.compile(r"!?\[((?:[^\[\]]|\[[^\]]*\])*)\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def prose_lines(path):
    """(line number, text) of the lines outside fenced code, inline code spans blanked."""
    inside = False
    for n, line in enumerate(path.read_text().splitlines(), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        if not inside:
            yield n, re.sub(r"`[^`]*`", "``", line)


def slug(heading):
    """GitHub's anchor of a heading: its text (links as their text, no markup), lower case,
    every character that is not a letter, digit, space, '-' or '_' dropped, spaces to '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)
    return re.sub(r"[^\w\- ]", "", text.strip().lower()).replace(" ", "-")


def anchors(path):
    """The anchors of a page's headings, duplicates numbered as GitHub does (-1, -2, ...)."""
    seen, out = {}, set()
    inside = False
    for line in path.read_text().splitlines():
        if FENCE.match(line):
            inside = not inside
            continue
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m and not inside:
            s = slug(m.group(1))
            out.add(s if s not in seen else f"{s}-{seen[s]}")
            seen[s] = seen.get(s, 0) + 1
    return out


def test_slug_follows_githubs_rules():
    assert slug("Mixing, shift, table, tail correction, restart, rRESPA info") == \
        "mixing-shift-table-tail-correction-restart-rrespa-info"
    assert slug("`pair_style gran/hooke/stickslip`") == "pair_style-granhookestickslip"
    assert slug("Is it correct? [law](docs/law.md)") == "is-it-correct-law"


def test_every_relative_link_and_anchor_resolves():
    broken = []
    for page in markdown_files():
        for n, line in prose_lines(page):
            for m in LINK.finditer(line):
                target = m.group(2)
                if re.match(r"[a-z]+:", target):
                    continue  # external: refused by the next test
                path, _, anchor = target.partition("#")
                dest = (page.parent / path).resolve() if path else page
                where = f"{page.relative_to(ROOT)}:{n}: ({target})"
                if not dest.exists():
                    broken.append(f"{where} no such file")
                elif anchor and (dest.suffix != ".md" or anchor not in anchors(dest)):
                    broken.append(f"{where} no heading with anchor #{anchor}")
    assert not broken, "\n".join(broken)


DATE = re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b")
HYGIENE = [(DATE, "a date"), (re.compile(r"\b[Ss]essions?\b"), "work-session talk"),
           (re.compile(r"\.\./shared/|shared notes"), "notes outside the repository"),
           (re.compile(r"\]\(\s*<?https?:"), "a link outside the repository")]


def shown(page):
    """A page's path as the findings name it: relative to the repository's root."""
    return page.relative_to(ROOT).as_posix() if page.is_relative_to(ROOT) else str(page)


def page_lines(page):
    """(line number, text, inside its page's History section) of a page's lines."""
    history = False
    for n, line in enumerate(page.read_text().splitlines(), 1):
        history = history or (shown(page) in HISTORY_PAGES and line.startswith("## History"))
        yield n, line, history


RELEASE = re.compile(r"^## \[\d+\.\d+\.\d+\] - 20\d\d-[01]\d-[0-3]\d$")  # CHANGELOG.md's release headings


def test_user_pages_carry_no_dates_sessions_or_outside_links():
    """Dates only under '## History' of docs/performance.md and docs/testing.md and in
    CHANGELOG.md's release headings; work-session talk, notes outside the repository and
    outside links nowhere."""
    found = []
    for page in markdown_files():
        for n, line, history in page_lines(page):
            dated = history or (shown(page) == "CHANGELOG.md" and RELEASE.match(line))
            for pattern, what in HYGIENE:
                if pattern.search(line) and not (dated and what == "a date"):
                    found.append(f"{page.relative_to(ROOT)}:{n}: {what}: {line.strip()[:100]}")
    assert not found, "\n".join(found)


# --- how the pages speak ----------------------------------------------------------------------
# Every page, its History sections included, says what is true impersonally: no first person
# (a microsecond written "us" after a number is a unit; a type pair's index "I" comes with a
# "J": I..J, I ≠ J), no issue numbers of this project (another project's, "owner/repo#N", may
# be cited), no phrases of a lab notebook. History may hold dates, commit ids, the machine's
# load and the suite's or a benchmark's figures as they were measured then; nothing else is
# special there.
FIRST_PERSON = re.compile(r"\b(?:[Ww]e|[Oo]urs?|[Oo]urselves|I(?!\s*\S{0,2}\s*J\b)|[Mm]e|[Mm]y)\b"
                          r"|(?<!\d )(?<!\d)\b[Uu]s\b")
ISSUE = re.compile(r"\b[Ii]ssues? #?\d+|(?<![\w/#])#\d+\b")
NOTEBOOK = re.compile(r"\b(?:given up|gave up|not retrieved|if asked|what was asked|asked of it|(?:what )?we found|"
                      r"scratch scripts?|not committed|the issue|project's notes|gpu lent|device tool|todo|fixme|"
                      r"for now)\b", re.IGNORECASE)


def prose_without_links(page):
    """prose_lines with each link's target dropped (its text kept)."""
    for n, text in prose_lines(page):
        yield n, re.sub(r"\]\([^)]*\)", "]", text)


def voice_findings(lines):
    """What breaks the pages' voice in (line number, prose) pairs: one line per finding."""
    found = []
    for n, text in lines:
        for what, pattern in (("first person", FIRST_PERSON), ("an issue number", ISSUE),
                              ("a notebook phrase", NOTEBOOK)):
            hit = pattern.search(text)
            if hit:
                found.append(f"{n}: {what} ({hit.group(0)!r}): {text.strip()[:90]}")
    return found


def test_voice_findings_catch_each_kind():
    lines = list(enumerate(["What we found", "as our runs show", "I ran it", "issue 24 asked", "(#12)",
                            "Given up: the fall", "Not retrieved, so", "Size, if asked", "5 us a step",
                            "lammps/lammps#3022", "for I ≠ J and I..J", "The drag's saw-tooth"], 1))
    got = voice_findings([(n, re.sub(r"`[^`]*`", "``", t)) for n, t in lines])
    assert [int(f.split(":")[0]) for f in got] == [1, 1, 2, 3, 4, 5, 6, 7, 8], got


# How a result was found (what was tried and dropped, on whose machine, what a page said before)
# belongs to the History sections; a page outside them says what is true now. CHANGELOG.md
# says what each release changed, so it may say what was.
HOW_IT_WAS_FOUND = re.compile(r"\b(?:measured here|measured and left out|first study|pilots?|shared the machine|"
                              r"cause (?:was |is )?not found|the former|found here|later pairs)\b", re.IGNORECASE)


def how_it_was_found(page):
    """(line number, phrase) of the notebook's phrases outside a page's History section."""
    history_lines = {n for n, _, history in page_lines(page) if history}
    return [(n, m.group(0)) for n, text in prose_without_links(page) if n not in history_lines
            for m in HOW_IT_WAS_FOUND.finditer(text)]


def test_how_it_was_found_is_told_from_what_is_true(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("A row at 0.1 measured and left out.\nSet aside after short pilots.\nThe former gap.\n"
                    "Its cause was not found.\nThe bed stops at 21.5°.\n")
    assert [n for n, _ in how_it_was_found(page)] == [1, 2, 3, 4]


def test_pages_say_what_is_true_now():
    """No notebook of how a result was found outside the History sections (CHANGELOG apart)."""
    found = [f"{shown(page)}:{n}: {phrase!r}" for page in markdown_files() if shown(page) != "CHANGELOG.md"
             for n, phrase in how_it_was_found(page)]
    assert not found, "\n".join(found)


def test_pages_speak_impersonally():
    found = [f"{page.relative_to(ROOT)}:{f}" for page in markdown_files()
             for f in voice_findings(prose_without_links(page))]
    assert not found, "\n".join(found)


# --- absolute paths ---------------------------------------------------------------------------
# An absolute path names one machine's folders unless the operating system or an installed
# package puts it there on every machine: the FHS's /usr, /etc and /bin (an installed
# package's files, e.g. /usr/share/lammps/examples, /etc/apt/sources.list.d) and the
# kernel's /proc, /sys and /dev. Anything else (/tmp, /work, /home, /root, /opt, /mnt, ...) is
# refused in every text file git tracks or would track, code included: a temporary folder
# is $TMPDIR (a shell's `${TMPDIR:-/tmp}`) or Python's tempfile, the repository's own files
# are relative to it, and a placeholder is written /path/to/...
ABSOLUTE = re.compile(r"(?<![\w.~$}\]:/*-])(?<!\w\")/([A-Za-z_][\w.+-]*)/[\w.+-][\w.+/-]*")
SYSTEM = {"usr", "etc", "bin", "proc", "sys", "dev", "path"}


def text_files():
    """(path relative to the root, text) of every file git tracks or would track that is text:
    files with a NUL byte or not UTF-8 are left out."""
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout.splitlines()
    for rel in out:
        path = ROOT / rel
        if not path.is_file():
            continue  # (deleted in the working tree)
        data = path.read_bytes()
        if b"\0" in data:
            continue
        try:
            yield rel, data.decode()
        except UnicodeDecodeError:
            continue


def machine_paths(text):
    """(line number, path) of each absolute path of `text` outside SYSTEM."""
    return [(text.count("\n", 0, m.start()) + 1, m.group(0)) for m in ABSOLUTE.finditer(text)
            if m.group(1) not in SYSTEM]


def test_machine_paths_are_told_from_system_ones():
    assert machine_paths('--out /tmp/t\n"/work/main/x", (/root/.cache/y), cd /home/u/z') == [
        (1, "/tmp/t"), (2, "/work/main/x"), (2, "/root/.cache/y"), (2, "/home/u/z")]
    assert machine_paths("/usr/share/lammps/examples /etc/apt/x /proc/PID/stat >/dev/null #!/usr/bin/env "
                         "/path/to/build https://github.com/a/b lammps/lammps#3022 m/s/x ${TMPDIR:-/tmp}/w "
                         "'*/src/*.h' \"$top\"/download/x") == []


# How one machine lent for a while was driven (its output folder's variable, a folder of the
# bundle beside the checkout, what it carries over, its kind) is no part of a check anyone
# reruns: a command names its files (BUNDLE, JIT_CACHE, OUT=DIR), not that set-up's.
LENDING = re.compile(r"OUT=\$OUT\b|(?<![\w/])\.gpu/|\blent\b|device machine|\(carry:|\bone H100\b")


def test_no_file_carries_a_lent_machines_setup():
    this = Path(__file__).relative_to(ROOT).as_posix()  # (its own examples of what is refused)
    found = [f"{rel}:{text.count(chr(10), 0, m.start()) + 1}: {m.group(0)!r}" for rel, text in text_files()
             if rel != this for m in LENDING.finditer(text)]
    assert not found, "\n".join(found)


def test_no_file_names_a_machines_folders():
    this = Path(__file__).relative_to(ROOT).as_posix()  # (its own examples of what is refused)
    found = [f"{rel}:{n}: {path}" for rel, text in text_files() if rel != this for n, path in machine_paths(text)]
    assert not found, "\n".join(found)


# --- counts of the suite's tests --------------------------------------------------------------
# A page may state the suite's size once ("N tests: D in the default suite, S opt-in") and a
# file's count as "test_file (N)"; outside History every other "N tests" is a count nothing
# checks, and is refused. History keeps its counts as they were measured on their dates.
SUITE = re.compile(r"\b(\d+) tests: (\d+) in the default suite, (\d+) opt-in\b")
FILE_COUNT = re.compile(r"\b(test_\w+) \((\d+)\)")
ANY_COUNT = re.compile(r"\b\d+ (?:(?:default|opt-in|new) )?tests\b(?! (?:the|that|whether|if|each|every|a|an)\b)")
CENSUS = """
import json, sys, pytest
class Census:
    def pytest_collection_finish(self, session):
        self.items = [[i.nodeid.split("::")[0], "slow" in i.keywords] for i in session.items]
census = Census()
code = pytest.main(["--collect-only", "-q", "-p", "no:cacheprovider", "-p", "no:xdist", "tests"], plugins=[census])
json.dump({"code": int(code), "items": getattr(census, "items", None)}, open(sys.argv[1], "w"))
"""


def suite_census(tmp_path):
    """{test file stem: [tests, opt-in tests]} of the whole suite as pytest collects it, in a
    process of its own (~3 s): this session may have collected only a part of it."""
    out = tmp_path / "census.json"
    subprocess.run([sys.executable, "-c", CENSUS, str(out)], cwd=ROOT, capture_output=True, timeout=300)
    got = json.loads(out.read_text())
    assert got["code"] == 0 and got["items"], f"the suite's collection failed (pytest exit {got['code']})"
    files = {}
    for path, slow in got["items"]:
        n = files.setdefault(Path(path).stem, [0, 0])
        n[0], n[1] = n[0] + 1, n[1] + slow
    return files


def count_findings(pages, files):
    """Each stated count (outside History) that disagrees with `files` (suite_census), or that
    nothing checks: one line each."""
    total, optin = sum(n for n, _ in files.values()), sum(s for _, s in files.values())
    found = []
    for page in pages:
        for n, line, history in page_lines(page):
            if history:
                continue
            where = f"{shown(page)}:{n}"
            checked = []
            for m in SUITE.finditer(line):
                checked.append(m.span())
                if tuple(map(int, m.groups())) != (total, total - optin, optin):
                    found.append(f"{where}: {m.group(0)!r}, the suite: {total} tests: {total - optin} in the "
                                 f"default suite, {optin} opt-in")
            for m in FILE_COUNT.finditer(line):
                if files.get(m.group(1), [None])[0] != int(m.group(2)):
                    found.append(f"{where}: {m.group(0)!r}, the suite: {files.get(m.group(1), ['no such file'])[0]}")
            for m in ANY_COUNT.finditer(line):
                if not any(a <= m.start() < b for a, b in checked):
                    found.append(f"{where}: {m.group(0)!r}, a count of tests nothing checks")
    return found


def test_count_findings_catch_each_kind(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("10 tests: 8 in the default suite, 2 opt-in.\n| a | test_a (7), test_b (3) |\n"
                    "771 tests: 755 in the default suite, 16 opt-in.\n| b | test_b (4), test_c (1) |\n"
                    "The profile: 708 tests in the default suite.\n")
    files = {"test_a": [7, 2], "test_b": [3, 0]}
    got = [f.split(": ", 1)[1] for f in count_findings([page], files)]
    assert got == ["'771 tests: 755 in the default suite, 16 opt-in', the suite: 10 tests: 8 in the default "
                   "suite, 2 opt-in", "'test_b (4)', the suite: 3", "'test_c (1)', the suite: no such file",
                   "'708 tests', a count of tests nothing checks"], got


def test_stated_test_counts_are_the_suites(tmp_path):
    found = count_findings(markdown_files(), suite_census(tmp_path))
    assert not found, "\n".join(found)


# --- what the pages say the code accepts ------------------------------------------------------
def test_readmes_engine_list_is_the_clis():
    """The README's `--engine a|b|...` names every engine `stickslip run` takes."""
    from stickslip.adapters import ENGINES, OPTIONAL_ENGINES

    listed = re.findall(r"--engine ((?:[a-z_]+\|)+[a-z_]+)", (ROOT / "README.md").read_text())
    assert listed and all(sorted(x.split("|")) == sorted(ENGINES + OPTIONAL_ENGINES) for x in listed), listed


def test_mu_s_range_is_the_codes_on_every_page():
    """μs: > 0 where pyref's checker (every Python engine and LIGGGHTS) refuses 0, and LAMMPS'
    stock range 0 <= xmu <= hi where its pair style checks that; the README's table says both,
    the pair style's page says LAMMPS'."""
    from pyref.laws import check_parameters

    with pytest.raises(ValueError, match="mu_s = 0: must be > 0"):
        check_parameters(mu_s=0.0)
    cpp = (ROOT / "lammps_plugin/pair_gran_hooke_stickslip.cpp").read_text()
    hi = re.search(r'"xmu \(mu_s\)", xmu, xmu >= 0\.0 && xmu <= ([\d.]+),', cpp).group(1)
    hi = f"{float(hi):g}"
    row = next(ln for ln in (ROOT / "README.md").read_text().splitlines() if ln.startswith("| μs |"))
    allowed = row.split("|")[4]
    assert "> 0" in allowed and "LAMMPS" in allowed and f"0–{hi}" in allowed, row
    page = (ROOT / "lammps_plugin/doc/pair_gran_hooke_stickslip.md").read_text()
    assert f"0 ≤ xmu ≤ {hi}" in page and f"`mu_s V` (0 ≤ V ≤ {hi})" in page


# --- the example inputs ---------------------------------------------------------------------

MPI_SINGLETON = {"OMP_NUM_THREADS": "1"}  # (and serial_mpi_env: one process, no MPI daemon)
SHORT = "2000"  # steps of a long example in the test: the input, its set-up and a first stretch


def run_example(exe, script, tmp_path, *args):
    """Run an example input from a copy in tmp_path (its outputs land there); returns stdout."""
    shutil.copy(script, tmp_path / script.name)
    proc = subprocess.run([str(exe), "-in", script.name, "-log", "none", *args], cwd=tmp_path,
                          capture_output=True, text=True, errors="replace", timeout=120,
                          env=dict(os.environ, **MPI_SINGLETON, **serial_mpi_env(tmp_path)))
    assert proc.returncode == 0 and "ERROR" not in proc.stdout, f"{script.name}:\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}"
    return proc.stdout


def mean_ratio(stdout):
    """The drag examples' last lines: the mean |F_s|/Fn over steps 1001-2500 and the slips."""
    mean = float(re.search(r"mean friction ratio .*?: ([0-9.]+)", stdout).group(1))
    slips = int(float(re.search(r"slips: ([0-9.]+)", stdout).group(1)))
    return mean, slips


# Mean over steps 1001-2500 of the drag's saw-tooth: mu_k + nu_s V/(2 Fn) = 0.4505 over whole
# periods; the window cuts a period of ~166 steps in 9, so it moves by at most
# (mu_s - mu_k)/9 ~ 0.006. The slips: the first at step ~830, then one every ~166 steps: 11.
DRAG_MEAN, DRAG_TOL, DRAG_SLIPS = 0.4505, 0.006, 11

LIGGGHTS_EXAMPLES = {"in.drag2d": (), "in.pour3d": ("-var", "steps", SHORT)}
LAMMPS_EXAMPLES = {"in.drag2d": (), "in.pour3d": ("-var", "steps", SHORT), "in.region_wall": ("-var", "steps", SHORT)}
# (the granular model's examples, lammps_plugin/examples/in.granular_*, run on LAMMPS 2025)
LAMMPS_2025_EXAMPLES = {"in.granular_drag2d": (), "in.granular_pour3d": ("-var", "steps", SHORT)}


def test_every_example_input_is_run_here():
    """A new example in an examples/ folder must be added to the lists above (and so be run)."""
    for folder, listed in (("liggghts_plugin/examples", LIGGGHTS_EXAMPLES),
                           ("lammps_plugin/examples", {**LAMMPS_EXAMPLES, **LAMMPS_2025_EXAMPLES})):
        assert sorted(p.name for p in (ROOT / folder).glob("in.*")) == sorted(listed), folder


@pytest.mark.parametrize("name", sorted(LIGGGHTS_EXAMPLES))
def test_liggghts_example_runs(tmp_path, name):
    skip_engine("liggghts")
    out = run_example(liggghts_adapter.LAUNCHER, ROOT / "liggghts_plugin/examples" / name, tmp_path,
                      "-echo", "none", *LIGGGHTS_EXAMPLES[name])
    if name == "in.drag2d":
        mean, slips = mean_ratio(out)
        assert abs(mean - DRAG_MEAN) <= DRAG_TOL and slips == DRAG_SLIPS, (mean, slips)
    else:
        assert "settled: mean coordination" in out


@pytest.mark.parametrize("name", sorted(LAMMPS_EXAMPLES))
def test_lammps_example_runs(tmp_path, name):
    skip_engine("lammps")
    out = run_example(lammps_adapter.LAUNCHER, ROOT / "lammps_plugin/examples" / name, tmp_path,
                      "-echo", "none", "-nocite", *LAMMPS_EXAMPLES[name])
    if name == "in.drag2d":
        mean, slips = mean_ratio(out)
        assert abs(mean - DRAG_MEAN) <= DRAG_TOL and slips == DRAG_SLIPS, (mean, slips)
    else:
        assert f"after {SHORT} steps" in out


@pytest.mark.parametrize("name", sorted(LAMMPS_2025_EXAMPLES))
def test_lammps_2025_example_runs(tmp_path, name):
    """The granular model's examples on the LAMMPS built with the sub-model: the drag's
    saw-tooth as the legacy styles' example gives it, the pour's short run to its end."""
    from stickslip.adapters import lammps_granular

    skip_engine("lammps_granular")
    out = run_example(lammps_granular.LAUNCHER, ROOT / "lammps_plugin/examples" / name, tmp_path,
                      "-echo", "none", "-nocite", *LAMMPS_2025_EXAMPLES[name])
    if name == "in.granular_drag2d":
        mean, slips = mean_ratio(out)
        assert abs(mean - DRAG_MEAN) <= DRAG_TOL and slips == DRAG_SLIPS, (mean, slips)
    else:
        assert f"after {SHORT} steps" in out


# --- DEM-Engine's example ---------------------------------------------------------------------
# deme_model/example_drag.py needs an NVIDIA GPU. Without one, what can run here does: its
# set-up, against a stand-in `deme` that records every call, is call for call the set-up of
# `stickslip run drag --engine deme` (the run the GPU check measured within its bounds,
# deme_model/README.md), and its reading of the engine's record, fed pyref's drag, prints the
# figures the LIGGGHTS and LAMMPS drags print. With a GPU it runs whole.
DEME_EXAMPLE = ROOT / "deme_model" / "example_drag.py"


def deme_example():
    import importlib.util

    spec = importlib.util.spec_from_file_location("deme_example_drag", DEME_EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def plain(x):
    """A call's arguments with the stand-in's objects (each call's own) as their type's name."""
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    return x if isinstance(x, (str, int, float, bool, dict, type(None))) else type(x).__name__


def test_deme_example_sets_up_the_drag_as_the_adapter_does():
    from deme_standin import FakeDeme

    from stickslip import scene as scene_mod
    from stickslip.adapters import deme as adapter

    example, run = FakeDeme(), FakeDeme()
    deme_example().build(example)
    adapter.build(scene_mod.load("drag"), run)
    assert len(example.log) > 20 and plain(example.log) == plain(run.log)


def drag_as_the_examples_print_it(capsys):
    """(the printed mean friction ratio, its text, the slips, the slip period in steps) of the
    drag example, read by DEM-Engine's example from pyref's drag (the LIGGGHTS and LAMMPS
    examples print the same figures: their tests above)."""
    from conftest import paper_case
    from deme_standin import FakeDeme

    sc, df = paper_case("drag")
    c = "grain-floor"
    slips = df[f"{c}_slip"].cumsum()
    values = {"ss_rec_fn": df[f"{c}_fn"], "ss_rec_fx": df[f"{c}_ftx"], "ss_rec_fy": df[f"{c}_fty"], "ss_rec_slips": slips}

    def record(family, name, step):  # the grain's record after `step` steps: pyref's row `step`
        return float(values[name].iat[step]) if name in values else 0.0
    deme_example().main(FakeDeme(record=record))
    out = capsys.readouterr().out
    mean, count = mean_ratio(out)
    slip_steps = (df.t[df[f"{c}_slip"] > 0] / sc.dt).round().to_numpy()
    period = float(np.mean(np.diff(slip_steps)))
    return mean, re.search(r"mean friction ratio .*?: ([0-9.]+)", out).group(1), count, period


def test_deme_example_reads_the_drag_from_the_record(capsys):
    mean, _, count, _ = drag_as_the_examples_print_it(capsys)
    assert abs(mean - DRAG_MEAN) <= DRAG_TOL and count == DRAG_SLIPS, (mean, count)


# A figure of the drag example stated on a page: the mean friction ratio over steps 1001-2500
# (on a line naming the window or the mean friction ratio) and the slip period in steps.
DRAG_PAGE_MEAN = re.compile(r"(?:1001-2500|mean friction ratio)\D*?(0\.45\d*)(\.\.\.)?")
DRAG_PAGE_PERIOD = re.compile(r"period of ~(\d+) steps")


def drag_findings(pages, shown_mean, period):
    """Each page's drag figure that is not what the examples print: a mean friction ratio that
    is not the printed one to the digits stated ("0.4502..." a prefix of it), a slip period
    that is not the measured one to the step."""
    found = []
    for page in pages:
        for n, line in enumerate(page.read_text().splitlines(), 1):
            for m in DRAG_PAGE_MEAN.finditer(line):
                stated, cut = m.group(1), m.group(2)
                digits = len(stated.split(".")[1])
                ok = (shown_mean.startswith(stated) if cut else
                      digits <= len(shown_mean.split(".")[1]) and round(float(shown_mean), digits) == float(stated))
                if not ok:
                    found.append(f"{shown(page)}:{n}: mean {stated}{cut or ''}, the examples print {shown_mean}")
            for m in DRAG_PAGE_PERIOD.finditer(line):
                if int(m.group(1)) != round(period):
                    found.append(f"{shown(page)}:{n}: period ~{m.group(1)} steps, measured {period:.1f}")
    return found


def test_drag_findings_catch_each_kind(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("over steps 1001-2500: 0.45025 (paper)\nthe mean friction ratio, 0.450\n"
                    "over steps 1001-2500 (0.4505: the dashpot)\n1001-2500: 0.4502... (paper)\n"
                    "1001-2500: 0.4503... (paper)\na period of ~166 steps\na period of ~165 steps\n")
    got = [f.split(": ", 1)[1] for f in drag_findings([page], "0.45025", 166.2)]
    assert got == ["mean 0.4505, the examples print 0.45025", "mean 0.4503..., the examples print 0.45025",
                   "period ~165 steps, measured 166.2"], got


def test_every_page_states_the_drag_as_the_examples_print_it(capsys):
    """The drag example's mean friction ratio and slip period, wherever a page states them, are
    the figures the examples print (the printed mean: pyref's drag read as the examples read
    it, to the five decimals the LAMMPS and DEM-Engine examples print; LIGGGHTS prints more)."""
    mean, text, _, period = drag_as_the_examples_print_it(capsys)
    found = drag_findings(markdown_files(), text, period)
    assert not found, "\n".join(found)


def test_deme_example_runs_on_a_gpu(tmp_path):
    from stickslip.adapters import deme as adapter

    why = adapter.available()
    if why:
        pytest.skip(f"DEM-Engine cannot run here ({why}): the example's set-up and reading are tested above")
    proc = subprocess.run([sys.executable, str(DEME_EXAMPLE)], cwd=tmp_path, capture_output=True, text=True,
                          timeout=1800)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    mean, count = mean_ratio(proc.stdout)
    assert abs(mean - DRAG_MEAN) <= DRAG_TOL and count == DRAG_SLIPS, (mean, count)


CONSOLE = re.compile(r"```console\n\$ \.venv/bin/(stickslip calibrate[^\n]*)\n(.*?)```", re.S)


def calibrate_examples():
    """(page, command, the output the page shows) for every `stickslip calibrate` console block."""
    found = [(p.relative_to(ROOT).as_posix(), m.group(1), m.group(2))
             for p in markdown_files() for m in CONSOLE.finditer(p.read_text())]
    return [pytest.param(*f, id=f"{f[0]}-{i}") for i, f in enumerate(found)]


@pytest.mark.parametrize("page,command,shown", calibrate_examples())
def test_calibrate_examples_print_what_the_page_shows(page, command, shown):
    """calibrate's examples answer from the committed map: a map, an interpolation or a
    message changed without its page would leave the page showing another answer."""
    script = Path(sys.executable).parent / "stickslip"
    proc = subprocess.run([str(script), *command.split()[1:]], cwd=ROOT, capture_output=True, text=True)
    assert proc.stdout + proc.stderr == shown, page


# --- figures stated on more than one page --------------------------------------------------------
# A figure measured once and copied: each copy is checked against the table it comes from.

def table_rows(text, header):
    """The rows (lists of cells) of the markdown table whose header row starts with `header`."""
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith(header))
    rows = []
    for ln in lines[start + 2:]:
        if not ln.startswith("|"):
            break
        rows.append([c.strip() for c in ln.strip().strip("|").split("|")])
    return rows


def section(text, heading):
    """The text of a page's section, from its heading to the next heading of its level."""
    level = heading.split(" ")[0]
    part = text.split(heading + "\n", 1)[1]
    return re.split(rf"^{level} ", part, flags=re.M)[0]


def cost_findings(readme, performance):
    """Each figure of the README's cost table (its step and exact timing cells: "0.98×",
    "0.98–1.03×", "7× slower") that is no rounding of a figure in the same column of
    performance.md's current figures for an engine of the same name (its first word)."""
    current = table_rows(section(performance, "## Current figures"), "| engine | benchmark |")
    found = []
    for row in table_rows(section(readme, "## What it costs"), "| engine | against |"):
        engine = row[0].split()[0]
        for column, cell in ((2, row[2]), (3, row[3])):
            known = [float(x) for r in current if r[0].split()[0] == engine
                     for x in re.findall(r"\d+(?:\.\d+)?", r[column + 1])]
            for x in re.findall(r"(\d+(?:\.\d+)?)(?=×|–)", cell):
                digits = len(x.split(".")[1]) if "." in x else 0
                if not any(round(y, digits) == float(x) for y in known):
                    found.append(f"README's {engine} {x}×: not in performance.md's current figures ({known})")
    return found


def test_cost_findings_catch_a_figure_that_is_not_the_measured_one():
    performance = ("## Current figures\n\n| engine | benchmark | against | step timing | exact timing |\n|---|---|---|---|---|\n"
                   "| YADE 2023 | x | y | 3.4× (3.38-3.54) | 3.4× |\n")
    readme = "## What it costs\n\n| engine | against | step | exact |\n|---|---|---|---|\n| YADE | y | {} | 3.4× |\n"
    assert cost_findings(readme.format("3.5×"), performance) == [] and len(cost_findings(readme.format("3.3×"),
                                                                                        performance)) == 1


def test_the_readmes_costs_are_the_current_figures():
    found = cost_findings((ROOT / "README.md").read_text(), (ROOT / "docs/performance.md").read_text())
    assert not found, "\n".join(found)


def test_yades_current_range_is_its_rows_over_both_runs():
    """performance.md's current YADE cells give each law's time ratio as the range over the
    History's two runs of the same law and timing (and the compiled law's instructions as
    counted there), not over other rows."""
    performance = (ROOT / "docs/performance.md").read_text()
    history = table_rows(section(performance, "### YADE"), "| law, timing |")
    first = lambda cell: float(re.match(r"\d+\.\d+", cell).group(0))
    runs = {r[0]: sorted((first(r[2]), first(r[3]))) for r in history}
    current = [r for r in table_rows(section(performance, "## Current figures"), "| engine | benchmark |")
               if r[0].startswith("YADE")]
    assert [r[0] for r in current] == ["YADE 2023.02a, the compiled law", "YADE 2023.02a, the Python law"]
    for row, law in zip(current, ("the compiled law", "the Python law")):
        for cell, timing in ((row[3], "step timing"), (row[4], "exact timing")):
            lo, hi = runs[f"{law}, {timing}"]
            assert f"time {lo:.3f}-{hi:.3f} in two runs" in cell, (cell, law, timing, lo, hi)
    for cell, timing in ((current[0][3], "step timing"), (current[0][4], "exact timing")):
        counted = next(r[4] for r in history if r[0] == f"the compiled law, {timing}")
        assert f"instructions {counted.split()[-1]}" in cell, (cell, counted)


def test_history_calls_no_figure_current():
    """A dated measurement stays what it was on its day: only "Current figures" says what holds now."""
    found = [f"{page}:{n}: {line.strip()[:80]}" for page in HISTORY_PAGES
             for n, line, history in page_lines(ROOT / page) if history and re.search(r"current figure", line, re.I)]
    assert not found, "\n".join(found)


# --- docs/granular-3d.md against the study's data -------------------------------------------------
GRANULAR_3D = ROOT / "docs" / "granular-3d.md"
STUDY = ROOT / "docs" / "granular-3d"


def plateau_mu(points):
    """The least of stock history's mu (LIGGGHTS' map, no rolling resistance) from which no
    angle (theta_start, theta_stop, theta_heap) differs from its value at any higher mu by two
    combined standard errors or more: where the angles stop moving with friction."""
    import pandas as pd

    h = points[(points.engine == "liggghts") & (points.group == "sweep") & (points.mu_s == points.mu_k)
               & (points["rolling"] == 0)]
    mus = sorted(h.mu_s.unique())
    moving = []
    for target, kind in (("theta_start", "incline"), ("theta_stop", "incline"), ("theta_heap", "heap")):
        g = h[h.kind == kind].set_index("mu_s")
        for i, a in enumerate(mus):
            for b in mus[i + 1:]:
                z = (g.loc[b, f"{target}_mean"] - g.loc[a, f"{target}_mean"]) / pd.Series(
                    [g.loc[a, f"{target}_se"], g.loc[b, f"{target}_se"]]).pow(2).sum() ** 0.5
                if abs(z) >= 2:
                    moving.append(a)
    return min(m for m in mus if all(m > x for x in moving))


PLATEAU = re.compile(r"stop moving\s+with\s+friction\s+from\s+μs?\s*=\s*(\d\.\d+)")
LOOSE_PLATEAU = re.compile(r"hardly move|moves? much with|levell?ing off above|μs? ≈ \d\.\d+ (?:the|no) ")


def plateau_findings(pages, mu):
    """Each statement of where the 3D angles stop moving with friction that is not `mu`, or
    that is not said the one way a test can check."""
    found = []
    for page in pages:
        text = " ".join(t for _, t in prose_lines(page))
        found += [f"{shown(page)}: 'from μ = {m.group(1)}', the data: {mu}" for m in PLATEAU.finditer(text)
                  if float(m.group(1)) != mu]
        found += [f"{shown(page)}: {m.group(0)!r}: say 'stop moving with friction from μ = {mu} on'"
                  for m in LOOSE_PLATEAU.finditer(text)]
    return found


def test_plateau_findings_catch_each_kind(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("the angles stop moving with\nfriction from μ = 0.65 on; they stop moving with friction from "
                    "μs = 0.5 on\nabove μs ≈ 0.6 the angles hardly move\n")
    assert [f.split(": ", 1)[1] for f in plateau_findings([page], 0.65)] == [
        "'from μ = 0.5', the data: 0.65", "'μs ≈ 0.6 the ': say 'stop moving with friction from μ = 0.65 on'",
        "'hardly move': say 'stop moving with friction from μ = 0.65 on'"]


def test_the_3d_pages_say_where_the_angles_stop_moving_as_the_map_measured_it():
    import pandas as pd

    mu = plateau_mu(pd.read_csv(STUDY / "points.csv", dtype={"nu_s": str}))
    pages = [ROOT / "README.md", GRANULAR_3D]
    assert sum(len(PLATEAU.findall(" ".join(t for _, t in prose_lines(p)))) for p in pages) >= 2
    found = plateau_findings(pages, mu)
    assert not found, "\n".join(found)


def test_the_studys_size_is_its_runs():
    """The cost table of docs/granular-3d.md: each group's runs and CPU hours (the runs' wall
    times summed, to 0.1) are runs.csv's, and so is the total the page states."""
    import pandas as pd

    runs = pd.read_csv(STUDY / "runs.csv")
    by_group = runs.groupby("group").agg(runs=("label", "size"), hours=("wall_time_s", lambda s: s.sum() / 3600))
    rows = table_rows(GRANULAR_3D.read_text(), "| group | what | runs | CPU hours |")
    stated = {r[0].strip("`"): (int(r[2]), float(r[3])) for r in rows}
    assert stated.pop("all") == (len(runs), round(runs.wall_time_s.sum() / 3600, 1))
    assert stated == {g: (int(r.runs), round(r.hours, 1)) for g, r in by_group.iterrows()}
    assert f"The study is {len(runs)} runs, {runs.wall_time_s.sum() / 3600:.1f} CPU hours" in GRANULAR_3D.read_text()


def test_the_pages_sphere_counts_are_the_scenes():
    """Every "N spheres" on docs/granular-3d.md is a count of the study's scenes (grains that
    move, fixed ones, the lid's, all of them; the 20 d bed twice the 10 d one's), and the
    scene descriptions name each scene's own."""
    from stickslip import scene as scene_mod
    from stickslip.studies import granular3d, granular3d_tables

    counts = {}
    for name in ("incline3d", "heap3d", "shear3d"):
        sc = scene_mod.load(name)
        counts[name] = {"moving": len(sc.moving_grains()), "fixed": sum(g.fixed for g in sc.grains) - len(
            sc.lid_grains()), "lid": len(sc.lid_grains()), "all": len(sc.grains)}
    deep = counts["incline3d"]["moving"] * granular3d.DEEP_LAYERS // granular3d_tables.SCENE_LAYERS
    allowed = {n for c in counts.values() for n in c.values()} | {deep}
    text = " ".join(t for _, t in prose_lines(GRANULAR_3D))
    stated = [int(n.replace(" ", "")) for n in re.findall(r"(?<![\d.])(\d[\d ]*\d|\d) spheres\b", text)]
    assert stated and not [n for n in stated if n not in allowed], (stated, allowed)
    for pattern, want in ((r"rough base of (\d+) fixed spheres", counts["incline3d"]["fixed"]),
                          (r"a bed of (\d+) spheres", counts["incline3d"]["moving"]),
                          (r"\((\d+) spheres with the base", counts["incline3d"]["all"]),
                          (r"\((\d+) fixed spheres, the incline's base\)", counts["heap3d"]["fixed"]),
                          (r"of (\d+) spheres \(19 × 5 × 10", counts["heap3d"]["moving"]),
                          (r"a heap \((\d+) spheres", counts["heap3d"]["all"]),
                          (r"a layer of (\d+) spheres", counts["shear3d"]["moving"]),
                          (r"slab like the base \((\d+)\s+spheres", counts["shear3d"]["lid"]),
                          (r"(\d+) spheres in all\)", counts["shear3d"]["all"])):
        got = re.findall(pattern, text)
        assert got and all(int(g) == want for g in got), (pattern, got, want)


# --- the README's quick start against the engine pages --------------------------------------------
LIGGGHTS_SETTINGS = ("absolute_damping", "limitForce", "slip_reset_total", "exact_slip_timing", "stick_slip_record",
                     "history_rotation", "history_on_separation", "tangential_damping")


def liggghts_lines(text):
    """{"pair_style gran" | "fix wall/gran": contact settings} of the first such line of a text's
    code blocks (continued lines joined) with a contact model: the keyword-value pairs of
    LIGGGHTS_SETTINGS it gives."""
    blocks = re.findall(r"```[^\n]*\n(.*?)```", text, re.S)
    out = {}
    for line in "\n".join(blocks).replace("&\n", " ").splitlines():
        words = line.split()
        pair, wall = words[:2] == ["pair_style", "gran"], words[:1] == ["fix"] and "wall/gran" in words[:4]
        if (pair or wall) and "model" in words:
            settings = {w: words[i + 1] for i, w in enumerate(words[:-1]) if w in LIGGGHTS_SETTINGS}
            out.setdefault("pair_style gran" if pair else "fix wall/gran", settings)
    return out


def test_liggghts_lines_are_told_apart():
    text = ("```\npair_style gran model hooke/stiffness tangential stick_slip absolute_damping on limitForce on\n"
            "fix floor all wall/gran model hooke/stiffness tangential stick_slip primitive type 1 zplane 0.0 &\n"
            "    store_force yes absolute_damping on\n```\n")
    assert liggghts_lines(text) == {"pair_style gran": {"absolute_damping": "on", "limitForce": "on"},
                                    "fix wall/gran": {"absolute_damping": "on"}}


def test_the_readmes_liggghts_lines_use_the_settings_of_its_page():
    """The README's LIGGGHTS quick start (its pair style and its wall) takes the contact
    settings of the LIGGGHTS page's first examples of each: a setting left out would give
    another force (limitForce: no tensile normal force)."""
    readme = (ROOT / "README.md").read_text()
    quick = readme.split("**LIGGGHTS.**", 1)[1].split("**LAMMPS", 1)[0]
    page = (ROOT / "liggghts_plugin/doc/tangential_model_stick_slip.md").read_text()
    page = section(page, "## Examples")
    got, want = liggghts_lines(quick), liggghts_lines(page)
    assert set(got) == {"pair_style gran", "fix wall/gran"} and {k: want[k] for k in got} == got, (got, want)


README_LINES = 250  # a front page: what a user needs on its first screens, the rest on the engine pages


def test_the_readme_is_a_front_page():
    assert len((ROOT / "README.md").read_text().splitlines()) <= README_LINES


COVERAGE_TARGETS = {"theta_start+theta_stop": "θ_start, θ_stop", "theta_start+theta_stop+theta_heap": "with θ_heap",
                    "theta_start+theta_stop+shear_peak+shear_steady+shear_dilation": "with the sheared layer"}


def coverage_rows(summary):
    """docs/granular-3d.md's round-trip table as coverage_summary.csv makes it: per set of
    targets, each range's holds cut / not cut, as stated and widened, the joint region's and
    the answers on an edge."""
    widened = summary.widening.max()
    rows = []
    for targets, g in summary.groupby("targets", sort=False):
        g = g.set_index(["widening", "statement", "ranges"])

        def held(w, what):
            cut, uncut = g.loc[(w, what, "cut")], g.loc[(w, what, "uncut")]
            return f"{cut.held} of {cut.pairs} / {uncut.held} of {uncut.pairs}"
        j = g.loc[(1.0, "joint region", "all")]
        rows.append(f"| {COVERAGE_TARGETS[targets]} | {held(1.0, 'mu_s range')} | {held(widened, 'mu_s range')} | "
                    f"{held(1.0, 'mu_k range')} | {held(widened, 'mu_k range')} | {j.held} of {j.pairs} "
                    f"({j.z:+.1f}) | {j.answers_on_map_edge}, {j.answers_on_law_bound} |".replace("-", "−"))
    return rows


def test_the_round_trips_table_is_its_csv():
    """The coverage table of docs/granular-3d.md, and the widening its header and text state,
    are coverage_summary.csv's."""
    import pandas as pd

    summary = pd.read_csv(STUDY / "coverage_summary.csv")
    page = GRANULAR_3D.read_text()
    missing = [r for r in coverage_rows(summary) if r not in page]
    assert not missing, "\n".join(missing)
    f = f"{summary.widening.max():.2f}"
    assert f"widened by {f} |" in page and f"f = {f}" in page


def test_the_last_profile_is_the_historys_newest():
    """docs/testing.md's "last profile" of the suite's CPU time is the newest one its History
    dates (History's entries are newest first): a newer profile added to History without the
    paragraph, or the paragraph kept from an older one, would tell two figures apart."""
    page = (ROOT / "docs/testing.md").read_text()
    stated = re.search(r"\*\*The last profile\*\*.*?the default\s+suite in ([\d.]+) CPU s", page, re.S)
    profiles = re.findall(r"STICKSLIP_TEST_CPU`?\)?:?\s*([\d.]+) CPU s|([\d.]+) CPU s\s+\(`STICKSLIP_TEST_CPU`\)",
                          section(page, "### The suite's run time"))
    newest = next(a or b for a, b in profiles)
    assert stated and round(float(stated.group(1))) == round(float(newest)), (stated and stated.group(1), newest)


# --- "above" and "below" -----------------------------------------------------------------------
# A page that sends the reader to another of its sections says which way: "the round trip
# above", "the core's 21 (below)", "[below](#the-scenes-and-why)". Where the words before
# "above"/"below" name a heading of the page (its last word of four letters or more, not one of
# GENERIC), or a link names the heading's anchor, that heading must lie that way.
DIRECTED = re.compile(r"\b((?:[\w'’-]+\s+){0,3}?[\w'’-]+)\s+\(?(above|below)\b")
DIRECTED_LINK = re.compile(r"\[(above|below)\]\(#([^)\s]+)\)")
GENERIC = {"that", "this", "with", "from", "each", "than", "what", "when", "where", "which", "there", "these",
           "those", "more", "less", "only", "also", "into", "over", "under", "both", "figures", "figure", "table",
           "tables", "line", "lines", "rows", "text"}


def heading_lines(page):
    """(line number, anchor, words) of each heading of a page below its title (levels 2-6)."""
    out, seen, inside = [], {}, False
    for n, line in enumerate(page.read_text().splitlines(), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if m and not inside:
            s = slug(m.group(2))
            anchor = s if s not in seen else f"{s}-{seen[s]}"
            seen[s] = seen.get(s, 0) + 1
            if len(m.group(1)) > 1:
                out.append((n, anchor, heading_words(m.group(2))))
    return out


def heading_words(text):
    """The words of a text, lower case, a possessive's "'s" dropped."""
    return [re.sub(r"['’]s$", "", w) for w in re.findall(r"[\w'’-]+", text.lower())]


def direction_findings(page):
    """Each "above"/"below" of a page that names one of its headings lying the other way."""
    heads = heading_lines(page)
    found = []
    for n, text in prose_lines(page):
        own = max((h for h, _, _ in heads if h <= n), default=0)  # the section the line is in
        for m in DIRECTED_LINK.finditer(text):
            target = [h for h, anchor, _ in heads if anchor == m.group(2)]
            if target and (target[0] < n) != (m.group(1) == "above"):
                found.append(f"{shown(page)}:{n}: {m.group(0)!r}: its heading is at line {target[0]}")
        for m in DIRECTED.finditer(re.sub(r"\]\([^)]*\)", "]", text)):
            named = [w for w in heading_words(m.group(1)) if len(w) >= 4 and w not in GENERIC]
            lines = [h for h, _, ws in heads if named and named[-1] in ws and h != own]
            if lines and not any((h < n) == (m.group(2) == "above") for h in lines):
                found.append(f"{shown(page)}:{n}: {m.group(0)!r}: its heading is at line {lines[0]}")
    return found


def test_direction_findings_catch_each_kind(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("# P\n\n## The law's core\n\nIts 21 mutants.\n\n## Tables\n\n| the core's 21 (below) |\n"
                    "the core's 21 (above); the round trip below; [below](#the-laws-core)\n"
                    "the figures below\n\n## The round trip\n\nText.\n")
    got = direction_findings(page)
    assert [f.split(": ", 2)[1] for f in got] == ['"the core\'s 21 (below"', "'[below](#the-laws-core)'"], got
    assert [f.split(":")[1] for f in got] == ["9", "10"], got


def test_above_and_below_point_to_their_headings():
    found = [f for page in markdown_files() for f in direction_findings(page)]
    assert not found, "\n".join(found)


# --- the command line the pages name ----------------------------------------------------------
# A `stickslip SUBCOMMAND --option ...` in a page's code (a span or a fenced block) names a
# subcommand of the parser and options it takes; "stickslip a / b / c" names three.
COMMAND = re.compile(r"(?:(?<=[\s`(])|^|(?<=bin/))(?<!from )stickslip ([a-z][a-z0-9-]*(?: / [a-z][a-z0-9_-]*)*)"
                     r"([^#`]*)")


def commands_named(page):
    """(line number, subcommand, its options) of each `stickslip` command in a page's code."""
    out, inside = [], False
    for n, line in enumerate(page.read_text().splitlines(), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        for part in [line] if inside else re.findall(r"`([^`]*)`", line):
            for m in COMMAND.finditer(part):
                names = m.group(1).split(" / ")
                options = re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", m.group(2)) if len(names) == 1 else []
                out += [(n, name, options) for name in names]
    return out


def command_findings(pages, parser):
    """Each subcommand a page names that the parser has not, and each option its subcommand
    does not take."""
    subs = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
    found = []
    for page in pages:
        for n, name, options in commands_named(page):
            if name not in subs:
                found.append(f"{shown(page)}:{n}: `stickslip {name}`: no such subcommand ({', '.join(subs)})")
                continue
            known = {o for a in subs[name]._actions for o in a.option_strings}
            found += [f"{shown(page)}:{n}: `stickslip {name} {o}`: no such option" for o in options if o not in known]
    return found


def test_command_findings_catch_each_kind(tmp_path):
    from stickslip.cli import build_parser

    page = tmp_path / "p.md"
    page.write_text("`stickslip run drag --engine lammps --speed 2`\n```sh\n.venv/bin/stickslip friction-speed\n"
                    "stickslip report / precision / friction_speed  # three\n```\nthe stickslip package, "
                    "`from stickslip import scene`\n")
    got = [f.split(": ", 1)[1].split(":")[0] for f in command_findings([page], build_parser())]
    assert got == ["`stickslip run --speed`", "`stickslip friction-speed`", "`stickslip friction_speed`"], got


def test_the_commands_the_pages_name_are_the_parsers():
    from stickslip.cli import build_parser

    pages = markdown_files()
    assert sum(len(commands_named(p)) for p in pages) > 50
    found = command_findings(pages, build_parser())
    assert not found, "\n".join(found)


# --- sections named by other files ------------------------------------------------------------
# A file that sends its reader to a section of a page by name (`docs/law.md "Energy"`, `(README,
# "The test suite")`, `lammps_plugin/README.md, "Restarts"`) names a heading, or a bold label,
# that the page has. The page's path is relative to the file's folder or one above it.
SECTION_REF = re.compile(r"\b((?:[\w.-]+/)*[\w.-]+\.md|README)(?:'s)?(?:,\s*(?:History,\s*)?|\s+)\"([^\"]{3,80})\"")


def section_names(page):
    """The text of a page's headings and bold labels, lower case, markup dropped."""
    text = page.read_text()
    names = re.findall(r"^#{1,6}\s+(.*?)\s*$", text, flags=re.M) + re.findall(r"\*\*([^*]+)\*\*", text)
    return [re.sub(r"[`*]", "", n).lower() for n in names]


def section_reference_findings(files):
    """Each reference to a section of a page (in (path, text) pairs) whose page has no such
    section, or that names no page."""
    found = []
    for rel, text in files:
        # a reference may wrap over lines, also in code comments ('#', '//', '*' leading the line)
        flat = re.sub(r"[ \t]*\n[ \t]*(?:#|//|\*(?!\*))?[ \t]*", " ", text)
        for m in SECTION_REF.finditer(flat):
            name = "README.md" if m.group(1) == "README" else m.group(1)
            here = ROOT / rel
            pages = [p / name for p in (here.parent, *here.parents) if (p / name).is_file() and p.is_relative_to(ROOT)]
            if not pages:
                found.append(f"{rel}: {m.group(0)!r}: no page {name}")
            elif not any(m.group(2).lower() in s for s in section_names(pages[0])):
                found.append(f"{rel}: {m.group(0)!r}: {shown(pages[0])} has no such section")
    return found


def test_section_reference_findings_catch_each_kind():
    files = [("pyproject.toml", '# the mutation run (README, "The test suite"): pip install\n'),
             ("tools/x.py", '# (docs/law.md "Energy"), (docs/law.md, "Exact slip\n# timing"), (docs/nope.md "Abc")\n'),
             ("docs/testing.md", 'docs/granular-3d.md, "The scenes and why"; docs/testing.md\'s "last profile"\n')]
    got = [f.split(": ", 2)[2] for f in section_reference_findings(files)]
    assert got == ["README.md has no such section", "no page docs/nope.md"], got


def test_every_section_a_file_names_is_its_pages():
    this = Path(__file__).relative_to(ROOT).as_posix()  # (its own examples)
    found = section_reference_findings([(rel, text) for rel, text in text_files() if rel != this])
    assert not found, "\n".join(found)


# --- requirements and calls the pages state ------------------------------------------------------

def test_the_readmes_requirements_are_pyprojects():
    """The README's pyref row names the Python version and the packages pyproject.toml
    requires, all of them and no other."""
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    row = next(ln for ln in (ROOT / "README.md").read_text().splitlines() if ln.startswith("| pyref |"))
    stated = row.split("|")[2]
    python = re.search(r"Python ≥ ([\d.]+)", stated)
    assert python and project["requires-python"] == f">={python.group(1)}", (stated, project["requires-python"])
    wanted = {re.split(r"[<>=\[ ]", d)[0] for d in project["dependencies"]}
    named = set(re.findall(r"\b(numpy|scipy|pandas|matplotlib|tqdm|[a-z][a-z0-9_-]+)\b", stated.split("with", 1)[1]
                           .split("(")[0]))
    assert named == wanted, (named, wanted)


def test_the_pages_make_the_deme_solver_as_the_adapter_does():
    """Every `deme.DEMSolver(...)` a page shows is the call the adapter makes first
    (stickslip/adapters/deme.py new_solver: DEM-Engine 3 takes a list of devices)."""
    first = re.search(r"deme\.DEMSolver\(([^)]*)\)", (ROOT / "stickslip/adapters/deme.py").read_text()).group(1)
    calls = [(shown(p), m.group(1)) for p in markdown_files() for m in re.finditer(r"deme\.DEMSolver\(([^)]*)\)",
                                                                                p.read_text())]
    assert first == "[0]" and calls and all(args == first for _, args in calls), calls


def test_the_lammps_examples_set_the_law_as_their_page_says():
    """lammps_plugin/examples/README.md names the inputs that set the law's keywords: each of
    them sets those words, and every other input names the sub-model (`tangential
    stick_slip`)."""
    page = (ROOT / "lammps_plugin/examples/README.md").read_text()
    m = re.search(r"((?:`in\.\w+`(?:, | and )?)+) set the law as docs/law\.md states it: `([^`]+)`", " ".join(page.split()))
    assert m, "the sentence naming the inputs that set the law"
    named, words = re.findall(r"`(in\.\w+)`", m.group(1)), m.group(2).split()
    for script in sorted((ROOT / "lammps_plugin/examples").glob("in.*")):
        text = " ".join(script.read_text().split())
        if script.name in named:
            assert " ".join(words) in text, (script.name, words)
        else:
            assert "tangential stick_slip" in text, script.name
    assert named, m.group(0)


def test_the_liggghts_page_reads_the_record_where_the_adapter_does():
    """The LIGGGHTS page's columns of `compute pair/gran/local id history` (3 columns of `id`,
    then the history) and of a wall's per-atom history are the layout the adapter reads
    (stickslip/adapters/liggghts.py: D in history values 1-3, then Fn, F_s, the slip count),
    wherever the page states them."""
    text = " ".join((ROOT / "liggghts_plugin/doc/tangential_model_stick_slip.md").read_text().split())
    a = liggghts_adapter
    pair = {"D": (4, 6), "Fn": (3 + a.RECORD_FN,) * 2, "F_s": (3 + a.RECORD_FS, 3 + a.RECORD_FS + 2),
            "slip count": (3 + a.RECORD_NSLIP,) * 2}
    listed = re.search(r"then the history: 4-6 `D`, (\d+) `Fn`, (\d+)-(\d+) `F_s`, (\d+) slip count", text)
    assert listed and tuple(map(int, listed.groups())) == (pair["Fn"][0], *pair["F_s"], pair["slip count"][0])
    wall = re.search(r"`f_history_<wallfixID>\[1\.\.3\]` = `D`, `\[(\d+)\]` = `Fn`, `\[(\d+)\.\.(\d+)\]` = `F_s`, "
                     r"`\[(\d+)\]` = slip count", text)
    assert wall and tuple(map(int, wall.groups())) == (a.RECORD_FN, a.RECORD_FS, a.RECORD_FS + 2, a.RECORD_NSLIP)
    for m in re.finditer(r"columns (\d+)-(\d+) of `compute pair/gran/local([^`]*)`", text):
        assert " id " in m.group(3) + " " and (int(m.group(1)), int(m.group(2))) == pair["D"], m.group(0)
