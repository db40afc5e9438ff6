# SPDX-License-Identifier: GPL-2.0-or-later
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


# ---------------------------------------------------------------- engines the tests need
# Every test that needs an engine (stickslip.adapters.ENGINES, each adapter's available())
# or a package beside it skips through needs_engine / skip_engine, whose reasons start with
# ENGINE_SKIP. As root (./run.sh test installs every engine then; CI runs as root) a missing
# engine stops the run at once with one line naming it; otherwise the run's last line counts
# the engine tests it skipped.
ENGINE_SKIP = "engine missing"


def as_root():
    return hasattr(os, "geteuid") and os.geteuid() == 0


def engine_missing(name):
    """None if the engine can run here, else why not (its adapter's word)."""
    from stickslip import adapters

    return adapters.get(name).available()


def needs_engine(name):
    """A mark (pytestmark, or on a test): skip when the engine cannot run here."""
    why = engine_missing(name)
    return pytest.mark.skipif(why is not None, reason=f"{ENGINE_SKIP}: {name}: {why}")


def skip_engine(name, why=None):
    """Inside a test: skip when the engine (or `why`, a package it needs) is missing; as
    root that is a failure, not a skip."""
    from stickslip import adapters

    why = why or engine_missing(name)
    if why is None:
        return
    if as_root() and adapters.required(name):
        pytest.fail(f"{name}: {why} (root runs need every engine: ./run.sh setup installs them)", pytrace=False)
    pytest.skip(f"{ENGINE_SKIP}: {name}: {why}")


def lammps_releases():
    """The modern LAMMPS releases a test runs on, one pytest parameter each (the adapter
    lammps_granular's RELEASES; the override alone when STICKSLIP_LAMMPS_GRANULAR is set)."""
    from stickslip.adapters import lammps_granular

    return ["override"] if lammps_granular.OVERRIDE else list(lammps_granular.RELEASES)


def lammps_release_launcher(release):
    """Inside a test: the release's lmp, or skip where it is not built; as root a release that
    the set-up switch asked for and that is missing is a failure."""
    from stickslip.adapters import lammps_granular, source_build_asked

    why = lammps_granular.release_missing(release)
    if why is None:
        return lammps_granular.built()[release]
    if as_root() and source_build_asked(release):
        pytest.fail(f"lammps_granular: {why}", pytrace=False)
    pytest.skip(f"{ENGINE_SKIP}: lammps_granular: {why}")


def pytest_configure(config):
    if hasattr(config, "workerinput") or not as_root():  # (xdist workers: the controller checks)
        return
    from stickslip import adapters

    _, missing = adapters.available()
    if missing:
        raise pytest.UsageError("engines missing on a root run (CI needs them all): "
                                + "; ".join(f"{e}: {why}" for e, why in missing.items()))


_engine_skips = {}  # engine -> number of tests skipped for it (reports reach the xdist controller)


def pytest_runtest_logreport(report):
    if report.skipped and isinstance(report.longrepr, tuple):
        reason = str(report.longrepr[2])
        if ENGINE_SKIP + ":" in reason:
            engine = reason.split(ENGINE_SKIP + ":", 1)[1].split(":", 1)[0].strip()
            _engine_skips[engine] = _engine_skips.get(engine, 0) + 1


@pytest.hookimpl(hookwrapper=True, tryfirst=True)
def pytest_sessionfinish(session):
    yield  # (outermost: after pytest's own summary line, so this is the run's last line)
    if _engine_skips and not hasattr(session.config, "workerinput"):
        tr = session.config.pluginmanager.get_plugin("terminalreporter")
        text = ", ".join(f"{e} {n}" for e, n in sorted(_engine_skips.items()))
        line = f"engine tests skipped: {sum(_engine_skips.values())} ({text}); as root they would fail"
        if tr is not None:
            tr.write_line(line)
        else:
            print(line)


# STICKSLIP_TEST_CPU=FILE: each test's CPU seconds (this process and the engines it ran and
# waited for: user + system), appended to FILE as "seconds<TAB>test id" lines. Wall times
# move with the machine's load; CPU times much less, which is what a profile of the suite
# on a shared machine needs (docs/testing.md).
_CPU_LOG = os.environ.get("STICKSLIP_TEST_CPU")


def _cpu_seconds():
    import resource

    return sum(u.ru_utime + u.ru_stime for u in (resource.getrusage(resource.RUSAGE_SELF),
                                                   resource.getrusage(resource.RUSAGE_CHILDREN)))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if not _CPU_LOG:
        yield
        return
    t0 = _cpu_seconds()
    yield
    with open(_CPU_LOG, "a") as f:
        f.write(f"{_cpu_seconds() - t0:.2f}\t{item.nodeid}\n")


def pytest_collection_modifyitems(config, items):
    # The default suite's long tests (marked long, 14-50 s each) run first: started last, one
    # of them would keep one worker busy after the others have run out of tests. (xdist's
    # worksteal gives them all to the first worker, whose short tests the others steal;
    # dealing them to two workers' shares in turn measured slower: docs/testing.md.)
    items[:] = [i for i in items if "long" in i.keywords] + [i for i in items if "long" not in i.keywords]
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


SHARED = None  # the session's folder of shared runs (set by shared_runs_folder)
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
    SHARED = base / "shared-runs"
    SHARED.mkdir(exist_ok=True)


def shared_result(name, identity, make):
    """make()'s value, made once per test session and shared by every test that asks for the
    same `identity` (a text that says everything the value depends on), in every xdist
    worker: the first to ask makes it while holding a file lock, the others wait for it and
    read it back (pickled). `name` only names the files."""
    key = hashlib.sha256(identity.encode()).hexdigest()[:24]
    if key not in _loaded:
        path = SHARED / f"{name}-{key}.pkl"
        with open(SHARED / f"{name}-{key}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
            if not path.exists():
                part = path.with_suffix(".part")
                pd.to_pickle(make(), part)
                part.rename(path)
            _loaded[key] = pd.read_pickle(path)
    return _loaded[key]


def paper_case(name, **overrides):
    """pyref's run of a case (a name and scene.load's overrides: duration, law, slip_timing,
    ...), made once per test session and shared by every test that reads it (shared_result).
    Returns (scene, time series). Runs are told apart by the scene's data with the overrides
    written in (scene.identity): a value the file already has is spelt by leaving the
    override out, as every caller does."""
    sc = scene_mod.load(name, **overrides)
    return sc, shared_result(name, scene_mod.identity(name, **overrides), lambda: run_pyref(sc)[0])
