# SPDX-License-Identifier: GPL-2.0-or-later
"""Adapter for LIGGGHTS 3.8 (Debian's package) with the stick_slip plugin.

Writes a LIGGGHTS input script for the scene (2D scenes with `dimension 2`; only the
effects the scene switches on), runs the plugin's launcher, and turns its dumps into
the standard time series. Per-contact force and slip count come from the model's own
record (`stick_slip_record on`: Fn, F_s and a slip counter kept in the contact history),
because LIGGGHTS' contact computes re-evaluate contacts and would report, at a slip
step, a force that was never applied. Only what [output] asks for is written (the
recorded grains and their contacts; the stats reduced to two numbers per row inside
LIGGGHTS), and a run whose output is not finite raises an error.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from . import RunResult
from .text_dumps import full_precision as _full_precision, id_ranges as _id_ranges
from . import missing
from .lammps_family import (box, boundary, fmt as _fmt, integrated, run_script, serial_mpi_env, vec as _vec,
                            work_folder)
from . import lid_script, ramp_script
from .. import law_options
from .text_dumps import atoms_dump, optional_dump, pair_record, recorded, run_lines, slips_dump, stats_dump, timeseries

NAME = "liggghts"
REPO = Path(__file__).resolve().parents[2]
# The plugin build (./run.sh setup): the launcher and the preloadable library. Defined here only.
# STICKSLIP_LIGGGHTS_BUILD points it at another build (tools/mutate_cpp.py: a mutant's).
BUILD = Path(os.environ.get("STICKSLIP_LIGGGHTS_BUILD") or REPO / "build" / "liggghts_plugin")
LAUNCHER = BUILD / "liggghts-stickslip"
PRELOAD = BUILD / "libstickslip_liggghts.so"
# contact history layout of the stick_slip model with the record on (1-based, as LIGGGHTS counts):
# D (3 values), then Fn, F_s (3), cumulative slip count
RECORD_FN, RECORD_FS, RECORD_NSLIP = 4, 5, 8
HISTORY_VALUES = 8


def law_settings(reset, slip_timing):
    """The contact-model settings of docs/law.md's law with its record on: `hooke/stiffness`'s
    absolute damping (gamman_abs, gammat_abs are nu_n, nu_s), no tensile normal force
    (limitForce, step 2), the reset and slip timing given."""
    return " ".join(["limitForce on"] + law_options.words("liggghts", reset=reset, slip_timing=slip_timing,
                                                          damping="absolute", record="yes"))


def available():
    return missing("liggghts", "apt-get install liggghts libliggghts-dev", LAUNCHER,
                   "./run.sh setup builds the plugin")


class _Script:
    """The input script and the facts needed to read its output back."""

    def __init__(self, scene, work: Path):
        self.scene, self.work = scene, work
        self.lines = []
        self.ids = {g.name: i + 1 for i, g in enumerate(scene.grains)}
        self.primitive = {}  # wall name -> fix id (per-atom history f_history_<id>)
        self.mesh = {}  # wall name -> fix id
        self._build()

    def add(self, *lines):
        self.lines.extend(lines)

    def _material(self):
        c, eff = self.scene.contact, self.scene.effects
        props = {"kn": c.kn, "kt": c.ks,
                 "gamman_abs": c.nu_n if eff["normal_damping"] else 0.0,
                 "gammat_abs": c.nu_s if eff["tangential_damping"] else 0.0,
                 "coefficientFriction": c.mu_s, "coefficientKineticFriction": c.mu_k}
        model = "model hooke/stiffness tangential stick_slip"
        if c.rolling:  # LIGGGHTS' own rolling model: torque capped at coefficientRollingFriction R Fn
            props["coefficientRollingFriction"] = c.rolling_mu
            model += f" rolling_friction {c.rolling}"
        for k, (name, value) in enumerate(props.items()):
            self.add(f"fix m{k} all property/global {name} peratomtypepair 1 {_fmt(value)}")
        return model, law_settings(c.reset, c.slip_timing)

    def _mesh_file(self, w, half):
        """A wall as two triangles; the shared diagonal crosses the wall's point at half/2
        off it, so a grain resting at the point touches one triangle only."""
        n = w.normal / np.linalg.norm(w.normal)
        if self.scene.dimension == 2:
            t2 = np.array([0.0, 0.0, 1.0])
            b = 0.45 * (self._hi[2] - self._lo[2])
        else:
            t2 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
            t2 /= np.linalg.norm(t2)
            b = half
        t1 = np.cross(t2, n)
        c = [w.point + a * t1 + s * b * t2 for a, s in ((-half, -1), (2 * half, -1), (2 * half, 1), (-half, 1))]
        path = self.work / f"wall_{w.name}.stl"
        with open(path, "w") as f:
            f.write("solid wall\n")
            for tri in ((c[0], c[1], c[2]), (c[0], c[2], c[3])):
                f.write(f" facet normal {_vec(n)}\n  outer loop\n")
                for p in tri:
                    f.write(f"   vertex {_vec(p)}\n")
                f.write("  endloop\n endfacet\n")
            f.write("endsolid wall\n")
        return path.name

    def _data_file(self, lo, hi):
        """The box and the grains as a LIGGGHTS data file (atom_style sphere): the only way
        LIGGGHTS 3.8 takes an initial spin (its `set` has no omega). In 2D LIGGGHTS makes
        the mass pi r^2 rho, per unit thickness, as the scene means it."""
        rows = ["grains written by stickslip", "", f"{len(self.scene.grains)} atoms", "1 atom types"]
        rows += [f"{_fmt(lo[k])} {_fmt(hi[k])} {a}lo {a}hi" for k, a in enumerate("xyz")]
        rows += ["", "Atoms", ""]
        rows += [f"{self.ids[g.name]} 1 {_fmt(2 * g.radius)} {_fmt(g.density)} {_vec(g.position)}"
                 for g in self.scene.grains]
        rows += ["", "Velocities", ""]
        rows += [f"{self.ids[g.name]} {_vec(g.velocity)} {_vec(g.angular_velocity)}" for g in self.scene.grains]
        (self.work / "grains.data").write_text("\n".join(rows) + "\n")
        return "grains.data"

    def _build(self):
        sc, eff = self.scene, self.scene.effects
        lo, hi, margin = box(sc)
        self._lo, self._hi = lo, hi
        d2 = sc.dimension == 2
        self.add("# written by stickslip (stickslip/adapters/liggghts.py) for scene " + sc.name,
                 "atom_style sphere", "atom_modify map array", "units si", "newton off",
                 "communicate single vel yes")
        if d2:
            self.add("dimension 2")
        self.add(boundary(sc), f"read_data {self._data_file(lo, hi)}")
        rmax = max(g.radius for g in sc.grains)
        self.add(f"neighbor {_fmt(0.2 * rmax)} bin", "neigh_modify delay 0")
        model, settings = self._material()
        self.add(f"pair_style gran {model} {settings}", "pair_coeff * *", f"timestep {_fmt(sc.dt)}")
        half = 0.4 * margin  # a mesh wall spans [-half, 2 half] along the wall: inside the box when turned
        for k, w in enumerate(sc.walls):
            fid = f"w{k}"
            axis = [j for j in range(3) if abs(w.normal[j]) == 1.0]
            moving = w.rotation is not None or np.any(w.velocity)
            if axis and not moving:
                j = axis[0]
                self.add(f"fix {fid} all wall/gran {model} primitive type 1 {'xyz'[j]}plane "
                         f"{_fmt(w.point[j])} {settings}")
                self.primitive[w.name] = fid
                continue
            stl = self._mesh_file(w, half)
            store = " store_force yes" if sc.output.stats else ""  # per-atom force: the stats' contact count
            self.add(f"fix mesh{k} all mesh/surface file {stl} type 1",
                     f"fix {fid} all wall/gran {model} mesh n_meshes 1 meshes mesh{k}{store} {settings}")
            self.mesh[w.name] = fid
            if w.rotation is not None:
                if np.any(w.velocity):
                    raise ValueError(f"wall {w.name}: a wall that both turns and translates is not supported on LIGGGHTS")
                r = w.rotation
                nrot, rate = sc.rotation_steps(w), sc.rotation_rate(w)
                # turns during steps 1..nrot (`step` is the step being made), then held
                self.add(f"variable omega{k} equal (step<={nrot})*{rate!r}",
                         f"fix move{k} all move/mesh mesh mesh{k} rotate/variable origin {_vec(r.pivot)} "
                         f"axis {_vec(r.axis)} omega v_omega{k}")
            else:
                self.add(f"fix move{k} all move/mesh mesh mesh{k} linear {_vec(w.velocity)}")
        if eff["gravity"]:
            self.add(*ramp_script.gravity(sc))
        # rotation off: integrate translation only, spins stay zero (nothing paid for them)
        moving, lines = integrated(sc, self.ids)
        self.moving = moving
        self.add(*lines)
        self.add(f"fix integrate {moving} nve/sphere" if eff["rotation"] else f"fix integrate {moving} nve")
        if sc.lid is not None:
            self.add(*lid_script.drive(sc))
        for g in sc.grains:
            if g.imposed:
                comps = " ".join("0.0" if c in g.imposed else "NULL" for c in "xyz")
                i = self.ids[g.name]
                self.add(f"group g{i} id {i}", f"fix hold{i} g{i} setforce {comps}")
        if d2:
            self.add("fix twod all enforce2d")
        self._output()

    def _output(self):
        """Dumps of what the scene records, at its interval, and nothing else (issue 15
        section 4): the grains named in [output] grains and in [output] contacts (one
        group), the pair contacts among those grains, the mesh-wall contacts of those
        grains; [output] stats (contacts touching, kinetic energy) are reduced inside
        LIGGGHTS to two numbers per row."""
        sc = self.scene
        every = sc.output.every
        pair_contacts, self.walls_of, self.recorded = recorded(sc, self.ids, self.primitive)
        mesh_contacts = {c[1] for c in sc.output.contacts if c[1] in self.mesh}
        self.add("group rec id " + _id_ranges(self.recorded))
        wall_cols = "".join(f" f_history_{self.primitive[name]}[{k}]" for name in self.walls_of
                            for k in range(RECORD_FN, RECORD_NSLIP + 1))
        dump, self.force_col, ncols = atoms_dump(every, wall_cols, sc.output.slip_stats)
        self.add(dump, "dump_modify atoms sort id", _full_precision("atoms", ncols, ints=1))
        local = "c_{0}[1] c_{0}[2] c_{0}[3] " + " ".join(
            f"c_{{0}}[{3 + k}]" for k in range(RECORD_FN, RECORD_NSLIP + 1))
        if pair_contacts:
            # pair/gran/local keeps the pairs with both grains in its group
            self.add("compute pairs rec pair/gran/local id history",
                     f"dump pairs all local {every} pairs.dump {local.format('pairs')}",
                     _full_precision("pairs", 8))
        if mesh_contacts:
            if len(mesh_contacts) > 1:
                raise ValueError("LIGGGHTS records the contacts of one mesh (moving or oblique) wall only; "
                                 f"the scene needs {sorted(mesh_contacts)}")
            self.add("compute walls rec wall/gran/local id history",
                     f"dump walls all local {every} walls.dump {local.format('walls')}",
                     _full_precision("walls", 8))
        if sc.output.stats:
            self._stats_output(every)
        if sc.output.slip_stats:  # (ids, Fn, F_s, slip counter)
            self.add("compute slips all pair/gran/local id history", *slips_dump(every, local.format("slips")),
                     _full_precision("slips", 8))
        self.add(*ramp_script.bulk_dump(sc, self.moving, lambda d, n: _full_precision(d, n, ints=1)))
        self.add(*ramp_script.run(sc, run_lines))

    def _stats_output(self, every):
        """[output] stats, reduced in LIGGGHTS: contacts touching (grain pairs that overlap,
        counted at both grains by compute contact/atom; grains overlapping a primitive
        wall's plane; grains a mesh wall pushes) and the kinetic energy (spin with the
        scene's inertia: disks in 2D, spheres in 3D). Written on grain 1's row of
        stats.dump, one row per output step."""
        sc = self.scene
        self.add("compute sse_cc all contact/atom", "compute sse_pairs all reduce sum c_sse_cc",
                 "compute sse_radius all property/atom radius")
        terms = ["c_sse_pairs/2"]
        for k, w in enumerate(sc.walls):
            name = f"sse_w{k}"
            if w.name in self.primitive:
                n, p = w.normal / np.linalg.norm(w.normal), w.point
                dist = "+".join(f"(({a}-{_fmt(p[j])})*{_fmt(n[j])})" for j, a in enumerate("xyz"))
                self.add(f'variable {name} atom "(c_sse_radius-({dist}))>0"')
            else:
                f = f"f_force_{self.mesh[w.name]}"
                self.add(f'variable {name} atom "({f}[1]*{f}[1]+{f}[2]*{f}[2]+{f}[3]*{f}[3])>0"')
            self.add(f"compute {name} all reduce sum v_{name}")
            terms.append(f"c_{name}")
        inertia = 0.5 if sc.dimension == 2 else 0.4
        spin = (f"+0.5*{inertia}*mass*c_sse_radius*c_sse_radius*(omegax*omegax+omegay*omegay+omegaz*omegaz)"
                if sc.effects["rotation"] else "")
        self.add(*stats_dump(every, "+".join(terms), spin), _full_precision("stats", 3, ints=1))

    def text(self):
        return "\n".join(self.lines) + "\n"


def _timeseries(script, work):
    pairs, walls = optional_dump(work / "pairs.dump"), optional_dump(work / "walls.dump")

    def record(a, b, steps):  # a grain pair or a mesh wall (primitive walls record per atom)
        ia = script.ids[a]
        rec = np.zeros((len(steps), 5))  # fn, fs (3), cumulative slips
        for r, s in enumerate(steps):
            blk = pairs.get(s) if b in script.ids else walls.get(s)
            if blk is None or not len(blk):
                continue
            if b in script.ids:
                if (got := pair_record(blk, ia, script.ids[b], fn_col=3)) is not None:
                    rec[r] = got
            else:  # a mesh wall: one row per touched triangle, summed
                for line in blk[blk[:, 2].astype(int) == ia]:
                    rec[r, :4] += line[3:7]
                    rec[r, 4] += line[7]
        return rec
    # slips.dump: id1 id2 - Fn F_s(3) count
    return timeseries("LIGGGHTS", script, work, record, slip_fn_col=3)


def run(scene, out_dir, progress=None, launcher=None, np_ranks=1):
    scene.refuse_unsupported("LIGGGHTS", ("periodic", "gravity_ramp", "rolling", "bulk", "lid"))
    work = work_folder(scene, out_dir, "LIGGGHTS")
    script = _Script(scene, work)
    (work / "in.scene").write_text(script.text())
    cmd = [str(launcher or LAUNCHER), "-in", "in.scene", "-log", "log.liggghts", "-echo", "none"]
    # one process needs no MPI daemon (lammps_family.serial_mpi_env)
    loop_time = run_script("LIGGGHTS", cmd, work, scene.steps, progress, np_ranks, serial_env=serial_mpi_env(work))
    df = _timeseries(script, work)
    return RunResult(df, ramp_script.steps_run(scene, df), loop_time)
