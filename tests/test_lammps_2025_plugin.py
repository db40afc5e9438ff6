# SPDX-License-Identifier: GPL-2.0-or-later
"""The legacy pair style on LAMMPS 2025 (issue 49, item 4): `pair_style gran/hooke/stickslip`
as a plugin (lammps_plugin/stickslip_lammpsplugin.cpp, built by lammps_plugin/lammps2025.cmake
into build/lammps_2025_plugin/libstickslip_lammps2025.so) that LAMMPS 2025's `plugin load`
takes, from the source Debian's LAMMPS builds (lammps_plugin/lammps_api.h).

- `plugin load` registers it and `plugin list` shows it;
- renamed, with stock's arguments and no law keyword, it is stock `gran/hooke/history` of the
  same LAMMPS bit for bit: a small pour's dumps and thermo, 1 and 2 ranks, newton off and on;
- the law's keywords keep the law's contract (stickslip/contract/cases.py): the pair rows of the
  legacy styles' batch (stickslip/contract/lammps.py) with a `plugin load` line first, and every
  type pair with its own mu_s, mu_k in both slip timings (that script loads the plugin from
  LAMMPS_PLUGIN_PATH, LAMMPS' other way to load one);
- a bad keyword stops the run with one ERROR line.

The wall fixes are not in the plugin: on LAMMPS 2023 and later `fix wall/gran granular ...
tangential stick_slip` gives the law on walls (lammps_plugin/README.md, "On LAMMPS built from
source"; tests/test_lammps_granular*.py), and LAMMPS 2025's own wall/gran hooke/history is no
longer the wall the legacy fix renames (test_the_wall_moves_to_the_sub_model). These tests need LAMMPS 2025
(STICKSLIP_SOURCE_BUILDS=lammps-2025 ./run.sh setup, which builds the plugin too): they skip
without it, and fail as root (CI). Costs (2 cores): pour ~2 s serial, ~5 s on 2 ranks;
the others < 1 s each.
"""
import os
from pathlib import Path

import numpy as np
import pytest

from conftest import skip_engine
from lammps_runs import CRASH_MARKERS, error_lines, read_dump, run_lammps
from stickslip.adapters import lammps_granular
from stickslip.contract import cases as lc, lammps as runners

pytestmark = pytest.mark.skipif(lammps_granular.release_missing("lammps-2025") is not None,
                                reason=f"engine missing: lammps_granular: {lammps_granular.release_missing('lammps-2025')}")

ROOT = Path(__file__).resolve().parent.parent
# (STICKSLIP_LAMMPS_2025_PLUGIN: another build of the plugin, e.g. a mutant's)
PLUGIN = Path(os.environ.get("STICKSLIP_LAMMPS_2025_PLUGIN")
              or ROOT / "build" / "lammps_2025_plugin" / "libstickslip_lammps2025.so")
LMP = lammps_granular.launcher("lammps-2025")  # (the plugin is built against 4 Feb 2025)


def test_the_plugin_is_built():
    """Where LAMMPS 2025 is built (./run.sh setup's switch; CI), so is the plugin: a missing
    one fails here."""
    skip_engine("lammps_granular", lammps_granular.release_missing("lammps-2025"))
    assert PLUGIN.is_file(), f"{PLUGIN} missing: STICKSLIP_SOURCE_BUILDS=lammps-2025 ./run.sh setup builds it"


def test_plugin_load_registers_the_pair_style(tmp_path):
    proc = run_lammps(tmp_path, "list", f"plugin load {PLUGIN}\nplugin list\n", exe=LMP)
    assert "Loading plugin: stickslip " in proc.stdout, proc.stdout[-2000:]
    listed = [line.split(":", 1)[1].strip() for line in proc.stdout.splitlines() if line.strip()[:1].isdigit()]
    assert listed == ["pair style plugin gran/hooke/stickslip"], proc.stdout[-2000:]


# ---------------------------------------------------------------- the drop-in

POUR = """atom_style sphere
boundary p p fm
newton {newton}
comm_modify vel yes
region reg block -6 6 -6 6 -0.5 16 units box
create_box 1 reg
neighbor 0.2 bin
neigh_modify delay 0
{load}pair_style {pair} 2000.0 NULL 50.0 NULL 0.5 {damping}
pair_coeff * *
timestep 0.001
fix 1 all nve/sphere
fix 2 all gravity 1.0 spherical 0.0 -180.0
fix zlower all wall/gran hooke/history 2000.0 NULL 50.0 NULL 0.5 {damping} zplane 0.0 2000.0
region slab block -5.0 5.0 -5.0 5.0 8.0 15.0 units box
fix ins all pour 600 1 300719 vol 0.2 50 region slab
compute 1 all erotate/sphere
thermo_style custom step atoms ke c_1 vol
thermo 500
thermo_modify lost ignore norm no format float %.17g
compute_modify thermo_temp dynamic/dof yes
dump d all custom 1000 dump.out id x y z vx vy vz fx fy fz omegax omegay omegaz
dump_modify d sort id format float %.17g
{extra}run 6000
"""


