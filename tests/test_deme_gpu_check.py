# SPDX-License-Identifier: GPL-2.0-or-later
"""tools/deme_gpu_check.py's parts that need no GPU (and its modules deme_gpu_contract.py,
deme_gpu_bench.py, deme_fn_ring.py): the contract rows' prescribed motion (expressions the
engine compiles) against the states the rows state, the bounds, the bench and the summary."""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from stickslip.contract import cases as lc, deme_shim

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
import deme_fn_ring as fn_ring  # noqa: E402
import deme_gpu_bench as bench  # noqa: E402
import deme_gpu_check as check  # noqa: E402
import deme_gpu_contract as contract  # noqa: E402


def test_contract_rows_prescribed_as_they_are_stated():
    """Each row's position, velocity and spin expressions, compiled as the engine's integration
    kernel runs them (functions of the float t), give at t = (k - 2) dt the state
    cases.state gives step k (the engine's force step k sees the prescription of
    the step before; step 1 the initial state): to 1e-12 m, m/s, rad/s (doubles; the engine's
    grid of 64 m / 2^37 = 4.7e-10 m rounds them again)."""
    cases = [deme_shim.float_case(c) for c in lc.CASES]
    bases = contract.row_layout(cases)
    funcs, wanted = [], []
    for c, (case, base) in enumerate(zip(cases, bases)):
        n_bodies = 1 if case.geometry == "wall" else 2
        for body in range(n_bodies):
            exprs = [e for group in contract.row_prescription(case, body, base) for e in group]
            funcs.append(f"static void f{len(funcs)}(float t, double *o) {{ " +
                         " ".join(f"o[{i}] = {e};" for i, e in enumerate(exprs)) + " }")
            states, start, k = [], lc.rest_positions(case, case.segments[0].delta), 0
            for seg in case.segments:
                begin = start
                for s in range(1, seg.steps + 1):
                    x, v, w = lc.state(case, seg, s, begin)
                    states.append(np.r_[x[body] + base, v[body], w[body]])
                start = x
            wanted.append(np.array(states))
    src = ["#include <cmath>", "#include <cstdio>", "using std::cos; using std::sin;"] + funcs
    src.append("typedef void (*F)(float, double *); static F fs[] = {" + ", ".join(f"f{i}" for i in range(len(funcs)))
               + "};")
    src.append("int main() { int n; double o[9]; while (scanf(\"%d\", &n) == 1) { float t; scanf(\"%f\", &t); "
               "fs[n](t, o); for (int i = 0; i < 9; i++) printf(\"%.17g \", o[i]); printf(\"\\n\"); } }")
    tmp = Path(tempfile.mkdtemp())
    (tmp / "p.cpp").write_text("\n".join(src))
    subprocess.run(["g++", "-O0", "-o", str(tmp / "p"), str(tmp / "p.cpp")], check=True)
    queries = [(i, k) for i, states in enumerate(wanted) for k in range(2, len(states) + 1)]
    stdin = "".join(f"{i} {repr(float((k - 2) * lc.DT))}\n" for i, k in queries)
    got = subprocess.run([str(tmp / "p")], input=stdin, capture_output=True, text=True, check=True).stdout.split("\n")
    for (i, k), line in zip(queries, got):
        values = np.array(line.split(), float)
        assert np.allclose(values, wanted[i][k - 1], rtol=0, atol=1e-12), (i, k, values, wanted[i][k - 1])


def test_drag_bounds_pass_pyref_against_itself_and_catch_an_early_slip():
    """The drag's comparison on pyref's own run: every difference 0; the same run with the
    saw-tooth 12 steps earlier (as the engine gave with the grain placed as the scene states
    it, 0.95 nm high) is out of the first slip's bound. The fixed plane's ring on the
    emulated float geometry is pyref's own start (Fn = W to 1e-3)."""
    from stickslip import analysis, columns
    from stickslip import scene as scene_mod
    from pyref import Simulation

    sc = scene_mod.load("drag")
    ring = check.float_ring(sc)
    assert 0 < ring < 1e-3
    df = columns.frame(sc, Simulation(sc).run())
    s = analysis.summarise(sc, df)
    for key, bound in check.drag_bounds(sc, ring).items():
        assert s[key] is not None and bound > 0
    f = fn_ring.fn_spread(sc, df)  # pyref starts at its static overlap: Fn = W to 1e-3
    assert abs(f["first"] - 1) < 1e-3 and f["min"] <= f["first"] <= f["max"] < 1 + 1e-3
    early = df.copy()
    c = "grain-floor"
    for col in (f"{c}_fs", f"{c}_slip", f"{c}_ftx"):
        early[col] = np.r_[early[col].to_numpy()[12:], np.zeros(12)]
    s2 = analysis.summarise(sc, early)
    assert abs(s2["first_slip_s"] - s["first_slip_s"]) > check.drag_bounds(sc, ring)["first_slip_s"]


