# SPDX-License-Identifier: GPL-2.0-or-later
"""tools/mutate_cpp.py finds every mutant in the law as it reads now: a law edited without
its mutants would leave them unfound (ERROR), and the mutation scores in docs/testing.md
would no longer describe the code."""
import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def load_tool():
    spec = importlib.util.spec_from_file_location("mutate_cpp", ROOT / "tools" / "mutate_cpp.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["mutate_cpp"] = module  # (its dataclasses look their module up by name)
    spec.loader.exec_module(module)
    return module


TOOL = load_tool()


@pytest.mark.parametrize("engine", sorted(TOOL.ENGINES))
def test_every_mutant_is_found_in_its_engines_source(engine):
    eng = TOOL.ENGINES[engine]
    unfound = []
    for m in eng.mutants:
        source = (ROOT / (m.file or eng.law_file)).read_text()
        found = len(TOOL.pattern(m.find).findall(source))
        if found != m.count:
            unfound.append(f"{m.id}: found {found} times, expected {m.count}")
    assert not unfound, unfound


@pytest.mark.parametrize("engine", sorted(TOOL.ENGINES))
def test_mutant_ids_are_unique(engine):
    ids = [m.id for m in TOOL.ENGINES[engine].mutants]
    assert len(ids) == len(set(ids))


def test_every_engine_that_includes_the_core_runs_its_mutants():
    """The law's core (lammps_plugin/granular/stick_slip_core.h) has one mutant list, and
    every engine whose build includes the core runs all of it; the others (DEM-Engine's own
    float copy) none of it."""
    core = TOOL.CORE
    for name, eng in TOOL.ENGINES.items():
        includes = any(core.startswith(folder + "/") for folder in (eng.source, *eng.copies))
        ids = {m.id for m in eng.mutants}
        core_ids = {m.id for m in TOOL.CORE_MUTANTS}
        assert (core_ids <= ids) if includes else not (core_ids & ids), name
    for folder in ("liggghts_plugin", "lammps_plugin"):
        text = "\n".join(p.read_text() for p in (ROOT / folder).rglob("*.h"))
        assert '#include "stick_slip_core.h"' in text, folder
