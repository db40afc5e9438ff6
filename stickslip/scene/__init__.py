# SPDX-License-Identifier: GPL-2.0-or-later
"""Scene files: one TOML file describes a case once, for every engine.

`load(path_or_name, **overrides)` reads and validates a scene and returns a `Scene`
(scene/model.py); any problem raises `SceneError` with a one-line message that names
the key and the allowed range (scene/reader.py; its tables scene/table.py, its grains
scene/grains.py), so no engine ever sees an invalid
scene. The largest stable time step, and the step below which collisions are accurate,
are scene/stability.py. Format: docs/scene-format.md.
"""
from pyref.laws import LAWS, RESETS, SLIP_TIMINGS

from ..errors import SceneError
from .model import Contact, Grain, Output, Scene, Wall, WallRotation
from .grains import MAX_START_OVERLAP
from .reader import CASES_DIR, EFFECTS, check_contact, find, identity, load, parse
from .stability import (
                        CONTACT_STEPS,
                        IMPACT_STEPS,
                        RESTITUTION_ERROR,
                        accuracy_warnings,
                        contact_steps,
                        contact_time,
                        critical_dt,
                        stability_limits,
)

__all__ = ["CASES_DIR", "CONTACT_STEPS", "EFFECTS", "IMPACT_STEPS", "LAWS", "MAX_START_OVERLAP", "RESETS",
           "RESTITUTION_ERROR", "SLIP_TIMINGS", "Contact", "Grain", "Output", "Scene", "SceneError", "Wall",
           "WallRotation", "accuracy_warnings", "check_contact", "contact_steps", "contact_time", "critical_dt",
           "find", "identity", "load", "parse", "stability_limits"]
