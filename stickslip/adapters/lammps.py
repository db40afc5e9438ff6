# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for LAMMPS (Debian's package) with the stick-slip plugin (lammps_plugin/).

Writes a LAMMPS input script for the scene (2D scenes with `dimension 2`; only the effects
the scene switches on) with the law's keywords that make the plugin run docs/law.md
exactly (`history_rotation keep_length lever_arm contact damping absolute limit_damping`,
the scene's reset, slip timing and mu_k), runs the plugin's launcher in one `run` (a run
split in two is not the same run in LAMMPS: lammps_plugin/README.md), and turns its dumps
into the standard time series. Per-contact forces and slip counts come from the law's own
record (`record yes`): what the law applied, kept in the contact's history and written by
every force evaluation, the set-up's too, so row 0 carries the set-up force as pyref's.

Walls: a fixed plane normal to an axis is a primitive wall (`fix wall/gran/stickslip
xplane|yplane|zplane`), one sliding along itself along an axis the same with `shear`; any
other plane is a region plane (`fix wall/gran/region/stickslip`), turned by `region ...
rotate v_theta` (the angle of each step is the scene's, Scene.rotation_steps and
rotation_rate) or moved by `region ... move` (no velocity in the set-up: the run's notes
say so). LAMMPS' region gives each contact the wall's rigid velocity of the step at the
surface point nearest the grain's centre (docs/law.md step 1), by differencing its angle
and place over the step.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from . import RunResult
from . import missing
from .lammps_family import box, boundary, fmt as _fmt, integrated, run_script, vec as _vec, work_folder
from . import lid_script, ramp_script
from .. import law_options
from .text_dumps import (atoms_dump, id_ranges, optional_dump, pair_record, recorded, run_lines, slips_dump,
                         stats_dump, timeseries)

NAME = "lammps"
REPO = Path(__file__).resolve().parents[2]
# The plugin build (./run.sh setup). Defined here only; STICKSLIP_LAMMPS_BUILD points it at
# another build (tools/mutate_cpp.py: a mutant's).
BUILD = Path(os.environ.get("STICKSLIP_LAMMPS_BUILD") or REPO / "build" / "lammps_plugin")
LAUNCHER = BUILD / "lmp-stickslip"
# A wall's per-atom record (lammps_plugin/README.md, `record yes`): column 1 the contact
# flag, 9 Fn, 10-12 the tangential force on the grain, 13 the contact's slip count
WALL_FLAG, WALL_FN, WALL_NSLIP = 1, 9, 13


def law_keywords(mu_k, reset, slip_timing, record=True):
    """The plugin's keywords for docs/law.md's law (every rule written out: the styles default
    to stock's), mu_k, the reset and slip timing given, the record on or off."""
    law = law_options.the_law(reset=reset, slip_timing=slip_timing, record="yes" if record else "no")
    return f"mu_k {_fmt(mu_k)} " + " ".join(law_options.words("lammps", explicit=True, **law))


def available():
    return missing("lmp", "apt-get install lammps liblammps-dev", LAUNCHER, "./run.sh setup builds the plugin")


def _full_precision(dump):
    """Dumps print 6 digits by default; forces and positions are compared far below that
    (integers, the ids, stay integers). LAMMPS flushes a dump file after every write by
    default: a small scene's rows are written thousands of times a second."""
    return f"dump_modify {dump} format float %.17g flush no"


def _axis_of(normal):
    """The axis (0, 1, 2) a unit normal lies along, or None."""
    axes = [j for j in range(3) if abs(normal[j]) == 1.0]
    return axes[0] if axes else None


class _Script:
    """The input script and the facts needed to read its output back."""

    def __init__(self, scene, work: Path):
        self.scene, self.work = scene, work
        self.lines = []
        self.notes = []
        self.ids = {g.name: i + 1 for i, g in enumerate(scene.grains)}
        self.walls = {}  # wall name -> fix id (every wall records per atom)
        self._build()

    def add(self, *lines):
        self.lines.extend(lines)

    def _data_file(self, lo, hi):
        """The box and the grains (atom_style sphere: id type diameter density x y z; the
        Velocities section carries the spins). The masses are set afterwards, exactly the
        scene's: read_data makes a sphere's mass from the density in 2D too."""
        sc = self.scene
        rows = ["grains written by stickslip", "", f"{len(sc.grains)} atoms", "1 atom types"]
        rows += [f"{_fmt(lo[k])} {_fmt(hi[k])} {a}lo {a}hi" for k, a in enumerate("xyz")]
        rows += ["", "Atoms # sphere", ""]
        rows += [f"{self.ids[g.name]} 1 {_fmt(2 * g.radius)} {_fmt(g.density)} {_vec(g.position)}" for g in sc.grains]
        rows += ["", "Velocities", ""]
        rows += [f"{self.ids[g.name]} {_vec(g.velocity)} {_vec(g.angular_velocity)}" for g in sc.grains]
        (self.work / "grains.data").write_text("\n".join(rows) + "\n")
        return "grains.data"

    def _coefficients(self):
        """Stock's coefficient arguments (Kn Kt gamma_n gamma_t xmu dampflag limit_damping)
        and the law's keywords, the same for the grain pairs and the walls."""
        c, eff = self.scene.contact, self.scene.effects
        nu_n = c.nu_n if eff["normal_damping"] else 0.0
        nu_s = c.nu_s if eff["tangential_damping"] else 0.0
        # limit_damping: no attractive normal force (docs/law.md step 2, Fn = max(0, ...))
        dampflag = 1 if nu_s > 0 else 0
        args = f"{_fmt(c.kn)} {_fmt(c.ks)} {_fmt(nu_n)} {_fmt(nu_s)} {_fmt(c.mu_s)} {dampflag} limit_damping"
        return args, law_keywords(c.mu_k, c.reset, c.slip_timing)

    # The contact model's lines, the one part a LAMMPS with another granular syntax changes
    # (stickslip/adapters/lammps_granular.py): the pair style, a wall's fix, pair/local's record.
    PAIR_RECORD = "p11 p1 p2 p3 p12"  # Fn, the tangential force on the first grain, its slip count

    def _pair_lines(self):
        args, keywords = self._coefficients()
        return [f"pair_style gran/hooke/stickslip {args} {keywords}", "pair_coeff * *"]

    def _wall_fix(self, fid, where):
        """The fix of a wall at `where` (`xplane lo hi [shear ...]` or `region ID`)."""
        args, keywords = self._coefficients()
        style = "wall/gran/region/stickslip" if where.startswith("region ") else "wall/gran/stickslip"
        return f"fix {fid} all {style} hooke/history {args} {where} {keywords}"

    def _build(self):
        sc, eff = self.scene, self.scene.effects
        lo, hi, _ = box(sc)
        d2 = sc.dimension == 2
        self.add("# written by stickslip (stickslip/adapters/lammps.py) for scene " + sc.name, "units si")
        if d2:
            self.add("dimension 2")
        # atoms are not sorted in memory: the neighbour lists keep one order through the run
        self.add("atom_style sphere", "atom_modify map array sort 0 0.0", "comm_modify vel yes",
                 boundary(sc), f"read_data {self._data_file(lo, hi)}")
        for g in sc.grains:
            self.add(f"set atom {self.ids[g.name]} mass {_fmt(sc.grain_mass(g))}")
        rmax = max(g.radius for g in sc.grains)
        self.add(f"neighbor {_fmt(0.2 * rmax)} bin", "neigh_modify delay 0 every 1 check yes")
        self.add(*self._pair_lines(), f"timestep {_fmt(sc.dt)}")
        for k, w in enumerate(sc.walls):
            self._wall(k, w)
        if eff["gravity"]:
            self.add(*ramp_script.gravity(sc))
        # rotation off: integrate translation only, spins stay zero
        moving, lines = integrated(sc, self.ids)
        self.moving = moving
        self.add(*lines)
        if eff["rotation"]:
            # a disk's inertia m r^2/2 in 2D (LAMMPS' default is a sphere's, 2/5)
            self.add(f"fix integrate {moving} nve/sphere" + (" disc" if d2 else ""))
        else:
            self.add(f"fix integrate {moving} nve")
        if sc.lid is not None:
            self.add(*lid_script.drive(sc))
        # imposed velocity components: no force along them, so they keep their start value
        # (one group per set of components: LAMMPS allows 32 groups)
        held = {}
        for g in sc.grains:
            if g.imposed and not g.fixed:
                held.setdefault("".join(sorted(g.imposed)), []).append(self.ids[g.name])
        for comps, ids in held.items():
            zero = " ".join("0.0" if c in comps else "NULL" for c in "xyz")
            self.add(f"group hold_{comps} id {id_ranges(ids)}", f"fix hold_{comps} hold_{comps} setforce {zero}")
        if d2:
            self.add("fix twod all enforce2d")
        self._output()

    def _wall(self, k, w):
        sc = self.scene
        fid = f"w{k}"
        self.walls[w.name] = fid
        j = _axis_of(w.normal)
        v = np.asarray(w.velocity, float)
        along = [a for a in range(3) if v[a] != 0.0]
        if j is not None and w.rotation is None and (not along or (len(along) == 1 and along[0] != j)):
            # a plane normal to axis j, the grains on the side its normal points to; a wall
            # sliding along itself (one axis) is stock's `shear` (the same velocity at every step)
            side = f"{_fmt(w.point[j])} NULL" if w.normal[j] > 0 else f"NULL {_fmt(w.point[j])}"
            shear = f" shear {'xyz'[along[0]]} {_fmt(v[along[0]])}" if along else ""
            self.add(self._wall_fix(fid, f"{'xyz'[j]}plane {side}{shear}"))
            return
        region = f"region r{k} plane {_vec(w.point)} {_vec(w.normal)} side in units box"
        if w.rotation is not None:
            if np.any(v):
                raise ValueError(f"wall {w.name}: a wall that both turns and translates is not supported on LAMMPS")
            r = w.rotation
            nrot = sc.rotation_steps(w)
            # the angle after step `step`: turns during steps 1..nrot, then held, with the
            # arithmetic of pyref's angle ((rate dt) times the steps turned)
            per_step = sc.rotation_rate(w) * sc.dt
            self.add(f"variable theta{k} equal {_fmt(per_step)}*((step<={nrot})*step+(step>{nrot})*{nrot})")
            region += f" rotate v_theta{k} {_vec(r.pivot)} {_vec(r.axis)}"
        elif np.any(v):
            # the place after step `step`: p0 + (v step) dt, as pyref's
            moves = [f"v_move{k}{a}" for a in "xyz"]
            for a, name in enumerate(moves):
                self.add(f"variable {name[2:]} equal {_fmt(v[a])}*step*{_fmt(sc.dt)}")
            region += " move " + " ".join(moves)
            self.notes.append(f"wall {w.name} moves as a LAMMPS region, which has no velocity in the set-up force "
                              "evaluation (pyref: the wall's velocity): the first half step differs if it touches "
                              "a grain")
        self.add(region, self._wall_fix(fid, f"region r{k}"))

    def _output(self):
        """Dumps of what the scene records, at its interval, and nothing else: the grains
        named in [output] grains and in [output] contacts (one group), with their wall
        contacts' records; the pair contacts among those grains; [output] stats reduced
        inside LAMMPS to two numbers per row."""
        sc = self.scene
        every = sc.output.every
        pair_contacts, self.walls_of, self.recorded = recorded(sc, self.ids, self.walls)
        self.add("group rec id " + id_ranges(self.recorded))
        wall_cols = "".join(f" f_{self.walls[name]}[{k}]" for name in self.walls_of
                            for k in range(WALL_FN, WALL_NSLIP + 1))
        dump, self.force_col, _ = atoms_dump(every, wall_cols, sc.output.slip_stats)
        self.add(dump, "dump_modify atoms sort id", _full_precision("atoms"))
        # a pair's record: ids, Fn, the tangential force on the first grain, its slip count
        local = "c_{0}ids[1] c_{0}ids[2] c_{0}[1] c_{0}[2] c_{0}[3] c_{0}[4] c_{0}[5]"
        record = f"pair/local {self.PAIR_RECORD} cutoff radius"
        if pair_contacts:
            # pair/local keeps the pairs with both grains in its group
            self.add(f"compute pairs rec {record}", "compute pairsids rec property/local patom1 patom2 cutoff radius",
                     f"dump pairs all local {every} pairs.dump {local.format('pairs')}", _full_precision("pairs"))
        if sc.output.stats:
            self._stats_output(every)
        if sc.output.slip_stats:
            self.add(f"compute slips all {record}", "compute slipsids all property/local patom1 patom2 cutoff radius",
                     *slips_dump(every, local.format("slips")), _full_precision("slips"))
        self.add(*ramp_script.bulk_dump(sc, self.moving, lambda d, n: _full_precision(d)))
        self.add(*ramp_script.run(sc, run_lines))

    def _stats_output(self, every):
        """[output] stats, reduced in LAMMPS: contacts touching (grain pairs that overlap,
        counted at both grains by compute contact/atom; grains a wall touches, its record's
        contact flag) and the kinetic energy (spin with the scene's inertia: disks in 2D,
        spheres in 3D). Written on grain 1's row of stats.dump, one row per output step."""
        sc = self.scene
        self.add("compute sse_cc all contact/atom", "compute sse_pairs all reduce sum c_sse_cc",
                 "compute sse_p all property/atom radius omegax omegay omegaz")
        terms = ["c_sse_pairs/2"]
        for k, name in enumerate(self.walls.values()):
            self.add(f"compute sse_w{k} all reduce sum f_{name}[{WALL_FLAG}]")
            terms.append(f"c_sse_w{k}")
        inertia = 0.5 if sc.dimension == 2 else 0.4
        # (this LAMMPS' atom-style variables know no radius or spin: compute property/atom)
        spin = (f"+0.5*{inertia}*mass*c_sse_p[1]*c_sse_p[1]*(c_sse_p[2]*c_sse_p[2]+c_sse_p[3]*c_sse_p[3]"
                "+c_sse_p[4]*c_sse_p[4])"
                if sc.effects["rotation"] else "")
        self.add(*stats_dump(every, "+".join(terms), spin), _full_precision("stats"))

    def text(self):
        return "\n".join(self.lines) + "\n"


def _timeseries(script, work):
    pairs = optional_dump(work / "pairs.dump")

    def record(a, b, steps):  # a grain pair (every wall records per atom): pair/local's record
        ia, ib = script.ids[a], script.ids[b]
        return np.array([pair_record(pairs.get(s, ()), ia, ib, fn_col=2) or [0.0] * 5 for s in steps])
    return timeseries("LAMMPS", script, work, record, slip_fn_col=2)


def run(scene, out_dir, progress=None, launcher=None, np_ranks=1):
    return run_with(_Script, launcher or LAUNCHER, "LAMMPS", scene, out_dir, progress, np_ranks)


def run_with(script_class, launcher, engine, scene, out_dir, progress, np_ranks):
    """A scene through `script_class`'s input script on `launcher` (the run of both LAMMPS
    adapters); the work folder is out_dir/<engine, lower case>."""
    scene.refuse_unsupported(engine, ("periodic", "gravity_ramp", "bulk", "lid"))
    work = work_folder(scene, out_dir, engine)
    script = script_class(scene, work)
    (work / "in.scene").write_text(script.text())
    cmd = [str(launcher), "-in", "in.scene", "-log", "log.lammps", "-echo", "none", "-nocite"]
    loop_time = run_script(engine, cmd, work, scene.steps, progress, np_ranks, env={"OMP_NUM_THREADS": "1"})
    df = _timeseries(script, work)
    return RunResult(df, ramp_script.steps_run(scene, df), loop_time, notes=script.notes)
