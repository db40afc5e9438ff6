"""`stickslip report`: the paper's three cases on every available engine.

Each case's kind (stickslip/kinds/) gives its figures (the paper's Figs. 9, 11, 12, 14
and 15) and its claims table; report.md shows them beside the paper's statements,
then the studies: what accuracy costs (precision.py), friction against sliding speed
(friction_speed.py) and the speed above which every step slips (thresholds.py).
"""
from __future__ import annotations

import sys
from pathlib import Path

from . import adapters, kinds
from . import scene as scene_mod
from .runner import run_scene

CASES = ("drag", "tray", "tilt")  # the paper's three examples (section 3), in cases/


def build_report(out: Path, engines=None, progress=True, studies=True):
    out = Path(out)
    ok, missing = adapters.available()
    engines = [e for e in (engines or ok) if e in ok]
    skipped = dict(missing)
    if "pyref" not in engines:
        engines = ["pyref"] + engines
    results = {case: {} for case in CASES}  # case -> {(law, engine): (scene, summary, df)}
    for case in CASES:
        base = scene_mod.load(case)
        kind = kinds.get(base.analysis["kind"])
        for law in (base.contact.law, *kind.COMPARISON_LAWS):
            sc = scene_mod.load(case, law=law)
            for eng in engines:
                if law != "stick_slip" and eng != "pyref":
                    continue  # the engines ship only the stick-slip law
                d = out / "runs" / _label(case, law, base) / eng
                try:
                    results[case][(law, eng)] = (sc, *run_scene(sc, eng, d, progress=progress))
                except Exception as e:  # an engine failing must not lose the others' results
                    sys.stderr.write(f"stickslip: {eng} failed on {_label(case, law, base)}: {e}\n")
                    skipped[eng] = f"failed on {_label(case, law, base)}: {e}"
    figs = []
    for case in CASES:
        if results[case]:
            figs += kinds.get(scene_mod.load(case).analysis["kind"]).figures(out, results[case])
    text = _markdown(results, engines, skipped, figs)
    if studies:
        from .studies import studies_section

        text += studies_section(out, CASES, engines, progress)
    (out / "report.md").write_text(text)
    print(f"wrote {out / 'report.md'}")
    return 0


def _label(case, law, base):
    return case if law == base.contact.law else f"{case}_{law}"


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
    lines.append("")
    for case in CASES:
        base = scene_mod.load(case)
        for law in dict.fromkeys(law for law, _ in results[case]):
            present = [e for e in engines if (law, e) in results[case]]
            sc = results[case][(law, present[0])][0]
            label = _label(case, law, base)
            lines += [f"## {label}", "", "| figure | " + " | ".join(present) + " |", "|---|" + "---|" * len(present)]
            for key, text in kinds.get(sc.analysis["kind"]).claims(sc):
                vals = [fmt(results[case][(law, e)][1].get(key)) for e in present]
                lines.append(f"| {cell(text)} | " + " | ".join(vals) + " |")
            # one line per distinct warning, naming the engines it came from
            notes = {}
            for e in present:
                for n in results[case][(law, e)][1].get("notes", []):
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
        for (law, eng) in sorted(results[case]):
            label = _label(case, law, base)
            lines.append(f"- [{label} / {eng}](runs/{label}/{eng}/summary.json)")
    return "\n".join(lines) + "\n"
