# SPDX-License-Identifier: GPL-2.0-or-later
"""A scene's driven lid ([lid], docs/scene-format.md; Scene.lid) in a LAMMPS-family script, as
LIGGGHTS and LAMMPS both write it (ramp_script.py is its neighbour for the gravity ramp).

The lid's grains are one body in translation: `fix nve` (no spin: torques on them do nothing)
and `fix aveforce`, which gives each grain the group's mean force plus a value, so they keep
one velocity. The value along z is the lid's load, -pressure x area / N; along x the spring's
pull / N, the spring's far end moving at `velocity` from `start`:
    lid_force = stiffness (velocity max(0, t - start) - lid_x),
lid_x being the lid's displacement from where it started (its centre of mass, unwrapped
across the periodic box). The variables lid_x, lid_z, lid_vx, lid_force (columns.LID) go to
the bulk dump. Defined once, before any variable a ramp's loop redefines. The group `lid`
is lammps_family.integrated's.
"""
from __future__ import annotations

import numpy as np

from .lammps_family import fmt as _fmt


def drive(scene):
    """The lid's integration, load and spring (after fix gravity: aveforce then averages it too)."""
    lid = scene.lid
    n = len(lid.names)
    x0 = float(np.mean([g.position[0] for g in scene.lid_grains()]))
    return ["fix lid_nve lid nve",
            f"variable lid_t equal step*{_fmt(scene.dt)}",
            f"variable lid_x equal xcm(lid,x)-{_fmt(x0)}",
            "variable lid_z equal xcm(lid,z)",
            "variable lid_vx equal vcm(lid,x)",
            f"variable lid_force equal {_fmt(lid.stiffness)}*({_fmt(lid.velocity)}*(v_lid_t>{_fmt(lid.start)})"
            f"*(v_lid_t-{_fmt(lid.start)})-v_lid_x)",
            f"variable lid_pull equal v_lid_force/{n}",
            f"fix lid_drive lid aveforce v_lid_pull 0.0 {_fmt(-lid.pressure * lid.area / n)}"]
