# SPDX-License-Identifier: GPL-2.0-or-later
"""The stick-slip law on DEM-Engine (PyPI `deme`): attach deme_model/stick_slip.cu to a solver.

    import sys; sys.path.insert(0, "/path/to/deme_model")
    import stickslip_deme
    model = stickslip_deme.attach(solver, normal="hertz")   # before solver.Initialize()

attach() writes the model's options in front of its text, hands it to
solver.DefineContactForceModel and declares on the returned model what the text reads:
the material properties (material_properties) and the wildcards (CONTACT_WILDCARDS,
owner_wildcards). With sweep=True mu_s and mu_k (and, with the linear normal force, nu_n and
nu_s) and the slip timing and reset are owner wildcards, set after Initialize() with
set_family_coefficients: new values without a new JIT compile. deme_model/README.md has the
details. This module needs no GPU and does not import deme: the tests read its text and
declarations on any machine.
"""
from __future__ import annotations

import sys
from pathlib import Path

__version__ = "1.0.0"  # the project's version, pyproject.toml's (tests/test_release.py checks they agree)

HERE = Path(__file__).resolve().parent
# beside this file in the repository (deme_model/); a wheel installs this module among the
# installed packages and the model as the stickslip package's data
MODEL_FILE = HERE / "stick_slip.cu"
if not MODEL_FILE.is_file():
    MODEL_FILE = HERE / "stickslip" / "data" / "deme_model" / "stick_slip.cu"

NORMALS = ("hertz", "hooke")
# the spring D (3) and the steps that slipped since the contact began
CONTACT_WILDCARDS = ("ss_dx", "ss_dy", "ss_dz", "ss_slips")
# record=True: what each body's last contact did (Fn, F_s on it, its spring, slip count,
# the time of the step's start at which the engine evaluated it)
RECORD_WILDCARDS = ("ss_rec_fn", "ss_rec_fx", "ss_rec_fy", "ss_rec_fz", "ss_rec_dx", "ss_rec_dy", "ss_rec_dz",
                    "ss_rec_slips", "ss_rec_t")
OPTIONS = ("STICKSLIP_HOOKE", "STICKSLIP_SWEEP", "STICKSLIP_EXACT", "STICKSLIP_RESET_TOTAL", "STICKSLIP_RECORD")
# ss_opts, per owner in the sweep: 1 slip_timing exact, 2 reset total
OPT_EXACT, OPT_TOTAL = 1, 2


def _check(**given):
    """docs/law.md's parameter rules, through pyref's one checker (this folder sits in the
    repository: its root is put on sys.path if pyref is not importable)."""
    try:
        from pyref.laws import check_parameters
    except ImportError:
        sys.path.insert(0, str(HERE.parent))
        from pyref.laws import check_parameters
    return check_parameters("stick_slip", **given)


def _options(normal, slip_timing, reset, sweep, record):
    if normal not in NORMALS:
        raise ValueError(f"normal = {normal!r}: must be one of {', '.join(NORMALS)}")
    _check(slip_timing=slip_timing, reset=reset)
    for name, value in (("sweep", sweep), ("record", record)):
        if not isinstance(value, bool):
            raise ValueError(f"{name} = {value!r}: must be True or False")
    return {"STICKSLIP_HOOKE": normal == "hooke", "STICKSLIP_SWEEP": sweep,
            "STICKSLIP_EXACT": slip_timing == "exact", "STICKSLIP_RESET_TOTAL": reset == "total",
            "STICKSLIP_RECORD": record}


def model_text(normal="hertz", slip_timing="step", reset="spring", sweep=False, record=False, source=None):
    """The force model's text with its options defined in front (and forgotten after). It
    starts with a newline: the engine puts the text right after a brace, and a preprocessor
    line must begin a line. (With sweep, slip_timing and reset are per owner instead.)"""
    opts = _options(normal, slip_timing, reset, sweep, record)
    if sweep:
        opts["STICKSLIP_EXACT"] = opts["STICKSLIP_RESET_TOTAL"] = False
    body = Path(source or MODEL_FILE).read_text()
    head = "".join(f"#define {k} {int(v)}\n" for k, v in opts.items())
    tail = "".join(f"#undef {k}\n" for k in OPTIONS)
    return "\n" + head + body + "\n" + tail