def pour(pair, newton, damped, load="", extra=""):
    """examples/pour/in.pour made small: 441 grains poured in two waves onto a floor wall
    (stock wall/gran hooke/history), landing from step ~1800 and piling up until step 6000.
    damped: tangential damping (dampflag 1, gamma_t = gamma_n/2) and limit_damping, so that
    stock's rescale of a slipping contact's shear carries the dashpot term."""
    return POUR.format(newton=newton, load=load, pair=pair, damping="1 limit_damping" if damped else "0",
                       extra=extra)


def thermo_lines(log):
    """The thermo rows of a log (each run's header to its Loop line), as written."""
    out, inside = [], False
    for line in Path(log).read_text().splitlines():
        if line.split()[:1] == ["Step"]:
            inside = True
        elif line.startswith("Loop time"):
            inside = False
        if inside:
            out.append(line)
    return out


@pytest.mark.parametrize("np_,newton,damped", [(1, "off", True), (2, "off", False), (2, "on", True)])
def test_renamed_pour_is_stock_bit_for_bit(tmp_path, np_, newton, damped):
    """The same LAMMPS 2025 run twice, with `pair_style gran/hooke/history` and with `plugin
    load` + `pair_style gran/hooke/stickslip` and the same arguments: the dumps (every
    grain's position, velocity, force and spin at %.17g) and the thermo rows are the same
    bytes."""
    stock = run_lammps(tmp_path / "stock", "pour", pour("gran/hooke/history", newton, damped), exe=LMP, np_=np_)
    ours = run_lammps(tmp_path / "ours", "pour", pour("gran/hooke/stickslip", newton, damped, f"plugin load {PLUGIN}\n"),
                      exe=LMP, np_=np_)
    assert "Loading plugin: stickslip " in ours.stdout and "Loading plugin" not in stock.stdout
    if np_ > 1:
        assert f"on {np_} procs" in (tmp_path / "ours" / "log.pour").read_text()
    frames = read_dump(tmp_path / "ours" / "dump.out")
    last = frames[6000]
    assert len(last) > 400 and abs(last[:, 7:10]).max() > 0, "no grains or no forces: nothing was compared"
    assert (tmp_path / "stock" / "dump.out").read_bytes() == (tmp_path / "ours" / "dump.out").read_bytes()
    rows = thermo_lines(tmp_path / "ours" / "log.pour")
    assert len(rows) >= 13 and rows == thermo_lines(tmp_path / "stock" / "log.pour")


WALL_STEP = """atom_style sphere
atom_modify map array
boundary f f f
comm_modify vel yes
region box block -2 2 -2 2 -1 2 units box
create_box 1 box
create_atoms 1 single 0 0 0.49 units box
set atom 1 diameter 1.0 density 1.0
pair_style gran/hooke/history 2000.0 NULL 10.0 NULL 0.5 1
pair_coeff * *
timestep 0.001
fix m all move linear 0.01 0 0
fix w all wall/gran {wall} zplane 0.0 NULL
dump d all custom 1 dump.w id fx fy fz
dump_modify d format float %.17g
run 1
"""


def test_the_wall_moves_to_the_sub_model(tmp_path):
    """Why the plugin has no wall fix (lammps_plugin/README.md, "On LAMMPS built from source"):
    one grain (R = 0.5, overlap 0.01) dragged along a floor for one step. Debian's LAMMPS's
    wall/gran hooke/history, which the legacy wall/gran/stickslip renames, gives
    F_x = -(Kt v dt + meff gamma_t v) (measured there: -0.03617993877991494), as pair
    gran/hooke/history does; LAMMPS 2025's stock wall/gran hooke/history (rebuilt on the
    granular model as linear_history_classic) multiplies Kt by the contact radius
    a = sqrt(R delta): a renamed wall could not be stock's there and the legacy wall at once.
    `fix wall/gran granular hooke Kn gamma_n damping mass_velocity tangential stick_slip Kt
    gamma_t/gamma_n mu_s mu_k` gives the legacy wall's force."""
    kt, gamma_n, v, dt, delta, R = 2000.0 * 2.0 / 7.0, 10.0, 0.01, 0.001, 0.01, 0.5
    meff = np.pi / 6.0  # (the grain's mass: the wall's side has none)
    damp = meff * 0.5 * gamma_n * v  # gamma_t NULL = gamma_n / 2

    def fx(wall, name):
        run_lammps(tmp_path / name, "wall", WALL_STEP.format(wall=wall), exe=LMP)
        return read_dump(tmp_path / name / "dump.w")[1][0][1]

    stock = fx("hooke/history 2000.0 NULL 10.0 NULL 0.5 1", "stock")
    sub_model = fx(f"granular hooke 2000.0 10.0 damping mass_velocity tangential stick_slip {kt!r} 0.5 0.5 0.5",
                   "sub_model")
    assert sub_model == pytest.approx(-(kt * v * dt + damp), rel=1e-12)
    assert stock == pytest.approx(-(kt * np.sqrt(R * delta) * v * dt + damp), rel=1e-12)


