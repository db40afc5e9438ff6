# SPDX-License-Identifier: GPL-2.0-or-later
"""Issue 51, `stickslip calibrate` with uncertainties: targets with their standard errors or a
file of repeats, the map's interpolation chosen by leave-one-out, ranges with a stated meaning
(delta chi2 = 1 profiled, 2.30 joint) flagged where the map's edge cuts them, the region's
figure, and the round trip's coverage machinery (granular3d_calibration.py) on synthetic maps
whose answers are known. The committed page's examples: test_granular3d.py."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pandas as pd
import pytest

from stickslip.cli import main
from stickslip.studies import calibrate, calibrate_fit, calibrate_map, granular3d_calibration
from test_granular3d import _synthetic_map

SLOPE = 20.0  # deg per unit of mu_s: the synthetic map's theta_start = 20 + 20 mu_s


def _surf(path, method="auto"):
    return calibrate.prepare(calibrate_map.read_points(path), 0.0, method)[0]


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    """The synthetic map's surfaces (made once: the leave-one-out and the grid take a while)."""
    return _surf(_synthetic_map(tmp_path_factory.mktemp("synthetic")))


@pytest.fixture(scope="module")
def precise(tmp_path_factory):
    return _surf(_precise_map(tmp_path_factory.mktemp("precise")))


def _half_width(r, name):
    lo, hi = r.ranges[name]
    return (hi - lo) / 2


def _precise_map(tmp_path):
    """The synthetic map measured precisely: every point's se 0.01 (the floor, 0.05, counts)."""
    path = _synthetic_map(tmp_path)
    pts = pd.read_csv(path)
    pts[[c for c in pts if c.endswith("_se")]] = 0.01
    pts.to_csv(path, index=False)
    return path


@pytest.mark.parametrize("se, n, k", [(0.4, None, 1.0), (0.4, 3, 1.3213), (0.4, 2, 1.8374), (0.8, 4, 1.1969)])
def test_a_range_is_the_target_error_over_the_slope_times_students_factor(precise, se, n, k):
    """theta_start = 20 + 20 mu_s depends on mu_s alone, so with mu_k profiled (theta_stop met
    by mu_k, within a grid step's 0.1 deg, well inside its 0.5) chi2 = k^2 where theta_start is off
    by one error: on a precise map mu_s's half-range is k se_target / 20, k Student's t (84.13 %)
    at n - 1 degrees of freedom (1 for a known error), to the grid's step."""
    r = calibrate_fit.solve({"theta_start": calibrate_fit.Target(34.0, se, n),
                             "theta_stop": calibrate_fit.Target(21.0, 0.5)}, precise)
    assert (r.mu_s, r.mu_k) == pytest.approx((0.7, 0.5), abs=calibrate_fit.GRID)
    assert _half_width(r, "mu_s") == pytest.approx(k * se / SLOPE, abs=calibrate_fit.GRID) and r.cut == {}


def test_the_maps_error_is_its_points_weighted_mean(synthetic):
    """An exact target on the map of se 0.3: the prediction there is a weighted mean of the
    points (barycentric weights), its se sqrt(sum w^2) 0.3, from 0.3 / sqrt(3) at a triangle's
    centre to 0.3 at a point; mu_s's half-range is that over the slope."""
    surf = synthetic
    r = calibrate_fit.solve({"theta_start": calibrate_fit.Target(34.0), "theta_stop": calibrate_fit.Target(21.0)},
                            surf)
    assert 0.3 / math.sqrt(3) / SLOPE - calibrate_fit.GRID < _half_width(r, "mu_s") < 0.3 / SLOPE + calibrate_fit.GRID
    var = surf.pred["theta_start"][1]
    assert np.nanmin(var) == pytest.approx(0.09 / 3, rel=0.01) and np.nanmax(var) == pytest.approx(0.09)


def test_the_joint_region_is_wider_than_the_profiled_range(synthetic):
    """Delta chi2 = 2.30 (two coefficients at 68 %, known errors) holds points that delta chi2 = 1
    does not: along mu_s alone a point 1.2 half-ranges from the answer is outside the range and
    inside the joint region (1.2^2 = 1.44 < 2.30)."""
    r = calibrate_fit.solve({"theta_start": calibrate_fit.Target(34.0, 0.3),
                             "theta_stop": calibrate_fit.Target(21.0, 0.3)}, synthetic)
    h = _half_width(r, "mu_s")
    k_best = r.mu_k + 0.5 * 1.2 * h  # theta_stop = 15 + 20 (2 mu_k - mu_s) unchanged
    assert r.delta == {"mu_s": 1.0, "mu_k": 1.0, "joint": calibrate_fit.DELTA_JOINT}
    assert 1.0 < r.delta_at(r.mu_s + 1.2 * h, k_best) < calibrate_fit.DELTA_JOINT


