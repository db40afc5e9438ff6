# SPDX-License-Identifier: GPL-2.0-or-later
"""One owner per fact. A figure the pages state (a ratio, a time, a count, a version) is
measured or set in one place, its owner: a page, a data file or the code. A page that
states it elsewhere states the owner's value: each fact below names its owner, reads the
value there, and finds every statement of it on every page (outside the History sections
of docs/performance.md and docs/testing.md, which keep what was measured on their dates).
A copy may round the owner's value to the digits it shows, nothing else.

A precise figure (four significant digits or more) written on two pages is a copy: it must
be a fact here, so that a change of the owner shows where it is copied
(test_a_precise_figure_on_two_pages_is_a_fact). The test suite's size, the drag example's
figures, the README's costs and where the 3D angles stop moving are checked by
tests/test_docs.py.
"""
from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pandas as pd
import pytest

from stickslip.scene import stability
from test_docs import FENCE, markdown_files, page_lines, section, shown, table_rows

ROOT = Path(__file__).resolve().parent.parent
MONTHS = "Jan Feb Mar Apr May Jun Jul Aug Sep Oct Nov Dec".split()


def read(rel):
    return (ROOT / rel).read_text()


def pages_text():
    """{page: its text outside fenced code and History, lines joined by spaces}: a statement
    may wrap over lines."""
    out = {}
    for page in markdown_files():
        inside, kept = False, []
        for _, line, history in page_lines(page):
            if FENCE.match(line):
                inside = not inside
                continue
            if not inside and not history:
                kept.append(line)
        out[shown(page)] = " ".join(kept)
    return out


@dataclass
class Fact:
    """A figure with one owner: `value()` reads it there (text, or a number a copy may round);
    each pattern's first group is a statement of it on a page."""
    name: str
    owner: str
    value: Callable[[], object]
    patterns: tuple


def agrees(stated, value):
    """A statement is the owner's value: the same text, or a number within half a unit of the
    last digit shown (the owner's value rounded; at a tie either way)."""
    if isinstance(value, str):
        return stated == value
    digits = len(stated.split(".")[1]) if "." in stated else 0
    return abs(value - float(stated)) <= 0.5 * 10 ** -digits * (1 + 1e-9)


def fact_findings(facts, texts):
    """One line for each statement of a fact that is not its owner's value, and for a fact
    no page states any more (its patterns would check nothing)."""
    found = []
    for fact in facts:
        value, seen = fact.value(), 0
        for page, text in texts.items():
            for pattern in fact.patterns:
                for m in re.finditer(pattern, text):
                    seen += 1
                    if not agrees(m.group(1), value):
                        found.append(f"{page}: {fact.name} {m.group(1)!r} ({m.group(0)[:70]!r}), its owner "
                                     f"({fact.owner}): {value}")
        if not seen:
            found.append(f"{fact.name}: no page states it (its owner: {fact.owner}); a pattern is out of date")
    return found


# --- the owners' values ---------------------------------------------------------------------------

def mutants(name):
    """How many mutants tools/mutate_cpp.py makes: of one engine, or the law's core's."""
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import mutate_cpp
    finally:
        sys.path.pop(0)
    return getattr(mutate_cpp, name)


def score(heading):
    """"K of N": testing.md's score of a mutation section ("Score: N mutants, K killed")."""
    m = re.search(r"Score: (\d+) mutants, (\d+) killed", section(read("docs/testing.md"), heading))
    return f"{m.group(2)} of {m.group(1)}"


def pyref_score():
    m = re.search(r"(\d+) of the (\d+) with tests detected", section(read("docs/testing.md"), "### pyref's kernel"))
    return f"{m.group(1)} of {m.group(2)}"


def precision_row(column):
    """docs/precision.md's tilt ladder at the scene's step: the step or exact timing's error
    (columns 1, 3) or final speed (2, 4)."""
    rows = table_rows(read("docs/precision.md"), "| dt (s) | step timing: error |")
    row = next(r for r in rows if "the scene's" in r[0])
    return float(row[column].strip("*% "))


