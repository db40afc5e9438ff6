#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""DEM-Engine's page's picture: the paper's drag and tilt as the GPU ran them (the time series
the GPU check leaves, tools/gpu_check.sh: drag_deme.csv.gz, tilt_deme.csv.gz).

    .venv/bin/python tools/deme_gpu_figure.py [SERIES_DIR] [PNG]
        # default: deme_model/measured deme_model/measured/drag_tilt_gpu.png

Left: the drag's |F_s|/Fn on the GPU over pyref's (run here, 0.2 s): the same saw-tooth, the
slips on the same steps. Right: the tilt's Fn / (W cos beta) while the grain sticks and the
plate turns, the GPU's float geometry against 1 (pyref's stays within 4e-4 of it), with the
one event the GPU shows (deme_model/README.md, "Measured").
"""
import sys
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tools")]
from deme_fn_ring import sticking_fn_over_weight  # noqa: E402
from pyref import Simulation  # noqa: E402
from stickslip import columns, plotstyle, scene  # noqa: E402
from stickslip.kinds import drag  # noqa: E402


def main(series=ROOT / "deme_model/measured", png=None):
    series = Path(series)
    png = Path(png) if png else series / "drag_tilt_gpu.png"
    sd, st = scene.load("drag"), scene.load("tilt")
    gpu_drag = pd.read_csv(series / "drag_deme.csv.gz")
    gpu_tilt = pd.read_csv(series / "tilt_deme.csv.gz")
    ref_drag = columns.frame(sd, Simulation(sd).run())

    plt = plotstyle.pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.2))
    for df, label, style in ((ref_drag, "pyref (double)", dict(color="gray", lw=3.0, alpha=0.5)),
                             (gpu_drag, "DEM-Engine on a GPU (float)", dict(color="C0", lw=1.0))):
        left.plot(df["t"] * 1e3, drag.friction_ratio(df, drag.prefix(sd)), label=label, **style)
    p = sd.contact
    for level, text in ((p.mu_s, "μs"), (p.mu_k, "μk"), (2 * p.mu_k - p.mu_s, "2μk − μs")):
        left.axhline(level, color="gray", lw=0.6, ls="--")
        left.text(0.05, level + 0.004, text, va="bottom", fontsize=8)
    left.set_xlabel("time (ms): the drag, §3.1")
    left.set_ylabel("|F_s| / Fn")
    left.set_ylim(0, 0.56)
    left.legend(loc="lower right", fontsize=8)

    t, ratio = sticking_fn_over_weight(st, gpu_tilt)
    right.plot(t, ratio, color="C0", lw=0.8, label="DEM-Engine on a GPU")
    right.axhline(1.0, color="gray", lw=0.6, ls="--")
    right.set_xlabel("time (s): the tilt, §3.2, until the first slip")
    right.set_ylabel("Fn / (W cos β)")
    right.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)
    print(f"wrote {png}")
    return png


if __name__ == "__main__":
    main(*sys.argv[1:3])
