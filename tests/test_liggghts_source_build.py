# SPDX-License-Identifier: GPL-2.0-or-later
"""`tangential stick_slip` built into LIGGGHTS-PUBLIC 3.8 the LIGGGHTS way (the law's two headers
copied into src/, then `make auto`: liggghts_plugin/README.md,
"Build into LIGGGHTS"; `STICKSLIP_SOURCE_BUILDS=liggghts-public ./run.sh setup` builds it
into build/liggghts_public/source/src/lmp_auto) must give the plugin's answers
(build/liggghts_plugin/liggghts-stickslip, against Debian's library) on the same input, to
the last bit: the thermo output and dumps are written with 17 significant digits and must
be the same text. The law is the same two files in both builds, and the builds' flags
(LIGGGHTS' Makefile.auto: -O2 -funroll-loops; the plugin: -O3 -fno-tree-vectorize
-fno-math-errno) may not change a floating-point result: no -ffast-math, and no fused
multiply-add to contract into (x86-64's SSE2; none in lmp_auto, the plugin or Debian's
library, by objdump).

Scenes: liggghts_plugin/examples/in.drag2d whole (the paper's drag, 2500 steps) and the
first 30000 steps of in.pour3d (400 spheres land in the box: ~460 contacts, most of which
have slipped), as the examples are, with only output lines added. Measured on the shared
2-core machine: a drag run ~0.1 s, a pour run ~1.2 s; each test runs two or three at once.

Without the source build the tests skip; under CI (CI set) or when the set-up was asked
for it (STICKSLIP_SOURCE_BUILDS names liggghts-public) a missing build is a failure.
"""
import os
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from conftest import ENGINE_SKIP, skip_engine
from stickslip.adapters.liggghts import LAUNCHER
from stickslip.adapters.lammps_family import serial_mpi_env

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "liggghts_plugin" / "examples"
# the law: the two files copied (the LIGGGHTS model and the law's engine-free core)
HEADERS = (ROOT / "liggghts_plugin" / "tangential_model_stick_slip.h", ROOT / "law_core" / "stick_slip_core.h")
# (STICKSLIP_LIGGGHTS_PUBLIC: another build of it)
LMP_AUTO = Path(os.environ.get("STICKSLIP_LIGGGHTS_PUBLIC")
                or ROOT / "build" / "liggghts_public" / "source" / "src" / "lmp_auto")
SWITCH = "liggghts-public"
POUR_STEPS = 30000
DIGITS = " ".join(["%d"] + ["%.17g"] * 12)


@pytest.fixture(autouse=True)
def builds():
    skip_engine("liggghts")  # the plugin and Debian's LIGGGHTS
    if LMP_AUTO.is_file():
        # the build holds the law as it is now (the set-up copies it again when it changed)
        for header in HEADERS:
            copy = LMP_AUTO.parent / header.name
            if not (copy.is_file() and copy.read_bytes() == header.read_bytes()):
                pytest.fail(f"{copy} is not {header.relative_to(ROOT)}: STICKSLIP_SOURCE_BUILDS={SWITCH} "
                            "./run.sh setup rebuilds it", pytrace=False)
        return
    where = LMP_AUTO.relative_to(ROOT) if LMP_AUTO.is_relative_to(ROOT) else LMP_AUTO
    why = f"{where} missing: STICKSLIP_SOURCE_BUILDS={SWITCH} ./run.sh setup builds it"
    if os.environ.get("CI") or SWITCH in os.environ.get("STICKSLIP_SOURCE_BUILDS", "").split(","):
        pytest.fail(f"LIGGGHTS-PUBLIC from source: {why} (CI must set STICKSLIP_SOURCE_BUILDS={SWITCH})",
                    pytrace=False)
    pytest.skip(f"{ENGINE_SKIP}: {SWITCH}: {why}")


def edit(text, old, new):
    assert text.count(old) == 1, f"the example changed: {old!r} is not in it once"
    return text.replace(old, new)


def drag_script():
    return edit((EXAMPLES / "in.drag2d").read_text(), "thermo_modify   format float %.6g\n",
                "thermo_modify   format float %.17g\n"
                "dump            d all custom 50 dump.all id x y z vx vy vz fx fy fz omegax omegay omegaz\n"
                f'dump_modify     d format "{DIGITS}"\n')


def pour_script(pair_settings="", wall_settings=""):
    text = edit((EXAMPLES / "in.pour3d").read_text(), "thermo          5000\n",
                "thermo          1000\nthermo_modify   format float %.17g\n"
                "dump            d all custom 5000 dump.all id x y z vx vy vz fx fy fz omegax omegay omegaz\n"
                f'dump_modify     d format "{DIGITS}" sort id\n')
    text = edit(text, "limitForce on stick_slip_record on\n", f"limitForce on stick_slip_record on{pair_settings}\n")
    return edit(text, '"absolute_damping on limitForce on"', f'"absolute_damping on limitForce on{wall_settings}"')


def run(exe, folder, script, extra=(), check=True):
    """Run `script` in `folder` with `exe`; returns (exit code, stdout)."""
    folder.mkdir()
    (folder / "in.case").write_text(script)
    env = dict(os.environ, **serial_mpi_env(folder))  # one process: no MPI daemon
    proc = subprocess.run([str(exe), "-in", "in.case", "-log", "none", *extra], cwd=folder, env=env,
                          capture_output=True, text=True, errors="replace", timeout=120)
    if check:
        assert proc.returncode == 0 and "ERROR" not in proc.stdout, \
            f"{exe.name}: exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    return proc.returncode, proc.stdout