def costs(engine, ranks=1):
    c = pd.read_csv(ROOT / "docs/drum/costs.csv")
    return c[(c.engine == engine) & (c.ranks == ranks)].iloc[0]


def fixed_angle_difference(engine, layers):
    """|θ_stop at fixed angles − Weinhart et al.'s fit| of a bed (validation.csv)."""
    v = pd.read_csv(ROOT / "docs/granular-3d/validation.csv")
    return abs(float(v[(v.engine == engine) & (v.layers == layers)].difference_fixed.iloc[0]))


def lammps_releases():
    """The LAMMPS releases the project builds or loads into, as the pages write them: the
    sources ./run.sh builds (stickslip.adapters.lammps_granular.RELEASES) and Debian's, whose
    version the plugin is built for (lammps_plugin/lammps_api.h)."""
    from stickslip.adapters.lammps_granular import RELEASES

    debian = re.search(r"STICKSLIP_LAMMPS_VERSION (\d{4})(\d\d)(\d\d)", read("lammps_plugin/lammps_api.h"))
    y, mo, d = (int(x) for x in debian.groups())
    return {date for date, _ in RELEASES.values()} | {f"{d} {MONTHS[mo - 1]} {y}"}


def source_build_minutes(what):
    """Minutes of a source build in testing.md's History, newest first: its first entry that
    times the builds ("LAMMPS 4 Feb 2025 7 min 46 s, ...")."""
    text = " ".join(section(read("docs/testing.md"), "### The suite's run time").split())
    m = re.search(re.escape(what) + r" (\d+) min (\d+) s", text)
    return int(m.group(1)) + int(m.group(2)) / 60


def widening(rolling):
    """(f, ranges) the map's leave_pair_out.csv measures at a rolling resistance."""
    from stickslip.studies import calibrate_map

    return calibrate_map.widening(pd.read_csv(ROOT / "docs/granular-3d/leave_pair_out.csv"), rolling)


def runslow_minutes():
    m = re.search(r"`--runslow` \([^)]*\): \d+ passed in (\d+) s",
                  " ".join(section(read("docs/testing.md"), "### The suite's run time").split()))
    return int(m.group(1)) / 60


