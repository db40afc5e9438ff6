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
        source = (ROOT / eng.source / (m.file or eng.law_file)).read_text()
        found = len(TOOL.pattern(m.find).findall(source))
        if found != m.count:
            unfound.append(f"{m.id}: found {found} times, expected {m.count}")
    assert not unfound, unfound


@pytest.mark.parametrize("engine", sorted(TOOL.ENGINES))
def test_mutant_ids_are_unique(engine):
    ids = [m.id for m in TOOL.ENGINES[engine].mutants]
    assert len(ids) == len(set(ids))
