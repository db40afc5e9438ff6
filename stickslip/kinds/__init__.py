# SPDX-License-Identifier: GPL-2.0-or-later
"""Case kinds: what a scene's `[analysis] kind` means, one module per kind, and what kinds
share: paper.py (what the paper says, checked), stick_resolution.py (how well a run
resolved its stick phases).

A kind module provides (the contract; report, precision and analysis only loop):
- NAME, and NAMES: the `[analysis]` keys it needs, each with its rule ("grain": a
  recorded grain, "contact": a recorded contact, "wall": a wall, "turning wall": a
  turning wall whose angle is recorded, "seconds": a time >= 0, "phase": the index of a
  gravity_ramp phase), checked when the scene is loaded;
- summarise(scene, df) -> dict: the headline figures of a run (summary.json);
- errors(scene, summary, df, ref_summary, ref_df) -> dict: relative error measures of a
  run against a converged reference run (`stickslip precision`);
- PRECISION_DURATION: simulated time of the precision runs (None: the scene's);
- COMPARISON_LAWS: the other tangential laws the report runs the scene with;
- REPORT_TIMINGS: the slip timings the report runs the scene in;
- claims(scene) -> [(summary key, text)]: the report table rows;
- paper_statements(scene) -> [kinds.paper.Statement]: what the paper says, checked;
- figures(out, runs) -> [png names]: the report figures, from
  runs[(law, slip timing, engine)] = (scene, summary, df) of this kind's scene;
- precision_figures(out, runs) -> [png names]: extra figures of a time-step ladder,
  from runs[(engine, slip timing, dt)] = (scene, summary, df).
"""
from __future__ import annotations

from ..errors import SceneError
from . import drag, drum, heap3d, hold3d, incline3d, none, shear3d, tilt, tray

KINDS = {k.NAME: k for k in (none, drag, tray, tilt, drum, incline3d, hold3d, heap3d, shear3d)}


def get(name):
    try:
        return KINDS[name]
    except KeyError:
        raise SceneError(f"analysis.kind = {name!r}: must be one of {', '.join(KINDS)}") from None


def read_names(table, kind, grains, walls, output, ramp=None) -> dict:
    """The kind's `[analysis]` names, each checked against the scene (table: the reader's
    `[analysis]` table, which then refuses any key the kind does not know)."""
    grain_names = {g.name for g in grains}
    turning = {w.name for w in walls if w.rotation is not None}
    got = {}
    for key, rule in kind.NAMES.items():
        v = table.get(key, required=True)
        where = table.key(key)
        if rule == "grain":
            if not isinstance(v, str) or v not in grain_names:
                raise SceneError(f"{where} = {v!r}: must be a grain name")
            if v not in output.grains:
                raise SceneError(f"{where} = {v!r}: the grain must be recorded (add it to output.grains)")
        elif rule == "contact":
            if not isinstance(v, list) or v not in output.contacts:
                raise SceneError(f"{where} = {v!r}: must be a recorded contact (one of output.contacts)")
        elif rule == "wall":
            if not isinstance(v, str) or v not in {w.name for w in walls}:
                raise SceneError(f"{where} = {v!r}: must be a wall name")
        elif rule == "seconds":
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v <= 1e100:
                raise SceneError(f"{where} = {v!r}: must be a time in seconds, >= 0")
            v = float(v)
        elif rule == "phase":
            n = len(ramp.phases) if ramp is not None else 0
            if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v < n:
                raise SceneError(f"{where} = {v!r}: must be the index of a gravity_ramp.phase (0 to {n - 1})"
                                 if n else f"{where}: needs a [gravity_ramp] with phases")
        elif rule == "turning wall":
            if not isinstance(v, str) or v not in turning:
                raise SceneError(f"{where} = {v!r}: must be a turning wall (with a rotation)")
            if v not in output.walls:
                raise SceneError(f"{where} = {v!r}: its angle must be recorded (add it to output.walls)")
        got[key] = v
    return got
