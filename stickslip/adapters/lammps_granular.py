# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for LAMMPS as granular users build it today: `pair_style granular` and `fix
wall/gran granular` with the tangential sub-model `stick_slip` (lammps_plugin/granular/),
compiled into the modern LAMMPS releases that `./run.sh setup` builds from Debian's source
behind its switch (RELEASES: `STICKSLIP_SOURCE_BUILDS=lammps-2025,lammps-2026`).

The script is the LAMMPS adapter's (stickslip/adapters/lammps.py: grains, walls, gravity,
integration, dumps) with the contact model in the granular syntax:
`hooke Kn nu_n damping velocity tangential stick_slip[/total][/exact]/record Ks x mu_s mu_k
limit_damping`. `damping velocity` makes nu_n absolute (docs/law.md step 2), and the
sub-model's tangential damping is x times it, so x is nu_s/nu_n. The record (`/record`)
gives the law's Fn, force and slip count: compute pair/local p13-p17 for grain pairs, the
wall fixes' per-atom columns 9-13 (keyword `contacts`), the LAMMPS adapter's columns.

Where this differs from docs/law.md (lammps_plugin/doc/gran_sub_mod_tangential_stick_slip.md):
LAMMPS' granular model takes V_s with the radii as lever arms and a wall's torque at the
radius (the law: the middle of the overlap), which only scenes with rotation see (the
run's notes say so), and it has no tangential dashpot without a normal one.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

from .. import law_options
from .lammps import REPO, _Script, _fmt, run_with

NAME = "lammps_granular"
# The releases ./run.sh builds (its LAMMPS_RELEASES): the switch's word -> (LAMMPS' version,
# the build's folder under build/), oldest first. Defined here only.
RELEASES = {"lammps-2025": ("4 Feb 2025", "lammps_2025"), "lammps-2026": ("4 Jul 2026", "lammps_2026")}
# STICKSLIP_LAMMPS_GRANULAR: another LAMMPS build folder (tools/mutate_cpp.py: a mutant's; a
# patched tree's), then the only release the adapter and the tests use.
OVERRIDE = os.environ.get("STICKSLIP_LAMMPS_GRANULAR")


def launcher(release):
    """The `lmp` of a release (a word of RELEASES)."""
    return REPO / "build" / RELEASES[release][1] / "build" / "lmp"


def built():
    """{release: its lmp} for the releases built here ({"override": its lmp} when
    STICKSLIP_LAMMPS_GRANULAR is set)."""
    if OVERRIDE:
        return {"override": Path(OVERRIDE) / "lmp"}
    return {r: launcher(r) for r in RELEASES if launcher(r).is_file()}


# the newest release built here runs the scenes (the drop-in and restart tests run on each)
LAUNCHER = next(reversed(built().values()), launcher(list(RELEASES)[-1]))


def release_missing(release):
    """None if the release is built here, else why not in one line."""
    if OVERRIDE:
        return None if release == "override" else f"STICKSLIP_LAMMPS_GRANULAR={OVERRIDE} replaces {release}"
    if launcher(release).is_file():
        return None
    return f"{launcher(release)} missing (STICKSLIP_SOURCE_BUILDS={release} ./run.sh setup builds it)"


def available():
    if not LAUNCHER.is_file():
        return (f"{LAUNCHER} missing (STICKSLIP_SOURCE_BUILDS={','.join(RELEASES)} ./run.sh setup builds "
                "the modern LAMMPS releases)")
    return None


def dashpot_ratio(nu_s, nu_n):
    """x such that LAMMPS' tangential damping x * nu_n is nu_s to the last bit: nu_s/nu_n,
    or a neighbour of it where that product rounds off nu_s."""
    x = nu_s / nu_n
    for candidate in (x, math.nextafter(x, math.inf), math.nextafter(x, -math.inf)):
        if candidate * nu_n == nu_s:
            return candidate
    return x


def model_words(kn, nu_n, ks, nu_s, mu_s, mu_k, reset, slip_timing, record=True):
    """The granular model's words for a Hookean contact with the law: `damping velocity`
    (nu_n absolute), the sub-model `stick_slip` with the options as the name's suffixes, its
    dashpot x = nu_s/nu_n (nu_s > 0 needs nu_n > 0)."""
    x = dashpot_ratio(nu_s, nu_n) if nu_s > 0.0 else 0.0
    name = law_options.sub_model(reset=reset, slip_timing=slip_timing, record="yes" if record else "no")
    damping = " ".join(law_options.words("lammps_granular", damping="absolute"))
    return (f"hooke {_fmt(kn)} {_fmt(nu_n)} {damping} tangential {name} "
            f"{_fmt(ks)} {_fmt(x)} {_fmt(mu_s)} {_fmt(mu_k)} limit_damping")


def granular_model(scene):
    """The granular model's words for the scene's contact (pair_coeff and every wall)."""
    c, eff = scene.contact, scene.effects
    nu_n = c.nu_n if eff["normal_damping"] else 0.0
    nu_s = c.nu_s if eff["tangential_damping"] else 0.0
    if nu_s > 0.0 and nu_n == 0.0:
        raise ValueError("contact.nu_s: LAMMPS' granular model scales the tangential dashpot by the normal one, "
                         "so nu_s > 0 needs nu_n > 0 (effects.normal_damping on)")
    return model_words(c.kn, nu_n, c.ks, nu_s, c.mu_s, c.mu_k, c.reset, c.slip_timing)


class _GranularScript(_Script):
    """The LAMMPS adapter's script with the contact model in the granular syntax."""

    PAIR_RECORD = "p13 p14 p15 p16 p17"  # the sub-model's record: Fn, F_s on the first grain, slips

    def _build(self):
        if self.scene.effects["rotation"]:
            self.notes.append("LAMMPS' granular model takes the sliding velocity with the radii as lever arms "
                              "and a wall's torque at the radius (docs/law.md step 1: the middle of the overlap)")
        super()._build()

    def _pair_lines(self):
        return ["pair_style granular", f"pair_coeff * * {granular_model(self.scene)}"]

    def _wall_fix(self, fid, where):
        style = "wall/gran/region" if where.startswith("region ") else "wall/gran"
        # (the geometry words come after the model's; `contacts`: the per-atom record)
        return f"fix {fid} all {style} granular {granular_model(self.scene)} {where} contacts"


def run(scene, out_dir, progress=None, launcher=None, np_ranks=1):
    return run_with(_GranularScript, launcher or LAUNCHER, "LAMMPS", scene, out_dir, progress, np_ranks)
