# SPDX-License-Identifier: GPL-2.0-or-later
"""pyref's two-state static/dynamic law (`static_dynamic`, LAMMPS' linear_history/static),
the comparison beside the stick-slip law: its steps worked out by hand (exact in binary),
the paper's drag as the sub-model's page draws and tells it, and the scene format's key.
Cost: ~2 s (the two drags, shared with the other tests that run them)."""
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import paper_case
from pyref.laws import LawParams, tangential_force
from stickslip import scene as scene_mod
from stickslip.kinds import drag

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "lammps_plugin" / "doc" / "gran_sub_mod_tangential_stick_slip.md"
FIGURE = ROOT / "tools" / "static_dynamic_figure.py"
DT = 1.0 / 16


def test_the_limit_switches_from_static_to_dynamic_and_back():
    """One contact, Fn = 1, Ks = 1, no dashpot, mu_s 0.5, mu_dynamic (mu_k) 0.375, the spring
    gaining 1/16 a step: |F| = 0.4375 and 0.5 stick (the limit is exceeded, not reached);
    0.5625 is cut to mu_s Fn = 0.5 and the contact slides; the next step's 0.5625 is cut to
    mu_k Fn = 0.375; moving back, 0.3125 < 0.375 sticks and the contact is static again, its
    limit mu_s once more. The work balance: -F.V dt less the spring's gain, no dashpot's."""
    p = LawParams(law="static_dynamic", kn=32.0, nu_n=0.0, ks=1.0, nu_s=0.0, mu_s=0.5, mu_k=0.375)
    fn, D, sliding = np.array([1.0]), np.array([[0.375, 0.0, 0.0]]), None
    forward, back = np.array([[1.0, 0.0, 0.0]]), np.array([[-1.0, 0.0, 0.0]])
    for V, force, spring, slides in ((forward, 0.4375, 0.4375, False), (forward, 0.5, 0.5, False),
                                     (forward, 0.5, 0.5, True), (forward, 0.375, 0.375, True),
                                     (back, 0.3125, 0.3125, False), (forward, 0.375, 0.375, False)):
        s = tangential_force(D, V, fn, DT, p, energy=True, sliding=sliding)
        assert np.array_equal(s.force, [[-force, 0, 0]]) and np.array_equal(s.spring, [[spring, 0, 0]])
        assert s.slipped.tolist() == [slides]
        work = -float(s.force[0] @ V[0]) * DT - 0.5 * (spring ** 2 - float(D[0] @ D[0]))
        assert s.dissipated_dashpot[0] == 0.0 and s.dissipated_slip[0] == work
        # a sticking step books the explicit step's Ks |V dt|^2 / 2 (as the stick-slip law), a cut more
        assert (work > 1.0 / 512) == slides and work >= 1.0 / 512
        D, sliding = s.spring, s.slipped


def test_a_cut_keeps_spring_and_dashpot_at_the_limit():
    """With a dashpot the cut force is carried by spring and dashpot together (as
    linear_history rescales): the next step starts from the limit plus the spring's gain."""
    p = LawParams(law="static_dynamic", kn=32.0, nu_n=0.0, ks=1.0, nu_s=0.5, mu_s=0.5, mu_k=0.375)
    V = np.array([[1.0, 0.0, 0.0]])
    s = tangential_force(np.array([[0.25, 0.0, 0.0]]), V, np.array([1.0]), DT, p)  # trial -0.3125 - 0.5
    assert np.array_equal(s.force, [[-0.5, 0, 0]]) and np.array_equal(s.spring, [[0.0, 0, 0]])
    s = tangential_force(s.spring, V, np.array([1.0]), DT, p, sliding=s.slipped)  # -0.0625 - 0.5 > 0.375
    assert np.array_equal(s.force, [[-0.375, 0, 0]]) and s.slipped.tolist() == [True]