def run_both(tmp_path, jobs):
    """jobs: (name, exe, script, extra) run two at a time -> {name: stdout}."""
    with ThreadPoolExecutor(max_workers=2) as pool:
        outs = pool.map(lambda j: run(j[1], tmp_path / j[0], j[2], j[3])[1], jobs)
        return {j[0]: out for j, out in zip(jobs, outs)}


def answers(folder, stdout, files):
    """What a run computed: its thermo rows and printed results (the text between the
    thermo header and "Loop time", and the lines the script prints) and its dump files."""
    lines, keep, table = [], False, 0
    for line in stdout.splitlines():
        if line.split()[:1] == ["Step"]:
            keep, table = True, table + 1
        elif line.startswith("Loop time"):
            keep = False
        if keep or line.startswith(("mean friction", "slips:", "force applied", "settled:")):
            lines.append(line)
    assert table, f"no thermo output in {folder}"
    return lines, {f: (folder / f).read_bytes() for f in files}


def assert_same(tmp_path, a, b, outs, files):
    ta, fa = answers(tmp_path / a, outs[a], files)
    tb, fb = answers(tmp_path / b, outs[b], files)
    assert ta == tb, next(f"{a}: {x}\n{b}: {y}" for x, y in zip(ta + [""], tb + [""]) if x != y)
    for f in files:
        assert fa[f] == fb[f], f"{f} differs between {a} and {b}"


def test_drag_gives_the_plugins_answers_bit_for_bit(tmp_path):
    script = drag_script()
    outs = run_both(tmp_path, [("plugin", LAUNCHER, script, ()), ("in_tree", LMP_AUTO, script, ())])
    assert_same(tmp_path, "plugin", "in_tree", outs, ["dump.all"])
    # the compiled-in combination (the set-up's whitelist), not LIGGGHTS' generic model
    assert "not located in any whitelist" not in outs["in_tree"]
    assert "slips: 11;" in outs["in_tree"]


def test_pour_gives_the_plugins_answers_bit_for_bit(tmp_path):
    script, steps = pour_script(), ("-var", "steps", str(POUR_STEPS))
    outs = run_both(tmp_path, [("plugin", LAUNCHER, script, steps), ("in_tree", LMP_AUTO, script, steps)])
    assert_same(tmp_path, "plugin", "in_tree", outs, ["dump.all", "dump.contacts", "dump.grains"])
    assert "not located in any whitelist" not in outs["in_tree"]
    # the pile has formed and its contacts have slipped (dump.contacts' last column)
    rows = [r.split() for r in (tmp_path / "in_tree" / "dump.contacts").read_text().splitlines()[9:]]
    assert len(rows) > 300 and sum(float(r[-1]) > 0 for r in rows) > 0.5 * len(rows)


def test_keyword_settings_in_tree_are_spelled_on_off(tmp_path):
    """In LIGGGHTS' own build, LIGGGHTS parses the settings: history_rotation project and
    history_on_separation keep are the on/off settings stick_slip_history_project and
    stick_slip_keep_separated (the plugin knows both spellings)."""
    plugin = pour_script(" history_rotation project history_on_separation keep", " history_rotation project")
    in_tree = pour_script(" stick_slip_history_project on stick_slip_keep_separated on",
                          " stick_slip_history_project on")
    steps = ("-var", "steps", str(POUR_STEPS))
    outs = run_both(tmp_path, [("plugin", LAUNCHER, plugin, steps), ("in_tree", LMP_AUTO, in_tree, steps),
                               ("default", LMP_AUTO, pour_script(), steps)])
    assert_same(tmp_path, "plugin", "in_tree", outs, ["dump.all", "dump.contacts"])
    assert (tmp_path / "in_tree" / "dump.all").read_bytes() != (tmp_path / "default" / "dump.all").read_bytes()
    code, out = run(LMP_AUTO, tmp_path / "keyword", plugin, steps, check=False)
    assert code != 0 and "Unknown argument or wrong keyword order: 'history_rotation'" in out


def test_combination_outside_the_whitelist_runs_generic_with_the_plugins_answers(tmp_path):
    """hooke/stiffness with cohesion sjkr2 and rolling friction cdt is compiled in neither
    build: both run it through their copy of LIGGGHTS' generic contact model (and say so)."""
    script = edit(pour_script(), "tangential stick_slip absolute_damping",
                  "tangential stick_slip cohesion sjkr2 rolling_friction cdt absolute_damping")
    script = edit(script, '"model hooke/stiffness tangential stick_slip"',
                  '"model hooke/stiffness tangential stick_slip cohesion sjkr2 rolling_friction cdt"')
    script = edit(script, "coefficientKineticFriction peratomtypepair 1 0.45\n",
                  "coefficientKineticFriction peratomtypepair 1 0.45\n"
                  "fix             m7 all property/global coefficientRollingFriction peratomtypepair 1 0.05\n"
                  "fix             m8 all property/global cohesionEnergyDensity peratomtypepair 1 50\n")
    steps = ("-var", "steps", str(POUR_STEPS))
    outs = run_both(tmp_path, [("plugin", LAUNCHER, script, steps), ("in_tree", LMP_AUTO, script, steps)])
    assert all("not located in any whitelist" in out for out in outs.values())
    assert_same(tmp_path, "plugin", "in_tree", outs, ["dump.all", "dump.contacts", "dump.grains"])
