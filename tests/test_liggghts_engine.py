"""The LIGGGHTS plugin against pyref on the paper's cases, through the adapter (issue 3).

LIGGGHTS and pyref integrate the same way (velocity Verlet, forces from x(t) and
v(t - dt/2), the setup force of step 0 without a spring increment), so on the same scene
and dt they differ only by the order of floating-point sums. The tolerances below are
round-off bounds: a quantity of scale F carried over N steps may drift by about
N * eps * F (eps = 2.2e-16); we allow 10 times that (`scale_of` says what F is). Row 0 is left out: LIGGGHTS' record
of a contact is written by the first step, pyref writes the setup force.
"""
import numpy as np
import pytest

from stickslip import analysis
from stickslip import scene as scene_mod
from stickslip.adapters import liggghts as liggghts_adapter
from conftest import paper_case, run_pyref

needs_liggghts = pytest.mark.skipif(liggghts_adapter.available() is not None,
                                    reason=str(liggghts_adapter.available()))
EPS = np.finfo(float).eps


def run_liggghts(name, tmp_path, **kw):
    sc = scene_mod.load(name, **kw)
    return sc, liggghts_adapter.run(sc, tmp_path).timeseries


def roundoff(sc, scale):
    return 10 * sc.steps * EPS * scale


def scale_of(sc, df, col):
    """The size of the terms a column is summed from: a contact's force components are
    of the size of its normal force; a velocity is at least what gravity gives over the
    run (g * duration), since it accumulates force increments."""
    for a, b in sc.output.contacts:
        if col.startswith(f"{a}-{b}_"):
            return np.abs(df[f"{a}-{b}_fn"]).max()
    scale = np.abs(df[col]).max()
    if "_v" in col:
        scale = max(scale, float(np.linalg.norm(sc.gravity)) * sc.duration)
    return scale


def assert_series_agree(sc, dl, dp):
    assert list(dl.columns) == list(dp.columns)
    assert len(dl) == len(dp)
    for col in dl.columns:
        if col.endswith("_slip"):
            continue
        a, b = dl[col].to_numpy()[1:], dp[col].to_numpy()[1:]
        assert np.abs(a - b).max() <= roundoff(sc, scale_of(sc, dp, col)), col
    for a, b in sc.output.contacts:
        c = f"{a}-{b}"
        # LIGGGHTS makes a contact at zero overlap (pyref at > 0): with Fn = 0 it slips
        # with zero force, so slip counts are compared where a normal force acts
        touching = (dl[f"{c}_fn"] > 0) | (dp[f"{c}_fn"] > 0)
        assert (dl[f"{c}_slip"][touching] == dp[f"{c}_slip"][touching])[1:].all(), c


@needs_liggghts
def test_drag_matches_pyref(tmp_path):
    sc, dl = run_liggghts("drag", tmp_path)
    _, dp, _ = paper_case("drag")
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    for k in ("fs_fn_max", "fs_fn_min", "fs_fn_mean", "slip_period_s"):
        assert sl[k] == pytest.approx(sp[k], rel=0.01), k
    assert sl["slip_count"] == sp["slip_count"]
    assert_series_agree(sc, dl, dp)


@needs_liggghts
def test_tilt_matches_pyref(tmp_path):
    """The turning plate is a mesh wall moved by fix move/mesh rotate/variable."""
    sc, dl = run_liggghts("tilt", tmp_path)
    _, dp, _ = paper_case("tilt")
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    for k in ("tan_beta_first_slip", "accel_stick_slip_mps2", "accel_steady_mps2"):
        assert sl[k] == pytest.approx(sp[k], rel=0.01), k
    # The plate's nodes are turned step by step (rounding accumulates in the mesh), not
    # set from the angle as in pyref: positions keep round-off agreement, forces to the
    # round-off of the contact's overlap (Kn * eps * r per step).
    c = "grain-plate"
    r = sc.grains[0].radius
    for col in ("grain_x", "grain_y", "grain_vx", "grain_vy"):
        assert np.abs(dl[col] - dp[col]).max() <= roundoff(sc, scale_of(sc, dp, col)), col
    dfn = np.abs(dl[f"{c}_fn"] - dp[f"{c}_fn"]).to_numpy()[1:]
    assert dfn.max() <= sc.steps * sc.contact.kn * EPS * r
    assert (dl[f"{c}_slip"] == dp[f"{c}_slip"])[1:].all()


