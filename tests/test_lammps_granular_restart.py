# SPDX-License-Identifier: GPL-2.0-or-later
"""The contact history of the tangential sub-model `stick_slip` (lammps_plugin/granular/) in
each modern LAMMPS release across processes and MPI ranks: through write_restart + read_restart, and
between the two bodies of a contact (the sub-model's history transfer factors).

Restarts. "Exactly" means what it means in LAMMPS (tests/test_lammps_restart.py): a new `run`
re-evaluates every force in its set-up, so the reference for a restarted run is the same
script split at the same step in one process (`run N1` then `run N2`). The scene is
test_lammps_granular_dropin.py's collapsing pile with the law's own state in use (mu_k =
0.8 mu_s, so that a slip drops the force below the threshold; /record, so that each
contact's Fn, F_s, slip count and dissipated work travel in its history too), on 2 ranks:
write_restart after N1 steps, then a new process with read_restart (pair granular keeps its
coefficients in the restart file; the wall fixes are given again with the same IDs to get
their per-atom history back) must continue with the split run's bytes: every grain's x, v,
omega and force, every pair contact's record (pair/local p13-p18) and every wall contact's
(the walls' per-atom columns 9-14). The history read back has content: at the restart step
most contacts have slipped before (~100 pair contacts, ~35 on the floor, ~15 on the side
walls). Two faults of LAMMPS 4 Feb 2025 shape the scripts (each shown by a test below, with
stock linear_history where it applies): a plain `write_restart` between two runs on 2 ranks
mixes up contacts' histories, in the run that goes on and in the file, so the file is
written with `write_restart ... noinit`; and pair granular's global cutoff setting is not
kept in the file, so the reader gives `pair_style granular` again, or it would run without
a single pair contact.

History transfer. A contact's history is kept from one of its two grains; when LAMMPS moves
it to the other grain (a neighbour list rebuilt after atoms are sorted or change ranks,
fix neigh/history's pre_exchange) it multiplies each value by the sub-model's transfer
factor: -1 for D and F_s (they change sign seen from the other body), +1 for Fn, the slip
count and the work. The scene: 25 dimers of adhesive grains (dmt: the pull-off holds a
dimer together while its grains slide and turn about each other), each grain in one pair
contact only, its two grains given opposite velocities across their axis and random spins,
so that the contact slides (slip after slip) for ~1700 steps and then sticks, the dimers
drifting through the ranks' boundary (x = 0 on 2 ranks) in an open box (with newton off a
contact across a periodic boundary is computed from both grains, each with the other's
image shifted by the box length, whose round-off parts the two sides: 2e-13 after 900
steps, measured). With one contact a grain no force is a sum whose order the rank count
could change, so the run is the same bytes on 1 and 2 ranks with newton on and off, and
so must every contact's record be, seen from whichever grain each run reports it
(pair/local: on 1 rank the neighbour list's first grain; on 2 ranks with newton off each
rank computes a pair split between the ranks from its own grain, and the lower or higher
id reports it). A wrong factor is seen: the slip count or the work of a contact changes
sign (or D turns and the forces change) when its history is moved, which happens ~30
times in each run (atoms are sorted every 100 steps), at other steps in each. (Measured
with a patched copy of the sub-model: the slip count's or the work's factor -1, or D's +1,
fail this test; Fn's and F_s's factors cannot be seen by anything: every force evaluation
writes them before the record is read.)

Measured on the shared 2-core machine (load 2-4): the restart tests ~1.5 s each (three
2-rank runs), the write_restart one ~1.8 s (four), the cutoff one ~1 s, the dimers ~1.3 s
(two serial runs of 0.1 s, two 2-rank ones): ~8 s for the module (~4.7 s CPU); up to twice
that when the machine is busier (load ~9).
"""
import numpy as np
import pytest

from conftest import needs_engine
from lammps_runs import read_dump, run_lammps
from test_lammps_granular_dropin import fixes, lmp, models, ours_words, output, pile, stock_words, thermo_text  # noqa: F401

pytestmark = needs_engine("lammps_granular")  # a modern LAMMPS built with the sub-model (each release: lmp)

N1, N2, EVERY = 1500, 500, 100


def law(name):
    """The tangential words: the sub-model `name` with mu_k = 0.8 mu_s."""
    return lambda ks, x, mu: f"{name} {ks:g} {x:g} {mu:g} {0.8 * mu:g}"


