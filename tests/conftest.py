import functools
import sys
from pathlib import Path

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


def paper_case(name, law=None, duration=None):
    """The paper's cases are run once per test session and shared by the tests."""
    # one cache key however the caller spells it (lru_cache keys keywords and positions apart)
    return _paper_case(name, law, duration)


@functools.lru_cache(maxsize=None)
def _paper_case(name, law, duration):
    kw = {}
    if law:
        kw["law"] = law
    if duration:
        kw["duration"] = duration
    sc = scene_mod.load(name, **kw)
    df, sim = run_pyref(sc)
    return sc, df, sim