FACTS = [
    Fact("DEM-Engine's version", "pyproject.toml's gpu extra",
         lambda: re.search(r"deme\[cuda12\]>=([\d.]+)", read("pyproject.toml")).group(1),
         (r"\bdeme`? (\d+\.\d+\.\d+)", r"DEM-Engine (\d+\.\d+\.\d+)")),
    Fact("the CUDA wheels' version", "tools/deme_bundle.sh",
         lambda: re.search(r"nvidia-cuda-runtime-cu12==(\d+\.\d+)", read("tools/deme_bundle.sh")).group(1),
         (r"CUDA (\d+\.\d+) (?:wheels|runtime)",)),
    Fact("LIGGGHTS' version", "run.sh's LIGGGHTS-PUBLIC source",
         lambda: re.search(r"version=(\d+\.\d+\.\d+)\+", read("run.sh")).group(1),
         (r"LIGGGHTS(?:-PUBLIC)? (\d+\.\d+\.\d+)",)),
    Fact("YADE's version", "README.md's engine table",
         lambda: re.search(r"\| YADE \| (\d{4}\.\d\d\w?) ", read("README.md")).group(1),
         (r"YADE (\d{4}\.\d\d\w?)\b",)),
    Fact("the law's core's mutants", "tools/mutate_cpp.py, CORE_MUTANTS", lambda: str(len(mutants("CORE_MUTANTS"))),
         (r"core's (\d+)\b", r"its (\d+) mutants \(`CORE_MUTANTS`")),
    Fact("LIGGGHTS' mutants killed", "docs/testing.md, its score", lambda: score("### The C++ law on LIGGGHTS"),
         (r"(\d+ of \d+) \(LIGGGHTS\)",)),
    Fact("LAMMPS 2021's mutants killed", "docs/testing.md, its score", lambda: score("### The C++ law on LAMMPS"),
         (r"(\d+ of \d+) \(LAMMPS 2021's styles\)",)),
    Fact("the sub-model's mutants killed", "docs/testing.md, its score", lambda: score("### The sub-model on LAMMPS"),
         (r"(\d+ of \d+) \(LAMMPS' sub-model\)",)),
    Fact("YADE's compiled law's mutants killed", "docs/testing.md, its score",
         lambda: score("### The compiled law on YADE"), (r"(\d+ of \d+) \(YADE's compiled law\)",)),
    Fact("DEM-Engine's mutants killed", "docs/testing.md, its score",
         lambda: score("### The force model on DEM-Engine"), (r"(\d+ of \d+) \(DEM-Engine\)",)),
    Fact("DEM-Engine's mutants", "tools/mutate_cpp.py, DEME_MUTANTS", lambda: str(len(mutants("DEME_MUTANTS"))),
         (r"builds (\d+) mutants of\s+`stick_slip\.cu`",)),
    Fact("pyref's mutants detected", "docs/testing.md, pyref's kernel", pyref_score,
         (r"pyref (\d+ of \d+) detected",)),
    Fact("the tilt's step timing error at the scene's dt", "docs/precision.md's tilt ladder",
         lambda: precision_row(1), (r"tilt the step timing is ([\d.]+) % off", r"by ([\d.]+) % on the paper's tilt",
                                    r"the answer is ([\d.]+) % off the converged")),
    Fact("the tilt's exact timing error at the scene's dt", "docs/precision.md's tilt ladder",
         lambda: precision_row(3), (r"converged answer, the exact timing ([\d.]+) %",)),
    Fact("the A/A control's spread on DEM-Engine, per cent", "docs/performance.md's current figures",
         lambda: 100 * (float(re.search(r"\(A/A\) gave ([\d.]+)", read("docs/performance.md")).group(1)) - 1),
         (r"engine's own model differ by (\d+) %",)),
    Fact("pyref's tilt final speed, step timing at the scene's dt", "docs/precision.md's tilt ladder",
         lambda: precision_row(2), (r"\| final speed \| [^|]*\| [^|]*\| [^|]*\| ([\d.]+) m/s \|",)),
    Fact("pyref against LIGGGHTS on the drum", "docs/drum/costs.csv",
         lambda: float(costs("pyref").wall_time_s / costs("liggghts").wall_time_s),
         (r"\| pyref \| [^|]*\| (\d+)× slower", r"\| pyref \| [^|]*\| [^|]*\| (\d+)x slower")),
    Fact("pyref's grain-steps per second on the drum", "docs/drum/costs.csv",
         lambda: float(costs("pyref").grain_steps_per_s) / 1e6, (r"slower \(([\d.]+)e6 grain-steps/s\)",)),
    Fact("the 10 d bed's θ_stop at fixed angles against Weinhart et al.", "docs/granular-3d/validation.csv",
         lambda: fixed_angle_difference("liggghts", 18),
         (r"within ([\d.]+)° for a 10 d bed", r"the 10 d bed is within ([\d.]+)° of their fit")),
    Fact("the 20 d bed's θ_stop at fixed angles against Weinhart et al.", "docs/granular-3d/validation.csv",
         lambda: fixed_angle_difference("liggghts", 36),
         (r"and ([\d.]+)° for a 20 d bed", r"the 20 d bed ([\d.]+)° above it")),
    Fact("LAMMPS 4 Feb 2025's build time", "docs/testing.md's History",
         lambda: source_build_minutes("LAMMPS 4 Feb 2025"), (r"4 Feb 2025 and 4 Jul 2026, from Debian's source \((\d+) and",)),
    Fact("LAMMPS 4 Jul 2026's build time", "docs/testing.md's History",
         lambda: source_build_minutes("4 Jul 2026 with its test programs"),
         (r"from Debian's source \(\d+ and (\d+) min on 2 cores",)),
    Fact("LIGGGHTS-PUBLIC's build time", "docs/testing.md's History",
         lambda: source_build_minutes("LIGGGHTS-PUBLIC"), (r"that way, once \(([\d.]+) min on 2 cores\)",)),
    Fact("the four source builds' time", "docs/testing.md's History",
         lambda: float(re.search(r"source builds took (\d+) min", " ".join(read("docs/testing.md").split())).group(1)),
         (r"builds all four \((\d+) min on 2 cores",)),
    Fact("the steps per contact below which a run warns", "stickslip/scene/stability.py, CONTACT_STEPS",
         lambda: str(stability.CONTACT_STEPS),
         (r"accuracy\s+warning starts below (\d+)", r"accuracy bar is (\d+)", r"fewer than (\d+) steps\s+\(`stability")),
    Fact("calibrate's widening without rolling resistance", "docs/granular-3d/leave_pair_out.csv",
         lambda: widening(0.0)[0], (r"Without rolling resistance f = ([\d.]+)", r"widened by ([\d.]+) as measured",
                                    r"beside the map: ([\d.]+) without rolling resistance")),
    Fact("the ranges it comes from", "docs/granular-3d/leave_pair_out.csv", lambda: str(widening(0.0)[1]),
         (r"Without rolling resistance f = [\d.]+, from (\d+) ranges",)),
    Fact("calibrate's widening with rolling resistance 0.1", "docs/granular-3d/leave_pair_out.csv",
         lambda: widening(0.1)[0], (r"with rolling resistance 0\.1, f = ([\d.]+)", r"([\d.]+) with it\)")),
    Fact("the suite with the opt-in tests", "docs/testing.md's History", runslow_minutes,
         (r"with them the suite takes (\d+) min on 2\s+cores",)),
]


