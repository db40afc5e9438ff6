# SPDX-License-Identifier: GPL-2.0-or-later
"""`stickslip report`: the paper's three cases on every available engine.

Each case's kind (stickslip/kinds/) gives its figures (the paper's Figs. 9, 11, 12, 14
and 15) and its claims table; report.md shows them beside the paper's statements,
then the studies: what accuracy costs (precision.py), friction against sliding speed
(friction_speed.py) and the speed above which every step slips (thresholds.py).
"""
from __future__ import annotations

import sys
from pathlib import Path

from . import adapters, kinds, parallel, runner
from .kinds import paper
from . import scene as scene_mod
from .studies import drum_study
from .studies.report_plan import plan as study_plan

CASES = ("drag", "tray", "tilt")  # the paper's three examples (section 3), in cases/


def build_report(out: Path, engines=None, progress=True, studies=True, cpu_log=None):
    """Every run of the report (cases and studies) goes to parallel.run_all at once, so
    both cores stay busy; the costliest runs start first; a run the cases and a study both
    ask for runs once. cpu_log: see parallel.run_all."""
    out = Path(out)
    ok, missing = adapters.available()
    engines = [e for e in (engines or ok) if e in ok]
    skipped = dict(missing)
    if "pyref" not in engines:
        engines = ["pyref"] + engines
    keys, tasks = [], []
    for case in CASES:
        base = scene_mod.load(case)
        kind = kinds.get(base.analysis["kind"])
        for law in (base.contact.law, *kind.COMPARISON_LAWS):
            for timing in kind.REPORT_TIMINGS if law == "stick_slip" else ("step",):
                for eng in engines:
                    if law != "stick_slip" and eng != "pyref":
                        continue  # the engines ship only the stick-slip law
                    keys.append((case, law, timing, eng))
                    # (the runs' warnings go into report.md's tables, not to the console)
                    tasks.append(runner.task(case, eng, out / "runs" / _label(case, law, timing, base) / eng,
                                             warn=False, law=law, slip_timing=timing))
    study_tasks, finish_studies = study_plan(out, CASES, engines) if studies else ([], None)
    unique, results_of = runner.once(tasks + study_tasks)
    got = results_of(parallel.run_all(unique, "report", progress, cpu_log))
    results = {case: {} for case in CASES}  # case -> {(law, timing, engine): (scene, summary, df)}
    for (case, law, timing, eng), r in zip(keys, got):
        if isinstance(r, Exception):  # an engine failing must not lose the others' results
            label = _label(case, law, timing, scene_mod.load(case))
            sys.stderr.write(f"stickslip: {eng} failed on {label}: {r}\n")
            skipped[eng] = f"failed on {label}: {r}"
        else:
            results[case][(law, timing, eng)] = r
    figs = []
    for case in CASES:
        if results[case]:
            figs += kinds.get(scene_mod.load(case).analysis["kind"]).figures(out, results[case])
    text = _markdown(results, engines, skipped, figs)
    if studies:
        text += finish_studies(got[len(tasks):])
    text += drum_study.report_section(out)
    (out / "report.md").write_text(text)
    print(f"wrote {out / 'report.md'}")
    return 0


def _label(case, law, timing, base):
    label = case if law == base.contact.law else f"{case}_{law}"
    return label if timing == base.contact.slip_timing else f"{label}_{timing}"


def fmt(v):
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.5g}"
    return str(v)


def cell(text):
    """Text for a Markdown table cell (a pipe would end the cell)."""
    return str(text).replace("|", "\\|")


def _markdown(results, engines, skipped, figs):
    lines = ["# stickslip report", "",
             "The paper's three cases (Khellaf & Mansouri 2024, section 3) run from the scene files in "
             "`cases/` on every available engine. Each run's `timeseries.csv` and `summary.json` are under "
             "`runs/<case>/<engine>/`.", ""]
    lines.append("Engines: " + ", ".join(engines))
    for e, why in skipped.items():
        lines.append(f"- {e} not run: {why}")
    lines += ["", "## The paper's statements beside the runs", "",
              "Every quantitative or checkable statement of the paper's section 3, the value each engine gives (and "
              "each slip timing, for case 3: the paper ties its speed effect to the time step) and a verdict. How "
              "each statement is read (its tolerance and why) is in the third column.", ""]
    for case in CASES:
        lines += _paper_table(case, results[case])
    for case in CASES:
        base = scene_mod.load(case)
        for law, timing in dict.fromkeys((law, timing) for law, timing, _ in results[case]):
            present = [e for e in engines if (law, timing, e) in results[case]]
            sc = results[case][(law, timing, present[0])][0]
            label = _label(case, law, timing, base)
            lines += [f"## {label}", "", "| figure | " + " | ".join(present) + " |", "|---|" + "---|" * len(present)]
            for key, text in kinds.get(sc.analysis["kind"]).claims(sc):
                vals = [fmt(results[case][(law, timing, e)][1].get(key)) for e in present]
                lines.append(f"| {cell(text)} | " + " | ".join(vals) + " |")
            # one line per distinct warning, naming the engines it came from: the report's scenes
            # are the paper's, so their warnings are stated here, where the figures are
            notes = {}
            for e in present:
                for n in results[case][(law, timing, e)][1].get("notes", []):
                    notes.setdefault(n, []).append(e)
            lines += [""] + [f"> warning ({', '.join(es)}): {n}" for n, es in notes.items()] + [""]
            if law != "stick_slip":
                lines += ["(pyref only: the paper's comparison law; the engines ship only the stick-slip law)", ""]
    lines += ["## Figures", ""]
    for name in figs:
        lines += [f"![{name}]({name})", ""]
    lines += ["Every headline figure comes from the case kinds in `stickslip/kinds/`, reading the same "
              "columns from each engine. Summaries in JSON:", ""]
    for case in CASES:
        base = scene_mod.load(case)
        for (law, timing, eng) in sorted(results[case]):
            label = _label(case, law, timing, base)
            lines.append(f"- [{label} / {eng}](runs/{label}/{eng}/summary.json)")
    return "\n".join(lines) + "\n"


def _paper_table(case, runs):
    if not runs:
        return []
    sc = next(iter(runs.values()))[0]
    kind = kinds.get(sc.analysis["kind"])
    rows = paper.rows(kind.paper_statements(sc), runs, fmt)
    columns = sorted({c for *_, values, _, _ in rows for c in values},
                     key=lambda c: (c[0] != "step", adapters.ENGINES.index(c[1]) if c[1] in adapters.ENGINES else 9))
    timed = len({t for t, _ in columns}) > 1
    head = [f"{e} ({t})" if timed else e for t, e in columns]
    lines = [f"### {case}", "", "| § | the paper says | how it is checked | " + " | ".join(head) + " | verdict | why |",
             "|---|---|---|" + "---|" * len(head) + "---|---|"]
    for section, text, how, values, verdicts, why in rows:
        verdict = "; ".join(f"{v} ({t})" if timed else v for t, v in sorted(verdicts.items(), key=lambda kv: kv[0] != "step"))
        lines.append(f"| {section} | {cell(text)} | {cell(how)} | " + " | ".join(values.get(c, "—") for c in columns)
                     + f" | {verdict} | {cell(why)} |")
    return lines + [""]