def _answer(capsys, *argv):
    """calibrate's whole answer (--json) for these arguments."""
    assert main(["calibrate", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_file_of_repeats_gives_the_mean_and_its_standard_error(tmp_path, capsys):
    """Three repeats of theta_start around 34 (33.6, 34.0, 34.4: se 0.231) and two of theta_stop
    (20.8, 21.2: se 0.2): the answer is the means', the targets line of --details says what was
    taken; on a precise map mu_s's range comes from theta_start's 3 repeats alone: Student's t at
    2 dof."""
    path = _precise_map(tmp_path)
    (tmp_path / "m.csv").write_text("theta_start,theta_stop\n33.6,20.8\n34.0,21.2\n34.4,\n")
    given = ["--measurements", str(tmp_path / "m.csv"), "--map", str(path)]
    assert main(["calibrate", *given, "--details"]) == 0
    out = capsys.readouterr().out
    assert "targets: theta_start 34.00 +- 0.23 deg (mean of 3), theta_stop 21.00 +- 0.20 deg (mean of 2)" in out
    assert "chi2 within (k f)^2 of its least, the other coefficient profiled" in out
    a = _answer(capsys, *given)
    (lo, hi), ms = a["mu_s"]["range"], a["mu_s"]["value"]
    assert ms == pytest.approx(0.7, abs=0.005) and lo < 0.7 < hi
    assert 1.29 < a["mu_s"]["k"] < 1.33 and 2.0 <= a["mu_s"]["dof"] < 2.2  # the map's floor (0.05 deg) adds a little
    se = 0.4 / math.sqrt(3)
    assert a["targets"]["theta_start"] == {"value": pytest.approx(34.0), "se": pytest.approx(se), "n": 3}


@pytest.mark.parametrize("lo, hi, shown", [(0.505, 0.645, "0.58 (0.50 to 0.65"), (0.503, 0.893, "0.58 (0.50 to 0.90"),
                                           (0.5675, 0.5925, "0.580 (0.567 to 0.593"), (0.35, 0.85, "0.6 (0.3 to 0.9"),
                                           (0.58, 0.58, "0.580 (0.580 to 0.580"), (0.35, 0.93, "0.6 (0.3 to 0.93"),
                                           (0.21, 0.85, "0.6 (0.21 to 0.9")])
def test_the_answer_has_the_digits_its_range_allows(lo, hi, shown):
    """The value and its range to the decimal of the range's half-width's first significant
    digit (two digits where it is 1), from 1 to 3 decimals (the grid's step is 0.0025); the
    range rounded outwards, so that the printed range holds the computed one, but never onto
    the map's extent (here mu_s 0.2 to 1.0), which would read as its edge: 0.93 stays 0.93,
    0.21 stays 0.21."""
    c = {"value": 0.58, "range": [lo, hi], "cut": {"low": None, "high": None}, "extent": [0.2, 1.0]}
    assert calibrate._coefficient_line("mu_s", c) == f"mu_s = {shown})"


# Ranges calibrate gave on the committed map, as (low, high), the edges cutting each end, the map's
# extent: 24.5/21.5 deg's mu_s and 25.8/22.6 deg's mu_k and mu_s (both ends cut there).
ANSWERED = [((0.3475, 0.93), (("mu_k = mu_s",), None), (0.2, 1.0)),
            ((0.4925, 0.94), (("mu_k = mu_s / 2",), None), (0.1, 1.0)),
            ((0.7475, 1.0), (("mu_k = mu_s",), ("map",)), (0.2, 1.0)),
            ((0.2, 0.4975), (("map", "mu_k = mu_s"), ("mu_k = mu_s / 2",)), (0.2, 1.0))]


@pytest.mark.parametrize("computed, cuts, extent", ANSWERED)
def test_the_printed_range_holds_the_computed_one_and_names_only_real_edges(computed, cuts, extent):
    """Each printed end lies outside or on the computed range; an end named an edge is printed
    as the computed end itself (the edge's value there), with every edge that cuts it named;
    an uncut end is never printed on the map's extent (which would read as its edge)."""
    c = {"value": sum(computed) / 2, "range": list(computed), "cut": dict(zip(("low", "high"), cuts)),
         "extent": list(extent)}
    line = calibrate._coefficient_line("mu_k", c)
    m = re.match(r"mu_k = [\d.]+ \(([\d.]+) to ([\d.]+)((?:; [\d.]+ is [^;]+, not an uncertainty)*)\)$", line)
    assert m, line
    lo, hi = float(m.group(1)), float(m.group(2))
    assert lo <= computed[0] and hi >= computed[1], line
    named = re.findall(r"; ([\d.]+) is ([^;]+), not an uncertainty", m.group(3))
    assert [float(v) for v, _ in named] == [v for v, cut in zip(computed, cuts) if cut], line
    assert [w for _, w in named] == [" and ".join(calibrate.EDGE[e] for e in cut) for cut in cuts if cut], line
    for v, cut in zip((lo, hi), cuts):
        assert cut or extent[0] < v < extent[1], line


def test_the_answer_comes_first_and_only_the_targets_given_are_shown(synthetic, tmp_path, capsys):
    """The plain answer: mu_s's and mu_k's lines, then one line on what the ranges mean; no
    statistics (those are --details'), and in --details and --json only the targets given."""
    path = _synthetic_map(tmp_path)
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "21", "--theta-stop-se", "0.3",
                 "--map", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    # the synthetic map has no leave_pair_out.csv beside it: the first line says the ranges are not widened
    assert lines[0].startswith(f"note: no leave_pair_out.csv beside --map {path}: the ranges are not widened")
    assert lines[1].startswith("mu_s = 0.70") and lines[2].startswith("mu_k = 0.50") and len(lines) == 4
    assert lines[3].startswith("each range: where its coefficient lies with 68 % confidence, the other left free")
    assert lines[3].endswith("the targets' errors; not widened (first line)); --details: the statistics")
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "21", "--map", str(path), "--details"]) == 0
    out = capsys.readouterr().out
    assert "the map at the answer: theta_start 34.0 +- " in out and "theta_heap" not in out
    a = _answer(capsys, "--theta-start", "34", "--theta-stop", "21", "--map", str(path))
    assert set(a["targets"]) == set(a["map_at_answer"]) == set(a["interpolation"]["own_error"]) == {"theta_start",
                                                                                                    "theta_stop"}


