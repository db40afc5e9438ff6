# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract on LAMMPS (runners.py), both routes: lammps_plugin/'s styles on
Debian's LAMMPS (LegacyStyles) and the tangential sub-model in LAMMPS 2025's granular model
(GranularSubModel), run by the adapters' launchers, read back from the law's record through
the adapters' dump reader."""
from __future__ import annotations

import dataclasses
import math
import tempfile
from pathlib import Path

import numpy as np

from ..adapters.lammps import LAUNCHER, law_keywords
from ..adapters.lammps_family import fmt as _f, run_script, serial_mpi_env
from ..adapters.lammps_granular import LAUNCHER as GRANULAR_LAUNCHER, model_words
from ..adapters.text_dumps import read_dump
from . import cases as lc

# The plugin's styles with the law as docs/law.md states it (lammps_plugin/README.md):
# keep_length, contact lever arm, absolute damping, limit_damping (Fn >= 0), record yes.
# Its record holds Fn, the applied F_s and the slip count, not the spring D (history 0-2
# are in no output of pair/local or the wall's per-atom array): the trace's D is None and
# the spring shows in the next step's force (F = -Ks D - nu_s V_s).
#
# One LAMMPS process runs many rows (each one costs ~0.3 s to start): every wall row on its
# own grain with its own wall fix, the pair rows that share the pair style's settings as
# pairs of their own type (pair_coeff gives each its mu_s, mu_k), all in one `run`. Each
# row's moving grain is driven by `fix move variable` (position and velocity piecewise in
# the step number), so its changes of state happen inside a step, as on the other engines;
# a new `run` would evaluate every contact once more in its set-up (no time passes, but a
# slip there resets the spring uncounted). Only a rigid turn needs `fix move rotate` (it
# also sets the spins) and so a `run` of its own; the set-up before it sees every row of the
# pair batch in the state its last step left, all sticking (the turning rows at 4 w of
# T = 32 w, the re-contact at 4 w of 24 w), which a set-up leaves as it is. (A row that is
# at or above its threshold at a turn's start would need a process of its own.)

# compute pair/local's record (lammps_plugin/README.md): Fn, F_s on patom1, slips
RECORD_COLUMNS = (11, 1, 2, 3, 12)


def lammps_coefficients(case):
    """The pair style's or wall's stock arguments: Kn Kt nu_n nu_s mu_s dampflag limit_damping."""
    return f"{_f(lc.KN)} {_f(lc.KS)} {_f(case.nu_n)} {_f(case.nu_s)} {_f(case.mu_s)} 1 limit_damping"


def lammps_keywords(case, record=True):
    """The law's keywords for a case (docs/law.md's rules: the adapter's), the record on or off."""
    return law_keywords(case.mu_k, case.reset, case.timing, record)


def _piecewise(spans):
    """A LAMMPS equal-style expression of the step number: value v for steps a..b (spans of
    (a, b, v)), 0 elsewhere; products by 0 or 1 and sums of one value with zeros are exact."""
    terms = [f"(step>={a})*(step<={b})*({_f(v)})" for a, b, v in spans if v != 0.0]
    return '"' + (" + ".join(terms) or "0.0") + '"'


LAMMPS_HEAD = """units si
atom_style sphere
atom_modify map array
boundary f f f
comm_modify vel yes
region box block -16 16 -16 16 -4 4 units box
create_box {ntypes} box
timestep {dt}
neighbor 0.25 bin
neigh_modify delay 0 every 1 check yes
"""


