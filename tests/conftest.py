import fcntl
import hashlib
import os
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from stickslip import columns  # noqa: E402
from stickslip import scene as scene_mod  # noqa: E402
from pyref import Simulation  # noqa: E402


def pytest_addoption(parser):
    parser.addoption("--runslow", action="store_true", help="also run the long opt-in tests")


def pytest_collection_modifyitems(config, items):
    if config.getoption("--runslow"):
        return
    skip = pytest.mark.skip(reason="long run: opt in with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


def run_pyref(sc, energy=False):
    """Run a scene on pyref; returns (timeseries DataFrame, Simulation)."""
    if energy:
        sc.output.energy = True
    sim = Simulation(sc)
    return columns.frame(sc, sim.run()), sim


SHARED = None  # the session's folder of shared pyref runs (set by shared_runs_folder)
_loaded = {}   # this process's copies of them


@pytest.fixture(scope="session", autouse=True)
def shared_runs_folder(tmp_path_factory):
    """One folder per test session for the runs paper_case shares. With pytest-xdist each
    worker's temporary folder is a subfolder of the session's, so the workers share its
    parent; without xdist the session's own folder is used."""
    global SHARED
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    SHARED = base / "shared-pyref-runs"
    SHARED.mkdir(exist_ok=True)


def paper_case(name, **overrides):
    """pyref's run of a case (a name and scene.load's overrides: duration, law, slip_timing,
    ...), made once per test session and shared by every test that reads it, in every
    xdist worker: the first to ask runs it while holding a file lock, the others wait for
    it and read its time series. Returns (scene, time series). Runs are told apart by the
    scene's data with the overrides written in (scene.identity): a value the file already
    has is spelt by leaving the override out, as every caller does."""
    sc = scene_mod.load(name, **overrides)
    key = hashlib.sha256(scene_mod.identity(name, **overrides).encode()).hexdigest()[:24]
    if key not in _loaded:
        path = SHARED / f"{name}-{key}.pkl"
        with open(SHARED / f"{name}-{key}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
            if not path.exists():
                df, _ = run_pyref(sc)
                part = path.with_suffix(".part")
                df.to_pickle(part)
                part.rename(path)
            _loaded[key] = pd.read_pickle(path)
    return sc, _loaded[key]