def test_the_pour_slips(tmp_path):
    """The drop-in's pour slips: with `record yes` (no other change to the contacts), the
    contacts open at its end have slipped hundreds of times (their record's slip counts,
    compute pair/local p12, summed)."""
    extra = "compute pl all pair/local p12 cutoff radius\ncompute slips all reduce sum c_pl inputs local\nthermo_style custom step c_slips\n"
    script = pour("gran/hooke/stickslip", "off", True, f"plugin load {PLUGIN}\n", extra)
    script = script.replace("limit_damping\npair_coeff", "limit_damping record yes\npair_coeff")
    assert "record yes" in script
    proc = run_lammps(tmp_path, "slips", script + 'print "slips $(c_slips)"\n', exe=LMP)
    slips = float(proc.stdout.split("slips ")[-1].split()[0])
    assert slips > 200, slips


# ---------------------------------------------------------------- the law's keywords

class PluginStyles(runners.LegacyStyles):
    """The legacy styles' contract batch, the plugin loaded first."""

    @staticmethod
    def pair_lines(case):
        return [f"plugin load {PLUGIN}"] + runners.LegacyStyles.pair_lines(case)


def test_the_pair_rows_of_the_contract():
    """The contract's pair rows (a stuck pair turning fast and slowly: D turned keeping its
    length; re-contact from a zero spring) through the plugin, with the law's keywords
    (mu_k, reset spring, keep_length, damping absolute, lever_arm contact, record yes)."""
    cases = [c for c in lc.CASES if c.geometry == "pair"]
    assert len(cases) >= 3 and all(runners._lammps_key(c) == runners._lammps_key(cases[0]) for c in cases)
    traces = runners._lammps_batch(cases, PluginStyles, exe=LMP)
    for case in cases:
        lc.compare(case, traces[case.name])


@pytest.mark.parametrize("timing", ["step", "exact"])
def test_every_type_pair_keeps_the_contract(tmp_path, monkeypatch, timing):
    """Six grain pairs of types 1..3 sliding, each with its own mu_s and mu_k from pair_coeff,
    through the legacy styles' script (stickslip/contract/lammps.py's lammps_type_pairs) on
    LAMMPS 2025: the plugin is loaded at start-up from LAMMPS_PLUGIN_PATH, where LAMMPS loads
    every file named *plugin.so."""
    (tmp_path / "stickslip_lammps2025plugin.so").symlink_to(PLUGIN)
    monkeypatch.setenv("LAMMPS_PLUGIN_PATH", str(tmp_path))
    traces = runners.run_lammps_type_pairs(timing, styles=None, exe=LMP)
    assert set(traces) == set(lc.TYPE_PAIRS)
    for pair, trace in traces.items():
        w = lc.X * (np.array([1.0, 0, 0]) if 1 in pair else np.array([0, 1.0, 0]))
        lc.compare_type_pair(pair, trace, w)
        assert trace["slips"][-1] > 0, pair


# ---------------------------------------------------------------- refusals

BOX = """atom_style sphere
region b block 0 1 0 1 0 1
create_box 1 b
"""


@pytest.mark.parametrize("line,words", [
    ("pair_style gran/hooke/stickslip 2000 NULL 50 NULL 0.5 1 mu_k 0.4 slip_timing exactly",
     ["slip_timing 'exactly' is not allowed", "exact or step"]),
    ("pair_style gran/hooke/stickslip 2000 NULL 50 NULL 0.5 1 sticky yes",
     ["unknown keyword 'sticky'", "limit_damping"]),
    ("pair_style gran/hooke/stickslip 2000 NULL 50 NULL 0.5 1 mu_k 0.1", ["mu_k = 0.1", "[0.25, 0.5]"]),
], ids=["bad value", "unknown keyword", "mu_k range"])
def test_a_bad_keyword_is_one_error_line(tmp_path, line, words):
    proc = run_lammps(tmp_path, "bad", f"plugin load {PLUGIN}\n{BOX}{line}\npair_coeff * *\nrun 0\n", exe=LMP,
                      check=False)
    errors = error_lines(proc)
    assert proc.returncode != 0 and len(errors) == 1, (proc.returncode, proc.stdout[-2000:])
    for w in words:
        assert w in errors[0], (w, errors[0])
    for marker in CRASH_MARKERS:
        assert marker not in proc.stdout + proc.stderr, (marker, proc.stderr[-1000:])
