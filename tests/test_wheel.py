# SPDX-License-Identifier: GPL-2.0-or-later
"""Install without a clone: `python -m build` makes an sdist and a wheel; the wheel, installed
into a new virtual environment in a folder outside the repository, runs `stickslip run drag`
(pyref) and `stickslip calibrate` on the files it carries with the checkout's answers, holds
pyref to the law's contract (stickslip.contract), gives the DEM-Engine model's text, and YADE
imports the law from it and runs a scene. pip takes the
dependencies from the registry (after ./run.sh setup, from its cache). Opt-in (--runslow):
about a minute of building and installing; `./run.sh wheel-check` runs it, and CI does.
"""
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tomllib
from pathlib import Path

import pytest

from conftest import skip_engine

ROOT = Path(__file__).resolve().parent.parent
VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
CHECKOUT_CLI = Path(sys.executable).parent / "stickslip"  # the repository's editable install
CALIBRATE = ["calibrate", "--theta-start", "24.5", "--theta-stop", "21.5"]
# a file of each kind the sdist must carry for the wheel (setup.py, MANIFEST.in)
IN_SDIST = ("cases/drag.toml", "yade_law/run_scene.py", "yade_law/stickslip_yade/kernel.py",
            "deme_model/stickslip_deme.py", "deme_model/stick_slip.cu", "docs/granular-3d/points.csv",
            "LICENSE", "CITATION.cff")


def run(cmd, cwd, env=None, timeout=600):
    proc = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, f"{' '.join(map(str, cmd))}:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc.stdout


def summary_without_timing(folder):
    s = json.loads((folder / "summary.json").read_text())
    s.pop("wall_time_s")
    return s


@pytest.mark.slow
def test_the_wheel_installed_outside_the_repository_runs_pyref_calibrate_and_the_yade_law(tmp_path):
    assert ROOT not in tmp_path.parents
    source, dist, venv, work, ref = (tmp_path / n for n in ("source", "dist", "venv", "work", "ref"))
    work.mkdir()
    # built from a copy of the files git tracks or would track: setuptools adds the files that
    # an earlier build's stickslip.egg-info lists, so a build in the checkout is not the clone's
    for f in run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT).splitlines():
        if (ROOT / f).is_file():
            (source / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / f, source / f)
    run([sys.executable, "-m", "build", "--outdir", dist, source], cwd=tmp_path)
    with tarfile.open(dist / f"stickslip-{VERSION}.tar.gz") as sdist:
        names = {n.split("/", 1)[1] for n in sdist.getnames() if "/" in n}
    assert not [f for f in IN_SDIST if f not in names]

    run([sys.executable, "-m", "venv", venv], cwd=tmp_path)
    run([venv / "bin" / "python", "-m", "pip", "install", "-q", dist / f"stickslip-{VERSION}-py3-none-any.whl"],
        cwd=tmp_path)
    # nothing of the repository on the way: not its folder, not its environment
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    where = json.loads(run([venv / "bin" / "python", "-c", "import json, stickslip, pyref, stickslip_deme; "
                            "print(json.dumps([stickslip.__file__, pyref.__file__, str(stickslip_deme.MODEL_FILE), "
                            "stickslip_deme.__version__, stickslip_deme.model_text()[:60]]))"], cwd=work, env=env))
    assert all(Path(p).is_relative_to(venv) for p in where[:3]) and Path(where[2]).is_file(), where
    assert where[3] == VERSION and "#define STICKSLIP_HOOKE" in where[4]
    assert run([venv / "bin" / "stickslip", "--version"], cwd=work, env=env) == f"stickslip {VERSION}\n"
    # the law's contract travels with the package: every row on the wheel's pyref
    run([venv / "bin" / "python", "-c", "from stickslip.contract import cases, runners\n"
         "for c in cases.CASES: cases.compare(c, runners.run_pyref(c))"], cwd=work, env=env)

    # pyref on the wheel's scene file, and calibrate on its measured map: the checkout's answers
    run([venv / "bin" / "stickslip", "run", "drag", "--quiet"], cwd=work, env=env)
    run([CHECKOUT_CLI, "run", "drag", "--quiet", "--out", ref], cwd=tmp_path)
    got = summary_without_timing(work / "runs" / "drag" / "pyref")
    assert got["version"] == VERSION and got == summary_without_timing(ref)
    assert run([venv / "bin" / "stickslip", *CALIBRATE], cwd=work, env=env) == run([CHECKOUT_CLI, *CALIBRATE], cwd=ROOT)

    # YADE (Debian's, on the system's Python) imports the law from the environment's packages,
    # and the command line runs a scene on it through the wheel's scene runner
    skip_engine("yade")
    packages = run([venv / "bin" / "python", "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                   cwd=work, env=env).strip()
    (work / "law.py").write_text("import json, stickslip_yade, pyref.laws\n"
                                 "print('LAW', json.dumps([stickslip_yade.__version__, stickslip_yade.__file__, "
                                 "pyref.laws.__file__]))\n")
    out = run(["yade", "-n", "-x", "law.py"], cwd=work, env=dict(env, PYTHONPATH=packages), timeout=120)
    version, *files = json.loads(next(line for line in out.splitlines() if line.startswith("LAW "))[4:])
    assert version == VERSION and all(Path(f).is_relative_to(venv) for f in files), files
    run([venv / "bin" / "stickslip", "run", "drag", "--engine", "yade", "--duration", "0.002", "--quiet"],
        cwd=work, env=env)
    assert summary_without_timing(work / "runs" / "drag" / "yade")["version"] == VERSION
