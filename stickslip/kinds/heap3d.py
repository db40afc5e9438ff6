# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "heap3d": the slope of a heap left on a plate (cases/heap3d.toml, docs/granular-3d.md).

From the recorded grains at the last row: the plate is the scene's fixed grains (its
x-extent and the mean top of its spheres: kinds.incline3d.base_surface); the heap is the
moving grains above the plate and within its extent. Its surface is the highest grain top
in bins of one mean diameter along x (over the whole periodic depth); each flank's slope
is a straight-line fit to the surface bins between FIT_LOW and FIT_HIGH of the heap's
height (the rounded crest and the toe at the plate's edge left out); theta_heap is the
mean of the two flanks' angles, and their half-difference says how far apart they are.
"""
from __future__ import annotations

import math

import numpy as np

from .incline3d import base_surface
from .none import paper_statements, precision_figures  # noqa: F401 (the contract: neither, as kind none)

NAME = "heap3d"
NAMES = {}
PRECISION_DURATION = None
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)

# The flanks are fitted between these shares of the heap's height above the plate.
FIT_LOW, FIT_HIGH = 0.15, 0.85


def plate(scene):
    """(x min, x max, surface height) of the plate: its fixed spheres' extent and mean top."""
    fixed = [g for g in scene.grains if g.fixed]
    x = np.array([g.position[0] for g in fixed])
    r = max(g.radius for g in fixed)
    return float(x.min() - r), float(x.max() + r), base_surface(scene)


def profile(scene, row):
    """(bin centres, surface height above the plate) of the heap at one row of the series."""
    lo, hi, z0 = plate(scene)
    names = [g.name for g in scene.grains if not g.fixed and g.name in set(scene.output.grains)]
    radius = {g.name: g.radius for g in scene.grains}
    x = np.array([row[f"{n}_x"] for n in names])
    z = np.array([row[f"{n}_z"] for n in names]) + np.array([radius[n] for n in names])
    width = 2.0 * float(np.mean([radius[n] for n in names]))
    on = (x >= lo) & (x <= hi) & (z > z0)
    edges = np.arange(lo, hi + width, width)
    k = np.digitize(x[on], edges) - 1
    top = np.full(len(edges) - 1, 0.0)
    np.maximum.at(top, np.clip(k, 0, len(top) - 1), z[on] - z0)
    return 0.5 * (edges[:-1] + edges[1:]), top


def flanks(xc, top):
    """The two flanks' slopes (rise over run, both positive for a heap) and the heap's height."""
    height = float(top.max())
    crest = int(np.argmax(top))
    band = (top >= FIT_LOW * height) & (top <= FIT_HIGH * height)
    slopes = []
    for side in (np.arange(len(top)) < crest, np.arange(len(top)) > crest):
        sel = band & side
        slopes.append(abs(np.polyfit(xc[sel], top[sel], 1)[0]) if sel.sum() >= 3 else math.nan)
    return slopes, height


def summarise(scene, df):
    last = df.iloc[-1]
    xc, top = profile(scene, last)
    (left, right), height = flanks(xc, top)
    a = [math.degrees(math.atan(s)) for s in (left, right)]
    lo, hi, z0 = plate(scene)
    heap = [g for g in scene.grains if not g.fixed and lo <= last[f"{g.name}_x"] <= hi and last[f"{g.name}_z"] > z0]
    out = {"theta_heap_deg": float(np.mean(a)), "theta_left_deg": a[0], "theta_right_deg": a[1],
           "flank_half_difference_deg": abs(a[0] - a[1]) / 2, "heap_height": height, "grains_on_plate": len(heap)}
    # the heap's kinetic energy per grain (translation), in m g d: is it at rest?
    e = sum(0.5 * scene.grain_mass(g) * sum(last[f"{g.name}_v{a}"] ** 2 for a in "xyz") for g in heap)
    mgd = np.mean([scene.grain_mass(g) for g in heap]) * float(np.linalg.norm(scene.gravity)) * 2 * np.mean(
        [g.radius for g in heap])
    out["heap_ekin_per_grain_mgd"] = e / len(heap) / mgd if heap else math.nan
    return out


def errors(scene, summary, df, ref_summary, ref_df):
    ref = ref_summary["theta_heap_deg"]
    return {"theta_heap": abs(summary["theta_heap_deg"] - ref) / ref}


def claims(scene):
    return [("theta_heap_deg", "theta_heap (deg)"), ("heap_height", "heap height (d)")]


def figures(out, runs):
    """The heap's surface and its fitted flanks, one figure per run."""
    from ..plotstyle import pyplot, save

    plt, names = pyplot(), []
    for key, (scene, summary, df) in runs.items():
        xc, top = profile(scene, df.iloc[-1])
        fig, ax = plt.subplots(figsize=(6, 3))
        ax.step(xc, top, where="mid")
        ax.set_aspect("equal")
        ax.set_xlabel("x (d)")
        ax.set_ylabel("surface above the plate (d)")
        ax.set_title(f"theta_heap {summary['theta_heap_deg']:.1f} deg")
        names.append(save(fig, out, f"heap3d_{'_'.join(str(k) for k in key)}.png"))
    return names