@needs_liggghts
def test_tray_matches_pyref(tmp_path):
    sc, dl = run_liggghts("tray", tmp_path, duration=0.5)
    _, dp, _ = paper_case("tray", duration=0.5)
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    assert not sl["reached_bottom"]
    r = sc.grains[0].radius
    assert sl["y1_final_m"] - r == pytest.approx(sp["y1_final_m"] - r, rel=0.01)
    assert sl["time_to_rest_s"] == pytest.approx(sp["time_to_rest_s"], rel=0.01)
    assert_series_agree(sc, dl, dp)


@needs_liggghts
def test_reset_total_matches_pyref(tmp_path):
    """The reset option means the same on both engines (docs/law.md, step 5)."""
    sc, dl = run_liggghts("drag", tmp_path, reset="total", duration=2.5e-3)
    dp, _ = run_pyref(sc)
    assert_series_agree(sc, dl, dp)


@needs_liggghts
def test_effects_off_are_left_out_of_the_script(tmp_path):
    """Only the effects a scene switches on appear in the input script."""
    sc = scene_mod.load("drag", duration=1e-5, effect_gravity=False, effect_normal_damping=False,
                        effect_tangential_damping=False)
    liggghts_adapter.run(sc, tmp_path)
    text = (tmp_path / "liggghts" / "in.scene").read_text()
    assert "gravity" not in text.replace("scene drag", "")
    assert "nve/sphere" not in text  # rotation off: translation only
    assert "gamman_abs peratomtypepair 1 0.0" in text and "gammat_abs peratomtypepair 1 0.0" in text
    sc = scene_mod.load("tilt", duration=1e-5, effect_rotation=True)
    liggghts_adapter.run(sc, tmp_path)
    text = (tmp_path / "liggghts" / "in.scene").read_text()
    assert "fix gravity all gravity" in text and "nve/sphere" in text and "move/mesh" in text


@needs_liggghts
def test_liggghts_error_is_one_line(tmp_path):
    """An error inside LIGGGHTS reaches the user as its one-line message, not a traceback."""
    sc = scene_mod.load("drag", duration=1e-5)
    sc.contact.mu_k = 0.6  # past the scene check, so that LIGGGHTS itself refuses it
    with pytest.raises(ValueError) as e:
        liggghts_adapter.run(sc, tmp_path)
    msg = str(e.value)
    assert "coefficientKineticFriction" in msg and "0.6" in msg and "[0.25, 0.5]" in msg
    assert "\n" not in msg


@needs_liggghts
def test_poured_packing_statistics_match_pyref(tmp_path):
    """120 polydisperse disks poured into a tray (rotation on), on LIGGGHTS and pyref.
    Contact-rich and chaotic: paths part after the first collisions, so only statistics
    can agree (the tolerances of the YADE version of this test, tests/test_yade_engine.py):
    both at rest (kinetic energy < 1 % of its peak), mean height within 2 %, number of
    contacts within 10 %."""
    import tomllib

    from test_packing import POUR

    text = POUR.format(nx=12, ny=10, duration=0.15, dt=5e-6, width=0.003 + 12 * 2 * 0.002 * 1.2 * 1.05 + 0.001)
    sc = scene_mod.parse(tomllib.loads(text))
    sc.output.grains = [g.name for g in sc.grains]
    dp, _ = run_pyref(sc)
    dl = liggghts_adapter.run(sc, tmp_path).timeseries
    for df in (dp, dl):
        assert np.isfinite(df.to_numpy()).all()
        assert df["ekin"].iloc[-1] < 0.01 * df["ekin"].max()
    heights = lambda df: np.mean([df[f"{g.name}_y"].iloc[-1] for g in sc.grains])  # noqa: E731
    assert heights(dl) == pytest.approx(heights(dp), rel=0.02)
    assert dl["n_contacts"].iloc[-1] == pytest.approx(dp["n_contacts"].iloc[-1], rel=0.10)