def split_run(words, newton, write_restart=None, record=True):
    """The reference: N1 steps, then N2 more in the same process; write_restart: with
    `write_restart restart.n1` and these words between the two runs (the file the reader
    continues: "noinit", see test_write_restart_needs_noinit_between_runs)."""
    between = f"write_restart restart.n1 {write_restart}\n" if write_restart is not None else ""
    return (pile(words, newton) + fixes(words, record=record) + f"run {N1}\n" + between
            + output(EVERY, record=record, record_every=EVERY) + f"run {N2}\n")


def reader(words, newton):
    """A new process continuing the file (the pair style, its coefficients, the box,
    the grains and the contacts' history come from it; `newton`, the neighbour settings,
    the fixes and the side walls' region do not). `pair_style granular` is given again
    (it keeps the coefficients read): LAMMPS 4 Feb 2025 does not keep pair granular's
    global cutoff setting in the file, and without it the pair style has no neighbours
    (test_pair_granular_needs_its_style_again_after_read_restart)."""
    return (f"newton {newton}\nprocessors * 1 1\nread_restart restart.n1\npair_style granular\n"
            "neighbor 0.2 bin\nneigh_modify delay 0\n"
            + fixes(words, record=True) + output(EVERY, record=True, record_every=EVERY) + f"run {N2}\n")


def rows(path):
    """The pair contacts of a local dump -> {step: {(id_lo, id_hi): values}}: each seen from
    its lower id (the other grain sees F_s, columns 1-3 after the ids, with the opposite
    sign; Fn, the slips and the work alike)."""
    out = {}
    for step, table in read_dump(path).items():
        seen = {}
        for r in table:
            i, j, vals = int(r[0]), int(r[1]), r[2:].copy()
            if i > j:
                i, j = j, i
                vals[1:4] *= -1
            assert (i, j) not in seen, f"contact {(i, j)} listed twice at step {step}"
            seen[i, j] = (vals, int(r[0]))
        out[step] = seen
    return out


@pytest.mark.parametrize("name,newton", [("stick_slip/record", "off"), ("stick_slip/total/exact/record", "on")])
def test_restart_continues_every_contact(tmp_path, name, newton, lmp):
    """2 ranks: the split run against write_restart + read_restart in a new process; the
    continued run's dumps (grains, pair records, wall records) and thermo output are the
    split run's bytes from the restart step on; the run that wrote the file (`write_restart
    restart.n1 noinit`) between its two runs is the split run's bytes too; and the records
    read back at the restart step hold slips: pair, floor and side-wall contacts that have
    slipped before N1."""
    words = models(law(name))
    run_lammps(tmp_path / "split", "split", split_run(words, newton), exe=lmp, np_=2)
    run_lammps(tmp_path / "writer", "writer", split_run(words, newton, write_restart="noinit"), exe=lmp, np_=2)
    (tmp_path / "read").mkdir()
    (tmp_path / "read" / "restart.n1").write_bytes((tmp_path / "writer" / "restart.n1").read_bytes())
    run_lammps(tmp_path / "read", "read", reader(words, newton), exe=lmp, np_=2)
    for dump in ("dump.atoms", "dump.contacts", "dump.walls"):
        split = (tmp_path / "split" / dump).read_bytes()
        assert (tmp_path / "writer" / dump).read_bytes() == split, f"write_restart changed {dump}"
        assert (tmp_path / "read" / dump).read_bytes() == split, f"the restarted run's {dump} differs"
    split_log = (tmp_path / "split" / "log.split").read_text()
    assert thermo_text(tmp_path / "read" / "log.read") in split_log[split_log.index("\nLoop time"):]

    at_restart = rows(tmp_path / "read" / "dump.contacts")[N1]
    walls = read_dump(tmp_path / "read" / "dump.walls")[N1]
    pair_slipped = sum(v[4] > 0 for v, _ in at_restart.values())
    floor_slipped, side_slipped = (walls[:, 5] > 0).sum(), (walls[:, 11] > 0).sum()
    print(f"at the restart step: {pair_slipped} of {len(at_restart)} pair contacts, {floor_slipped} floor "
          f"and {side_slipped} side-wall contacts have slipped before")
    assert pair_slipped > 50 and floor_slipped > 20 and side_slipped > 5


