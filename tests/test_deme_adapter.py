# SPDX-License-Identifier: GPL-2.0-or-later
"""The DEM-Engine adapter (stickslip/adapters/deme.py) and its helper
(deme_model/stickslip_deme.py) without a GPU: what they ask of the engine, checked against a
stand-in `deme` module that records every call, and how the adapter turns the engine's
record into the time series. The engine itself runs in tools/gpu_check.sh."""
import math
import subprocess

import numpy as np
import pytest

from stickslip import adapters, columns
from stickslip import scene as scene_mod
from stickslip.adapters import deme as adapter

from deme_standin import FakeDeme

ss = adapter.helper()


def _drag():
    return scene_mod.load("drag", duration=2e-5)


# ---------------------------------------------------------------- availability and refusals
def test_not_an_engine_a_root_run_demands():
    """DEM-Engine is optional (a GPU engine CI never has): `stickslip run` takes it, the
    suite's root check (adapters.available) does not ask for it."""
    assert "deme" in adapters.OPTIONAL_ENGINES and "deme" not in adapters.ENGINES
    assert adapters.get("deme") is adapter
    ok, missing = adapters.available()
    assert "deme" not in ok and "deme" not in missing


def test_available_names_why_not(monkeypatch):
    import importlib.util
    import ctypes

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "deme" else real(name, *a))
    assert "`deme` not installed" in adapter.available() and "[gpu]" in adapter.available()
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: object() if name == "deme" else real(name, *a))

    def no_driver(name, *a, **kw):
        raise OSError(f"{name}: cannot open shared object file")
    monkeypatch.setattr(ctypes, "CDLL", no_driver)
    assert adapter.available().startswith("no CUDA driver (libcuda.so.1 not found)")


@pytest.mark.parametrize("change, word", [
    (lambda s: setattr(s.contact, "law", "coulomb"), "stick_slip only"),
    (lambda s: setattr(s.output, "energy", True), "output.energy"),
    (lambda s: s.effects.__setitem__("rotation", True), "effects.rotation in 2D"),
    (lambda s: setattr(s, "gravity_rate", 0.1), "turning gravity"),
])
def test_refusals_are_one_line(change, word):
    sc = _drag()
    change(sc)
    with pytest.raises(ValueError) as e:
        adapter.check_scene(sc)
    assert word in str(e.value) and "\n" not in str(e.value)


# ---------------------------------------------------------------- the helper
def test_model_text_options_and_declarations():
    """attach(): the options in front of the file's text (after a newline: the engine puts
    the text right after a brace), the properties and wildcards the text reads, at most the
    engine's 16 owner wildcards."""
    text = ss.model_text("hooke", "exact", "total", record=True)
    assert text.startswith("\n#define STICKSLIP_HOOKE 1\n")
    for opt, v in (("SWEEP", 0), ("EXACT", 1), ("RESET_TOTAL", 1), ("RECORD", 1)):
        assert f"#define STICKSLIP_{opt} {v}\n" in text
    assert ss.MODEL_FILE.read_text() in text and "$" not in text  # ($: the engine's regex replacement)
    log = FakeDeme()
    solver = log.DEMSolver()
    ss.attach(solver, normal="hooke", sweep=True, record=True)
    must, = log.calls("model", "SetMustHaveMatProp")
    assert must[0] == {"kn", "ks"} and log.calls("model", "SetMustPairwiseMatProp")[0][0] == {"kn", "ks"}
    assert log.calls("model", "SetPerContactWildcards")[0][0] == {"ss_dx", "ss_dy", "ss_dz", "ss_slips"}
    owners = log.calls("model", "SetPerOwnerWildcards")[0][0]
    assert {"ss_mu_s", "ss_mu_k", "ss_nu_n", "ss_nu_s", "ss_opts", "ss_rec_t"} <= owners and len(owners) <= 16
    assert ss.material_properties("hertz") == ({"E", "nu", "CoR", "mu", "mu_k"}, {"CoR", "mu", "mu_k"})
    for name in ss.owner_wildcards("hooke", sweep=True, record=True) + ss.CONTACT_WILDCARDS:
        assert name in ss.MODEL_FILE.read_text()


@pytest.mark.parametrize("kw, word", [
    (dict(mu_s=0.5, mu_k=0.2), "mu_k"), (dict(mu_s=-1.0, mu_k=0.2), "mu_s"),
    (dict(mu_s=0.5, mu_k=0.45, reset="none"), "reset"), (dict(mu_s=0.5, mu_k=0.45, nu_s=float("nan")), "nu_s"),
])
def test_sweep_values_refuse_bad_input(kw, word):
    with pytest.raises(ValueError) as e:
        ss.sweep_values(**kw)
    assert str(e.value).startswith(word)


