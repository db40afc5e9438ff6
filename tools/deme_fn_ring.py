# SPDX-License-Identifier: GPL-2.0-or-later
"""How far a one-grain case's normal force strays while the grain sticks before its first
slip: Fn over the weight's normal share, read from a run's time series (pyref's, the GPU's
or the emulated engine's). The GPU check bounds its figures with it (tools/deme_gpu_check.py),
the emulation reports it (tools/deme_plane_emulation.py) and the page's figure draws it
(tools/deme_gpu_figure.py)."""


def sticking_fn_over_weight(sc, df):
    """The recorded contact's Fn while it sticks before the first slip (rows 1 on), over the
    weight's normal share W cos(angle) (the tilt's plate turns): (times, ratios)."""
    import numpy as np

    c = "-".join(sc.output.contacts[0])
    fn = df[f"{c}_fn"].to_numpy()
    first = np.flatnonzero(df[f"{c}_slip"].to_numpy() > 0)
    end = first[0] if len(first) else len(fn)
    angle = df[f"{sc.output.walls[0]}_angle"].to_numpy() if sc.output.walls else np.zeros(len(fn))
    w = sc.grain_mass(sc.grains[0]) * 9.81 * np.cos(angle)
    return df["t"].to_numpy()[1:end], (fn / w)[1:end]


def fn_spread(sc, df):
    """sticking_fn_over_weight's first value, least and most: how far the start rings."""
    _, rel = sticking_fn_over_weight(sc, df)
    return {"first": float(rel[0]), "min": float(rel.min()), "max": float(rel.max())} if len(rel) else {}


def ring_of(spread):
    """How far Fn strays relatively before the first slip, from fn_spread's figures:
    max |Fn / (W cos beta) - 1|."""
    return max(1.0 - spread["min"], spread["max"] - 1.0)
