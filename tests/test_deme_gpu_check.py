"""tools/deme_gpu_check.py's parts that need no GPU: the contract rows' prescribed motion
(expressions the engine compiles) against the states the rows state, and the summary."""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import contract_runners as runners
import deme_shim
import law_contract as lc

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
import deme_gpu_check as check  # noqa: E402


def test_contract_rows_prescribed_as_they_are_stated():
    """Each row's position, velocity and spin expressions, compiled as the engine's integration
    kernel runs them (functions of the float t), give at t = (k - 2) dt the state
    contract_runners._state gives step k (the engine's force step k sees the prescription of
    the step before; step 1 the initial state): to 1e-12 m, m/s, rad/s (doubles; the engine's
    grid of 64 m / 2^37 = 4.7e-10 m rounds them again)."""
    cases = [deme_shim.float_case(c) for c in lc.CASES]
    bases = check.row_layout(cases)
    funcs, wanted = [], []
    for c, (case, base) in enumerate(zip(cases, bases)):
        n_bodies = 1 if case.geometry == "wall" else 2
        for body in range(n_bodies):
            exprs = [e for group in check.row_prescription(case, body, base) for e in group]
            funcs.append(f"static void f{len(funcs)}(float t, double *o) {{ " +
                         " ".join(f"o[{i}] = {e};" for i, e in enumerate(exprs)) + " }")
            states, start, k = [], runners.rest_positions(case, case.segments[0].delta), 0
            for seg in case.segments:
                begin = start
                for s in range(1, seg.steps + 1):
                    x, v, w = runners._state(case, seg, s, begin)
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


def test_drag_bounds_pass_pyref_against_itself_and_catch_a_late_slip():
    """The drag's comparison on pyref's own run: every difference 0; the same run with the
    saw-tooth three steps later is out of the first slip's bound."""
    from stickslip import analysis, columns
    from stickslip import scene as scene_mod
    from pyref import Simulation

    sc = scene_mod.load("drag")
    df = columns.frame(sc, Simulation(sc).run())
    s = analysis.summarise(sc, df)
    for key, bound in check.drag_bounds(sc).items():
        assert s[key] is not None and bound > 0
    late = df.copy()
    c = "grain-floor"
    for col in (f"{c}_fs", f"{c}_slip", f"{c}_ftx"):
        late[col] = np.r_[np.zeros(3), late[col].to_numpy()[:-3]]
    s2 = analysis.summarise(sc, late)
    assert abs(s2["first_slip_s"] - s["first_slip_s"]) > check.drag_bounds(sc)["first_slip_s"]


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
