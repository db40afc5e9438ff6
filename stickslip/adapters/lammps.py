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

import math
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np

from . import RunResult
from .ramp_script import bulk_dump, bulk_variables, ramp_loop, ramp_setup
from .text_dumps import id_ranges, read_dump, timeseries

NAME = "lammps"
REPO = Path(__file__).resolve().parents[2]
# The plugin build (./run.sh setup). Defined here only; STICKSLIP_LAMMPS_BUILD points it at
# another build (tools/mutate_cpp.py: a mutant's).
BUILD = Path(os.environ.get("STICKSLIP_LAMMPS_BUILD") or REPO / "build" / "lammps_plugin")
LAUNCHER = BUILD / "lmp-stickslip"
# A wall's per-atom record (lammps_plugin/README.md, `record yes`): column 1 the contact
# flag, 9 Fn, 10-12 the tangential force on the grain, 13 the contact's slip count
WALL_FLAG, WALL_FN, WALL_NSLIP = 1, 9, 13
# the law of docs/law.md, in the plugin's keywords
LAW_KEYWORDS = "history_rotation keep_length lever_arm contact damping absolute record yes"


def available():
    if shutil.which("lmp") is None:
        return "LAMMPS not installed (apt-get install lammps liblammps-dev)"
    if not LAUNCHER.is_file():
        return f"plugin not built ({LAUNCHER} missing; ./run.sh setup builds it)"
    return None


def _fmt(x):
    return repr(float(x))


