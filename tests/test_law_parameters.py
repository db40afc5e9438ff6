# SPDX-License-Identifier: GPL-2.0-or-later
"""pyref's parameter rules (pyref.laws.check_parameters, docs/law.md): the one checker of the
Python engines (scenes, the YADE law). Each refusal is one message that names the parameter
and what is allowed; each acceptance returns the values as floats. Cost: < 0.1 s."""
import math

import numpy as np
import pytest

from pyref.laws import check_parameters

GOOD = dict(kn=1e5, nu_n=0.1, ks=8e4, nu_s=0.05, mu_s=0.5, mu_k=0.4, reset="spring", slip_timing="step")


@pytest.mark.parametrize("change,message", [
    ({"law": "friction"}, "law = 'friction': must be one of stick_slip, visco_elastic, visco_plastic, coulomb"),
    ({"reset": "both"}, "reset = 'both': must be one of spring, total"),
    ({"slip_timing": "fine"}, "slip_timing = 'fine': must be one of step, exact"),
    ({"kn": 0.0}, "kn = 0: must be > 0"),
    ({"ks": 0.0}, "ks = 0: must be > 0"),
    ({"mu_s": 0.0, "mu_k": 0.0}, "mu_s = 0: must be > 0"),
    ({"nu_n": -1.0}, "nu_n = -1: must be >= 0"),
    ({"nu_s": -0.5}, "nu_s = -0.5: must be >= 0"),
    ({"nu_s": math.inf}, "nu_s = inf: must be a finite number"),
    ({"nu_s": True}, "nu_s = True: must be a finite number"),
    ({"ks": np.bool_(True)}, f"ks = {np.bool_(True)!r}: must be a finite number"),  # (numpy 2: np.True_)
    ({"kn": "100"}, "kn = '100': must be a finite number"),
    ({"mu_k": 0.6}, "mu_k = 0.6: must be in [mu_s/2, mu_s] = [0.25, 0.5] so that 0 <= Fmin = (2 mu_k - mu_s) "
                    "Fn <= mu_k Fn"),
    ({"mu_k": 0.2}, "mu_k = 0.2: must be in [mu_s/2, mu_s] = [0.25, 0.5]"),
])
def test_each_refusal_names_the_parameter_and_what_is_allowed(change, message):
    kw = dict(GOOD, **change)
    with pytest.raises(ValueError) as e:
        check_parameters(**kw)
    assert str(e.value).startswith(message), str(e.value)


def test_mu_k_without_mu_s_is_refused_with_the_range():
    with pytest.raises(ValueError, match=r"^mu_k needs mu_s: the allowed range is \[mu_s/2, mu_s\]$"):
        check_parameters(mu_k=0.4)


def test_an_unknown_parameter_is_named():
    with pytest.raises(TypeError, match=r"^check_parameters: unknown parameter 'a_first'$"):
        check_parameters(zz_last=1.0, a_first=2.0, kn=1.0)


def test_accepted_values_come_back_as_floats_and_only_those_given():
    out = check_parameters(kn=100, mu_s=1, mu_k=np.float32(0.75), reset="total")
    assert out == {"kn": 100.0, "mu_s": 1.0, "mu_k": 0.75, "reset": "total"}
    assert all(type(v) is float for k, v in out.items() if k != "reset")
    assert check_parameters(**GOOD) == {k: (float(v) if not isinstance(v, str) else v) for k, v in GOOD.items()}
    assert check_parameters(slip_timing="exact") == {"slip_timing": "exact"}


def test_rules_that_depend_on_the_law():
    """ks must be > 0 only for the laws with a spring; the mu_k range is stick-slip's (the
    classic laws use mu_k alone: Table 1); a value that is not given is not checked, and
    one given later in the list is still checked after it."""
    assert check_parameters("coulomb", ks=0.0, mu_s=0.5, mu_k=0.9)["ks"] == 0.0
    assert check_parameters("visco_plastic", ks=0.0, mu_s=0.5, mu_k=0.1)["mu_k"] == 0.1
    with pytest.raises(ValueError, match="^ks = 0: must be > 0$"):
        check_parameters("visco_elastic", ks=0.0)
    with pytest.raises(ValueError, match="^mu_k = -1: must be >= 0$"):
        check_parameters("coulomb", kn=1.0, mu_k=-1.0)  # (kn given, ks not: mu_k still checked)
