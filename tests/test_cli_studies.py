# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip report`, `bench` and `thresholds` run for real through the command line
(cli.main), reduced where the full run is long, checking what they write."""
import csv
import json
import math
import re

import pytest

from stickslip import adapters, kinds, report
from stickslip.bench import pyref as pyref_bench
from stickslip.studies import thresholds
from stickslip import scene as scene_mod
from stickslip.cli import main

PNG = b"\x89PNG\r\n\x1a\n"


def table(text, heading):
    """The rows (lists of cells) of the first Markdown table after `heading`."""
    rows, seen = [], False
    for line in text.split("\n")[text.split("\n").index(heading) + 1:]:
        if line.startswith("|"):
            seen = True
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
            if not set("".join(cells)) <= set("-"):
                rows.append(cells)
        elif seen:
            break
    return rows[0], rows[1:]


def test_thresholds_writes_every_measured_speed_within_the_bisections_width(tmp_path, capsys):
    """The whole command (9 bisections on the drag, ~3 s of pyref): each measured V* must
    be the formula's within what the bisection resolves. `measure` halves a bracket in log
    speed until hi/lo <= 1 + 1e-3 and returns its geometric mean, which is then within a
    factor sqrt(1 + 1e-3) of any speed in the bracket, the threshold included (the formula
    is the step timing's exact threshold for Fn = m g, the drag's load to ~1e-8)."""
    assert main(["thresholds", "--out", str(tmp_path)]) == 0
    rows = list(csv.DictReader(open(tmp_path / "thresholds.csv")))
    assert sorted((float(r["dt_s"]), float(r["nu_s"])) for r in rows) == sorted(
        (dt, nu) for dt in thresholds.DTS for nu in thresholds.NU_S)
    drag = scene_mod.load("drag")
    fn = drag.grain_mass(drag.grains[0]) * 9.81
    width = math.sqrt(1 + 1e-3) - 1
    for r in rows:
        measured, formula = float(r["v_star_measured_mps"]), float(r["v_star_formula_mps"])
        assert formula == thresholds.formula(drag, float(r["dt_s"]), float(r["nu_s"]), fn)
        assert abs(measured / formula - 1) <= width, r
        assert float(r["rel_diff"]) == pytest.approx(measured / formula - 1, abs=1e-15)
    assert (tmp_path / "thresholds.png").read_bytes()[:8] == PNG
    lines = [line for line in capsys.readouterr().out.split("\n") if line.startswith("dt=")]
    assert len(lines) == len(rows)


def lattice_contacts(n_grains):
    """stickslip/bench/pyref.py's packing, a cubic lattice pressed together: each grain touches
    its 6 lattice neighbours and the bottom layer the floor."""
    side = max(2, round(n_grains ** (1 / 3)))
    nz = max(2, round(n_grains / side**2))
    return 2 * (side - 1) * side * nz + side * side * (nz - 1) + side * side


def test_bench_on_small_packings(tmp_path, monkeypatch):
    """`bench --engines pyref --reps 1` on packings of 27 to 125 grains (a few seconds;
    the real sizes take minutes): every figure written, the contact counts those of the
    pressed lattice, the rates consistent with the times."""
    monkeypatch.setattr(pyref_bench, "PYREF_SIZES", (27, 64, 125))
    monkeypatch.setattr(pyref_bench, "STEP_BUDGET", 1000)
    monkeypatch.setattr(pyref_bench, "CONTACT_TARGET_GRAINS", 64)
    monkeypatch.setattr(pyref_bench, "TIMED_STEPS", 5)
    assert main(["bench", "--out", str(tmp_path), "--reps", "1", "--engines", "pyref"]) == 0
    rows = list(csv.DictReader(open(tmp_path / "bench.csv")))
    assert {r["benchmark"] for r in rows} == {"pyref", "effects"}
    sized = [r for r in rows if r["case"].endswith(" grains")]
    assert [int(r["case"].split()[0]) for r in sized] == [27, 64, 125]
    for r in sized:
        n = int(r["case"].split()[0])
        # contacts are steady during the timed steps (pyref_bench.packing), so their mean is the count
        assert int(r["contacts"]) == lattice_contacts(n), r
        t, rate = float(r["seconds_per_step"]), float(r["contact_steps_per_s"])
        assert t > 0 and rate == pytest.approx(lattice_contacts(n) / t, rel=0.5 / lattice_contacts(n))
    exponent = [float(r["value"]) for r in rows if r["case"].startswith("scaling exponent")]
    assert len(exponent) == 1 and math.isfinite(exponent[0])
    effects = {r["case"]: r for r in rows if r["benchmark"] == "effects"}
    assert set(effects) == {"all on", "gravity off", "rotation off", "normal_damping off",
                            "tangential_damping off", "all off"}
    assert float(effects["all on"]["ratio_to_all_on"]) == 1.0
    assert all(float(r["ratio_to_all_on"]) > 0 for r in effects.values())
    md = (tmp_path / "bench.md").read_text()
    assert md.count("\n| pyref |") + md.count("\n| effects |") == len(rows)


def test_report_on_the_drag_on_every_engine(tmp_path, monkeypatch):
    """`report --no-precision` with the drag alone (the paper's first case, 2500 steps on
    each available engine, ~20 s wall on the loaded machine): the case's table shows each
    engine's own summary figures, the paper's statements on the drag all hold on every
    engine, and every figure and summary it links exists."""
    monkeypatch.setattr(report, "CASES", ("drag",))
    out = tmp_path / "report"
    assert main(["report", "--out", str(out), "--no-precision", "--quiet"]) == 0
    text = (out / "report.md").read_text()
    ok, _ = adapters.available()
    assert f"Engines: {', '.join(ok)}" in text
    summaries = {e: json.loads((out / "runs" / "drag" / e / "summary.json").read_text()) for e in ok}
    head, rows = table(text, "## drag")
    assert head == ["figure"] + ok
    sc = scene_mod.load("drag")
    claims = kinds.get("drag").claims(sc)
    assert len(rows) == len(claims)
    for (key, label), row in zip(claims, rows):
        assert row[0] == report.cell(label)
        assert row[1:] == [report.fmt(summaries[e][key]) for e in ok], key
    head, rows = table(text, "### drag")
    verdict = head.index("verdict")
    assert rows and all(row[verdict] == "matches" for row in rows), [row[verdict] for row in rows]
    for link in re.findall(r"\]\(([^)]+)\)", text):
        if "://" in link or link.startswith("../"):
            continue
        assert (out / link).is_file(), link
        if link.endswith(".png"):
            assert (out / link).read_bytes()[:8] == PNG