def _vec(a):
    return " ".join(_fmt(x) for x in a)


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

    def _box(self):
        sc = self.scene
        pos = np.array([g.position for g in sc.grains])
        rmax = max(g.radius for g in sc.grains)
        pts = np.vstack([pos] + [w.point[None, :] for w in sc.walls]) if sc.walls else pos
        margin = 10 * rmax + 0.02  # room for the grains to move
        lo, hi = pts.min(axis=0) - margin, pts.max(axis=0) + margin
        if sc.dimension == 2:
            lo[2], hi[2] = -margin, margin  # z is periodic and inert in 2D
        for axis, (a, b) in sc.periodic.items():  # the periodic box is the scene's own
            lo["xyz".index(axis)], hi["xyz".index(axis)] = a, b
        return lo, hi

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
        keywords = f"mu_k {_fmt(c.mu_k)} reset {c.reset} slip_timing {c.slip_timing} {LAW_KEYWORDS}"
        return args, keywords

    def _build(self):
        sc, eff = self.scene, self.scene.effects
        lo, hi = self._box()
        d2 = sc.dimension == 2
        self.add("# written by stickslip (stickslip/adapters/lammps.py) for scene " + sc.name, "units si")
        if d2:
            self.add("dimension 2")
        # atoms are not sorted in memory: the neighbour lists keep one order through the run
        self.add("atom_style sphere", "atom_modify map array sort 0 0.0", "comm_modify vel yes",
                 "boundary " + ("f f p" if d2 else " ".join("p" if a in sc.periodic else "f" for a in "xyz")),
                 f"read_data {self._data_file(lo, hi)}")
        for g in sc.grains:
            self.add(f"set atom {self.ids[g.name]} mass {_fmt(sc.grain_mass(g))}")
        rmax = max(g.radius for g in sc.grains)
        self.add(f"neighbor {_fmt(0.2 * rmax)} bin", "neigh_modify delay 0 every 1 check yes")
        args, keywords = self._coefficients()
        self.add(f"pair_style gran/hooke/stickslip {args} {keywords}", "pair_coeff * *", f"timestep {_fmt(sc.dt)}")
        for k, w in enumerate(sc.walls):
            self._wall(k, w, args, keywords)
        if eff["gravity"]:
            self._gravity()
        # rotation off: integrate translation only, spins stay zero; fixed grains are not
        # integrated: they keep their place and zero velocity and spin
        moving = "all"
        fixed = [self.ids[g.name] for g in sc.grains if g.fixed]
        if fixed:
            # two fixed grains never act on each other: keep their pairs out of the neighbour list
            self.add("group fixed id " + id_ranges(fixed), "group moving subtract all fixed",
                     "neigh_modify exclude group fixed fixed")
            moving = "moving"
        self.moving = moving
        if eff["rotation"]:
            # a disk's inertia m r^2/2 in 2D (LAMMPS' default is a sphere's, 2/5)
            self.add(f"fix integrate {moving} nve/sphere" + (" disc" if d2 else ""))
        else:
            self.add(f"fix integrate {moving} nve")
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

    def _wall(self, k, w, args, keywords):
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
            self.add(f"fix {fid} all wall/gran/stickslip hooke/history {args} {'xyz'[j]}plane {side}{shear} {keywords}")
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
        self.add(region, f"fix {fid} all wall/gran/region/stickslip hooke/history {args} region r{k} {keywords}")

    def _gravity(self):
        sc = self.scene
        g = np.asarray(sc.gravity, float)
        gn = float(np.linalg.norm(g))
        if gn == 0:
            return
        if sc.gravity_ramp is not None:
            self.add(*ramp_setup(sc))
        elif sc.gravity_rate or sc.gravity_spinup[1]:
            # turning gravity (Scene.gravity_at) as one angle, fix gravity's `spherical` style:
            # it evaluates the variable at every step, `step` being the step whose positions
            # it acts on (the arithmetic of stickslip/adapters/liggghts.py).
            # 2D: (sin theta, cos theta), theta = theta0 - a; 3D: phi = phi0 + a (about z).
            (r0, t0), deg, t = sc.gravity_spinup, 180.0 / math.pi, f"step*{_fmt(sc.dt)}"
            a = f"({_fmt(r0 * deg)}*{t}+{_fmt((sc.gravity_rate - r0) * deg)}*({t}>{_fmt(t0)})*({t}-{_fmt(t0)}))"
            u = g / gn
            if sc.dimension == 2:
                self.add(f"variable gtheta equal {_fmt(math.degrees(math.atan2(u[0], u[1])))}-{a}",
                         f"fix gravity all gravity {gn!r} spherical 0.0 v_gtheta")
            else:
                theta, phi = math.degrees(math.acos(u[2])), math.degrees(math.atan2(u[1], u[0]))
                self.add(f"variable gphi equal {_fmt(phi)}+{a}",
                         f"fix gravity all gravity {gn!r} spherical v_gphi {_fmt(theta)}")
        else:
            self.add(f"fix gravity all gravity {gn!r} vector {_vec(g / gn)}")

    def _output(self):
        """Dumps of what the scene records, at its interval, and nothing else: the grains
        named in [output] grains and in [output] contacts (one group), with their wall
        contacts' records; the pair contacts among those grains; [output] stats reduced
        inside LAMMPS to two numbers per row."""
        sc = self.scene
        every = sc.output.every
        pair_contacts = [c for c in sc.output.contacts if c[1] in self.ids]
        self.walls_of = sorted({c[1] for c in sc.output.contacts if c[1] in self.walls}, key=list(self.walls).index)
        names = set(sc.output.grains) | {a for a, _ in sc.output.contacts} | {b for _, b in pair_contacts}
        if sc.output.slip_stats:  # the sliding speed of every contact needs every grain
            names = set(self.ids)
        # the rows of every dump: at least one grain, so that the steps are always written
        self.recorded = sorted(self.ids[n] for n in names) or [1]
        self.add("group rec id " + id_ranges(self.recorded))
        cols = "id x y z vx vy vz omegax omegay omegaz"
        for name in self.walls_of:
            cols += "".join(f" f_{self.walls[name]}[{k}]" for k in range(WALL_FN, WALL_NSLIP + 1))
        self.force_col = len(cols.split())  # with slip_stats: force and torque, for the half-step velocities
        if sc.output.slip_stats:
            cols += " fx fy fz tqx tqy tqz"
        self.add(f"dump atoms rec custom {every} atoms.dump {cols}", "dump_modify atoms sort id",
                 _full_precision("atoms"))
        # a pair's record: ids, Fn, the tangential force on the first grain, its slip count
        local = "c_{0}ids[1] c_{0}ids[2] c_{0}[1] c_{0}[2] c_{0}[3] c_{0}[4] c_{0}[5]"
        record = "pair/local p11 p1 p2 p3 p12 cutoff radius"
        if pair_contacts:
            # pair/local keeps the pairs with both grains in its group
            self.add(f"compute pairs rec {record}", "compute pairsids rec property/local patom1 patom2 cutoff radius",
                     f"dump pairs all local {every} pairs.dump {local.format('pairs')}", _full_precision("pairs"))
        if sc.output.stats:
            self._stats_output(every)
        if sc.output.slip_stats:
            # every grain pair's record at each recorded step and at the step before it: a
            # counter that moved between them slipped in the row's step (columns.SLIP_STATS).
            # The dump's next step comes from a variable.
            self.add(f"compute slips all {record}", "compute slipsids all property/local patom1 patom2 cutoff radius",
                     f"variable slipnext equal (step%{every}=={every - 1})*(step+1)"
                     f"+(step%{every}!={every - 1})*((floor(step/{every})+1)*{every}-1)",
                     f"dump slips all local {every} slips.dump {local.format('slips')}",
                     "dump_modify slips every v_slipnext", _full_precision("slips"))
        if sc.output.bulk or sc.gravity_ramp is not None:
            lines, _ = bulk_dump(sc, "bk_one", every)
            self.add(*bulk_variables(sc, self.moving), "group bk_one id 1", *lines, _full_precision("bulk"))
        self.add(f"thermo {max(1, sc.steps // 50)}", "thermo_style custom step atoms", "thermo_modify norm no")
        # a ramp's run ends on its conditions: a loop of intervals (ramp_script.py)
        self.add(*(ramp_loop(sc) if sc.gravity_ramp is not None else [f"run {sc.steps}"]))

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
        self.add(f'variable sse_e atom "0.5*mass*(vx*vx+vy*vy+vz*vz){spin}"',
                 "compute sse_ke all reduce sum v_sse_e",
                 f'variable sse_n equal "{"+".join(terms)}"', "variable sse_k equal c_sse_ke",
                 "variable sse_an atom v_sse_n", "variable sse_ak atom v_sse_k",
                 "group sse_one id 1",
                 f"dump stats sse_one custom {every} stats.dump id v_sse_an v_sse_ak",
                 _full_precision("stats"))

    def text(self):
        return "\n".join(self.lines) + "\n"


