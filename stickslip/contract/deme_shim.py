# SPDX-License-Identifier: GPL-2.0-or-later
"""DEM-Engine's force model (deme_model/stick_slip.cu) on the CPU: the shim library and a runner
of the law's contract (cases.py) through it.

deme_model/shim/contact_step.cpp includes the model's text in functions that declare the
variables DEM-Engine's force kernel gives it; g++ builds them into one library (cached in
build/deme_shim/<hash of the sources>/, or taken from $STICKSLIP_DEME_SHIM_BUILD: the folder
tools/mutate_cpp.py builds a mutant into). This module feeds it one contact and one step at
a time, with the contact's geometry as the engine computes it (A is the contract's grain i,
B its wall or grain j), and reads back what the model wrote: the force on A, the contact
wildcards (spring D, slip count) and, with the record, the owner wildcards.
"""
from __future__ import annotations

import ctypes
import fcntl
import hashlib
import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np

from . import cases as lc

ROOT = Path(__file__).resolve().parents[2]  # the checkout: the shim builds from its deme_model/
MODEL = ROOT / "deme_model"
SOURCES = ("stick_slip.cu", "shim/deme_shim.h", "shim/deme_shim_layout.h", "shim/undef_options.h",
           "shim/contact_step.cpp")
# -ffp-contract=off: one rounding per operation (no fused multiply-add), as the model reads
FLAGS = ("-std=c++17", "-O2", "-ffp-contract=off", "-fPIC", "-shared")
LIBRARY = "libstickslip_deme_shim.so"
VARIANTS = ("ss_hooke_step_spring", "ss_hooke_step_total", "ss_hooke_exact_spring", "ss_hooke_exact_total",
            "ss_hooke_sweep_record", "ss_hertz_step_spring", "ss_hertz_sweep_record")
F32 = np.float32


def layout():
    """The enum constants of shim/deme_shim_layout.h: {name: value}."""
    text = re.sub(r"//[^\n]*|/\*.*?\*/", "", (MODEL / "shim" / "deme_shim_layout.h").read_text(), flags=re.S)
    names = {}
    for body in re.findall(r"enum\s*\{(.*?)\}", text, re.S):
        nxt = 0
        for item in filter(None, (i.strip() for i in body.split(","))):
            name, _, expr = (p.strip() for p in item.partition("="))
            nxt = eval(expr, {}, dict(names)) if expr else nxt  # (the header's own arithmetic)
            names[name] = nxt
            nxt += 1
    return names


L = layout()


def build_dir():
    """The folder holding the library: $STICKSLIP_DEME_SHIM_BUILD, or one per source hash."""
    given = os.environ.get("STICKSLIP_DEME_SHIM_BUILD")
    if given:
        return Path(given)
    h = hashlib.sha256(" ".join(FLAGS).encode())
    for name in SOURCES:
        h.update((MODEL / name).read_bytes())
    return ROOT / "build" / "deme_shim" / h.hexdigest()[:16]


def library_path():
    """Builds the library if it is not there (under a lock: test workers share it)."""
    out = build_dir()
    lib = out / LIBRARY
    if os.environ.get("STICKSLIP_DEME_SHIM_BUILD"):
        assert lib.is_file(), f"STICKSLIP_DEME_SHIM_BUILD: no {LIBRARY} in {out}"
        return lib
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "build.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not lib.is_file():
            part = out / (LIBRARY + ".part")
            proc = subprocess.run(["g++", *FLAGS, "-o", str(part), str(MODEL / "shim" / "contact_step.cpp")],
                                  capture_output=True, text=True)
            assert proc.returncode == 0, f"the shim does not build:\n{proc.stderr[-4000:]}"
            part.rename(lib)
    return lib


_LIB = None


def functions():
    """{variant name: ctypes function}."""
    global _LIB
    if _LIB is None:
        _LIB = ctypes.CDLL(str(library_path()))
    ptr = ctypes.c_void_p
    out = {}
    for name in VARIANTS:
        f = getattr(_LIB, name)
        f.argtypes, f.restype = [ptr] * 6, None
        out[name] = f
    return out