def test_sweep_values_without_a_compile():
    log = FakeDeme()
    solver = log.DEMSolver()
    ss.set_family_coefficients(solver, 3, mu_s=0.5, mu_k=0.45, nu_s=33.1, slip_timing="exact", reset="total")
    got = {args[1]: args[2] for args in log.calls("solver", "SetFamilyOwnerWildcardValue")}
    assert got == {"ss_mu_s": 0.5, "ss_mu_k": 0.45, "ss_nu_s": 33.1, "ss_opts": 3}
    assert not log.calls("solver", "DefineContactForceModel")
    with pytest.raises(ValueError, match="normal"):
        ss.model_text("linear")


# ---------------------------------------------------------------- what the adapter asks
def test_drag_scene_as_the_engine_sees_it():
    """The paper's drag: an equivalent sphere of the disk's mass per metre, its x velocity
    held at V, z velocity and spin held at 0 (in the plane, no rolling), the others free;
    the floor a fixed plane; the linear law with the scene's coefficients and its record."""
    sc = _drag()
    fake = FakeDeme()
    solver, grains = adapter.build(sc, fake)
    (text,), = fake.calls("solver", "DefineContactForceModel")
    assert "#define STICKSLIP_HOOKE 1\n" in text and "#define STICKSLIP_RECORD 1\n" in text
    assert "#define STICKSLIP_EXACT 0\n" in text and "#define STICKSLIP_RESET_TOTAL 0\n" in text
    (props,), = fake.calls("solver", "LoadMaterial")
    assert props == {"kn": 1.2e7, "nu_n": 41.38, "ks": 9.6e6, "nu_s": 33.10, "mu": 0.5, "mu_k": 0.45}
    (mass, radius, _), = fake.calls("solver", "LoadSphereType")
    assert mass == pytest.approx(2600 * math.pi * 0.002 ** 2, rel=1e-15) and radius == 0.002
    fam = grains["grain"][1]
    assert fake.calls("solver", "SetFamilyPrescribedLinVel") == [(fam, "1e-05", "none", "0", False)]
    assert fake.calls("solver", "SetFamilyPrescribedAngVel") == [(fam, "0", "0", "0", False)]
    shift = adapter.wall_shift(sc, sc.walls[0])  # (test_the_engine_holds_the_scenes_overlap)
    assert fake.calls("wall", "AddPlane") == [([0.0, shift, 0.0], [0.0, 1.0, 0.0], "LoadMaterial")]
    assert fake.calls("wall", "SetInitPos") == [([0.0, 0.0, 0.0],)]
    assert fake.calls("solver", "SetFamilyFixed") == [(adapter.WALL_FAMILY0,)]
    assert fake.calls("solver", "SetGravitationalAcceleration") == [([0.0, -9.81, 0.0],)]
    assert fake.calls("solver", "SetIntegrator") == [("centered_difference",)]
    (_, (lo, hi), _), = fake.calls("solver", "InstructBoxDomainDimension")
    assert lo < 0.002 < hi and math.log2(hi - lo) == round(math.log2(hi - lo))  # a power of 2


def _engine_overlap(sc, placed=True):
    """The grain's overlap with the first wall as the engine computes it from what the adapter
    gives it (placed) or from the scene's positions as given: the position minus the box's
    corner in float (DEMDynamicThread, AddClumps and SetInitPos), onto the engine's grid
    (box / 2^37), back in double; the float radius; the plane's offset from its owner and its
    normal as float; at the start (the plate not yet turned)."""
    f = lambda v: np.float64(np.float32(v))  # noqa: E731
    (lo, hi) = adapter.domain(sc)[1]
    step = (hi - lo) / 2 ** 37
    held = lambda x: lo + np.round(f(f(x) - f(lo)) / step) * step  # noqa: E731
    g, w = sc.grains[0], sc.walls[0]
    n = f(w.normal)
    if placed:
        owner, rel = adapter.wall_placement(sc, w)
        c = held(np.array(adapter.engine_position(sc, g)))
        plane = held(np.array(owner)) + f(np.array(rel))
    else:
        c = held(g.position - adapter.origin(sc))
        plane = held(w.point - adapter.origin(sc))
    return f(g.radius) - (c - plane) @ n


@pytest.mark.parametrize("name, off", [("drag", 0.03), ("tilt", 0.07)])
def test_the_engine_holds_the_scenes_overlap(name, off):
    """The paper's overlaps are 1e-5 of the radius (drag 2.67e-8 m on 2 mm), near float's
    2^-24 of a coordinate: the grain on the positions the engine holds exactly and the wall
    moved along its normal give the engine the scene's overlap to its grid (box / 2^38, 3.4e-5
    of the drag's and 1.1e-5 of the tilt's overlap). Placed as given, Fn would start off by
    3 % (drag) and 7 % (tilt), as the engine showed."""
    sc = scene_mod.load(name)
    g, w = sc.grains[0], sc.walls[0]
    want = g.radius - float((g.position - w.point) @ w.normal)
    (lo, hi) = adapter.domain(sc)[1]
    assert abs(_engine_overlap(sc) - want) <= (hi - lo) / 2 ** 38
    assert abs(_engine_overlap(sc, placed=False) - want) > off * want
    # the grain's position and the wall's owner are exact in float, and so is each minus the corner
    owner, _ = adapter.wall_placement(sc, w)
    for x in adapter.engine_position(sc, g) + owner:
        assert float(np.float32(x)) == x and float(np.float32(np.float32(x) - np.float32(lo))) == x - lo
    assert abs(adapter.wall_shift(sc, w)) <= adapter.float_step(sc)


