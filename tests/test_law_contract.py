"""The law's contract on every engine (tests/law_contract.py): one-contact cases with
exact numbers, each engine's record compared to hand-worked values to the ulp."""
import numpy as np
import pytest

import contract_runners as runners
import law_contract as lc
from conftest import skip_engine
from stickslip.adapters import ENGINES


@pytest.mark.parametrize("engine", sorted(runners.RUNNERS))
@pytest.mark.parametrize("case", lc.CASES, ids=lambda c: c.name)
def test_contract(case, engine):
    skip_engine(engine)
    lc.compare(case, runners.RUNNERS[engine](case))


def test_every_engine_has_the_contract():
    """An engine added to stickslip.adapters.ENGINES must bring its contract runner (or
    say whose kernel it runs)."""
    missing = set(ENGINES) - set(runners.RUNNERS) - set(runners.SHARED_KERNEL)
    assert not missing, f"engines without a contract runner in tests/contract_runners.py: {sorted(missing)}"
    undecided = set(runners.RUNNERS) - set(runners.TYPE_PAIR_RUNNERS) - set(runners.NO_TYPE_PAIRS)
    assert not undecided, f"engines with neither a per-type-pair runner nor a reason: {sorted(undecided)}"


@pytest.mark.parametrize("timing", ["step", "exact"])
@pytest.mark.parametrize("engine", sorted(runners.TYPE_PAIR_RUNNERS))
def test_coefficients_per_type_pair(engine, timing):
    """mu_s and mu_k read for the contact's own pair of types: every pair different. In
    both timings (each reads them on its own path): without a dashpot and with every slip
    at a step's very end, the exact timing's slips restart at Fmin with nothing of the step
    left (E3, E7), which is the step timing's result."""
    skip_engine(engine)
    traces = runners.TYPE_PAIR_RUNNERS[engine](timing)
    # (1, 1) is the wall's own type on LIGGGHTS (no contact); LAMMPS' grains use all three
    assert set(lc.TYPE_PAIRS) - {(1, 1)} <= set(traces) <= set(lc.TYPE_PAIRS)
    for pair, trace in traces.items():
        w = lc.X * (np.array([1.0, 0, 0]) if 1 in pair else np.array([0, 1.0, 0]))
        lc.compare_type_pair(pair, trace, w)
