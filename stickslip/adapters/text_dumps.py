# SPDX-License-Identifier: GPL-2.0-or-later
"""Text dumps of the LAMMPS family (LIGGGHTS is a LAMMPS fork and writes the same
format): writing them at full precision, reading them back, and what both adapters compute
from them (the slip statistics of columns.SLIP_STATS, group ranges of atom ids)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from .. import columns


def full_precision(dump, ncols, ints=0):
    """Dumps print 6 digits by default; forces and positions are compared far below that."""
    return f'dump_modify {dump} format "' + " ".join(["%d"] * ints + ["%.17g"] * (ncols - ints)) + '"'


def recorded(scene, ids, walls):
    """What a LAMMPS-family script dumps, and nothing else: the recorded pair contacts (both
    grains in `ids`), the walls of `walls` whose contacts are recorded (in its order), and the
    atom ids of the grains the dumps hold: those named in [output] grains and contacts (every
    grain with slip_stats, whose sliding speeds need them all; at least one, so that every
    output step is written)."""
    out = scene.output
    pair_contacts = [c for c in out.contacts if c[1] in ids]
    walls_of = sorted({c[1] for c in out.contacts if c[1] in walls}, key=list(walls).index)
    names = set(out.grains) | {a for a, _ in out.contacts} | {b for _, b in pair_contacts}
    if out.slip_stats:
        names = set(ids)
    return pair_contacts, walls_of, sorted(ids[n] for n in names) or [1]


def atoms_dump(every, wall_columns, slip_stats):
    """The atoms dump of the recorded grains (group rec): id, place, velocity, spin, then
    `wall_columns` (each recorded wall's per-atom record), then with slip_stats the force and
    torque (for the half-step velocities). Returns its command, the index of its force
    column and its number of columns."""
    cols = "id x y z vx vy vz omegax omegay omegaz" + wall_columns
    force_col = len(cols.split())
    if slip_stats:
        cols += " fx fy fz tqx tqy tqz"
    return f"dump atoms rec custom {every} atoms.dump {cols}", force_col, len(cols.split())


def slips_dump(every, entries):
    """Every grain pair's record (`entries` of compute `slips`) at each output step and at the
    step before it: a counter that moved between them slipped in the row's step
    (columns.SLIP_STATS). The dump's next step comes from a variable."""
    return [f"variable slipnext equal (step%{every}=={every - 1})*(step+1)"
            f"+(step%{every}!={every - 1})*((floor(step/{every})+1)*{every}-1)",
            f"dump slips all local {every} slips.dump {entries}", "dump_modify slips every v_slipnext"]


def stats_dump(every, contacts, spin):
    """[output] stats reduced inside the engine to two numbers per output step, written on
    grain 1's row of stats.dump: `contacts` (an equal-style formula of the contacts touching)
    and the kinetic energy, translational plus `spin` (a per-atom formula, "" without
    rotation)."""
    return [f'variable sse_e atom "0.5*mass*(vx*vx+vy*vy+vz*vz){spin}"', "compute sse_ke all reduce sum v_sse_e",
            f'variable sse_n equal "{contacts}"', "variable sse_k equal c_sse_ke",
            "variable sse_an atom v_sse_n", "variable sse_ak atom v_sse_k", "group sse_one id 1",
            f"dump stats sse_one custom {every} stats.dump id v_sse_an v_sse_ak"]


def run_lines(steps):
    """The run, its progress printed 50 times (the adapters read it) as plain counts."""
    return [f"thermo {max(1, steps // 50)}", "thermo_style custom step atoms", "thermo_modify norm no",
            f"run {steps}"]


def read_dump(path):
    """Blocks of a LAMMPS or LIGGGHTS dump: {step: 2D float array} ('atoms' or 'local' dumps).
    A block is ITEM: TIMESTEP, the step, ITEM: NUMBER OF ..., the count, ITEM: BOX BOUNDS
    and three lines of bounds, ITEM: ATOMS|ENTRIES, then the rows. pandas' C parser reads
    every number of the file at once (the ITEM lines dropped as comments; rows end with a
    space, hence one more column): a drum run's dumps hold millions of rows, which line by
    line in Python took a third of the run, and the same values come out (%.17g round-trips)."""
    with open(path) as f:
        head = [next(f, "") for _ in range(9)]
    if not head[0].startswith("ITEM: TIMESTEP"):
        return {}
    ncols = len(head[8].split()) - 2  # "ITEM: ATOMS id x y ..." / "ITEM: ENTRIES c_..."
    v = pd.read_csv(path, sep=" ", header=None, comment="I", names=range(ncols + 1), dtype=float,
                    engine="c").to_numpy()[:, :ncols]
    blocks, k = {}, 0
    while k < len(v):  # the step, the count, three lines of bounds, the rows
        step, count = int(v[k, 0]), int(v[k + 1, 0])
        if k + 5 + count > len(v):
            raise RuntimeError(f"{path} is cut short at step {step} (the run stopped while writing?)")
        blocks[step] = v[k + 5:k + 5 + count] if count else np.zeros((0, 0))
        k += 5 + count
    return blocks


def slip_stats(script, atoms, slips, steps, fn_col):
    """columns.SLIP_STATS of every row from the pair records (slips.dump: id1 id2 in the first
    two columns, Fn in column fn_col, then F_s (3 values) and the slip count, at each row's
    step and the step before) and the grains (atoms.dump, every grain):
    a contact slipped in the row's step when its counter moved from the step before (a new
    contact: when it is not zero). |V_s| from the dumped velocities and spins, with lever
    arms to the contact point midway in the overlap (docs/law.md), and the velocities the
    contact force was computed with: velocity Verlet's half step, v(n+1/2) = v(n+1) -
    dt/2 f(n+1)/m (and the spins alike), from the dumped end-of-step velocities and
    forces (fixed grains are not integrated: zero). With the end-of-step velocities a
    contact sliding at the threshold speed could be counted on the other side of it.
    `script`: the adapter's script, with the scene, ids (grain name -> atom id), recorded
    (atom ids in atoms.dump, sorted) and force_col (atoms.dump's column of fx; fy, fz, tqx,
    tqy, tqz follow; id x y z vx vy vz omegax omegay omegaz come first)."""
    sc, p = script.scene, script.scene.contact.law_params(script.scene.effects)
    radius, half_dt_m, half_dt_i = (np.zeros(len(sc.grains) + 1) for _ in range(3))
    for g in sc.grains:
        k = script.ids[g.name]
        radius[k] = g.radius
        if not g.fixed:
            half_dt_m[k], half_dt_i[k] = 0.5 * sc.dt / sc.grain_mass(g), 0.5 * sc.dt / sc.grain_inertia(g)
    fc = script.force_col
    row_of = np.zeros(max(script.recorded) + 1, int)  # atom id -> its row in atoms.dump (sorted by id)
    row_of[script.recorded] = np.arange(len(script.recorded))
    big = len(sc.grains) + 1

    def key(a, b):  # a pair by its two ids in either order: a neighbour-list rebuild may swap them
        return np.minimum(a, b) * big + np.maximum(a, b)

    rows = []
    for s in steps:
        blk = slips.get(s, np.zeros((0, fn_col + 5)))
        if not len(blk):
            rows.append((0, 0, 0, 0.0))
            continue
        i, j = blk[:, 0].astype(int), blk[:, 1].astype(int)
        prev = slips.get(s - 1, np.zeros((0, fn_col + 5)))
        was = np.zeros(len(blk))  # each pair's counter at the step before (0: not in contact then)
        if len(prev):
            before = key(prev[:, 0].astype(int), prev[:, 1].astype(int))
            order = np.argsort(before)
            at = np.minimum(np.searchsorted(before[order], key(i, j)), len(order) - 1)
            found = before[order][at] == key(i, j)
            was[found] = prev[order[at[found]], fn_col + 4]
        count = blk[:, fn_col + 4]
        sel = (count != was) & (count > 0) & (blk[:, fn_col] > 0)
        a = atoms[s]
        ids = a[:, 0].astype(int)
        v = a[:, 4:7] - half_dt_m[ids][:, None] * a[:, fc:fc + 3]  # the half step's, as the force saw them
        w = a[:, 7:10] - half_dt_i[ids][:, None] * a[:, fc + 3:fc + 6]
        ri, rj = row_of[i[sel]], row_of[j[sel]]
        d = a[rj, 1:4] - a[ri, 1:4]
        dist = np.linalg.norm(d, axis=1)
        n = d / dist[:, None]
        half = 0.5 * (radius[i[sel]] + radius[j[sel]] - dist)
        lever = (radius[i[sel]] - half)[:, None] * w[ri] + (radius[j[sel]] - half)[:, None] * w[rj]
        v_rel = v[ri] - v[rj] + np.cross(lever, n)
        vs = np.linalg.norm(v_rel - np.sum(v_rel * n, axis=1)[:, None] * n, axis=1)
        fn = blk[sel, fn_col]
        drop = 2.0 * (p.mu_s - p.mu_k) * fn
        ratio = np.linalg.norm(blk[sel, fn_col + 1:fn_col + 4], axis=1) / np.where(fn > 0, fn, np.inf)
        rows.append((int(sel.sum()), int(np.sum(vs * p.nu_s >= drop)),
                     int(np.sum(vs * (p.nu_s + p.ks * sc.dt) >= drop)), float(ratio.sum())))
    return [list(c) for c in zip(*rows)]


def id_ranges(ids, through=":", sep=" "):
    """Sorted whole numbers as runs: atom ids as LAMMPS/LIGGGHTS group ranges by default,
    1 2 3 5 -> '1:3 5' (through="-", sep=",": '1-3,5')."""
    parts, start = [], ids[0]
    for prev, cur in zip(ids, ids[1:] + [None]):
        if cur != prev + 1:
            parts.append(str(start) if start == prev else f"{start}{through}{prev}")
            start = cur
    return sep.join(parts)


def wall_record(atom_row, k):
    """The k-th wall's record in a grain's row of atoms.dump: Fn, the force on the grain (3),
    the slips counted (5 columns a wall, after the grain's 10)."""
    return atom_row[10 + 5 * k:15 + 5 * k]


def pair_record(lines, ia, ib, fn_col):
    """The record of the contact between atoms ia and ib in a block of a pair dump (its
    columns from fn_col on: Fn, the force on the first atom (3), the slips counted), as the
    force on ia; None where the block holds no such contact."""
    for line in lines:
        if {int(line[0]), int(line[1])} == {ia, ib}:
            sign = 1.0 if int(line[0]) == ia else -1.0
            return [line[fn_col], *(sign * line[fn_col + 1:fn_col + 4]), line[fn_col + 4]]
    return None


def optional_dump(path):
    """read_dump of a dump the script writes only when the scene records such contacts."""
    return read_dump(path) if path.is_file() else {}


def timeseries(engine, script, work, contact_record, slip_fn_col):
    """The timeseries frame (stickslip/columns.py) from the dumps a LAMMPS-family script
    wrote into `work`: atoms.dump (the recorded grains: id x y z vx vy vz omegax omegay omegaz,
    then the per-atom records of the walls script.walls_of), stats.dump and slips.dump when
    the scene asks. contact_record(a, b, steps): the engine's record of any other contact a-b
    (pairs; LIGGGHTS' mesh walls) at each step, (steps, 5): Fn, the force on a (3), the
    slips counted since the contact began. slip_fn_col: Fn's column in slips.dump. A
    non-finite value stops with one line naming the column, time and step."""
    sc = script.scene
    d = sc.dimension
    atoms = read_dump(work / "atoms.dump")
    steps = sorted(atoms)
    row = {i: k for k, i in enumerate(script.recorded)}  # the atoms dump is sorted by id
    for s in steps:
        if len(atoms[s]) != len(row) or not np.array_equal(atoms[s][:, 0], script.recorded):
            raise RuntimeError(f"{engine}: the dump at step {s} does not hold the recorded grains "
                               f"(lost atoms?); see {work / 'screen.txt'}")
    cols = {"t": [s * sc.dt for s in steps]}
    spin = ([9] if d == 2 else [7, 8, 9]) if sc.effects["rotation"] else []
    picks = [1 + k for k in range(d)] + [4 + k for k in range(d)] + spin
    for name in sc.output.grains:
        i = row[script.ids[name]]
        blk = np.array([atoms[s][i] for s in steps])
        cols.update(zip(columns.grain(name, d, sc.effects["rotation"]), blk[:, picks].T))
    for a, b in sc.output.contacts:
        if b in script.walls_of:
            rec = np.array([wall_record(atoms[s][row[script.ids[a]]], script.walls_of.index(b)) for s in steps])
        else:
            rec = contact_record(a, b, steps)
        # slips since the previous row; a counter that drops means the contact was remade
        count = rec[:, 4]
        slips = np.diff(count, prepend=0.0)
        slips = np.where(slips < 0, count, slips)
        values = [rec[:, 0], np.linalg.norm(rec[:, 1:4], axis=1), *rec[:, 1:1 + d].T, np.rint(slips).astype(int)]
        cols.update(zip(columns.contact(a, b, d), values))
    for name in sc.output.walls:
        w = next(w for w in sc.walls if w.name == name)
        nrot = sc.rotation_steps(w) if w.rotation else 0
        rate = sc.rotation_rate(w) if w.rotation else 0.0
        cols[columns.wall(name)[0]] = [rate * sc.dt * min(s, nrot) for s in steps]
    if sc.output.stats:
        stats = read_dump(work / "stats.dump")
        cols.update(zip(columns.STATS, ([int(round(stats[s][0][1])) for s in steps],
                                        [float(stats[s][0][2]) for s in steps])))
    if sc.output.slip_stats:
        cols.update(zip(columns.SLIP_STATS,
                        slip_stats(script, atoms, read_dump(work / "slips.dump"), steps, fn_col=slip_fn_col)))
    if sc.output.bulk or sc.gravity_ramp is not None or sc.lid is not None:
        # bulk.dump (ramp_script.bulk_dump): id, then tilt and phase (a ramp), BULK, LID (a lid)
        bulk = read_dump(work / "bulk.dump")
        names = (list(columns.RAMP) if sc.gravity_ramp is not None else []) + (
            list(columns.BULK) if sc.output.bulk else []) + (list(columns.LID) if sc.lid is not None else [])
        values = np.array([bulk[s][0][1:1 + len(names)] for s in steps]).reshape(len(steps), len(names))
        got = dict(zip(names, values.T))
        for name in columns.BULK + columns.LID + columns.RAMP:  # in columns.names' order
            if name in got:
                cols[name] = np.rint(got[name]).astype(int) if name == "phase" else got[name]
    df = pd.DataFrame(cols)
    bad = ~np.isfinite(df.to_numpy(dtype=float))
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise RuntimeError(f"{engine} produced non-finite values: {df.columns[c]} = {df.iat[r, c]} at t = "
                           f"{df['t'].iat[r]:.6g} s (step {steps[r]}); the run is not usable "
                           f"(see {work / 'screen.txt'})")
    return df