def test_write_restart_needs_noinit_between_runs(tmp_path, lmp):
    """LAMMPS 4 Feb 2025, 2 ranks: a plain `write_restart` between two runs changes the
    run after it, with stock linear_history as with stick_slip. The command first inits
    the system and moves atoms between ranks (comm->exchange, comm->borders), then fix
    neigh/history's write_restart copies the contacts' history from the neighbour list
    into the atoms (pre_exchange) with that list's stale atom indices: contacts lose their
    history or get another's, in the process that goes on and in the file. `noinit`
    skips the init and the move: the history fix neigh/history copied into the atoms at
    the end of the run (post_run) is what is written, nothing changes. Shown here: stock
    with `write_restart` differs from stock without; stick_slip/total with mu_k = mu_s
    and the same `write_restart` is stock's changed run byte for byte (the loss is LAMMPS',
    the sub-model is stock through it); stock with `noinit` is stock without."""
    def run(name, tangential, write_restart):
        words = models(tangential)
        run_lammps(tmp_path / name, name, split_run(words, "off", write_restart, record=False), exe=lmp, np_=2)
        return (tmp_path / name / "dump.atoms").read_bytes()

    stock = run("stock", stock_words, None)
    stock_written = run("stock_written", stock_words, "")
    ours_written = run("ours_written", ours_words, "")
    stock_noinit = run("stock_noinit", stock_words, "noinit")
    assert stock_written != stock, "write_restart changed nothing: the LAMMPS bug is not shown (fixed?)"
    assert ours_written == stock_written
    assert stock_noinit == stock


def test_pair_granular_needs_its_style_again_after_read_restart(tmp_path, lmp):
    """LAMMPS 4 Feb 2025: pair granular writes no global settings to a restart file and its
    constructor leaves the global cutoff unset, so after read_restart the pair style's
    cutoff is 0 (the log's "master list distance cutoff = 0": no ghost atoms, one
    neighbour bin for the whole box): on 2 ranks with newton off the grains no longer see
    each other (with newton on, measured, the contacts split between the ranks are lost:
    74 of 80 left). `pair_style granular` given again resets the setting and keeps the
    coefficients read from the file (Input::pair_style calls settings() for the same
    style). The pile after 200 steps (serial), read on 2 ranks, `run 0`."""
    words = models(law("stick_slip/record"))
    writer = pile(words) + fixes(words) + "run 200\nwrite_restart restart.n1\n"
    run_lammps(tmp_path / "write", "write", writer, exe=lmp)
    count = {}
    for again in (False, True):
        work = tmp_path / f"read-{again}"
        work.mkdir()
        (work / "restart.n1").write_bytes((tmp_path / "write" / "restart.n1").read_bytes())
        script = ("newton off\nread_restart restart.n1\n" + ("pair_style granular\n" if again else "")
                  + "neighbor 0.2 bin\n" + fixes(words, record=True) + output(record=True, record_every=1) + "run 0\n")
        run_lammps(work, "read", script, exe=lmp, np_=2)
        count[again] = len(read_dump(work / "dump.contacts")[200])
        cutoff = "master list distance cutoff = 0\n" in (work / "log.read").read_text()
        assert cutoff != again, (again, "the pair style's cutoff")
    print(f"pair contacts at the restart step: {count[True]} with pair_style given again, {count[False]} without")
    assert count[False] == 0 and count[True] > 50


# ---------------------------------------------------------------- history transfer


def dimers(seed=5, drift=0.5, across=0.6, spin=1.5):
    """The dimers' data file (the module's docstring): 25 pairs of grains (diameter 1,
    overlapping by 0.002), centres on a 5 x 5 grid in y and z (2.5 apart: a dimer turning
    about its centre reaches 1.0) at random x in [-1.2, 0.3]; the axis random, the two
    grains' velocities drift along x plus and minus `across` along a random direction
    across the axis, random spins."""
    rng = np.random.default_rng(seed)
    atoms, velocities = [], []
    for iy in range(5):
        for iz in range(5):
            centre = np.array([rng.uniform(-1.2, 0.3), -5.0 + 2.5 * iy, -5.0 + 2.5 * iz])
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            cross = rng.normal(size=3)
            cross -= cross.dot(axis) * axis
            cross /= np.linalg.norm(cross)
            for sign in (-1, 1):
                k = len(atoms) + 1
                x = centre + sign * 0.499 * axis
                v = np.array([drift, 0.0, 0.0]) + sign * across * cross
                w = rng.normal(size=3) * spin
                atoms.append(f"{k} 1 1.0 1.0 " + " ".join(repr(float(c)) for c in x))
                velocities.append(f"{k} " + " ".join(repr(float(c)) for c in (*v, *w)))
    return (f"dimers\n\n{len(atoms)} atoms\n1 atom types\n\n-6 6 xlo xhi\n-7 7 ylo yhi\n-7 7 zlo zhi\n\n"
            "Atoms # sphere\n\n" + "\n".join(atoms) + "\n\nVelocities\n\n" + "\n".join(velocities) + "\n")