def test_the_range_cut_by_the_maps_edge_is_called_a_bound(tmp_path, capsys):
    """A target near mu_s = 0.8 (theta_start 35.8 +- 0.6: mu_s 0.79 +- 0.03) reaches the map's
    edge; one near mu_k = mu_s (theta_stop for mu_k = mu_s - 0.01) reaches the law's bound."""
    path = _synthetic_map(tmp_path)
    assert main(["calibrate", "--theta-start", "35.8", "--theta-start-se", "0.6", "--theta-stop", "20.8",
                 "--map", str(path), "--region-png", str(tmp_path / "r.png")]) == 0
    out = capsys.readouterr().out
    assert "mu_s = 0.79 (0.76 to 0.80; 0.80 is the map's edge, not an uncertainty)" in out
    assert "edge:" not in out  # the answer, 0.79, is inside; only its range reaches the edge
    assert (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f"wrote {tmp_path / 'r.png'}" in out
    a = _answer(capsys, "--theta-start", "32", "--theta-stop", "26.8", "--theta-stop-se", "0.5", "--map", str(path))
    assert "mu_k = mu_s" in (a["mu_k"]["cut"]["high"] or []) + (a["mu_s"]["cut"]["low"] or [])


def test_an_answer_on_the_maps_edge_or_on_a_laws_bound_is_told(tmp_path, capsys):
    """theta_start 36.5 +- 0.6 on the synthetic map (20 + 20 mu_s: 36 at its edge mu_s = 0.8) is
    within 3 standard errors of the map, so it is answered, at mu_s = 0.800, where the map stops:
    calibrate says that the map does not bracket the answer. An answer on one of the law's bounds
    is told the same way: theta_stop of mu_k = mu_s (a history contact) and theta_stop below what
    mu_k = mu_s / 2 gives (15 + 20 (2 mu_k - mu_s): 15 at the bound)."""
    path = _synthetic_map(tmp_path)
    assert main(["calibrate", "--theta-start", "36.5", "--theta-start-se", "0.6", "--theta-stop", "20.8",
                 "--map", str(path)]) == 0
    out = capsys.readouterr().out
    assert "edge: the answer lies on the map's edge (mu_s 0.800, mu_k " in out and "mu_s = 0.80" in out
    _curved_map(tmp_path, lambda s, k: 20 + 20 * s)  # the dense layout: points on mu_k = mu_s / 2 too
    surf = _surf(path)
    for stop, bound in ((27.0, "mu_k = mu_s"), (14.6, "mu_k = mu_s / 2")):
        r = calibrate_fit.solve({"theta_start": calibrate_fit.Target(32.0),
                                 "theta_stop": calibrate_fit.Target(stop, 0.5)}, surf)
        assert r.edge == (bound,) and r.mu_k == pytest.approx(r.mu_s if bound == "mu_k = mu_s" else r.mu_s / 2,
                                                             abs=calibrate_fit.GRID)
    assert main(["calibrate", "--theta-start", "32", "--theta-stop", "14.6", "--theta-stop-se", "0.5",
                 "--map", str(path)]) == 0
    assert "edge: the answer lies on the law's bound mu_k = mu_s / 2 (mu_s 0.600, " in capsys.readouterr().out
    r = calibrate_fit.solve({"theta_start": calibrate_fit.Target(32.0), "theta_stop": calibrate_fit.Target(21.0)}, surf)
    assert r.edge == ()


@pytest.mark.parametrize("argv, message", [
    (["--theta-start", "34", "--theta-start-se", "-1", "--theta-stop", "21"], "must be a standard error in [0, 90)"),
    (["--theta-start", "34", "--theta-stop", "21", "--interpolation", "cubic"], "invalid choice: 'cubic'"),
    (["--theta-start", "34", "--theta-stop-se", "0.3", "--theta-heap", "22"], "--theta-stop-se 0.3: give --theta-stop "
                                                                            "too"),
    (["--measurements", "m.csv", "--theta-start", "34"], "--theta-start 34: theta_start is also in --measurements"),
    (["--measurements", "bad_column.csv"], "column 'theta_go': the columns must be among theta_start, theta_stop"),
    (["--measurements", "one.csv"], "theta_stop has 1 value(s): needs n >= 2 repeats"),
    (["--measurements", "text.csv"], "theta_stop = 'flat': not a number"),
    (["--measurements", "range.csv"], "theta_start = 95: must be an angle in degrees, in (0, 90)"),
    (["--measurements", "missing.csv"], "cannot be read as CSV"),
    (["--theta-start", "34", "--shear-peak", "0.5"], "--shear-peak: the map has no shear3d measurements (stickslip "
                                                      "study-3d --groups shear measures them)"),
    (["--theta-start", "34", "--shear-steady", "7"], "must be a stress ratio, in (0, 5)"),
])
def test_bad_calibrate_input_is_one_line_with_status_2(tmp_path, capsys, monkeypatch, argv, message):
    path = _synthetic_map(tmp_path)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "m.csv").write_text("theta_start,theta_stop\n34,21\n34.2,21.2\n")
    (tmp_path / "bad_column.csv").write_text("theta_start,theta_go\n34,21\n34.2,21.2\n")
    (tmp_path / "one.csv").write_text("theta_start,theta_stop\n34,21\n34.2,\n")
    (tmp_path / "text.csv").write_text("theta_start,theta_stop\n34,21\n34.2,flat\n")
    (tmp_path / "range.csv").write_text("theta_start,theta_stop\n95,21\n34.2,21.1\n")
    try:
        code = main(["calibrate", *argv, "--map", str(path)])
    except SystemExit as e:  # argparse's refusals
        code = e.code
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1, err


