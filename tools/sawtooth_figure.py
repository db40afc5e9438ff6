#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The README's picture: the drag case's friction saw-tooth (paper section 3.1, Fig. 9),
|F_s|/Fn against time, between mu_s and 2 mu_k - mu_s with mean mu_k.

    .venv/bin/stickslip run drag                 # -> runs/drag/pyref/timeseries.csv
    .venv/bin/python tools/sawtooth_figure.py [RUN_DIR] [PNG]   # default: runs/drag/pyref docs/img/sawtooth.png
"""
import json
import sys
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from stickslip import plotstyle, scene  # noqa: E402
from stickslip.kinds import drag  # noqa: E402

run = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "runs/drag/pyref"
png = Path(sys.argv[2]) if len(sys.argv) > 2 else ROOT / "docs/img/sawtooth.png"
summary = json.loads((run / "summary.json").read_text())
sc = scene.load(summary["scene"])
p, df = sc.contact, pd.read_csv(run / "timeseries.csv")
ratio = drag.friction_ratio(df, drag.prefix(sc))

plt = plotstyle.pyplot()
fig, ax = plt.subplots(figsize=(6.4, 2.6))
ax.plot(df["t"] * 1e3, ratio, color="C0", lw=1.2)
for level, text, style in ((p.mu_s, "μs", "-"), (p.mu_k, "μk: the mean", "--"), (2 * p.mu_k - p.mu_s, "2μk − μs", "-")):
    ax.axhline(level, color="gray", lw=0.7, ls=style)
    ax.text(0.05, level + 0.005, f"{text} = {level:g}", va="bottom", fontsize=8)
ax.set_xlabel("time (ms): a disk dragged at 1e-5 m/s over a floor")
ax.set_ylabel("|F_s| / Fn")
ax.set_ylim(0, 0.56)
ax.set_xlim(0, df["t"].iloc[-1] * 1e3)
fig.tight_layout()
png.parent.mkdir(parents=True, exist_ok=True)
fig.savefig(png, dpi=100)
print(f"wrote {png}")
