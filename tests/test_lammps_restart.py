# SPDX-License-Identifier: GPL-2.0-or-later
"""Restarts of the LAMMPS plugin (issue 30, item 4): `write_restart` and `read_restart`
continue every contact's history (the spring D, and with `record yes` Fn, F_s, the slip
count and the dissipated work), on the same rank count and across rank counts; and
`write_restart` alone does not change a run, which it does with stock styles on this
LAMMPS (lammps/lammps#3022, lammps_plugin/contact_history_fix.h).

"Exactly" means: a new `run` re-evaluates every force in its set-up, with stock styles too
(lammps_plugin/README.md, "What this LAMMPS does, with stock styles too"), so the reference for a restarted run is
the same script split at the same step in one process (`run N1` then `run N2`), not one
uninterrupted run. On the same rank count the restarted run's dumps must be those bytes.
Across rank counts the forces on a grain are summed in another order, so the trajectories
part by round-off after the first step; what must be identical is every contact's history
and record at the set-up of the continued run (each is computed from its own two grains
only, whichever rank holds it).

The scene: a flowing pile, 539 grains on a lattice in a box periodic in x and y, on a
floor wall, under gravity tilted 26 degrees as examples/pour's chute, examples/pour's
material (Kn 2000, dt 0.001, mu_s 0.5); two ranks split it along x (`processors * 1 1`), and the flow carries
grains and contacts across the ranks' boundary and the periodic ones.
"""
import fcntl

import numpy as np
import pytest

import conftest

from conftest import needs_engine
from lammps_runs import STOCK, read_dump, run_lammps

pytestmark = needs_engine("lammps")  # LAMMPS installed and the plugin built (the adapter's check)

F17 = "%.17g"

# examples/pour's material; the law's own settings: mu_k < mu_s, the paper's reset, the
# history kept in full (so that the slip count and the work are compared too)
STOCK_ARGS = "2000.0 NULL 50.0 NULL 0.5 0"
LAW = "mu_k 0.4 reset spring history_rotation keep_length record yes"


def scene(styles="ours", law=LAW, newton="off"):
    """The flowing pile up to its first run (no run). styles: 'ours' (the plugin with the
    law's keywords `law`) or 'stock' (gran/hooke/history + wall/gran, stock arguments)."""
    pair = f"gran/hooke/history {STOCK_ARGS}" if styles == "stock" else f"gran/hooke/stickslip {STOCK_ARGS} {law}"
    return f"""atom_style sphere
boundary p p fm
newton {newton}
processors * 1 1
comm_modify vel yes
region reg block -6 6 -4 4 -0.5 12 units box
create_box 1 reg
neighbor 0.2 bin
neigh_modify delay 0
timestep 0.001
lattice sc 1.05
region fill block -5.9 5.9 -3.9 3.9 0.6 7 units box
create_atoms 1 region fill
set group all diameter 1.0 density 1.0
velocity all create 1.0 4928459 loop geom
pair_style {pair}
pair_coeff * *
""" + fixes(styles, law)


def fixes(styles="ours", law=LAW):
    """What a restart file does not hold: the fixes (the wall, with the same ID, gets its
    contacts' history back from the file)."""
    wall = f"wall/gran hooke/history {STOCK_ARGS}" if styles == "stock" else \
        f"wall/gran/stickslip hooke/history {STOCK_ARGS}"
    return f"""fix 1 all nve/sphere
fix 2 all gravity 1.0 chute 26.0
fix zlower all {wall} zplane 0.0 2000.0 {law if styles == "ours" else ""}
"""


def output(every, record=True):
    """Every grain's state, and every pair contact's record (record yes: p11 Fn, p1-p3 F_s on
    patom1, p12 slip count, p13 work; stock: p1-p4, the tangential force from its shear)."""
    values = "p11 p1 p2 p3 p12 p13" if record else "p1 p2 p3 p4"
    return f"""compute pl all pair/local {values} cutoff radius
compute ids all property/local patom1 patom2 cutoff radius
dump loc all local {every} dump.contacts c_ids[1] c_ids[2] c_pl[*]
dump_modify loc format float {F17}
dump atoms all custom {every} dump.atoms id x y z vx vy vz fx fy fz omegax omegay omegaz
dump_modify atoms sort id format float {F17}
"""