def test_compare_case_beside_the_emulation(tmp_path, monkeypatch):
    """compare_case on the drag with a stand-in engine that returns pyref's own run: every row
    within its bound, each with the emulated engine's figure beside it, the ring from the
    emulation (pyref's start: < 1e-3), and the summary prints them; with the shim missing
    (the emulation fails) the bounds that take the ring are nan, their rows OUT, said in one
    line."""
    import argparse
    from types import SimpleNamespace

    from stickslip import columns
    from stickslip.adapters import deme as adapter
    from pyref import Simulation

    monkeypatch.setattr(adapter, "run", lambda sc, out: SimpleNamespace(
        timeseries=columns.frame(sc, Simulation(sc).run()), notes=["stand-in"]))
    args = argparse.Namespace(work=str(tmp_path), tilt_every=50)
    res = check.compare_case("drag", args, log=lambda s: None)
    assert res["float_ring"] < 1e-3 and res["fn"]["emulated"]
    assert all(r["ok"] and r["emulated"] is not None for r in res["rows"]), res["rows"]
    res["ok"] = True
    (tmp_path / "drag.json").write_text(json.dumps(res))
    text = check.summary(argparse.Namespace(work=str(tmp_path), parts=["drag"]), 1.0)
    assert "fs_fn_min" in text and "(emulated 0.4" in text, text
    said = []

    def no_shim(sc):
        raise OSError("no libstickslip_deme_shim.so")

    monkeypatch.setattr(check, "emulated", no_shim)
    res = check.compare_case("drag", args, log=said.append)
    out = {r["quantity"] for r in res["rows"] if not r["ok"]}
    assert out == {"fs_fn_min", "fs_fn_mean", "first_slip_s", "slip_period_s"}, out
    assert any("no emulated float geometry" in s for s in said)


def test_summary_reads_every_part(tmp_path):
    """The printed summary from each part's JSON (a failed part prints its error)."""
    work = tmp_path / "w"
    work.mkdir()
    (work / "contract.json").write_text(json.dumps({"ok": True, "init_s": 100.0, "rows": [
        {"row": "threshold_reached_slips", "contract": "pass", "vs_cpu_ulps": 0.0, "vs_cpu_slips_equal": True}]}))
    (work / "drag.json").write_text(json.dumps({"ok": True, "wall_s": 12.0, "rows": [
        {"quantity": "fs_fn_max", "deme": 0.4999, "pyref": 0.5, "diff": -1e-4, "bound": 8e-4, "ok": True}]}))
    (work / "bench.json").write_text(json.dumps({"ok": False, "error": "RuntimeError: out of memory"}))
    args = check.main.__globals__["argparse"].Namespace(work=str(work), parts=["contract", "drag", "bench"])
    text = check.summary(args, 300.0)
    assert "contract on the GPU: 1 of 1 rows pass" in text and "fs_fn_max" in text
    assert "bench: RuntimeError: out of memory" in text


class _BenchSolver:
    """A stand-in for the bench's DEMSolver: records what it is asked, steps nothing, and
    prints its statistics with C printf in the engine's format (DEMSolver::ShowTimingStats,
    ShowThreadCollaborationStats)."""

    log = []
    made = 0

    def __init__(self, *a):
        self.freq = None
        # a serial number, not id(): a solver the bench has let go may leave its address to
        # the next one, and two solvers would log as one
        _BenchSolver.made += 1
        self.serial = _BenchSolver.made

    def __getattr__(self, name):
        def call(*args):
            _BenchSolver.log.append((self.serial, name, args))
            if name == "SetCDUpdateFreq":
                self.freq = args[0]
            return {"GetNumContacts": 1523200, "GetUpdateFreq": float(self.freq or 37.5),
                    "GetBinSize": 4.25e-3}.get(name)
        return call

    def ShowThreadCollaborationStats(self):
        import ctypes
        libc = ctypes.CDLL(None)
        libc.printf(b"\n~~ kT--dT CO-OP STATISTICS ~~\nNumber of steps dynamic executed: %d\n", 20000)
        libc.printf(b"Number of updates kinematic gets: %d\nAverage steps per dynamic update: %s\n", 400, b"50")

    def ShowTimingStats(self):
        import ctypes
        libc = ctypes.CDLL(None)
        libc.printf(b"\n~~ kT TIMING STATISTICS ~~\nkT total active time: %s seconds\n", b"1.5")
        libc.printf(b"\n~~ dT TIMING STATISTICS ~~\ndT total active time: %s seconds\n", b"9.25")
        libc.printf(b"Calculate contact forces: %s seconds, 60%% of dT total runtime\n", b"5.5")


