# SPDX-License-Identifier: GPL-2.0-or-later
"""What accuracy costs (issue 5): dt ladders, the every-step-slips speed, the warning."""
import copy
import csv

import numpy as np
import pytest

from stickslip import analysis
from stickslip import scene as scene_mod
from stickslip.studies.precision import run_precision
from stickslip.studies.thresholds import formula, measure
from conftest import run_pyref, skip_engine


@pytest.mark.parametrize("dt,nu_s", [(1e-6, 0.0), (4e-6, 33.1), (1.6e-5, 100.0)])
def test_every_step_slips_above_the_formula_speed(dt, nu_s):
    """V* = 2(mu_s - mu_k)Fn/(Ks dt + nu_s), measured by bisection to 0.1 %: the measured
    speed must agree to the bisection's resolution (the formula is exact for the law)."""
    base = scene_mod.load("drag")
    measured, predicted = measure(base, dt, nu_s, rel_tol=1e-3)
    assert measured == pytest.approx(predicted, rel=1e-3)


def test_precision_ladder_on_drag(tmp_path):
    csv_path, orders = run_precision("drag", ["pyref"], tmp_path, progress=False)
    rows = list(csv.DictReader(open(csv_path)))
    dts = sorted({float(r["dt_s"]) for r in rows})
    assert len(rows) >= 12 and dts[-1] / dts[0] >= 10**1.5
    assert (tmp_path / "precision_drag_work.png").is_file() and (tmp_path / "precision_drag_dt.png").is_file()
    # The reference is the exact-timing run at the finest step, never a run at the measured dt.
    (ref,) = [r for r in rows if r["reference"] == "True"]
    assert ref["slip_timing"] == "exact" and float(ref["dt_s"]) == dts[0]
    err = {(r["slip_timing"], float(r["dt_s"])): float(r["err_mean_friction"])
           for r in rows if r["reference"] == "False"}
    step = {dt: e for (m, dt), e in err.items() if m == "step"}
    # The coarsest step is further from the reference than the finest one; first order or better.
    assert step[max(step)] > step[min(step)]
    assert orders[("pyref", "step", "mean_friction")] > 0.5
    # Placing the slips at their time is never less accurate than testing at the step's end.
    for dt in dts[1:]:
        assert err[("exact", dt)] <= err[("step", dt)], dt


def test_under_resolved_run_warns_once_and_resolved_run_does_not():
    sc = scene_mod.load("drag")
    df, _ = run_pyref(sc)
    assert analysis.warnings(sc, analysis.summarise(sc, df)) == []
    fast = copy.deepcopy(sc)
    v_star = formula(sc, sc.dt, sc.contact.nu_s, sc.grain_mass(sc.grains[0]) * 9.81)
    fast.grains[0].velocity = np.array([3 * v_star, 0.0, 0.0])  # every step slips
    df, _ = run_pyref(fast)
    w = analysis.warnings(fast, analysis.summarise(fast, df))
    assert len(w) == 1 and "under-resolves the stick phase" in w[0]


def test_precision_reference_engine(tmp_path):
    """`--reference liggghts`: the finest exact-timing LIGGGHTS run is the reference and
    pyref's need not run at all. On the drag, LIGGGHTS equals pyref at equal dt to
    round-off, so the errors must be those of a pyref-referenced ladder to 1e-9
    (relative errors ~1e-5..1e-2, round-off ~1e-13)."""
    from stickslip import adapters

    skip_engine("liggghts")
    factors = (4, 2, 1, 0.5)
    lig, _ = run_precision("drag", ["liggghts"], tmp_path / "lig", factors, progress=False, reference="liggghts")
    ref, _ = run_precision("drag", ["pyref"], tmp_path / "ref", factors, progress=False)
    rows_l = list(csv.DictReader(open(lig)))
    rows_p = list(csv.DictReader(open(ref)))
    assert {r["engine"] for r in rows_l} == {"liggghts"}
    assert [(r["slip_timing"], float(r["dt_s"])) for r in rows_l if r["reference"] == "True"] == \
        [("exact", min(factors) * 2e-6)]
    for a, b in zip(rows_l, rows_p):
        assert (a["slip_timing"], float(a["dt_s"])) == (b["slip_timing"], float(b["dt_s"]))
        for k in ("err_mean_friction", "err_slip_period"):
            if a["reference"] == "False":
                assert float(a[k]) == pytest.approx(float(b[k]), rel=1e-9, abs=1e-12)