def _broken(rows, column, value):
    rows[column] = rows[column].astype(object)
    rows.loc[2, column] = value
    return rows


@pytest.mark.parametrize("change, message", [
    (lambda p: p.drop(columns="engine"), "no column 'engine': a map has the columns kind, engine, group"),
    (lambda p: p.drop(columns=[c for c in p if c.endswith("_mean")]), "no column of a target's mean: expected one of "
                                                                     "theta_start_mean"),
    (lambda p: p.drop(columns="theta_stop_se"), "column theta_stop_mean has no theta_stop_se beside it"),
    (lambda p: _broken(p, "mu_k", "half"), "column mu_k, line 4: 'half': expected a finite number"),
    (lambda p: _broken(p, "mu_s", np.nan), "column mu_s, line 4: empty: expected a finite number"),
    (lambda p: _broken(p, "theta_start_mean", "inf"), "column theta_start_mean, line 4: 'inf': expected a finite "
                                                       "number"),
    (lambda p: _broken(p, "theta_start_se", np.nan), "column theta_start_se, line 4: empty: expected a finite number "
                                                      "(the standard error of the mean beside it)"),
    (lambda p: p.assign(rolling=0.2), "column rolling has no map rows at --rolling 0: it was measured at 0.2 only"),
    (lambda p: p.assign(engine="lammps"), "no rows with engine 'liggghts' and group 'sweep' or 'shear'"),
    (None, "cannot be read as CSV"),
    # a NaN written in a map cell, and an empty one where the row's kind measures the target
    (lambda p: _broken(p, "theta_stop_mean", "nan"), "column theta_stop_mean, line 4: 'nan': expected a finite number"),
    (lambda p: _broken(p.assign(theta_start_n=3), "theta_start_n", "NaN"), "column theta_start_n, line 4: 'NaN': expected a finite number"),
    (lambda p: _broken(p, "theta_start_mean", np.nan), "column theta_start_mean, line 4: empty: expected a finite "
                                                        "number (a map row of kind incline measures theta_start)"),
    # a column renamed: its statistics without their mean, or a name study-3d does not write
    (lambda p: p.rename(columns={"theta_stop_mean": "theta_stop_avg"}), "column 'theta_stop_avg' is not a column of "
                                                                         "a map"),
    (lambda p: p.drop(columns="theta_stop_mean"), "column theta_stop_se has no theta_stop_mean beside it"),
    # a row twice, and one map point twice (another material's name, the same point)
    (lambda p: pd.concat([p, p.iloc[[2]]]), "line 18 repeats line 4: each row once"),
    (lambda p: pd.concat([p, p.iloc[[2]].assign(theta_start_mean=40.0)]), "lines 4 and 18: two map points of kind "
                                                                          "incline at mu_s 0.35, mu_k 0.35"),
])
def test_a_malformed_map_is_one_line_naming_the_file_and_column(tmp_path, capsys, change, message):
    """A map that is not study-3d's points.csv (a column missing or of the wrong type, an empty
    cell where a number belongs, no rows at the rolling resistance asked) is refused in one
    line naming the file, the column and what was expected, never a traceback."""
    path = _synthetic_map(tmp_path)
    if change is None:
        path.write_bytes(b"\xff\xfe\x00binary")
    else:
        change(pd.read_csv(path, dtype={"nu_s": str})).to_csv(path, index=False)
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "21", "--map", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"stickslip: error: --map {path}: ") and message in err and err.count("\n") == 1, err