class Contact:
    """One contact's state between calls: its wildcards, the owners' wildcards, the materials."""

    def __init__(self, variant):
        self.f = functions()[variant]
        self.mat = np.zeros(L["MAT_SIZE"], F32)
        self.own = np.zeros(L["OWN_SIZE"], F32)
        self.wc = np.zeros(4, F32)
        self.force = np.zeros(3, F32)

    def pairwise(self, name, a, b, value):
        """Material property `name` (kn, nu_n, ks, nu_s, mu, mu_k, CoR) for types a and b."""
        k = L["M_" + name.upper()] * L["NM"] * L["NM"]
        self.mat[k + a * L["NM"] + b] = self.mat[k + b * L["NM"] + a] = value

    def material(self, name, a, value):
        """E or nu of material type a."""
        self.mat[L["M_E_OFFSET"] + (0 if name == "E" else L["NM"]) + a] = value

    def owner(self, name, owner, value):
        """An owner wildcard (W_* or R_* names of the layout) of owner 0 (A) or 1 (B)."""
        self.own[L[name] * L["NO"] + owner] = value

    def owned(self, name, owner=0):
        return float(self.own[L[name] * L["NO"] + owner])

    def step(self, overlap, area, kin, a_pos=(0.0, 0.0, 0.0), b_pos=(0.0, 0.0, 0.0)):
        """One step: the engine's overlap and area, kin (kinematics()) and A's centre and B's
        point in double. Left at the origin with kinematics()' radius 0, a wall contact's
        distances disagree (|0 - (0 - overlap)| > 0) and the model keeps the engine's overlap."""
        geo = np.zeros(L["GEO_SIZE"])
        geo[L["G_OVERLAP"]], geo[L["G_AREA"]] = overlap, area
        geo[L["G_APOS"]:L["G_APOS"] + 3], geo[L["G_BPOS"]:L["G_BPOS"] + 3] = a_pos, b_pos
        kin = np.asarray(kin, F32)
        assert kin.shape == (L["KIN_SIZE"],)
        self.f(geo.ctypes.data, kin.ctypes.data, self.mat.ctypes.data, self.own.ctypes.data,
               self.wc.ctypes.data, self.force.ctypes.data)
        return self.force.astype(np.float64)


def apply_ori_q(v, q):
    """The engine's applyOriQToVector3 in float (as on its GPU, without fused multiply-adds):
    v turned by the quaternion q = (x, y, z, w), both taken as float."""
    X, Y, Z = (F32(c) for c in v)
    x, y, z, w = (F32(c) for c in q)
    one, two = F32(1), F32(2)
    return np.array([(two * (w * w + x * x) - one) * X + (two * (x * y - w * z)) * Y + (two * (x * z + w * y)) * Z,
                     (two * (x * y + w * z)) * X + (two * (w * w + y * y) - one) * Y + (two * (y * z - w * x)) * Z,
                     (two * (x * z - w * y)) * X + (two * (y * z + w * x)) * Y + (two * (w * w + z * z) - one) * Z],
                    F32)


def kinematics(b2a, va, vb, wa, wb, cpa, cpb, ts, time, contact_type, mats=(1, 1), masses=(1.0, 1.0),
               qa=(0, 0, 0, 1), qb=(0, 0, 0, 1), radius=0.0):
    """The kin array (shim/deme_shim_layout.h) from its parts (radius: A's)."""
    kin = np.zeros(L["KIN_SIZE"])
    for key, value in (("K_B2A", b2a), ("K_ALINVEL", va), ("K_BLINVEL", vb), ("K_AROTVEL", wa), ("K_BROTVEL", wb),
                       ("K_LOCCPA", cpa), ("K_LOCCPB", cpb), ("K_AORIQ", qa), ("K_BORIQ", qb)):
        kin[L[key]:L[key] + len(value)] = value
    kin[L["K_AMASS"]], kin[L["K_BMASS"]] = masses
    kin[L["K_TS"]], kin[L["K_TIME"]], kin[L["K_CONTACT_TYPE"]] = ts, time, contact_type
    kin[L["K_AMAT"]], kin[L["K_BMAT"]] = mats
    kin[L["K_ARADIUS"]] = radius
    return kin


SPHERE_SPHERE, SPHERE_ANALYTICAL = (1 << 4) | 1, (1 << 4) | 4  # deme::encodeType (shim/deme_shim.h)