def test_bench_reads_the_engines_own_statistics(tmp_path, monkeypatch):
    """The bench, on a stand-in engine: both models alternated each round; with --cd-freq the
    pair again with detection every N steps and a fixed bin size for both (adaptive
    scheduling off); with --control the engine's model in two solvers (adaptive); each pair's
    first stock solver waits for warm_stock's compile; the engine's printed statistics read
    back as numbers and shown in the summary."""
    from stickslip.adapters import deme as adapter

    fake = type("FakeDeme", (), {"DEMSolver": _BenchSolver})
    monkeypatch.setattr(adapter, "_import_deme", lambda: fake)
    monkeypatch.setattr(adapter, "helper", lambda: type("H", (), {"attach": staticmethod(lambda *a, **k: None)}))
    work = tmp_path / "w"
    work.mkdir()
    args = check.main.__globals__["argparse"].Namespace(
        work=str(work), parts=["bench", "warm_stock"], bench_grid=2, rounds=3, bench_steps=10, settle_steps=5,
        cd_freq=20, control=True, t0=check.time.time(), deadline=60.0)
    _BenchSolver.log = []
    monkeypatch.setattr(bench, "wait_json", lambda path, timeout: _BenchSolver.log.append((None, "wait", path.name)))
    out = bench.run_bench(args, lambda msg: None)
    # each pair waits once for warm_stock, before its first stock solver is made
    calls = [(name, a) for i, name, a in _BenchSolver.log if name in ("wait", "UseFrictionalHertzianModel")]
    assert calls == [("wait", "warm_stock.json"), ("UseFrictionalHertzianModel", ())] * 3 \
        + [("UseFrictionalHertzianModel", ())], calls
    assert len(out["ratios"]) == 3 and len(out["fixed_cd"]["ratios"]) == 3 and len(out["control"]["ratios"]) == 3
    # the control's two solvers are both the engine's model, detection adaptive; the pairs'
    # first solvers are the force model (attach, stubbed here: no engine model called)
    stock = {i for i, name, a in _BenchSolver.log if name == "UseFrictionalHertzianModel"}
    assert len(stock) == 4 and out["control"]["pair"] == ["stock_a", "stock_b"]
    assert out["control"]["update_freq"]["stock_b"] == [37.5] * 3 and out["bin_size"]["stickslip"] == [4.25e-3] * 3
    assert out["engine_stats"]["stock"]["Number of updates kinematic gets"] == 400
    assert out["engine_stats"]["stickslip"]["dT: Calculate contact forces"] == 5.5
    assert out["engine_stats"]["stock"]["kT: kT total active time"] == 1.5
    assert out["update_freq"]["stock"] == [37.5] * 3 and out["fixed_cd"]["update_freq"]["stock"] == [20.0] * 3
    fixed = {i for i, name, a in _BenchSolver.log if name == "DisableAdaptiveUpdateFreq"}
    assert len(fixed) == 2 and all((i, "SetCDUpdateFreq", (20,)) in _BenchSolver.log for i in fixed)
    assert fixed == {i for i, name, a in _BenchSolver.log if name == "DisableAdaptiveBinSize"}
    (work / "bench.json").write_text(json.dumps({**out, "ok": True}, default=str))
    text = check.summary(args, 100.0)
    assert "contact detection: adaptive" in text and "contact detection: 20" in text
    assert "stick-slip / stock per round" in text and "stock (a) / stock (b) per round" in text
    assert "A/A control" in text and "bin size after each block (m): stick-slip 0.00425, 0.00425" in text
    assert "Number of updates kinematic gets 400" in text and "dT: Calculate contact forces 5.5" in text


def test_the_pages_gpu_figure_is_made_from_the_stored_series(tmp_path):
    """tools/deme_gpu_figure.py draws deme_model/README.md's picture from the GPU check's time
    series kept in deme_model/measured/, and the page's figures are those series': the drag's
    slips on pyref's steps, the tilt's Fn / (W cos beta) between 0.646 and 1.350 (its one event)."""
    import deme_gpu_figure as fig
    import pandas as pd

    from stickslip import scene

    ROOT = Path(__file__).resolve().parents[1]
    png = fig.main(ROOT / "deme_model" / "measured", tmp_path / "f.png")
    assert png.stat().st_size > 20_000
    st = scene.load("tilt")
    t, ratio = fn_ring.sticking_fn_over_weight(st, pd.read_csv(ROOT / "deme_model" / "measured" / "tilt_deme.csv.gz"))
    assert (round(ratio.min(), 3), round(ratio.max(), 3)) == (0.646, 1.350)
    assert round(t[-1] + (t[1] - t[0]), 4) == 0.9272  # the first slip's row: the page's 0.9272 s
    quiet = np.abs(ratio[t < 0.444] - 1)
    assert quiet.max() < 1.3e-3  # the page's 0.9990-1.0013 before the event
    page = (ROOT / "deme_model" / "README.md").read_text()
    assert "tools/deme_gpu_figure.py" in page and "measured/drag_tilt_gpu.png" in page
