#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model's page's picture: the paper's drag case (section 3.1) with the stick-slip
law and with the two-state static/dynamic law (LAMMPS' linear_history/static, pyref's
`static_dynamic`: mu_dynamic = mu_k), |F_s|/Fn against time, both run by pyref here.

    .venv/bin/python tools/static_dynamic_figure.py [PNG]   # default: docs/img/stick_slip_vs_static_dynamic.png
"""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from pyref import Simulation  # noqa: E402
from stickslip import columns, plotstyle, scene  # noqa: E402
from stickslip.kinds import drag  # noqa: E402

PNG = ROOT / "docs" / "img" / "stick_slip_vs_static_dynamic.png"
# (pyref's law, label, colour, line width): the two-state law drawn first and wider, so that
# the saw-tooth shows over it where both stick
LAWS = (("static_dynamic", "the two-state law (linear_history/static)", "C3", 2.6),
        ("stick_slip", "the stick-slip law (stick_slip)", "C0", 1.1))


def drag_ratio(law):
    """(times, |F_s|/Fn) of the drag with the law (the case's own coefficients)."""
    sc = scene.load("drag", law=law)
    df = columns.frame(sc, Simulation(sc).run())
    return df["t"].to_numpy(), drag.friction_ratio(df, drag.prefix(sc)), sc.contact


def main(argv):
    png = Path(argv[1]) if len(argv) > 1 else PNG
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 2.8))
    for law, label, color, width in LAWS:
        t, ratio, p = drag_ratio(law)
        ax.plot(t * 1e3, ratio, color=color, lw=width, label=label, alpha=0.75 if width > 2 else 1.0)
    for level, text, style in ((p.mu_s, "μs", "-"), (p.mu_k, "μk", "--"), (2 * p.mu_k - p.mu_s, "2μk − μs", "-")):
        ax.axhline(level, color="gray", lw=0.7, ls=style)
        ax.text(0.05, level + 0.005, f"{text} = {level:g}", va="bottom", fontsize=8)
    ax.set_xlabel("time (ms): a disk dragged at 1e-5 m/s over a floor")
    ax.set_ylabel("|F_s| / Fn")
    ax.set_ylim(0, 0.6)
    ax.set_xlim(0, t[-1] * 1e3)
    ax.legend(loc="lower right", fontsize=8, frameon=False)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    print(f"wrote {png.relative_to(ROOT) if png.is_relative_to(ROOT) else png}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