def _curved_map(tmp_path, surface, mus=(0.2, 0.35, 0.5, 0.65, 0.8), se=0.05):
    """A points.csv of the dense map's layout (history on the diagonal, and on each row of
    mu_s a point on mu_k = mu_s / 2 and one half way) with theta_start = surface(mu_s, mu_k)."""
    rows = []
    for ms in mus:
        for mk in (ms, ms / 2, 0.75 * ms):
            rows.append({"kind": "incline", "engine": "liggghts", "group": "sweep", "mu_s": ms, "mu_k": round(mk, 4),
                         "nu_s": "0" if mk == ms else "paper", "timing": "step", "rolling": 0.0,
                         "theta_start_mean": surface(ms, mk), "theta_start_se": se,
                         "theta_stop_mean": 15 + 20 * (2 * mk - ms), "theta_stop_se": se})
    pd.DataFrame(rows).to_csv(tmp_path / "points.csv", index=False)
    return calibrate_map.from_points(calibrate_map.read_points(tmp_path / "points.csv"), 0.0)


def test_leave_one_out_chooses_the_interpolation_that_predicts_the_left_out_points(tmp_path):
    """A quadratic surface is predicted exactly by the quadratic fit and not by the linear
    triangulation (it curves between the points): quadratic chosen, its own error ~0. A surface
    with a kink at mu_s = 0.35 (stock history's saturation) is not a quadratic: the linear one,
    whose triangles end at the kink, predicts it better."""
    rows = calibrate_map.loo(_curved_map(tmp_path, lambda s, k: 20 + 30 * s - 25 * s * s + 8 * s * k))
    assert calibrate_map.choose(rows) == "quadratic"
    err = calibrate_map.interp_error(rows)
    assert err["theta_start", "quadratic"][0] < 0.01 < err["theta_start", "linear"][0]
    q = rows[(rows.method == "quadratic") & (rows.target == "theta_start")]
    assert np.nanmax(np.abs(q.residual)) < 1e-6 and np.isfinite(q.residual).sum() >= 9  # all but hull corners
    rows = calibrate_map.loo(_curved_map(tmp_path, lambda s, k: 20 + 25 * min(s, 0.35) + 2 * s))
    assert calibrate_map.choose(rows) == "linear"


def test_the_interpolation_is_a_weighted_mean_of_the_points(tmp_path):
    """Both interpolations give w . y with the weights summing to 1 (a constant surface is
    reproduced) and the variance sum w^2 se^2: for the quadratic this is the fit's covariance."""
    m = _curved_map(tmp_path, lambda s, k: 25.0, se=0.3)["theta_start"]
    at = np.array([[0.6, 0.45], [0.3, 0.2], [0.9, 0.5]])
    for method in calibrate_map.METHODS:
        w = calibrate_map.weights(method, m, at)
        assert np.allclose(w[:2].sum(axis=1), 1.0) and np.isnan(w[2]).all()  # (0.9, 0.5): outside the hull
    a = calibrate_map._design(m.xy)
    cov = np.linalg.inv(a.T @ (a / m.se[:, None] ** 2))
    x = calibrate_map._design(at[:1])
    _, var, _ = calibrate_map.predict(calibrate_map.weights("quadratic", m, at[:1]), m)
    assert var[0] == pytest.approx((x @ cov @ x.T).item())


def _coverage_points(rng, pairs, fills=3, spread=0.5):
    """A planar map measured precisely (se 0.02) and `pairs` random true pairs inside it, each
    measured on `fills` fills with a Gaussian spread per fill: the points of a study's tables."""
    rows = []
    for ms in (0.2, 0.35, 0.5, 0.65, 0.8):
        for mk in (ms, ms / 2, 0.75 * ms):
            rows.append({"kind": "incline", "group": "sweep", "mu_s": ms, "mu_k": mk, "nu_s": "paper",
                         "theta_start_mean": 20 + 20 * ms, "theta_start_se": 0.02,
                         "theta_stop_mean": 15 + 20 * (2 * mk - ms), "theta_stop_se": 0.02})
    seen = set()
    while len(seen) < pairs:  # distinct pairs on the grid
        ms = round(rng.uniform(0.35, 0.7) / 0.0025) * 0.0025
        mk = round(ms * (0.5 + 0.5 * rng.uniform(0.25, 0.75)) / 0.0025) * 0.0025
        if (ms, mk) in seen:
            continue
        seen.add((ms, mk))
        start = 20 + 20 * ms + spread * rng.standard_normal(fills)
        stop = 15 + 20 * (2 * mk - ms) + spread * rng.standard_normal(fills)
        rows.append({"kind": "incline", "group": "coverage", "mu_s": ms, "mu_k": mk, "nu_s": "paper", "fills": fills,
                     "theta_start_mean": start.mean(), "theta_start_se": start.std(ddof=1) / math.sqrt(fills),
                     "theta_start_n": fills, "theta_stop_mean": stop.mean(),
                     "theta_stop_se": stop.std(ddof=1) / math.sqrt(fills), "theta_stop_n": fills})
    return pd.DataFrame(rows).assign(engine="liggghts", timing="step", rolling=0.0, theta_heap_mean=np.nan)