def _compile_angle(code):
    """The turning wall's quaternion code, compiled as the engine's integration kernel would run
    it (a function of the float t), returning the angle 2 atan2(|q_xyz|, q_w)."""
    import tempfile
    from pathlib import Path
    from stickslip.contract import deme_shim

    src = ('#include "deme_shim.h"\n#include <cstdio>\n#include <cstdlib>\n'
           "static float4 q(float t) { " + code + " }\n"
           "int main(int c, char **v) { for (int i = 1; i < c; i++) { float4 r = q((float)atof(v[i])); "
           'printf("%.9g\\n", 2 * atan2(sqrt((double)r.x * r.x + (double)r.y * r.y + (double)r.z * r.z), '
           "(double)r.w)); } }\n")
    tmp = Path(tempfile.mkdtemp())
    (tmp / "q.cpp").write_text(src)
    subprocess.run(["g++", "-O1", "-I", str(deme_shim.MODEL / "shim"), "-o", str(tmp / "q"), str(tmp / "q.cpp")],
                   check=True)
    return lambda ts: [float(x) for x in subprocess.run([str(tmp / "q"), *map(repr, ts)], check=True,
                                                        capture_output=True, text=True).stdout.split()]


def test_turning_plate_follows_pyrefs_angle():
    """The tilt's plate: after the engine's force step k (its integration at t = (k-1) dt) the
    plate is set for step k + 1 at pyref's angle of step k (rate dt min(k, steps turning)),
    turning at the rate while k <= steps turning, then held. Float bound: the quaternion is
    float (2^-24 relative of its components: 1e-7 rad), t is float (t 2^-24 rate)."""
    sc = scene_mod.load("tilt")
    w = sc.walls[0]
    n, rate, dt = sc.rotation_steps(w), sc.rotation_rate(w), sc.dt
    quat, spin = adapter.turning_prescription(sc, w)
    angle = _compile_angle(quat)
    ks = [1, 2, 1000, n - 1, n, n + 1, sc.steps - 1]
    got = angle([(k - 1) * dt for k in ks])
    for k, a in zip(ks, got):
        want = rate * dt * min(k, n)
        assert abs(a - want) <= 2e-7 + 2 ** -24 * k * dt * rate, (k, a, want)
    # spin while t = (k - 1) dt < (n - 1/2) dt, i.e. k <= n; held after
    threshold = (n - 0.5) * dt
    assert spin[2] == f"(((double)t < {threshold!r}) ? {rate!r} : 0.0)"
    assert (n - 1) * dt < threshold < n * dt
    assert spin[0] == spin[1] == f"(((double)t < {threshold!r}) ? 0.0 : 0.0)"


def test_time_series_from_the_record():
    """Rows: positions and velocities from the trackers; Fn, the tangential force and the
    slip count from the grain's record when the engine evaluated the contact in the row's
    last step (else not touching: zeros), c_slip the count's increase since the previous row
    (a contact made again counts from 0). Row 0: zero contact forces (no set-up evaluation)."""
    sc = scene_mod.load("drag", duration=12 * 2e-6)
    dt = sc.dt
    counts = {1: 0, 2: 1, 3: 3, 4: 3, 5: 3, 6: 1, 7: 2, 8: 2, 9: 2, 10: 2, 11: 2, 12: 4}

    def record(fam, name, step):
        if name == "ss_rec_t":
            return (step - 1) * dt if step not in (8, 9) else 0.0  # steps 8, 9: not evaluated (apart)
        return {"ss_rec_fn": 0.32, "ss_rec_fx": -0.15, "ss_rec_fy": 1e-9, "ss_rec_slips": counts[step]}.get(name, 0.5)
    fake = FakeDeme(record=record)
    monkey = adapter._import_deme
    adapter._import_deme = lambda: fake
    try:
        res = adapter.run(sc, "unused")
    finally:
        adapter._import_deme = monkey
    df = res.timeseries
    assert list(df.columns) == columns.names(sc)
    assert df["grain-floor_fn"].tolist() == [0.0] + [0.32] * 7 + [0.0, 0.0] + [0.32] * 3
    assert df["grain-floor_ftx"].iloc[1] == -0.15 and df["grain-floor_fs"].iloc[1] == pytest.approx(0.15)
    assert df["grain-floor_slip"].tolist() == [0, 0, 1, 2, 0, 0, 1, 1, 0, 0, 2, 0, 2]
    assert df["t"].iloc[-1] == pytest.approx(12 * dt) and df["grain_vx"].iloc[3] == 1e-5
    # one step a call: the engine steps while its float-summed time is below the duration
    assert fake.calls("solver", "DoDynamicsThenSync") == [(0.5 * dt,)] * 12