class LegacyStyles:
    """The contract in lammps_plugin/'s styles (Debian's LAMMPS): gran/hooke/stickslip and
    wall/gran/stickslip with the law's keywords; compute pair/local's record RECORD_COLUMNS."""
    record = RECORD_COLUMNS

    @staticmethod
    def pair_lines(case):
        return [f"pair_style gran/hooke/stickslip {lammps_coefficients(case)} {lammps_keywords(case)}",
                "pair_coeff * *"]

    @staticmethod
    def pair_coeff(t, case):
        return f"pair_coeff {t} {t} mu_s {_f(case.mu_s)} mu_k {_f(case.mu_k)}"

    @staticmethod
    def wall(k, case):
        return (f"fix w{k} i{k} wall/gran/stickslip hooke/history {lammps_coefficients(case)} zplane 0.0 NULL "
                f"{lammps_keywords(case)}")

    @staticmethod
    def turn(k, a, seg, base, start):
        """Case k's pair (atoms a, a+1) turned rigidly about z through `base` from step
        `start` on: fix move rotate, which spins both grains at omega too (V_s = 0 with the
        law's lever arms, the middle of the overlap)."""
        period = 2 * math.pi / seg.omega
        return [f"group g{k} id {a} {a + 1}",
                f"fix turn{k} g{k} move rotate {_f(base[0])} {_f(base[1])} {_f(base[2])} 0 0 1 {_f(period)}"]


def granular_model(case, record=True):
    """The case's contact in LAMMPS 2025's granular syntax (stickslip/adapters/lammps_granular.py):
    the sub-model's tangential dashpot is x times the normal damping's prefactor, nu_s = x nu_n.
    A case with a dashpot but no normal damping never moves along its normal (asserted), so
    there nu_n = 1 changes no force (v_n = 0 exactly) and x = nu_s."""
    nu_n = case.nu_n
    if case.nu_s > 0 and nu_n == 0:
        axis = 2 if case.geometry == "wall" else 0
        assert all(seg.velocity[axis] == 0 and not seg.omega for seg in case.segments), case.name
        nu_n = 1.0
    return model_words(lc.KN, nu_n, lc.KS, case.nu_s, case.mu_s, case.mu_k, case.reset, case.timing, record)


class GranularSubModel:
    """The contract in LAMMPS 2025's granular model with the sub-model stick_slip/record:
    pair_style granular and fix wall/gran granular (per-atom columns 9-13, as the legacy
    wall's); compute pair/local's record p13-p17 (Fn, F_s, slips)."""
    record = (13, 14, 15, 16, 17)

    @staticmethod
    def pair_lines(case):
        return ["pair_style granular", f"pair_coeff * * {granular_model(case)}"]

    @staticmethod
    def pair_coeff(t, case):
        return f"pair_coeff {t} {t} {granular_model(case)}"

    @staticmethod
    def wall(k, case):
        return f"fix w{k} i{k} wall/gran granular {granular_model(case)} zplane 0.0 NULL contacts"

    @staticmethod
    def turn(k, a, seg, base, start):
        """The rigid turn with the spins at which LAMMPS' granular kinematics see no sliding:
        they take V_s with the radii as lever arms, so a pair spinning at omega, as fix move
        rotate spins it, slides at delta*omega; at omega*d/(r_i + r_j) it does not (d = 2R -
        delta the distance of the centres). Each grain moves on its circle through fix move
        variable (which leaves the spin as set)."""
        d = 2 * lc.R - seg.delta
        w, h = seg.omega, d / 2
        theta = f"({_f(w * lc.DT)}*(step-{start}))"
        lines = [f"set atom {a} omega 0 0 {_f(w * d / (2 * lc.R))}", f"set atom {a + 1} omega 0 0 {_f(w * d / (2 * lc.R))}"]
        for b, sign in ((0, -1.0), (1, 1.0)):  # i at base - h x, j at base + h x
            r = sign * h
            lines += [f"variable tdx{k}{b} equal {_f(r)}*(cos{theta}-1)", f"variable tdy{k}{b} equal {_f(r)}*sin{theta}",
                      f"variable tvx{k}{b} equal {_f(-r * w)}*sin{theta}", f"variable tvy{k}{b} equal {_f(r * w)}*cos{theta}",
                      f"group t{k}{b} id {a + b}",
                      f"fix turn{k}{b} t{k}{b} move variable v_tdx{k}{b} v_tdy{k}{b} NULL v_tvx{k}{b} v_tvy{k}{b} NULL"]
        return lines


