# SPDX-License-Identifier: GPL-2.0-or-later
"""The engine's float geometry on a plane, emulated on the CPU (tools/deme_plane_emulation.py):
the force model through its shim, on the overlap DEM-Engine would hand it, against pyref,
within the GPU check's bounds (tools/deme_gpu_check.py). With the engine's own overlap (a
float distance along a float normal) the drag's Fn steps by 0.87 % and the tilt's rings by
3 %, and both cases leave their bounds; with the model's distance in double (stick_slip.cu,
step 0) they keep them."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
import deme_fn_ring as fn_ring  # noqa: E402
import deme_gpu_check as check  # noqa: E402
import deme_plane_emulation as emulation  # noqa: E402


def _outside(runs, bounds, label):
    """The figures of run `label` further from pyref's than their bounds."""
    return sorted(k for k, b in bounds.items() if abs(runs[label][k] - runs["pyref"][k]) > b)


def _ring(figures):
    """float_ring from a run's figures (report's fn_over_w_*), without a second run."""
    return fn_ring.ring_of({k: figures[f"fn_over_w_{k}"] for k in ("min", "max")})


def test_drag_keeps_its_bounds_on_the_models_distance_only():
    """The drag (a fixed plane, normal exact in float): on the model's distance every figure
    is within drag_bounds of pyref's and Fn/W within pyref's start (1e-3); on the engine's
    overlap Fn steps by ulp(r)/overlap = 0.87 % and |Fs|/Fn after a slip falls below its
    bound (Fmin set on one step's Fn, read on the next)."""
    from stickslip import scene as scene_mod

    sc = scene_mod.load("drag")
    runs = emulation.report("drag", log=lambda s: None)
    bounds = check.drag_bounds(sc, _ring(runs["model distance"]))
    assert _outside(runs, bounds, "model distance") == []
    model = runs["model distance"]
    assert 1 - 1e-3 < model["fn_over_w_min"] <= model["fn_over_w_max"] < 1 + 1e-3
    engine = runs["engine overlap"]
    assert engine["fn_over_w_max"] - engine["fn_over_w_min"] > 0.0087
    assert "fs_fn_min" in _outside(runs, bounds, "engine overlap")


@pytest.mark.slow
def test_tilt_keeps_its_bounds_on_the_models_distance_only():
    """The tilt (125 000 steps, ~35 s): on the model's distance the first slip and the final
    speed are within tilt_bounds of pyref's (no spread part here: its 3 x spread term is 0);
    on the engine's overlap Fn rings by ~3 % and the grain slips early, out of the bound in
    tan(beta) (the GPU gave 0.4969 against pyref's 0.5002 so)."""
    from stickslip import scene as scene_mod

    sc = scene_mod.load("tilt")
    runs = emulation.report("tilt", log=lambda s: None)
    ring = _ring(runs["model distance"])
    assert ring < 0.01
    bounds = check.tilt_bounds(sc, None, runs["pyref"], ring)
    assert _outside(runs, bounds, "model distance") == []
    assert "tan_beta_first_slip" in _outside(runs, bounds, "engine overlap")
