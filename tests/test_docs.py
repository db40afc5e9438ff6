"""The documentation holds: every relative link and anchor of every *.md resolves, user pages
carry no dates, work-session talk, machine paths or links outside the repository (dated
measurements live in the history sections of docs/performance.md and docs/testing.md), and
every example input the docs call runnable runs on its engine (short: a few thousand steps).

The YADE example (yade_law/example_drag.py) is run by tests/test_yade_law.py; `stickslip run`
by tests/test_cli_studies.py.
"""
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import skip_engine
from stickslip.adapters import lammps as lammps_adapter
from stickslip.adapters import liggghts as liggghts_adapter

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
           (re.compile(r"(?<![\w.])/(work|home|root)/"), "an absolute machine path"),
           (re.compile(r"\.\./shared/|shared notes"), "notes outside the repository"),
           (re.compile(r"\]\(\s*<?https?:"), "a link outside the repository")]


def test_user_pages_carry_no_dates_sessions_machine_paths_or_outside_links():
    """Dates and measurement history only under '## History' of docs/performance.md and
    docs/testing.md; the rest nowhere."""
    found = []
    for page in markdown_files():
        rel = page.relative_to(ROOT).as_posix()
        history = False
        for n, line in enumerate(page.read_text().splitlines(), 1):
            history = history or (rel in HISTORY_PAGES and line.startswith("## History"))
            for pattern, what in HYGIENE:
                if pattern.search(line) and not (history and what in ("a date", "work-session talk")):
                    found.append(f"{rel}:{n}: {what}: {line.strip()[:100]}")
    assert not found, "\n".join(found)


# --- the example inputs ---------------------------------------------------------------------

MPI_SINGLETON = {"OMPI_MCA_ess_singleton_isolated": "1", "OMP_NUM_THREADS": "1"}
SHORT = "2000"  # steps of a long example in the test: the input, its set-up and a first stretch


def run_example(exe, script, tmp_path, *args):
    """Run an example input from a copy in tmp_path (its outputs land there); returns stdout."""
    shutil.copy(script, tmp_path / script.name)
    proc = subprocess.run([str(exe), "-in", script.name, "-log", "none", *args], cwd=tmp_path,
                          capture_output=True, text=True, errors="replace", timeout=120,
                          env=dict(os.environ, **MPI_SINGLETON))
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


def test_every_example_input_is_run_here():
    """A new example in an examples/ folder must be added to the lists above (and so be run)."""
    for folder, listed in (("liggghts_plugin/examples", LIGGGHTS_EXAMPLES), ("lammps_plugin/examples", LAMMPS_EXAMPLES)):
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