def _timeseries(script, work):
    pairs = read_dump(work / "pairs.dump") if (work / "pairs.dump").is_file() else {}

    def record(a, b, atoms, row, steps):
        ia = script.ids[a]
        rec = np.zeros((len(steps), 5))  # fn, fs (3), cumulative slips
        for r, s in enumerate(steps):
            if b in script.walls:  # the wall's per-atom record, 5 columns a wall after the grain's 10
                base = 10 + 5 * script.walls_of.index(b)
                rec[r] = atoms[s][row[ia]][base:base + 5]
                continue
            ib = script.ids[b]
            for line in pairs.get(s, ()):
                if {int(line[0]), int(line[1])} == {ia, ib}:
                    sign = 1.0 if int(line[0]) == ia else -1.0  # the record is the force on the first grain
                    rec[r] = [line[2], *(sign * line[3:6]), line[6]]
        return rec
    return timeseries("LAMMPS", script, work, record, slip_fn_col=2)


def run(scene, out_dir, progress=None, launcher=None, np_ranks=1):
    scene.refuse_unsupported("LAMMPS", ("periodic", "gravity_ramp", "bulk"))
    if scene.contact.law != "stick_slip":
        raise ValueError(f"the LAMMPS plugin implements stick_slip only, not {scene.contact.law}")
    if scene.output.energy:
        # the record has each contact's tangential work, not its split into slips and dashpot
        raise ValueError("output.energy: the LAMMPS adapter does not record the energy columns")
    work = Path(out_dir).resolve() / "lammps"
    work.mkdir(parents=True, exist_ok=True)
    for old in work.glob("*.dump"):
        old.unlink()
    script = _Script(scene, work)
    (work / "in.scene").write_text(script.text())
    cmd = [str(launcher or LAUNCHER), "-in", "in.scene", "-log", "log.lammps", "-echo", "none", "-nocite"]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if np_ranks > 1:
        cmd = ["mpirun", "-np", str(np_ranks)] + cmd
        if os.geteuid() == 0:  # OpenMPI refuses root unless told (CI runs as root)
            env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.perf_counter()
    loop, err = [], []
    with open(work / "screen.txt", "w") as screen:
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             encoding="utf-8", errors="replace", cwd=work, env=env)
        for line in p.stdout:
            screen.write(line)
            fields = line.split()
            if len(fields) == 2 and fields[0].isdigit() and progress is not None:
                progress(int(fields[0]), scene.steps)
            elif line.startswith("Loop time of"):
                loop.append(float(fields[3]))
            elif line.startswith("ERROR"):
                # "ERROR: text (file:line)" or "ERROR on proc N: text (file:line)"
                err.append(re.sub(r"\s*\([^()]*:\d+\)\s*$", "", line.split(":", 1)[1].strip()))
        p.wait()
    if err:
        raise ValueError(f"LAMMPS: {err[0]}")
    if p.returncode != 0 or not loop:
        raise RuntimeError(f"LAMMPS failed (exit {p.returncode}); see {work / 'screen.txt'}")
    df = _timeseries(script, work)
    steps = int(round(df["t"].iloc[-1] / scene.dt))  # a gravity ramp may end the run before time.duration
    return RunResult(df, steps, sum(loop), notes=script.notes)
