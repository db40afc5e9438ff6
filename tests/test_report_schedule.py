# SPDX-License-Identifier: GPL-2.0-or-later
"""How the report spends its two cores (issue 25): every task's cost in seconds, so the
longest runs start first whatever their kind, and a run asked for twice runs once. How the
report reads: its figures' legends name each run's engine and timing, and the runs it chose
on purpose keep their warnings in the report, not on the console."""
import csv

import pytest

from stickslip import parallel, report, runner
from stickslip import scene as scene_mod
from stickslip.scene import stability
from stickslip.studies.friction_speed import mean_friction
from stickslip.runner import run_named
from stickslip.studies.thresholds import _measure_drag


class _Planned(Exception):
    pass


def report_tasks(monkeypatch, tmp_path):
    """The tasks the report hands to parallel.run_all, without running them."""
    seen = []

    def capture(tasks, *args, **kwargs):
        seen.extend(tasks)
        raise _Planned

    monkeypatch.setattr(parallel, "run_all", capture)
    with pytest.raises(_Planned):
        report.build_report(tmp_path, engines=["pyref"], progress=False)
    return seen


def test_study_tasks_cost_seconds_as_runs_do(monkeypatch, tmp_path):
    """A friction-speed drag or a threshold bisection takes seconds, a 3 s tray run on
    pyref half a minute: their costs must say so (they were 1/(dt*V) and 1/dt, ~1e12,
    and so ran before every case)."""
    tasks = report_tasks(monkeypatch, tmp_path)
    trays = [c for c, fn, args in tasks if fn is run_named and args[0] == "tray" and "dt" not in args[3]]
    friction = [c for c, fn, _ in tasks if fn is mean_friction]
    bisections = [c for c, fn, _ in tasks if fn is _measure_drag]
    assert len(trays) == 3 and friction and bisections
    assert max(friction + bisections) < min(trays)
    assert min(trays) > 10 and max(friction) > 0.5  # seconds, on either side of the machine's speed


def test_a_run_asked_for_twice_runs_once(monkeypatch, tmp_path):
    """The case at the scene's dt is also a step of its precision ladder: it runs once, and
    the second folder gets the same files. Another dt, or another engine, is another run."""
    monkeypatch.setenv("STICKSLIP_JOBS", "1")
    dt = scene_mod.load("drag").dt
    case = runner.task("drag", "pyref", tmp_path / "case", law="stick_slip", slip_timing="step")
    rung = runner.task("drag", "pyref", tmp_path / "rung", dt=dt, slip_timing="step", duration=None)
    finer = runner.task("drag", "pyref", tmp_path / "finer", dt=dt / 2, slip_timing="step", duration=None)
    other_engine = runner.task("drag", "liggghts", tmp_path / "lig", law="stick_slip", slip_timing="step")
    assert len(runner.once([case, other_engine])[0]) == 2
    unique, results_of = runner.once([case, rung, finer])
    assert unique == [case, finer]
    got = results_of(parallel.run_all(unique, progress=False))
    assert (tmp_path / "rung" / "timeseries.csv").read_bytes() == (tmp_path / "case" / "timeseries.csv").read_bytes()
    assert got[1][1] == got[0][1] and got[1][2].equals(got[0][2])
    assert got[2][1]["dt_s"] == dt / 2 and got[2][1]["steps"] == 2 * got[0][1]["steps"]


def test_bench_report_gives_the_reports_time_and_where_it_went(monkeypatch):
    """`stickslip bench --report`: the report's wall time, its runs' CPU time and the share
    of each part (here a report that logs two tasks, without running them)."""
    from stickslip.bench import table

    tray = runner.task("tray", "pyref", "unused", law="coulomb", slip_timing="step")
    rung = runner.task("tilt", "pyref", "unused", dt=4e-6, slip_timing="exact", duration=None)
    drag = (1.0, mean_friction, ("drag", 1e-3, 2e-6, "step"))

    def fake_report(out, progress=True, cpu_log=None):
        cpu_log += [(tray, 30.0), (rung, 20.0), (drag, 1.5)]

    monkeypatch.setattr(report, "build_report", fake_report)
    rows = {r["case"]: r["value"] for r in table.report_rows()}
    (wall,) = [v for k, v in rows.items() if k.startswith("stickslip report, wall time s")]
    assert 0 <= wall < 5
    assert rows["CPU s of all its runs"] == 51.5
    assert rows["CPU s: case tray on pyref"] == 30.0 and rows["CPU s: ladder tilt on pyref"] == 20.0
    assert rows["CPU s: friction_speed"] == 1.5
    assert rows["CPU s of its longest run (case tray on pyref)"] == 30.0