def test_fact_findings_catch_a_copy_that_is_not_the_owners(tmp_path):
    facts = [Fact("a ratio", "here", lambda: 0.974, (r"ratio (\S+)x",)),
             Fact("a version", "there", lambda: "3.0.19", (r"deme (\d+\.\d+\.\d+)",)),
             Fact("a count", "here", lambda: "21", (r"core's (\d+)",))]
    texts = {"a.md": "ratio 0.98x and ratio 0.974x; deme 3.0.19", "b.md": "ratio 0.97x, deme 3.0.18"}
    got = fact_findings(facts, texts)
    assert [f.split(" '")[0] for f in got] == ["a.md: a ratio", "b.md: a version",
                                              "a count: no page states it (its owner: here); a pattern is out of date"], got


@pytest.mark.parametrize("fact", FACTS, ids=[f.name for f in FACTS])
def test_every_copy_of_a_fact_is_its_owners(fact):
    found = fact_findings([fact], pages_text())
    assert not found, "\n".join(found)


def test_the_mutation_scores_count_the_tools_mutants():
    """docs/testing.md's score of each engine counts the mutants tools/mutate_cpp.py makes."""
    for heading, name in (("### The C++ law on LIGGGHTS", "LIGGGHTS_MUTANTS"), ("### The C++ law on LAMMPS",
                          "LAMMPS_MUTANTS"), ("### The sub-model on LAMMPS", "LAMMPS_GRANULAR_MUTANTS"),
                          ("### The force model on DEM-Engine", "DEME_MUTANTS"),
                          ("### The compiled law on YADE", "YADE_CPP_MUTANTS")):
        assert score(heading).split(" of ")[1] == str(len(mutants(name))), heading


def test_every_lammps_release_a_page_names_is_one_the_project_builds():
    """A LAMMPS release named by its date ("4 Feb 2025") on any page is one ./run.sh builds
    from source or Debian's, which the plugin is built for."""
    releases = lammps_releases()
    found = [f"{page}: {m.group(0)!r}, not one of {sorted(releases)}" for page, text in pages_text().items()
             for m in re.finditer(rf"\b\d{{1,2}} (?:{'|'.join(MONTHS)}) 20\d\d\b", text) if m.group(0) not in releases]
    assert len(releases) == 3 and not found, "\n".join(found)