def test_the_round_trip_holds_the_truth_68_percent_of_the_time_on_a_known_map():
    """On a planar map, pairs measured on 3 fills each (the user's measurement, n = 3): mu_s's
    and mu_k's ranges and the joint region each hold the true pair in 68.27 % of 240 pairs, within
    3 binomial standard deviations (0.030 each). Taking each target's se as exact (no Student
    factor) would give ~58 %; leaving the target's se out of chi2, far less."""
    pts = _coverage_points(np.random.default_rng(51), 240)
    cov = granular3d_calibration.coverage(pts)
    s = granular3d_calibration.summary(cov).set_index(["targets", "statement", "ranges"])
    assert set(cov.targets) == {"theta_start+theta_stop"} and (cov.refused == "").all()
    for statement in ("mu_s range", "mu_k range", "joint region"):
        row = s.loc["theta_start+theta_stop", statement, "all"]
        assert row.pairs == 240 and abs(row.share - calibrate_fit.COVER) < 3 * row.binomial_sd, (statement, row.share)
    assert (cov.mu_s_cut == "").all()  # the truths are far from the edges: no range is cut


def test_the_study_writes_the_round_trips_tables_per_pair(tmp_path):
    """study-3d's tables of the round trip from points with coverage rows (synthetic series):
    one row per pair, set of targets and widening (1, and the one leave_pair_out.csv measures),
    the summary against 68.27 % with the binomial spread of the number of pairs, ranges cut by an
    edge and uncut ones apart, the map's leave-one-out and the interpolation chosen."""
    pts = _coverage_points(np.random.default_rng(1), 8)
    tables = granular3d_calibration.write(tmp_path, pts)
    f = calibrate_map.widening(pd.read_csv(tmp_path / "leave_pair_out.csv"), 0.0)[0]
    cov = pd.read_csv(tmp_path / "coverage.csv")
    assert sorted(set(cov.widening)) == sorted({1.0, f}) and len(cov) == 8 * len(set(cov.widening))
    assert set(cov.targets) == {"theta_start+theta_stop"} and cov.fills.eq(3).all()
    s = pd.read_csv(tmp_path / "coverage_summary.csv")
    assert set(s.statement) == {"mu_s range", "mu_k range", "joint region"} and set(s.ranges) == {"all", "cut", "uncut"}
    whole = s[s.ranges == "all"]
    assert whole.pairs.eq(8).all() and (s[s.ranges == "cut"].pairs.to_numpy() + s[(s.ranges == "uncut") & (
        s.statement != "joint region")].pairs.to_numpy() == 8).all()
    assert s.binomial_sd.iloc[0] == pytest.approx(math.sqrt(0.6827 * 0.3173 / 8))
    choice = pd.read_csv(tmp_path / "interpolation.csv")
    assert choice.chosen.sum() == 1 and (tmp_path / "loo.csv").is_file()
    md = granular3d_calibration.markdown(tables)
    assert "how often its ranges hold the truth" in md and "chosen by leave-one-out" in md and "widening" in md


def test_targets_that_disagree_on_the_map_are_told(tmp_path, capsys):
    """Three targets for two coefficients: the least chi2 at 1 degree of freedom says whether
    they agree. On the synthetic map (0.7, 0.5) gives theta_start 34, theta_stop 21 and
    theta_heap 22.8 (each se 0.3 on the map's points, 0.3 given): those agree (chi2 ~ 0);
    theta_heap 1.2 deg off (f = 2 mu_k - mu_s from theta_stop 0.300, from theta_heap 0.375)
    leaves chi2 ~ 7 at the compromise, p < 0.05, below the refusal at 9. Two targets: no line
    (0 dof)."""
    path = _synthetic_map(tmp_path)
    given = ["--theta-start", "34", "--theta-start-se", "0.3", "--theta-stop", "21", "--theta-stop-se", "0.3",
             "--map", str(path), "--details"]
    assert main(["calibrate", *given]) == 0
    assert "agreement:" not in capsys.readouterr().out
    assert main(["calibrate", *given, "--theta-heap", "22.8", "--theta-heap-se", "0.3"]) == 0
    out = capsys.readouterr().out
    line = next(t for t in out.splitlines() if t.startswith("agreement:"))
    assert float(line.split("p = ")[1]) > 0.5 and "warning:" not in out
    assert main(["calibrate", *given, "--theta-heap", "24.0", "--theta-heap-se", "0.3"]) == 0
    out = capsys.readouterr().out
    line = next(t for t in out.splitlines() if t.startswith("agreement:"))
    chi2 = float(line.split("least chi2 ")[1].split()[0])
    warning = out.splitlines()[4]  # the plain answer's: after the note (no widening file), mu_s, mu_k, the ranges
    assert 4.0 < chi2 < 9.0 and warning.startswith("warning: the targets do not agree with each other on the map"), out