def contacts(path):
    """The pair contacts of a local dump -> {step: {(id_lo, id_hi): values seen from id_lo}}
    (the rank holding a contact and the side it is held from depend on the rank count; seen
    from the other body the tangential force, columns 1-3 after the ids, changes sign)."""
    out = {}
    for step, rows in read_dump(path).items():
        seen = {}
        for r in rows:
            i, j, vals = int(r[0]), int(r[1]), r[2:].copy()
            if i > j:
                i, j = j, i
                vals[1:4] *= -1
            assert (i, j) not in seen, f"contact {(i, j)} listed twice at step {step}"
            seen[i, j] = vals
        out[step] = seen
    return out


N1, N2 = 1500, 200


def split_run(styles="ours", every=N2 // 4, write_restart=False, law=LAW, newton="off"):
    """The scene run N1 steps, then N2 more in the same process (optionally a write_restart
    between the two runs, as a user's script would)."""
    between = "write_restart restart.split\n" if write_restart else ""
    return (scene(styles, law, newton) + f"run {N1}\n" + between + output(every, record="record yes" in law and styles == "ours")
            + f"run {N2}\n")


def writer(law=LAW):
    return scene("ours", law) + f"run {N1}\nwrite_restart restart.n1\n"


def reader(every=N2 // 4, law=LAW, newton="off"):
    """Continues the restart file (the pair style and its coefficients come from the file;
    `newton` does not: LAMMPS keeps the current setting, on by default)."""
    return (f"newton {newton}\nprocessors * 1 1\nread_restart restart.n1\nneighbor 0.2 bin\nneigh_modify delay 0\n"
            + fixes("ours", law) + output(every) + f"run {N2}\n")


def written(np_):
    """On np_ ranks: the split run (the reference), and the same with a write_restart between
    its two runs; serial also a periodic restart file (`restart` command) at step N1 inside
    the first run. Made once per test session, shared by the xdist workers (conftest.paper_case's
    file lock). ~1 s serial, ~3 s on 2 ranks per run."""
    folder = conftest.SHARED / f"lammps-restart-{np_}"
    with open(f"{folder}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
        if not (folder / "complete").exists():
            run_lammps(folder / "split", "split", split_run(), np_=np_)
            run_lammps(folder / "writer", "writer", split_run(write_restart=True), np_=np_)
            if np_ == 1:
                # (its own run: a restart step makes LAMMPS rebuild the neighbour lists at that
                # step, after which write_restart has nothing stale to lose)
                script = scene() + f"restart {N1} restart.periodic\nrun {N1}\n"
                run_lammps(folder / "periodic", "periodic", script, np_=np_)
            (folder / "complete").touch()
    return folder


@pytest.mark.parametrize("np_", [1, 2])
def test_write_restart_changes_nothing_and_matches_the_periodic_file(np_):
    """Ours: a write_restart between two runs changes no byte of the run after it (stock's
    does, test below), on 1 and 2 ranks; serial, the file it writes outside the run is the
    file the `restart` command writes at the same step inside the run (stock's store from
    the neighbour list) byte for byte. (Runs shared with the next tests.)"""
    d = written(np_)
    for dump in ("dump.atoms", "dump.contacts"):
        assert (d / "writer" / dump).read_bytes() == (d / "split" / dump).read_bytes(), dump
    if np_ == 1:
        assert (d / "writer" / "restart.split").read_bytes() == \
            (d / "periodic" / f"restart.periodic.{N1}").read_bytes()


@pytest.mark.parametrize("wrote,reads", [(1, 1), (2, 2), (2, 1), (1, 2)])
def test_restart_continues_every_contact(tmp_path, wrote, reads):
    """read_restart of the file written at step N1 on `wrote` ranks, continued on `reads`
    ranks, against the split run on `wrote` ranks.

    - same rank count: the dumps (every grain's x, v, f, omega; every contact's Fn, F_s, slip
      count and work) are the split run's bytes;
    - across rank counts: at the set-up of the continued run (step N1) every contact's
      record and every grain's x, v, omega are identical; the force on a grain is a sum over
      its contacts (<= 12 grains and the wall) plus gravity, whose order depends on the
      ranks' neighbour lists: reordering a sum of n terms changes it by at most
      (n - 1) eps sum|terms|, here <= 13 x eps x 14 x (the largest contact force, |Fn| + |F_s|,
      or the weight).
    The history must have content: contacts that slipped before N1 (slip count > 0)."""
    d = tmp_path
    (d / "restart.n1").write_bytes((written(wrote) / "writer" / "restart.split").read_bytes())
    run_lammps(d, "reader", reader(), np_=reads)
    ref = written(wrote) / "split"
    if wrote == reads:
        for dump in ("dump.atoms", "dump.contacts"):
            assert (d / dump).read_bytes() == (ref / dump).read_bytes(), dump
    mine, theirs = contacts(d / "dump.contacts")[N1], contacts(ref / "dump.contacts")[N1]
    assert sorted(mine) == sorted(theirs)
    for key in theirs:
        assert np.array_equal(mine[key], theirs[key]), key
    slipped = sum(v[4] > 0 for v in theirs.values())
    assert slipped > 50, f"only {slipped} contacts have slipped before the restart: nothing tested"
    a, b = read_dump(d / "dump.atoms")[N1], read_dump(ref / "dump.atoms")[N1]
    for cols in (slice(1, 7), slice(10, 13)):  # x, v; omega
        assert np.array_equal(a[:, cols], b[:, cols])
    fmax = max(max(abs(v[0]) + np.linalg.norm(v[1:4]) for v in theirs.values()), np.pi / 6 * 1.0)
    eps = np.finfo(float).eps
    assert np.abs(a[:, 7:10] - b[:, 7:10]).max() <= 13 * eps * 14 * fmax


def test_stock_loses_history_at_write_restart_and_ours_does_not(tmp_path):
    """This LAMMPS' bug (lammps/lammps#3022), 2 ranks, newton off as examples/pour: with
    stock gran/hooke/history + wall/gran, issuing `write_restart` between two runs changes
    the run after it; contacts lost their history: at the set-up of the second run
    (nothing has moved) their tangential force (stock's single(): Kt |shear| capped at
    mu_s |Fn|, with dampflag 0 no dashpot) is 0 where the run without write_restart has a
    force; others get a history that is not theirs (the partner saved under a stale
    neighbour index is another grain). Our styles with stock's arguments, renamed (the drop-in), with the same
    write_restart give stock's run *without* it byte for byte: they keep the history, and
    where stock is not hit by the bug they are stock. ~10 s (three 2-rank runs)."""
    def run(name, styles, write_restart):
        script = split_run(styles, write_restart=write_restart, law="")
        run_lammps(tmp_path / name, name, script, np_=2)
        return tmp_path / name

    plain, written_ = run("stock", "stock", False), run("stock_wr", "stock", True)
    ours = run("ours_wr", "ours", True)
    before, after = contacts(plain / "dump.contacts")[N1], contacts(written_ / "dump.contacts")[N1]
    assert sorted(before) == sorted(after)
    lost = [k for k in before if after[k][3] == 0.0 and before[k][3] > 0.0]
    changed = [k for k in before if not np.array_equal(after[k], before[k])]
    print(f"stock, write_restart on 2 ranks: {len(lost)} of {len(before)} contacts lost their history, "
          f"{len(changed) - len(lost)} more got another one")
    assert len(lost) >= 10, f"stock lost the history of {len(lost)} of {len(before)} contacts: bug not shown"
    assert set(lost) <= set(changed)
    assert (written_ / "dump.atoms").read_bytes() != (plain / "dump.atoms").read_bytes()
    assert (ours / "dump.atoms").read_bytes() == (plain / "dump.atoms").read_bytes()