# --- figures against the data file they come from ------------------------------------------------

def test_the_drums_cost_table_is_its_csv():
    """docs/drum.md's table of what each engine costs on the drum: each row's wall time,
    grain-steps per second and ratio to LIGGGHTS on 1 rank are costs.csv's, rounded as shown."""
    rows = table_rows(read("docs/drum.md"), "| engine | wall time | grain-steps per second |")
    lig = costs("liggghts")
    assert len(rows) == len(pd.read_csv(ROOT / "docs/drum/costs.csv")), rows
    for name, wall, rate, against in rows:
        engine = name.split()[0].split(",")[0].lower()
        c = costs(engine, 2 if "2 MPI ranks" in name else 1)
        assert agrees(wall.split()[0], float(c.wall_time_s)), (name, wall, c.wall_time_s)
        mantissa, exp = rate.split("e")
        assert agrees(mantissa, float(c.grain_steps_per_s) / 10 ** int(exp)), (name, rate, c.grain_steps_per_s)
        ratio = against.split()[-1].rstrip("x") if "speed-up" in against else against.split("x")[0]
        want = (float(c.speedup_vs_1_rank) if "speed-up" in against else
                float(c.wall_time_s / lig.wall_time_s) if "slower" in against else 1.0)
        assert agrees(ratio, want), (name, against, want)


# --- a precise figure on two pages is a fact ------------------------------------------------------
PRECISE = re.compile(r"(?<![\w.])(\d+\.\d{3,}|\d\.\d{2,}(?=\d)|\d{1,3}(?: \d{3}){2,})(?![\w.])")


def precise_figures(texts):
    """{figure: {page, ...}} of the figures with four significant digits or more (0.9276,
    1.0026, 512 000), each page's text without links' targets."""
    out = {}
    for page, text in texts.items():
        for m in PRECISE.finditer(re.sub(r"\]\([^)]*\)", "]", text)):
            digits = re.sub(r"\D", "", m.group(1)).lstrip("0")
            if len(digits) >= 4:
                out.setdefault(m.group(1), set()).add(page)
    return out


# Copies that are facts of their own kind, checked elsewhere: the drag example's mean friction
# (tests/test_docs.py, test_every_page_states_the_drag_as_the_examples_print_it); the paper's DOI
# and Table 2 (the paper's numbers, not measured here); the GPU's driver and the benchmarks'
# sizes (how a measurement was made, stated with it).
NOT_MEASURED = {"0.45025", "10.15587", "2706", "5448.2024", "310428", "580.159", "512 000", "1 523 200"}
# The same digits for two quantities: the A/A control's ratio (performance.md) and the tray's
# friction peak at a 50 µm gap in N/m (tray-calibration.md).
COINCIDENT = {"1.089"}
# Pages generated from a data file (its copy by construction): the drum study's and the 3D
# study's tables.
GENERATED = ("docs/drum/study.md", "docs/granular-3d/summary.md")


def test_a_precise_figure_on_two_pages_is_a_fact():
    """A figure of four significant digits or more on two pages is either a fact of FACTS
    (its copies checked against its owner) or not a measurement (NOT_MEASURED)."""
    texts = {page: text for page, text in pages_text().items() if page not in GENERATED}
    checked = {m.group(1) for fact in FACTS for pattern in fact.patterns for text in texts.values()
               for m in re.finditer(pattern, text)}
    found = [f"{figure}: on {sorted(pages)}" for figure, pages in precise_figures(texts).items()
             if len(pages) > 1 and figure not in checked | NOT_MEASURED | COINCIDENT]
    assert not found, "copied figures that are not facts of this file:\n" + "\n".join(found)
