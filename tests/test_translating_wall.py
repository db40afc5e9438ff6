# SPDX-License-Identifier: GPL-2.0-or-later
"""A translating wall on every engine (issue 31: no engine ran one). The drag seen from
the grain: the grain held still and the floor drawn under it at -V. Relative motion is all
the law sees (docs/law.md step 1: V_s = v_i - v_wall at the contact point), and the floor
moves within its own plane, so the contact is the drag's: every engine must give pyref's
drag (paper_case) to round-off, step by step: |dFs| <= 10 N eps max|Fs| over N steps (the
convention of tests/test_liggghts_engine.py), the same slips at the same steps."""
import copy
import tomllib

import numpy as np
import pytest

from conftest import paper_case, skip_engine
from stickslip import adapters
from stickslip import scene as scene_mod
from stickslip.adapters import ENGINES

EPS = np.finfo(float).eps


def floor_drawn_under_the_grain():
    data = copy.deepcopy(tomllib.loads(scene_mod.find("drag").read_text()))
    v = data["grain"][0]["velocity"]
    data["name"] = "drag_wall"
    data["grain"][0]["velocity"] = [0.0, 0.0]
    data["wall"][0]["velocity"] = [-v[0], -v[1]]
    data["effects"]["moving_walls"] = True
    return scene_mod.parse(data)


@pytest.mark.parametrize("engine", ENGINES)
def test_translating_floor_is_the_drag(engine, tmp_path):
    skip_engine(engine)
    sc = floor_drawn_under_the_grain()
    df = adapters.get(engine).run(sc, tmp_path).timeseries
    _, ref = paper_case("drag")
    c = "grain-floor"
    assert len(df) == len(ref)
    # from row 1: LIGGGHTS' record is written by real steps, so its row 0 (set-up) holds no force
    fs, fs_ref = df[f"{c}_fs"].to_numpy()[1:], ref[f"{c}_fs"].to_numpy()[1:]
    tol = 10 * sc.steps * EPS * np.abs(fs_ref).max()
    assert np.abs(fs - fs_ref).max() <= tol, (np.abs(fs - fs_ref).max(), tol)
    assert np.array_equal(df[f"{c}_slip"].to_numpy(), ref[f"{c}_slip"].to_numpy())
    assert ref[f"{c}_slip"].sum() >= 8  # the saw-tooth happened