def material_properties(normal="hertz", sweep=False):
    """(must have, pairwise) material property names the model reads. mu is the static
    coefficient mu_s (the engine's own name), mu_k the kinetic one; with the linear normal
    force kn, ks (N/m) and nu_n, nu_s (N s/m); with Hertz-Mindlin the engine's E, nu, CoR.
    In the sweep mu, mu_k (and nu_n, nu_s) are owner wildcards instead."""
    if normal not in NORMALS:
        raise ValueError(f"normal = {normal!r}: must be one of {', '.join(NORMALS)}")
    if normal == "hooke":
        pairwise = {"kn", "ks"} | (set() if sweep else {"nu_n", "nu_s", "mu", "mu_k"})
        return set(pairwise), pairwise
    pairwise = {"CoR"} | (set() if sweep else {"mu", "mu_k"})
    return {"E", "nu"} | pairwise, pairwise


def owner_wildcards(normal="hertz", sweep=False, record=False):
    """The owner wildcard names the model reads (sweep) and writes (record)."""
    names = ()
    if sweep:
        names += ("ss_mu_s", "ss_mu_k") + (("ss_nu_n", "ss_nu_s") if normal == "hooke" else ()) + ("ss_opts",)
    return names + (RECORD_WILDCARDS if record else ())


def attach(solver, normal="hertz", slip_timing="step", reset="spring", sweep=False, record=False):
    """Make the stick-slip law the solver's contact force model (before Initialize()).
    normal: "hertz" (the engine's Hertz-Mindlin normal force and Mindlin's tangential
    stiffness and damping, from E, nu, CoR) or "hooke" (Fn = kn delta + nu_n v_n, Ks = ks,
    nu_s: the paper's linear law); slip_timing "step" | "exact" and reset "spring" | "total"
    (docs/law.md; per owner with sweep); record: keep each body's last contact in owner
    wildcards (read_record). Returns the engine's model object."""
    model = solver.DefineContactForceModel(model_text(normal, slip_timing, reset, sweep, record))
    must, pairwise = material_properties(normal, sweep)
    model.SetMustHaveMatProp(must)
    model.SetMustPairwiseMatProp(pairwise)
    model.SetPerContactWildcards(set(CONTACT_WILDCARDS))
    owners = owner_wildcards(normal, sweep, record)
    if owners:
        model.SetPerOwnerWildcards(set(owners))
    return model


def sweep_values(mu_s, mu_k, nu_n=None, nu_s=None, slip_timing="step", reset="spring"):
    """{owner wildcard: value} for the sweep, checked (ValueError naming the parameter and
    its range, docs/law.md). nu_n, nu_s: with the linear normal force only."""
    given = {"mu_s": mu_s, "mu_k": mu_k, "slip_timing": slip_timing, "reset": reset}
    given.update({k: v for k, v in (("nu_n", nu_n), ("nu_s", nu_s)) if v is not None})
    p = _check(**given)
    out = {"ss_mu_s": p["mu_s"], "ss_mu_k": p["mu_k"],
           "ss_opts": (OPT_EXACT if slip_timing == "exact" else 0) + (OPT_TOTAL if reset == "total" else 0)}
    out.update({f"ss_{k}": p[k] for k in ("nu_n", "nu_s") if k in p})
    return out


def set_family_coefficients(solver, family, **coefficients):
    """The sweep's values (sweep_values' arguments) for every body of a family, after
    Initialize(). A grain pair takes the mean of its two bodies' values, a wall contact its
    grain's."""
    for name, value in sweep_values(**coefficients).items():
        solver.SetFamilyOwnerWildcardValue(family, name, float(value))


def read_record(solver, family):
    """The record (record=True) of the first body of a family: {name without ss_rec_: value}."""
    return {name[len("ss_rec_"):]: float(solver.GetFamilyOwnerWildcardValue(family, name)[0])
            for name in RECORD_WILDCARDS}