DIMER_STEPS = 3000


def dimer_script(newton):
    """The dimers, DIMER_STEPS steps; atoms sorted every 100 steps (each sort renumbers
    them, and a contact whose grains swap order in the neighbour list has its history
    read from the other grain: transferred); every 100 steps every grain's state and every
    contact's record."""
    return f"""atom_style sphere
atom_modify sort 100 0.0
boundary f f f
newton {newton}
processors * 1 1
comm_modify vel yes
read_data dimers.data
neighbor 0.2 bin
neigh_modify delay 0
timestep 0.001
pair_style granular
pair_coeff * * dmt 1e4 400 0.3 0.3 damping viscoelastic tangential stick_slip/record 500 0.5 0.2 0.15
fix 1 all nve/sphere
compute pl all pair/local p13 p14 p15 p16 p17 p18 cutoff radius
compute ids all property/local patom1 patom2 cutoff radius
dump loc all local 100 dump.contacts c_ids[1] c_ids[2] c_pl[*]
dump_modify loc format float %.17g
dump d all custom 100 dump.atoms id x y z vx vy vz omegax omegay omegaz fx fy fz
dump_modify d sort id format float %.17g
run {DIMER_STEPS}
"""


def test_the_record_is_the_same_seen_from_either_grain(tmp_path, lmp):
    """The dimers on 1 rank (newton off: the reference; newton on) and on 2 ranks (newton
    off and on): every grain's state and every contact's record (Fn, F_s seen from the lower
    id, slips, work) identical at every 100th step; slip counts never fall. What was
    compared: contacts reported from the other grain than in the reference, contacts split
    between the ranks, contacts whose reporting grain changed between two dumps of one run
    (their history was transferred in between), and slips."""
    runs = {}
    for np_, newton in ((1, "off"), (1, "on"), (2, "off"), (2, "on")):
        work = tmp_path / f"{np_}-{newton}"
        work.mkdir()
        (work / "dimers.data").write_text(dimers())
        run_lammps(work, "dimers", dimer_script(newton), exe=lmp, np_=np_)
        runs[np_, newton] = work
    ref_dir = runs[1, "off"]
    ref = rows(ref_dir / "dump.contacts")
    atoms = read_dump(ref_dir / "dump.atoms")
    assert sorted(ref) == list(range(0, DIMER_STEPS + 1, 100)) and all(len(c) == 25 for c in ref.values()), \
        "a dimer broke apart or met another: not the scene described"
    split = sum((atoms[s][i - 1, 1] < 0) != (atoms[s][j - 1, 1] < 0) for s in ref for i, j in ref[s])
    moved = 0
    other_side = {}
    for key, work in runs.items():
        assert (work / "dump.atoms").read_bytes() == (ref_dir / "dump.atoms").read_bytes(), key
        mine = rows(work / "dump.contacts")
        assert sorted(mine) == sorted(ref)
        for step in ref:
            assert sorted(mine[step]) == sorted(ref[step]), (key, step)
            for pair, (vals, _) in ref[step].items():
                assert np.array_equal(mine[step][pair][0], vals), (key, step, pair, mine[step][pair][0], vals)
        other_side[key] = sum(mine[s][p][1] != ref[s][p][1] for s in ref for p in ref[s])
        steps = sorted(mine)
        for a, b in zip(steps, steps[1:]):
            for pair in mine[b]:
                assert mine[b][pair][0][4] >= mine[a][pair][0][4], (key, a, b, pair)
                moved += mine[b][pair][1] != mine[a][pair][1]
    slips = sum(v[4] for v, _ in ref[DIMER_STEPS].values())
    print(f"contact rows split between the ranks: {split}; reported from the other grain than on 1 rank "
          f"newton off: {other_side}; reporting grain changed between dumps: {moved}; slips: {slips:.0f}")
    assert split > 100 and other_side[2, "off"] > 20 and moved > 50 and slips > 1000