def _lammps_batch_script(cases, styles=LegacyStyles):
    """One script running every case of `cases` side by side (see above) in `styles`' syntax;
    case k's grain i is atom k+1 (walls) or 2k+1 (pairs; j: 2k+2), its record in dump.case<k>
    (walls) or dump.pairs."""
    pair = cases[0].geometry == "pair"
    lines = [LAMMPS_HEAD.format(ntypes=len(cases), dt=_f(lc.DT))]
    if pair:
        lines += styles.pair_lines(cases[0])
    turns = {}  # the step a turn begins after -> [(k, its segment, its centre)]
    for k, case in enumerate(cases):
        a = _first_atom(case, k)
        base = np.array([4.0 * (k % 7) - 12.0, 4.0 * (k // 7) - 12.0, 0.0])
        x0 = lc.rest_positions(case, case.segments[0].delta) + base
        if pair:  # (j stays where it is: i alone moves, along the normal too)
            lines.append(styles.pair_coeff(k + 1, case))
        for b, x in enumerate(x0):
            v = case.segments[0].velocity if b == 0 else (0.0, 0.0, 0.0)
            lines += [f"create_atoms {k + 1} single {_f(x[0])} {_f(x[1])} {_f(x[2])} units box",
                      f"set atom {a + b} diameter {_f(2 * lc.R)} density 1000 vx {_f(v[0])} vy {_f(v[1])} vz {_f(v[2])}"]
        lines.append(f"group i{k} id {a}")
        if not pair:
            lines += [styles.wall(k, case),
                      f"dump d{k} i{k} custom 1 dump.case{k} id " + " ".join(f"f_w{k}[{c}]" for c in (9, 10, 11, 12, 13)),
                      f"dump_modify d{k} format float %.17g"]
        # the moving grain's place (from where it was made) and velocity, segment by segment
        spans, first = {q: [] for q in ("dx", "dy", "dz", "vx", "vy", "vz")}, 1
        for seg in case.segments:
            last = first + seg.steps - 1
            if seg.omega:
                assert seg is case.segments[-1], "a turn must be a case's last segment"
                turns.setdefault(first - 1, []).append((k, seg, base))
                break
            xi = lc.rest_positions(case, seg.delta)[0] + base
            if pair:
                xi = x0[1] - [2 * lc.R - seg.delta, 0, 0]
            for q, value in zip(("dx", "dy", "dz", "vx", "vy", "vz"), (*(xi - x0[0]), *seg.velocity)):
                spans[q].append((first, last, value))
            first = last + 1
        for q, s in spans.items():
            lines.append(f"variable {q}{k} equal {_piecewise(s)}")
        lines.append(f"fix mv{k} i{k} move variable " + " ".join(f"v_{q}{k}" for q in spans))
    if pair:
        lines += lammps_pair_local(styles.record)
        lines += ["dump x all custom 1 dump.atoms id x y z", "dump_modify x format float %.17g sort id"]
    done = 0
    for start in sorted(turns):
        lines.append(f"run {start - done}")
        for k, seg, base in turns[start]:
            lines += [f"unfix mv{k}"] + styles.turn(k, _first_atom(cases[k], k), seg, base, start)
        done = start
    lines.append(f"run {max(c.steps for c in cases) - done}")
    return "\n".join(lines) + "\n"


def _run(work, name, script, exe):
    """Runs a LAMMPS input (in.<name>) in `work` on `exe` as the adapters run theirs (one
    process, no MPI daemon); an ERROR line raises ValueError."""
    (work / f"in.{name}").write_text(script)
    cmd = [str(exe), "-in", f"in.{name}", "-log", f"log.{name}", "-echo", "none", "-nocite"]
    run_script("LAMMPS", cmd, work, 0, None, env={"OMP_NUM_THREADS": "1"}, serial_env=serial_mpi_env(work))


def _lammps_batch(cases, styles=LegacyStyles, exe=None):
    """Runs the batch in `styles`' syntax on `exe` (None: the legacy styles' launcher);
    {case name: trace}."""
    with tempfile.TemporaryDirectory(prefix="contract-lammps-") as tmp:
        work = Path(tmp)
        _run(work, "contract", _lammps_batch_script(cases, styles), exe or LAUNCHER)
        if cases[0].geometry == "wall":
            records = [read_dump(work / f"dump.case{k}") for k in range(len(cases))]
        else:
            pairs, atoms = read_dump(work / "dump.pairs"), read_dump(work / "dump.atoms")
    out = {}
    for k, case in enumerate(cases):
        tr = lc.empty_trace(case.steps)
        tr["D"] = None  # not in LAMMPS' record (above)
        a = _first_atom(case, k)
        for s in range(case.steps):
            if case.geometry == "wall":
                if _segment_at(case, s).delta <= 0:
                    continue  # apart (the record is zeroed)
                row = records[k][s + 1][0][1:]
                normal = np.array([0.0, 0.0, -1.0])
            else:
                row = lammps_pair_row(pairs.get(s + 1, []), a, [1, 2, 3])
                if row is None:
                    continue  # apart
                xs = atoms[s + 1]
                d = xs[a][1:4] - xs[a - 1][1:4]
                normal = d / np.linalg.norm(d)
            tr["fn"][s], tr["F"][s], tr["slips"][s], tr["n"][s] = row[0], row[1:4], int(row[4]), normal
        out[case.name] = tr
    return out


def lammps_pair_local(columns):
    """Input lines: compute pair/local's `columns` (p numbers) of every contact, each step,
    after its atom ids, at %.17g into dump.pairs."""
    return [f"compute pl all pair/local {' '.join(f'p{c}' for c in columns)} cutoff radius",
            "compute ids all property/local patom1 patom2 cutoff radius",
            "dump p all local 1 dump.pairs c_ids[1] c_ids[2] " + " ".join(
                f"c_pl[{k}]" for k in range(1, len(columns) + 1)),
            "dump_modify p format float %.17g"]


def lammps_pair_row(frame, a, forces):
    """The values of the contact between atoms a and a+1 in one step of dump.pairs (None:
    apart), the `forces` columns turned into the force on a (they are on patom1)."""
    rows = [r for r in frame if {int(r[0]), int(r[1])} == {a, a + 1}]
    if not rows:
        return None
    row = rows[0][2:].copy()
    if int(rows[0][0]) != a:
        row[forces] = -row[forces]
    return row


def _first_atom(case, k):
    """The id of case k's grain i in a batch: one atom a case (walls) or two (pairs)."""
    return k + 1 if case.geometry == "wall" else 2 * k + 1


def _segment_at(case, step):
    """The segment that step (0-based) is in."""
    for seg in case.segments:
        if step < seg.steps:
            return seg
        step -= seg.steps
    raise IndexError(step)


def _lammps_key(case):
    """Cases that can share a process: all walls; pairs with the same pair-style settings."""
    if case.geometry == "wall":
        return ("wall",)
    return ("pair", case.timing, case.reset, case.nu_s, case.nu_n)


_LAMMPS_TRACES = {}


def run_lammps(case):
    """The LAMMPS plugin's law (lammps_plugin/stick_slip_law.h), read from its record: the
    wall's per-atom columns 9-13 or compute pair/local's p11, p1-p3, p12 (Fn, F_s on i,
    slips since the contact began). The case's whole batch runs at its first row."""
    key = ("legacy",) + _lammps_key(case)
    if key not in _LAMMPS_TRACES:
        batch = [c for c in lc.CASES if _lammps_key(c) == key[1:]]
        _LAMMPS_TRACES[key] = _lammps_batch(batch)
    return _LAMMPS_TRACES[key][case.name]


def run_lammps_granular(case):
    """The sub-model stick_slip (lammps_plugin/granular/) in LAMMPS 2025, read from its
    record (/record): the wall's per-atom columns 9-13 or compute pair/local's p13-p17."""
    key = ("granular",) + _lammps_key(case)
    if key not in _LAMMPS_TRACES:
        batch = [c for c in lc.CASES if _lammps_key(c) == key[1:]]
        _LAMMPS_TRACES[key] = _lammps_batch(batch, GranularSubModel, GRANULAR_LAUNCHER)
    return _LAMMPS_TRACES[key][case.name]


def lammps_type_pairs(timing="step", nu_s=0.0, record=True, styles=None, exe=None):
    """Six grain pairs side by side, one per pair of types 1..3, each with its own mu_s, mu_k
    from pair_coeff (cases.TYPE_PAIRS; LAMMPS' wall has one mu_s and mu_k per fix, so
    type 1 is a grain type here and (1, 1) a pair too), grain i sliding at one X a step.
    Pairs with a grain of type 1 have their normal along y and slide along x, the others
    normal x, sliding along y (the directions test_coefficients_per_type_pair expects).
    Runs lc.TYPE_PAIR_STEPS steps; returns {type pair: (steps, k) array}, each step's
    compute pair/local values for the contact, as the force on i: with record, Fn (p11),
    F_s (p1-p3), slips (p12); without, p1-p3 (the force single() re-evaluates). styles:
    None, the legacy styles; GranularSubModel, LAMMPS 2025's granular model (on `exe`),
    whose record is p13, p14-p16, p17."""
    coeff = lc.type_pair_coefficients()
    d = 2 * lc.R - lc.DELTA
    law = lc.Case("", "", "pair", (), 0.5, 0.5, nu_s=nu_s, timing=timing)  # (every pair's mu from pair_coeff)
    lines = [LAMMPS_HEAD.format(ntypes=3, dt=_f(lc.DT))]
    if styles is None:
        lines += [f"pair_style gran/hooke/stickslip {lammps_coefficients(law)} {lammps_keywords(law, record)}",
                  "pair_coeff * *"]
        lines += [f"pair_coeff {i} {j} mu_s {_f(ms)} mu_k {_f(mk)}" for (i, j), (ms, mk) in coeff.items()]
    else:
        lines += ["pair_style granular", f"pair_coeff * * {granular_model(law, record)}"]
        lines += [f"pair_coeff {i} {j} {granular_model(dataclasses.replace(law, mu_s=ms, mu_k=mk), record)}"
                  for (i, j), (ms, mk) in coeff.items()]
    first = {}
    for k, (ti, tj) in enumerate(sorted(coeff)):
        across = np.array([0.0, 1.0, 0.0]) if 1 in (ti, tj) else np.array([1.0, 0.0, 0.0])
        along = np.array([1.0, 0.0, 0.0]) if 1 in (ti, tj) else np.array([0.0, 1.0, 0.0])
        centre = np.array([4.0 * k - 10.0, 0.0, 0.0])
        for b, (t, x) in enumerate(((ti, centre - across * d / 2), (tj, centre + across * d / 2))):
            v = 0.25 * along if b == 0 else np.zeros(3)  # one X a step
            lines += [f"create_atoms {t} single {_f(x[0])} {_f(x[1])} {_f(x[2])} units box",
                      f"set atom {2 * k + b + 1} diameter {_f(2 * lc.R)} density 1000 "
                      f"vx {_f(v[0])} vy {_f(v[1])} vz {_f(v[2])}"]
        first[(ti, tj)] = 2 * k + 1
    columns = (styles or LegacyStyles).record if record else (1, 2, 3)
    forces = [1 + c for c in range(3)] if record else [0, 1, 2]  # (the record: Fn, then the force)
    lines += lammps_pair_local(columns) + [f"run {lc.TYPE_PAIR_STEPS}"]
    with tempfile.TemporaryDirectory(prefix="contract-lammps-") as tmp:
        work = Path(tmp)
        _run(work, "types", "\n".join(lines) + "\n", exe or LAUNCHER)
        pairs = read_dump(work / "dump.pairs")
    return {pair: np.array([lammps_pair_row(pairs[s + 1], a, forces) for s in range(lc.TYPE_PAIR_STEPS)])
            for pair, a in first.items()}


def run_lammps_type_pairs(timing="step", styles=None, exe=None):
    """lammps_type_pairs with the record: {type pair: trace}."""
    out = {}
    for pair, rows in lammps_type_pairs(timing, styles=styles, exe=exe).items():
        tr = lc.empty_trace(lc.TYPE_PAIR_STEPS)
        tr["D"] = None  # not in LAMMPS' record
        tr["fn"], tr["F"], tr["slips"] = rows[:, 0], rows[:, 1:4], rows[:, 4].astype(int)
        out[pair] = tr
    return out


def run_lammps_granular_type_pairs(timing="step"):
    return run_lammps_type_pairs(timing, GranularSubModel, GRANULAR_LAUNCHER)