def drag_ratio(law):
    sc, df = paper_case("drag", law=law)
    return drag.friction_ratio(df, drag.prefix(sc)), df["t"].to_numpy(), sc.contact


def test_the_pages_three_sentences_are_what_the_drag_gives():
    """The sub-model's page says in three sentences what each law gives on the paper's drag
    (mu_s 0.5, mu_k 0.45): both hold until mu_s Fn; the two-state law then slides at
    mu_dynamic Fn, every row after the break at 0.45 (to round-off: Fs/Fn of a force cut to
    0.45 Fn, a few ulps); the stick-slip law saw-tooths between mu_s Fn and (2 mu_k - mu_s) Fn
    (one loading step, Ks V dt = 0.2 % of mu_s Fn, below the peak) about mu_k Fn."""
    text = PAGE.read_text()
    section = text[text.index("## Beside linear_history/static"):text.index("## Mixing, restart info")]
    said = section.strip().split("\n\n")[-1]
    assert len(re.findall(r"[.!?](?:\s|$)", said)) == 3, said
    for claim in ("until its force reaches μs·Fn", "slides smoothly at μ_dynamic·Fn",
                  "saw-tooths between μs·Fn and (2μk − μs)·Fn about μk·Fn"):
        assert claim in said, claim
    two, t, p = drag_ratio("static_dynamic")
    one, _, _ = drag_ratio("stick_slip")
    broke = int(np.argmax(two >= p.mu_s - 1e-12))
    assert broke > 0 and np.array_equal(two[:broke], one[:broke])  # the same stick until then
    assert abs(two[broke] - p.mu_s) <= 1e-12 and np.abs(two[broke + 1:] - p.mu_k).max() <= 1e-12
    late = one[t > t[broke] * 1.5]
    assert abs(late.min() - (2 * p.mu_k - p.mu_s)) <= 1e-12 and p.mu_s * (1 - 3e-3) <= late.max() <= p.mu_s
    assert abs(late.mean() - p.mu_k) <= 0.01 * p.mu_k


def test_the_figure_is_made_by_the_command_the_page_names(tmp_path):
    """The page shows the committed PNG and names the command that makes it, which runs both
    laws and writes a PNG (here to a temporary file)."""
    text = PAGE.read_text()
    assert "`.venv/bin/python tools/static_dynamic_figure.py`" in text
    assert "](../../docs/img/stick_slip_vs_static_dynamic.png)" in text
    assert (ROOT / "docs" / "img" / "stick_slip_vs_static_dynamic.png").is_file()
    out = tmp_path / "laws.png"
    got = subprocess.run([sys.executable, str(FIGURE), str(out)], capture_output=True, text=True, cwd=ROOT)
    assert got.returncode == 0, got.stderr[-2000:]
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_scene_format_takes_the_law_and_refuses_a_dynamic_limit_above_the_static(tmp_path):
    """`law = "static_dynamic"` in a scene (its spring Ks required, as stick_slip's); mu_k
    above mu_s refused in one line naming it and its range."""
    assert scene_mod.load("drag", law="static_dynamic").contact.law == "static_dynamic"
    with pytest.raises(scene_mod.SceneError, match=r"^contact\.mu_k = 0\.6: must be in \[0, mu_s\] = \[0, 0\.5\]"):
        scene_mod.load("drag", law="static_dynamic", mu_k=0.6)
    text = (ROOT / "cases" / "drag.toml").read_text()
    scene = tmp_path / "drag.toml"
    scene.write_text(text.replace('law = "stick_slip"', 'law = "static_dynamic"').replace("mu_k = 0.45", "mu_k = 0.6"))
    got = subprocess.run([sys.executable, "-m", "stickslip.cli", "run", str(scene), "--out", str(tmp_path / "run")],
                         capture_output=True, text=True, cwd=ROOT)
    assert got.returncode == 2 and got.stderr.count("\n") == 1 and "mu_k = 0.6" in got.stderr, got.stderr