# --- the ranges' widening, measured by leaving the map's own points out ------------------------

def _lpo_rows(ratios, **extra):
    """leave_pair_out.csv's rows with these mu_s ratios on uncut ranges (mu_k's cut: not counted)."""
    return pd.DataFrame({"rolling": 0.0, "mu_s_ratio": ratios, "mu_k_ratio": 100.0, "mu_s_cut": "",
                         "mu_k_cut": "lo: map", "refused": "", **extra})


def test_the_widening_makes_68_percent_of_the_uncut_ranges_hold():
    """Ranges too narrow by a factor s put the truth at a profiled delta chi2 of s^2 chi2(1) over
    their threshold: the widening, the square root of that ratio's 68.27 % quantile (chi2(1)'s is
    1), is s, within 4 of the quantile's sampling spreads over 20 000 ranges (0.5 % each: the
    quantile's sqrt(p (1 - p) / n) over chi2(1)'s density there, 0.242, halved by the root). Ranges
    that already hold the truth more often are not narrowed; ranges cut by an edge, refused answers
    and true values off the map's remains do not count."""
    chi2 = np.random.default_rng(59).chisquare(1, 20000)
    f, n = calibrate_map.widening(_lpo_rows(1.5 ** 2 * chi2), 0.0)
    assert f == pytest.approx(1.5, rel=0.02) and n == 20000
    assert calibrate_map.widening(_lpo_rows(0.5 ** 2 * chi2), 0.0) == (1.0, 20000)
    rows = pd.concat([_lpo_rows(1.5 ** 2 * chi2), _lpo_rows([1e6] * 4000, refused="x"), _lpo_rows([np.inf] * 100),
                      _lpo_rows([1e6] * 4000).assign(mu_s_cut="hi: map"), _lpo_rows([1e6] * 4000).assign(rolling=0.1)])
    assert calibrate_map.widening(rows, 0.0) == (f, 20000)
    assert calibrate_map.widening(rows, 0.2) == (1.0, 0)


def test_a_widened_range_is_wider_by_the_factor(precise):
    """theta_start linear in mu_s: chi2 is quadratic in mu_s, so widening the threshold by f^2
    widens mu_s's range by f, to the grid's step."""
    targets = {"theta_start": calibrate_fit.Target(34.0, 0.4), "theta_stop": calibrate_fit.Target(21.0, 0.5)}
    plain, wide = calibrate_fit.solve(targets, precise), calibrate_fit.solve(targets, precise, 1.5)
    assert _half_width(wide, "mu_s") == pytest.approx(1.5 * _half_width(plain, "mu_s"), abs=calibrate_fit.GRID)
    assert wide.delta["joint"] == plain.delta["joint"] and wide.widen == 1.5


def test_leaving_a_point_out_changes_the_linear_map_only_around_it():
    """The map less one point, by recomputing only the grid points where it had a weight, is the
    map recomputed whole from the other points (points in general position: one triangulation)."""
    rng = np.random.default_rng(5)
    xy = rng.uniform(0, 1, (14, 2))
    p = calibrate_map.Points(xy, rng.normal(size=14), np.full(14, 0.3), np.full(14, 3.0))
    at = rng.uniform(-0.1, 1.1, (3000, 2))
    for method in calibrate_map.METHODS:
        w = calibrate_map.weights(method, p, at)
        for i in (0, 5, 13):
            got, rest = calibrate_map.without(method, p, at, w, i)
            np.testing.assert_allclose(got, calibrate_map.weights(method, rest, at), atol=1e-12)
            assert len(rest.mean) == 13