def _runs_of(case, keys):
    """The report's runs of a case as its figures take them, {(law, timing, engine): (scene,
    summary, timeseries)}, with made-up series of the scene's columns (a ramp in time, an
    angle that rises then holds): what a figure draws does not matter here, only its legend."""
    import numpy as np
    import pandas as pd

    from stickslip import columns

    runs = {}
    for law, timing, engine in keys:
        sc = scene_mod.load(case, law=law, slip_timing=timing)
        t = np.linspace(0.0, 1.0, 50)
        df = pd.DataFrame({c: np.full(len(t), 0.1) for c in columns.names(sc)})
        df["t"] = t
        for c in df:
            if c.endswith("_angle"):
                df[c] = np.minimum(t, 0.5)
        summary = {"t_first_slip_s": 0.4, "t_steady_s": 0.6, "fn_mean_N": 0.3}
        runs[(law, timing, engine)] = (sc, summary, df)
    return runs


@pytest.mark.parametrize("case, keys", [
    ("drag", [("stick_slip", "step", "pyref"), ("stick_slip", "step", "lammps")]),
    ("tray", [("stick_slip", "step", "pyref"), ("stick_slip", "step", "yade"), ("coulomb", "step", "pyref"),
              ("visco_plastic", "step", "pyref")]),
    ("tilt", [(law, timing, e) for law in ("stick_slip",) for timing in ("step", "exact")
              for e in ("pyref", "liggghts")]),
])
def test_every_legend_entry_names_its_engine_and_timing(monkeypatch, tmp_path, case, keys):
    """The report's figures of the paper's cases: every legend entry names the engine and the
    slip timing of its run (and the law where a figure shows several), and no two entries of
    one legend are the same (the tilt's figures show each engine in both timings)."""
    from stickslip import kinds, plotstyle

    legends = {}

    def save(fig, out, name, dpi=120):
        legends[name] = [[t.get_text() for t in ax.get_legend().get_texts()] for ax in fig.axes if ax.get_legend()]
        plotstyle.pyplot().close(fig)
        return name

    monkeypatch.setattr(plotstyle, "save", save)
    runs = _runs_of(case, keys)
    kinds.get(scene_mod.load(case).analysis["kind"]).figures(tmp_path, runs)
    assert legends and all(legends.values()), legends
    for name, axes in legends.items():
        for texts in axes:
            assert len(texts) == len(set(texts)), (name, texts)
            for text in texts:
                assert any(e in text and f"{t} timing" in text for _, t, e in keys), (name, text)


def test_a_chosen_runs_warnings_stay_in_its_summary_and_the_ladders_csv(tmp_path, capsys):
    """A run the report or a time-step ladder chose on purpose (the drag at 4 times its step:
    an impact on 20 steps, under the 25 an accurate collision needs) keeps its warning in its
    summary and prints nothing; the same run asked for by a user prints it. The ladder's CSV
    counts each run's warnings, and its one line says how many runs warned."""
    from stickslip.studies import precision

    dt = 4 * scene_mod.load("drag").dt
    _, summary, _ = run_named("drag", "pyref", tmp_path / "chosen", {"dt": dt, "duration": 0.02}, warn=False)
    assert summary["notes"] and capsys.readouterr().err == ""
    _, summary, _ = run_named("drag", "pyref", tmp_path / "asked", {"dt": dt, "duration": 0.02})
    assert capsys.readouterr().err == "".join(f"stickslip: warning: {n}\n" for n in summary["notes"])
    tasks, finish = precision.plan("drag", ["pyref"], tmp_path / "ladder", factors=(4, 2))
    assert all(args[4] is False for _, fn, args in tasks if fn is run_named)
    csv_path, _ = finish([fn(*args) for _, fn, args in tasks])
    assert capsys.readouterr().err == ""
    rows = list(csv.DictReader(open(csv_path)))
    # in 0.02 s the drag does not slip: its only warning is the impact's steps (stability.py)
    assert [int(r["warnings"]) > 0 for r in rows] == [
        stability.contact_steps(scene_mod.load("drag", dt=float(r["dt_s"]))) < stability.CONTACT_STEPS
        for r in rows] and len(rows) == 4, rows
    n = sum(int(r["warnings"]) > 0 for r in rows)
    assert precision.warned_line(csv_path).startswith(f"{n} of the ladder's {len(rows)} runs warn")
