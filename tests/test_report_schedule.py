# SPDX-License-Identifier: GPL-2.0-or-later
"""How the report spends its two cores (issue 25): every task's cost in seconds, so the
longest runs start first whatever their kind, and a run asked for twice runs once."""
import pytest

from stickslip import parallel, report, runner
from stickslip import scene as scene_mod
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