def test_leaving_each_point_out_holds_68_percent_on_a_map_with_right_errors(tmp_path):
    """A planar map measured with a Gaussian spread equal to its stated errors (0.3 deg, known):
    each point left out and answered by the others holds its truth in its uncut ranges 68.27 % of
    the time within 3 binomial standard deviations, so the widening stays near 1."""
    rng = np.random.default_rng(7)
    rows = []
    for ms in np.arange(0.2, 0.81, 0.1):
        for mk in ms * np.array([0.5, 0.625, 0.75, 0.875, 1.0]):
            rows.append({"kind": "incline", "engine": "liggghts", "group": "sweep", "mu_s": ms, "mu_k": mk,
                         "nu_s": "paper", "timing": "step", "rolling": 0.0,
                         "theta_start_mean": 20 + 20 * ms + 0.3 * rng.standard_normal(), "theta_start_se": 0.3,
                         "theta_stop_mean": 15 + 20 * (2 * mk - ms) + 0.3 * rng.standard_normal(),
                         "theta_stop_se": 0.3})
    lpo = granular3d_calibration.leave_pair_out(pd.DataFrame(rows), 0.0)
    ok = lpo[lpo.refused.fillna("") == ""]
    ratios = pd.concat([ok.loc[ok[f"{c}_cut"].fillna("") == "", f"{c}_ratio"] for c in ("mu_s", "mu_k")])
    n, held = len(ratios), int((ratios <= 1).sum())
    assert n >= 20 and abs(held / n - calibrate_fit.COVER) < 3 * math.sqrt(0.6827 * 0.3173 / n), (held, n)


def test_calibrate_widens_its_ranges_by_the_maps_own_measure(tmp_path, capsys):
    """With leave_pair_out.csv beside the map, calibrate's ranges are widened by the factor it
    measures (ratios of 4 on every uncut range: f = 2) and it says so."""
    path = _precise_map(tmp_path)
    given = ["--theta-start", "34", "--theta-start-se", "0.4", "--theta-stop", "21", "--theta-stop-se", "0.5",
             "--map", str(path)]
    plain = _answer(capsys, *given)
    _lpo_rows([4.0] * 10).to_csv(tmp_path / "leave_pair_out.csv", index=False)
    wide = _answer(capsys, *given)
    half = lambda a: (a["mu_s"]["range"][1] - a["mu_s"]["range"][0]) / 2  # noqa: E731
    assert wide["ranges"]["widened_by"] == 2.0 and wide["ranges"]["widening_from_ranges"] == 10
    assert half(wide) == pytest.approx(2 * half(plain), abs=calibrate_fit.GRID)
    assert main(["calibrate", *given]) == 0
    assert "widened by 2.00 as measured on the map's own points" in capsys.readouterr().out


@pytest.mark.parametrize("change, message", [
    (lambda r: r.drop(columns="mu_k_ratio"), "no column 'mu_k_ratio': expected leave_pair_out.csv of stickslip "
                                             "study-3d"),
    (lambda r: _broken(r, "mu_s_ratio", "wide"), "column mu_s_ratio, line 4: 'wide': expected a number"),
    (lambda r: _broken(r, "rolling", np.nan), "column rolling, line 4: empty: expected a number"),
])
def test_a_malformed_widening_file_is_one_line_naming_it(tmp_path, capsys, change, message):
    """leave_pair_out.csv beside the map, not as study-3d writes it: one line naming the file, the
    column and the line, status 2, no answer."""
    path = _precise_map(tmp_path)
    change(_lpo_rows([4.0] * 10)).to_csv(tmp_path / "leave_pair_out.csv", index=False)
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "21", "--map", str(path)]) == 2
    got = capsys.readouterr()
    assert got.out == "" and got.err.startswith(f"stickslip: error: {tmp_path / 'leave_pair_out.csv'} (beside --map)")
    assert message in got.err and got.err.count("\n") == 1, got.err


def test_a_widening_file_without_ranges_at_the_rolling_asked_is_said_first(tmp_path, capsys):
    """leave_pair_out.csv beside the map whose ranges are all at another rolling resistance:
    the answer's ranges are not widened, and the first line says so."""
    path = _precise_map(tmp_path)
    _lpo_rows([4.0] * 10).assign(rolling=0.1).to_csv(tmp_path / "leave_pair_out.csv", index=False)
    assert main(["calibrate", "--theta-start", "34", "--theta-stop", "21", "--map", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == (f"note: leave_pair_out.csv beside --map {path} has no ranges uncut by an edge at --rolling 0: "
                        "the ranges are not widened by the map's own measure (f = 1), so they may hold the truth less "
                        "often than 68 %") and lines[1].startswith("mu_s = 0.70")
    a = _answer(capsys, "--theta-start", "34", "--theta-stop", "21", "--map", str(path))
    assert a["ranges"]["widened_by"] == 1.0 and a["ranges"]["note"] == lines[0]


def test_calibrates_help_says_what_it_answers_and_what_it_needs(capsys):
    """`calibrate --help` names what it answers (mu_s and mu_k), that it needs two targets, and
    the rolling resistances the committed map measured (the values --rolling takes)."""
    with pytest.raises(SystemExit):
        main(["calibrate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    pts = calibrate_map.read_points(calibrate.DOCS / "points.csv")
    rolls = " or ".join(f"{r:g}" for r in sorted(pts[calibrate_map.on_map(pts)]["rolling"].unique()))
    assert "Answers mu_s and mu_k" in text and "at least two targets" in text, text
    assert f"{rolls} on the committed map" in text, (rolls, text)