def contract_geometry(case, x, v, w):
    """The engine's view of a contract row's contact at one state (A = grain i): overlap, the
    overlap area, B2A, the kinematic array, A's centre and B's point; the floor is an
    analytical plane z = 0 whose owner sits at the origin, grain j a sphere. Positions in
    double, as the engine keeps them."""
    R = lc.R
    if case.geometry == "wall":
        b2a = np.array([0.0, 0.0, 1.0])
        delta = R - x[0, 2]
        cp = x[0] - b2a * (R - delta / 2)
        area = math.pi * (R * R - (R - delta) ** 2)
        kin = kinematics(b2a, v[0], (0, 0, 0), w[0], (0, 0, 0), cp - x[0], cp, lc.DT, 0.0, SPHERE_ANALYTICAL,
                         radius=R)
        b_pos = (0.0, 0.0, 0.0)
    else:
        d = x[0] - x[1]
        b2a = d / np.linalg.norm(d)
        delta = 2 * R - np.linalg.norm(d)
        cp = x[1] + (R - delta / 2) * b2a
        area = math.pi * (R * delta - delta * delta / 4)
        kin = kinematics(b2a, v[0], v[1], w[0], w[1], cp - x[0], cp - x[1], lc.DT, 0.0, SPHERE_SPHERE, radius=R)
        b_pos = x[1]
    return delta, area, b2a, kin, x[0], b_pos


def variant_of(case, sweep):
    if sweep:
        return "ss_hooke_sweep_record"
    return f"ss_hooke_{case.timing}_{case.reset}"


def setup_contact(case, sweep):
    """A Contact holding the case's coefficients: materials (type 1 for both bodies), or, for
    the sweep, the owners' wildcards (both owners alike; kn and ks stay materials)."""
    c = Contact(variant_of(case, sweep))
    for name, value in (("kn", lc.KN), ("ks", lc.KS), ("nu_n", case.nu_n), ("nu_s", case.nu_s), ("mu", case.mu_s),
                        ("mu_k", case.mu_k)):
        c.pairwise(name, 1, 1, value)
    opts = (1 if case.timing == "exact" else 0) + (2 if case.reset == "total" else 0)
    for owner in (0, 1):
        for name, value in (("W_MU_S", case.mu_s), ("W_MU_K", case.mu_k), ("W_NU_N", case.nu_n),
                            ("W_NU_S", case.nu_s), ("W_OPTS", opts)):
            c.owner(name, owner, value)
    return c


def run_case(case, sweep=False):
    """The contract's trace of a case (cases.empty_trace) through the shim: materials
    and the contact wildcards, or the sweep's owner wildcards and the record."""
    c = setup_contact(case, sweep)
    out = lc.empty_trace(case.steps)
    x = lc.rest_positions(case, case.segments[0].delta)
    k = 0
    for seg in case.segments:
        start = x
        for s in range(1, seg.steps + 1):
            x, v, w = lc.state(case, seg, s, start)
            delta, area, b2a, kin, a_pos, b_pos = contract_geometry(case, x, v, w)
            kin[L["K_TIME"]] = k * lc.DT
            force = c.step(delta, area, kin, a_pos, b_pos)
            if delta > 0:
                if sweep:
                    out["fn"][k] = c.owned("R_FN")
                    out["F"][k] = [c.owned(q) for q in ("R_FX", "R_FY", "R_FZ")]
                    out["D"][k] = [c.owned(q) for q in ("R_DX", "R_DY", "R_DZ")]
                    out["slips"][k] = int(c.owned("R_SLIPS"))
                else:
                    b = b2a.astype(F32).astype(np.float64)
                    fn = float(force @ b)
                    out["fn"][k], out["F"][k] = fn, force - fn * b
                    out["D"][k], out["slips"][k] = c.wc[:3], int(c.wc[3])
                out["n"][k] = -b2a
            k += 1
    return out


def float_case(case):
    """The case as a float engine can take it: mu_s one float ulp above 15/32 where the row is
    about one ulp (one double ulp rounds to 15/32 in float, which would slip a step early)."""
    import dataclasses

    if case.name == "one_ulp_below_threshold_sticks":
        return dataclasses.replace(case, mu_s=float(np.nextafter(F32(lc.D24), F32(1.0))))
    return case
