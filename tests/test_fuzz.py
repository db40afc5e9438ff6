# SPDX-License-Identifier: GPL-2.0-or-later
"""Fuzz: malformed scenes and bad command lines (issue 15 section 6).

A seeded generator mutates the shipped scenes (and a small 3D scene with a lattice, a
spinning grain and a turning wall, so every key of docs/scene-format.md is reached) and
builds bad command lines for every subcommand. Every case is run through
`stickslip.cli.main` in this process and must give: a non-zero exit status (2), exactly
one line on stderr starting `stickslip: error:` that names the key or argument, no
traceback, and nothing written anywhere (the run's folder included: a refused call
writes nothing).

Nothing can run long: the engines and the studies are replaced by stand-ins that raise
`ReachedEngine`, so a malformed input that slips through is reported as a silent run
instead of being run. The unmutated scenes must reach the stand-in (the check that the
harness itself does not refuse everything).

A second lane runs valid but unusual scenes (odd outputs, every law, extreme numbers)
for real on pyref for 20 steps: each runs (exit 0, only `stickslip:` lines on stderr) or
is refused in one line (exit 1 or 2); a handful of calls go through a real process for
the exit status.

Default set (~10 s on 2 cores): every structural mutation of every base, a seeded sample
of the value mutations (~650 scene cases), ~160 command lines, ~70 real pyref runs, 6
processes. `--runslow` adds every value mutation and ~3000 random double mutations
(~5800 scene cases) and ~670 real runs (~1.5 min). STICKSLIP_FUZZ_SEED changes the seed
(the failure messages quote it).
"""
from __future__ import annotations

import copy
import io
import json
import math
import os
import random
import subprocess
import sys
import tomllib
from contextlib import redirect_stderr, redirect_stdout

import pytest

from stickslip import adapters, cli, report
from stickslip.bench import table as bench_table
from stickslip.studies import thresholds
from stickslip import scene as scene_mod
from stickslip.scene import reader

SEED = int(os.environ.get("STICKSLIP_FUZZ_SEED", "15"))
ROOT = scene_mod.CASES_DIR.parent

# A 3D scene that uses the keys the paper's cases do not: lattice, spin, axis of rotation.
BOX = {
    "name": "box", "description": "fuzz base", "dimension": 3, "gravity": [0.0, 0.0, -9.81],
    "effects": {"gravity": True, "rotation": True, "normal_damping": True, "tangential_damping": True,
                "moving_walls": True},
    "contact": {"law": "stick_slip", "kn": 10.0, "nu_n": 1e-5, "ks": 8.0, "nu_s": 1e-5, "mu_s": 0.5,
                "mu_k": 0.45, "reset": "spring", "slip_timing": "exact"},
    "time": {"dt": 1e-5, "duration": 1e-3},
    "output": {"every": 10, "grains": ["ball", "p1"], "contacts": [["p1", "floor"], ["ball", "lid"]],
               "walls": ["lid"], "stats": True, "energy": False},
    "analysis": {"kind": "none"},
    "grain": [{"name": "ball", "radius": 0.001, "density": 2600.0, "position": [0.0, 0.0, 0.02],
               "velocity": [0.0, 0.0, 0.0], "imposed": ["x"], "angular_velocity": [0.0, 0.0, 1.0]}],
    "lattice": [{"origin": [0.0, 0.0, 0.0011], "counts": [2, 2, 2], "radius": 0.001, "radius_spread": 0.1,
                 "spacing": 0.0025, "density": 2600.0, "velocity": [0.0, 0.0, 0.0], "velocity_jitter": 0.01,
                 "seed": 1, "prefix": "p"}],
    "wall": [{"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
             {"name": "lid", "point": [0.0, 0.0, 0.05], "normal": [0.0, 0.0, -1.0], "velocity": [0.0, 0.0, 0.0],
              "rotation": {"pivot": [0.0, 0.0, 0.05], "axis": [1.0, 0.0, 0.0], "rate": 1.0,
                           "stop_angle": 0.1}}],
}
BASES = {**{n: tomllib.loads(scene_mod.find(n).read_text()) for n in ("drag", "tray", "tilt")}, "box": BOX}

# What each key holds (its path with list indices as []): the kind decides the bad values.
SCHEMA = {
    "name": "name", "description": "text", "dimension": "dimension", "gravity": "vector",
    **{f"effects.{e}": "bool" for e in scene_mod.EFFECTS},
    "contact.law": "choice", "contact.reset": "choice", "contact.slip_timing": "choice",
    "contact.kn": "positive", "contact.ks": "positive", "contact.mu_s": "positive", "contact.mu_k": "positive",
    "contact.nu_n": "non-negative", "contact.nu_s": "non-negative",
    "time.dt": "positive", "time.duration": "positive",
    "output.every": "count", "output.grains": "grain list", "output.walls": "wall list",
    "output.contacts": "contact list", "output.stats": "bool", "output.energy": "bool",
    "analysis.kind": "choice", "analysis.grain": "grain name", "analysis.contact": "contact",
    "analysis.wall": "wall name", "analysis.floor": "wall name",
    "grain[].name": "text", "grain[].radius": "positive", "grain[].density": "positive",
    "grain[].position": "vector", "grain[].velocity": "vector", "grain[].imposed": "axes",
    "grain[].angular_velocity": "spin",
    "wall[].name": "text", "wall[].point": "vector", "wall[].normal": "vector", "wall[].velocity": "vector",
    "wall[].rotation.pivot": "vector", "wall[].rotation.axis": "vector3", "wall[].rotation.rate": "positive",
    "wall[].rotation.stop_angle": "angle",
    "lattice[].origin": "vector", "lattice[].counts": "counts", "lattice[].radius": "positive",
    "lattice[].radius_spread": "spread", "lattice[].spacing": "positive", "lattice[].density": "positive",
    "lattice[].velocity": "vector", "lattice[].velocity_jitter": "non-negative", "lattice[].seed": "seed",
    "lattice[].prefix": "text",
}
TABLES = ("effects", "contact", "time", "output", "analysis", "wall[].rotation")
ARRAYS = ("grain", "wall", "lattice")
REQUIRED = ("name", "dimension", "contact", "contact.kn", "contact.mu_s", "contact.mu_k", "contact.ks", "time",
            "time.dt", "time.duration", "grain[].radius", "grain[].density", "grain[].position", "wall[].point",
            "wall[].normal", "wall[].rotation.pivot", "wall[].rotation.rate", "wall[].rotation.stop_angle",
            "lattice[].counts", "lattice[].origin", "lattice[].radius", "lattice[].density", "analysis.grain",
            "analysis.contact", "analysis.wall", "analysis.floor")
NAN, INF = float("nan"), float("inf")
# Values of the wrong type for any key of a kind (a list or table for a number, and so on).
NOT_A_NUMBER = ["1.0", True, [1.0], {"x": 1.0}, NAN, INF, -INF, 1e300, -1.5e100, 10**400]
# Extreme values that may be valid (or refused for what they imply: a mass that
# underflows, a stability limit below dt): the run must be refused in one line or reach
# the engine, never raise.
EXTREME = [1e-300, 5e-324, 1e-100, 1e100, -1e100, 0.0, 1e-9, 1e9]


def bad_values(kind, dim, base):
    """Values a key of this kind must refuse, in a scene of this dimension."""
    vec = [0.0] * dim
    names = [g["name"] for g in base.get("grain", [])]
    return {
        "positive": NOT_A_NUMBER + [0, 0.0, -1.0, -1e300],
        "non-negative": NOT_A_NUMBER + [-1e-9, -1e300],
        "dimension": [2.0, 3.0, "2", True, [2], {"d": 2}, 1, 4, 0, -2, NAN],
        "count": [1.5, 2.0, "1", True, [1], {"n": 1}, 0, -1, NAN, INF, 10**30],
        "seed": [1.5, "1", True, [1], -1, NAN],
        "bool": [1, 0, 1.0, "true", "yes", [True], {"on": True}, NAN],
        "choice": [5, 1.5, True, ["stick_slip"], {"x": 1}, "bogus", "", "STICK_SLIP"],
        "name": [5, True, [1], {"x": 1}, "../../x", "", "a/b", ".hidden", "..", "a b", "x" * 101, "x\n",
                 "/abs"],
        "text": [5, 1.5, True, [1], {"x": 1}],
        "vector": [1.0, "0,0", [], vec[:-1], vec + [0.0], ["a"] + vec[1:], [NAN] + vec[1:], [INF] + vec[1:],
                   [True] + vec[1:], [[0.0]] + vec[1:], {"x": 0.0}],
        "vector3": [1.0, [0.0, 0.0], [NAN, 0.0, 1.0], [0.0, 0.0, 0.0], ["z", 0.0, 1.0], {"x": 1.0}],
        "spin": ([[0.0, 0.0, 1.0], "1", {"z": 1.0}, NAN, INF, True] if dim == 2 else
                 [1.0, [0.0, 1.0], [NAN, 0.0, 0.0], ["a", 0.0, 0.0], {"z": 1.0}]),
        "angle": NOT_A_NUMBER + [0.0, -0.1, 1.6, 3.2],
        "spread": NOT_A_NUMBER + [-0.1, 0.51, 2.0],
        "counts": [5, "2", [2.0] * dim, [0] * dim, [-1] * dim, [2] * (dim - 1), [2] * (dim + 1), [True] * dim,
                   [10**6] * dim, [10**30] * dim, {"n": 2}],
        "axes": ["x", ["q"], [1], {"x": 1}, ["w"], [["x"]]],
        "grain list": [5, "grain", {"g": 1}, ["nosuch"], [5], [[names[0]]] if names else [[]], [True]],
        "wall list": [5, "plate", {"w": 1}, ["nosuch"], [5], [["plate"]]],
        "contact list": [5, "grain", {"c": 1}, [5], ["a", "b"], [["nosuch", "floor"]], [[names[0]]],
                         [[names[0], "nosuch"]], [[names[0], names[0]]], [[names[0], "floor", "x"]]],
        "grain name": [5, True, ["grain"], {"g": 1}, "nosuch", "Grain", ""],
        "wall name": [5, ["floor"], {"w": 1}, "nosuch", "Floor"],
        "contact": [5, "grain", [5, 6], ["nosuch", "floor"], [[names[0], "floor"]], {"c": 1}],
    }[kind]


# ---------------------------------------------------------------- scene paths and TOML

def leaves(d, path=()):
    """(path, value) of every key of a scene, tables and arrays of tables walked into."""
    for k, v in d.items():
        p = path + (k,)
        yield p, v
        if isinstance(v, dict):
            yield from leaves(v, p)
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for i, x in enumerate(v):
                yield from leaves(x, p + (i,))


def generic(path):
    """The schema key of a path: list indices become []."""
    out = ""
    for p in path:
        out += "[]" if isinstance(p, int) else (f".{p}" if out else p)
    return out


def named(path):
    """How the reader names a key: grain[0].radius, wall[1].rotation.rate."""
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else p)
    return out


def at(d, path):
    for p in path:
        d = d[p]
    return d


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v == INF else "-inf" if v == -INF else repr(v))
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(map(toml_value, v)) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"


def dump(d):
    """A scene dict as TOML text (scalars first, then tables, then arrays of tables)."""
    def body(t):
        return [f"{json.dumps(k)} = {toml_value(v)}" for k, v in t.items()]
    head, tail = [], []
    for k, v in d.items():
        if isinstance(v, dict):
            tail += [f"[{json.dumps(k)}]", *body(v)]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for x in v:
                tail += [f"[[{json.dumps(k)}]]", *body(x)]
        else:
            head.append(f"{json.dumps(k)} = {toml_value(v)}")
    text = "\n".join(head + tail) + "\n"
    # the writer must say what the case means: the text reads back as the same data
    assert json.dumps(tomllib.loads(text), sort_keys=True) == json.dumps(d, sort_keys=True), text
    return text


# ---------------------------------------------------------------- scene mutations

class Case:
    """One malformed input: what it is, and the words one of which the error must contain."""

    def __init__(self, what, expect, data=None, raw=None, command="run", may_pass=False):
        self.what, self.expect, self.data, self.raw, self.command = what, expect, data, raw, command
        self.may_pass = may_pass  # a valid input is allowed: then it must reach the engine

    def __repr__(self):
        return f"<{self.what}>"


def set_value(base_name, path, value, expect=None):
    d = copy.deepcopy(BASES[base_name])
    parent = at(d, path[:-1])
    parent[path[-1]] = value
    return Case(f"{base_name}: {named(path)} = {toml_value(value)[:40]}", expect or [named(path)], d)


def value_cases(base_name):
    """Every key of the base set to each bad value of its kind."""
    base = BASES[base_name]
    for path, _ in leaves(base):
        kind = SCHEMA.get(generic(path))
        if kind is None:
            continue
        for v in bad_values(kind, base["dimension"], base):
            expect = [named(path)]
            if path[0] == "time" and kind == "positive":
                expect.append("time.duration / time.dt")  # a tiny dt is refused by its step count
            if path == ("analysis", "kind"):
                expect = ["analysis"]  # another kind's names are then missing or unknown
            yield set_value(base_name, path, v, expect)


def extreme_cases(base_name):
    """Every number of the base (vector components included) set to extreme values."""
    base = BASES[base_name]
    for path, v in leaves(base):
        if generic(path) not in SCHEMA:
            continue
        for x in EXTREME:
            if isinstance(v, float):
                c = set_value(base_name, path, x, [""])
            elif isinstance(v, list) and v and all(isinstance(e, float) for e in v):
                c = set_value(base_name, path, [x] + v[1:], [""])
            else:
                continue
            c.may_pass = True
            yield c


def structure_cases(base_name):
    """Tables replaced by lists and scalars, arrays by tables, required keys removed,
    unknown keys added at every level, names misspelt, starting states the engines
    cannot agree on, absurd sizes."""
    base = BASES[base_name]
    dim = base["dimension"]
    paths = dict(leaves(base))
    for path, v in paths.items():
        g = generic(path)
        if g in TABLES:
            for bad in ([1, 2], 5, "table", [], True):
                yield set_value(base_name, path, bad)
        if g in ARRAYS:
            for bad in (v[0], 5, "x", [5], [[]]):
                yield set_value(base_name, path, bad, [g])
        if g in REQUIRED and not (g == "contact.ks" and base["contact"].get("law", "stick_slip")
                                   not in ("stick_slip", "visco_elastic")):
            d = copy.deepcopy(base)
            del at(d, path[:-1])[path[-1]]
            yield Case(f"{base_name}: no {named(path)}", [named(path)], d)
        if isinstance(v, dict) and (g in TABLES or g.endswith("[]") or not path):
            for extra, value in (("colour", 1), ("Name", "x"), ("dt ", 1.0), ("", 0)):
                d = copy.deepcopy(base)
                at(d, path)[extra] = value
                yield Case(f"{base_name}: unknown key {named(path + (extra,))!r}", [named(path + (extra,))], d)
    for extra in ("colour", "Dimension", "grains"):
        d = copy.deepcopy(base)
        d[extra] = 1
        yield Case(f"{base_name}: unknown top-level key {extra}", [extra], d)
    # [analysis]: a key another kind needs is unknown to this one
    kind = base["analysis"]["kind"]
    for key in ("grain", "contact", "wall", "floor"):
        if key not in base["analysis"]:
            d = copy.deepcopy(base)
            d["analysis"][key] = "floor"
            yield Case(f"{base_name}: [analysis] {key} for kind {kind}", [f"analysis.{key}"], d)
    # gravity switched on without a gravity vector
    d = copy.deepcopy(base)
    d.pop("gravity")
    d["effects"]["gravity"] = True
    yield Case(f"{base_name}: gravity on, no vector", ["gravity"], d)
    # a wall that moves with moving_walls off
    d = copy.deepcopy(base)
    d["effects"]["moving_walls"] = False
    d["wall"][0]["velocity"] = [1.0] + [0.0] * (dim - 1)
    yield Case(f"{base_name}: moving wall, moving_walls off", ["moving_walls"], d)
    # a spinning grain with rotation off
    d = copy.deepcopy(base)
    d["effects"]["rotation"] = False
    d["grain"][0]["angular_velocity"] = 1.0 if dim == 2 else [0.0, 0.0, 1.0]
    yield Case(f"{base_name}: spin, rotation off", ["angular_velocity"], d)
    yield from start_cases(base_name)
    yield from size_cases(base_name)


def start_cases(base_name):
    """Grains behind or deep inside a wall, deep inside each other, at the same centre."""
    base = BASES[base_name]
    g0 = base["grain"][0]
    r = g0["radius"]
    for w in base["wall"]:
        n = [x / math.sqrt(sum(c * c for c in w["normal"])) for x in w["normal"]]
        foot = w["point"]
        for depth, words in ((0.5 * r, "deep inside"), (0.0, "behind"), (-0.5 * r, "behind"),
                             (-10 * r, "behind")):
            d = copy.deepcopy(base)
            d["grain"][0]["position"] = [p + depth * c for p, c in zip(foot, n)]
            d["grain"] = d["grain"][:1]
            d.pop("lattice", None)
            for k in ("output", "analysis"):  # keep only what names the one grain and this wall
                d[k] = {"kind": "none"} if k == "analysis" else {}
            yield Case(f"{base_name}: grain centre {depth / r:+g} r from wall {w['name']}",
                       [repr(g0["name"]), words], d)
    for gap, what in ((0.0, "same centre"), (1.0 * r, "overlap by 1 r"), (1.7 * r, "overlap by 0.3 r")):
        d = copy.deepcopy(base)
        twin = copy.deepcopy(g0)
        twin["name"] = "twin"
        twin["position"] = [g0["position"][0] + gap] + g0["position"][1:]
        twin.pop("imposed", None)
        d["grain"].append(twin)
        yield Case(f"{base_name}: two grains, {what}", ["'twin'"], d)


def size_cases(base_name):
    """Absurd sizes: steps, grains, output."""
    base = BASES[base_name]
    dim = base["dimension"]
    dt = base["time"]["dt"]
    for duration in (1e9, 1e300, dt * 1e11):
        d = copy.deepcopy(base)
        d["time"]["duration"] = duration
        yield Case(f"{base_name}: duration {duration:g}", ["time.duration"], d)
    for tiny in (1e-300, 5e-324, dt * 1e-11):
        d = copy.deepcopy(base)
        d["time"]["dt"] = tiny
        yield Case(f"{base_name}: dt {tiny:g}", ["time.dt"], d)
    d = copy.deepcopy(base)
    d["time"]["duration"] = dt * 1e-3
    yield Case(f"{base_name}: duration below one step", ["time.duration"], d)
    just_over = math.ceil(reader.MAX_GRAINS ** (1 / dim)) + 1
    for n in (just_over, 10**4, 10**7):
        d = copy.deepcopy(base)
        lat = {"origin": [0.0] * (dim - 1) + [1.0], "counts": [n] * dim, "radius": 1e-4, "density": 2600.0}
        d.setdefault("lattice", []).append(lat)
        i = len(d["lattice"]) - 1
        yield Case(f"{base_name}: lattice of {n}^{dim} grains", [f"lattice[{i}].counts", "grains"], d)
    # a lattice within the grain limit, but run for too many grain-steps: refused before
    # the grains are made (this would take seconds and a gigabyte to make)
    d = copy.deepcopy(base)
    n = int(reader.MAX_GRAINS ** (1 / dim) / 2)
    d.setdefault("lattice", []).append({"origin": [0.0] * (dim - 1) + [1.0], "counts": [n] * dim,
                                        "radius": 1e-4, "density": 2600.0})
    d["time"]["duration"] = dt * reader.MAX_GRAIN_STEPS / n**dim * 2
    yield Case(f"{base_name}: {n}^{dim} grains for {reader.MAX_GRAIN_STEPS * 2 / n**dim:.3g} steps",
               ["grain-steps"], d)


def file_cases():
    """Files that are not scenes at all."""
    yield Case("binary bytes", ["case.toml", "UTF-8"], raw=bytes(range(256)))
    yield Case("latin-1 text", ["case.toml", "UTF-8"], raw='name = "caf\xe9"\n'.encode("latin-1"))
    yield Case("not TOML", ["case.toml", "TOML"], raw=b"this is not a scene\n")
    yield Case("JSON", ["case.toml", "TOML"], raw=json.dumps(BASES["drag"]).encode())
    yield Case("empty file", ["name", "missing"], raw=b"")
    yield Case("NUL bytes", ["case.toml"], raw=b"name = \"x\"\x00\n")
    yield Case("duplicate key", ["case.toml", "TOML"], raw=b'name = "a"\nname = "b"\n')
    yield Case("truncated", ["case.toml", "TOML"], raw=scene_mod.find("drag").read_bytes()[:300])
    yield Case("UTF-16", ["case.toml"], raw=scene_mod.find("drag").read_text().encode("utf-16"))
    for depth in (10**5, 3000, 300, 100):  # nested past the parser's recursion, and within it
        yield Case(f"arrays nested {depth} deep", ["case.toml", "name"],
                   raw=b"name = " + b"[" * depth + b"]" * depth + b"\n")
        yield Case(f"tables nested {depth} deep", ["case.toml", "dimension"],
                   raw=b'name = "x"\ndimension = ' + b"{a = " * depth + b"1" + b"}" * depth + b"\n")


def misspelt_cases():
    """Grain and wall names misspelt where they are referred to: [output], [analysis]."""
    for base_name, base in BASES.items():
        for path, v in leaves(base):
            g = generic(path)
            if g.startswith(("output.grains", "output.walls", "output.contacts", "analysis.")) and g != "analysis.kind":
                for wrong in (lambda s: s + "x", lambda s: s.upper(), lambda s: s[:-1], lambda s: " " + s):
                    new = (wrong(v) if isinstance(v, str) else
                           [wrong(x) if isinstance(x, str) else [wrong(y) for y in x] for x in v])
                    yield set_value(base_name, path, new, [g.split("[")[0]])


def scene_cases(rng, sample=None):
    """The scene cases: all structural ones, and all or `sample` of the value ones."""
    cases = [c for b in BASES for c in structure_cases(b)] + list(misspelt_cases()) + list(file_cases())
    values = [c for b in BASES for c in value_cases(b)] + [c for b in BASES for c in extreme_cases(b)]
    if sample is not None:
        values = rng.sample(values, min(sample, len(values)))
    for c in cases + values:
        c.command = rng.choice(["run", "run", "run", "precision"])
    return cases + values


def double_cases(rng, n):
    """Random pairs of value mutations on one base: the error must name one of the two."""
    out = []
    by_base = {b: list(value_cases(b)) for b in BASES}
    for _ in range(n):
        b = rng.choice(list(BASES))
        c1, c2 = rng.sample(by_base[b], 2)
        d = copy.deepcopy(c1.data)
        for path, v in leaves(c2.data):
            if named(path) == c2.expect[0]:
                at(d, path[:-1])[path[-1]] = v
        try:
            dump(d)
        except AssertionError:
            continue  # the second mutation replaced the first one's table
        out.append(Case(f"{c1.what} + {c2.what}", c1.expect + c2.expect, d, command=rng.choice(["run", "precision"])))
    return out


def odd_cases(rng, sample=None):
    """Valid but unusual scenes, cut to 20 steps, to be run for real on pyref: output lists
    empty, reversed, at odd intervals; every law, reset and timing; spin; extreme numbers.
    Each must run (exit 0, only `stickslip:` lines on stderr) or be refused in one line."""
    out = []
    for base_name, base in BASES.items():
        short = copy.deepcopy(base)
        short["time"]["duration"] = short["time"]["dt"] * 20
        short["output"]["every"] = 1
        variants = {
            "no output": {"output": {}},
            "every 7": {"output": {**short["output"], "every": 7}},
            "every 20": {"output": {**short["output"], "every": 20}},
            "stats and energy": {"output": {**short["output"], "stats": True, "energy": True}},
            "one step": {"time": {**short["time"], "duration": short["time"]["dt"]}},
            "spin": {"effects": {**short["effects"], "rotation": True}},
        }
        for law in ("coulomb", "visco_plastic", "visco_elastic"):
            variants[f"law {law}"] = {"contact": {**short["contact"], "law": law}}
        variants["reset total, exact"] = {"contact": {**short["contact"], "reset": "total", "slip_timing": "exact"}}
        pairs = [c for c in short["output"].get("contacts", []) if c[1] in {g["name"] for g in short["grain"]}]
        if pairs:
            variants["reversed pair"] = {"output": {**short["output"], "contacts": [pairs[0][::-1]]},
                                         "analysis": {"kind": "none"}}
        for what, change in variants.items():
            d = copy.deepcopy(short)
            d.update(copy.deepcopy(change))
            out.append(Case(f"{base_name}: {what}", [""], d, may_pass=True))
        for c in extreme_cases(base_name):
            c.data["time"]["duration"] = c.data["time"]["dt"] * 20
            c.data["output"]["every"] = 1
            out.append(c)
    if sample is not None:
        keep = [c for c in out if "=" not in c.what]  # every variant, a sample of the extreme values
        out = keep + rng.sample([c for c in out if "=" in c.what], sample)
    return out


# ---------------------------------------------------------------- command lines

def cli_cases(tmp):
    """Bad calls of every subcommand: (argv, words one of which the error must contain)."""
    file_out = tmp / "afile"
    bad_outs = [("", "--out"), ("   ", "--out"), (str(file_out), "--out"), ("/proc/nosuch/dir", "--out"), ("/dev/null", "--out"),
                (f"{file_out}/sub", "--out"), ("/proc/self", "--out"), ("/sys/kernel", "--out")]
    numbers = ["inf", "-inf", "nan", "-1", "0", "-0", "1e999", "abc", "", "1,5", "0x10", "--1"]
    cases = []
    for arg in ("--dt", "--duration"):
        for v in numbers + ["1e-300"]:
            cases.append((["run", "drag", f"{arg}={v}"], [arg, f"time.{arg[2:]}"]))
    cases += [(["run", "drag", "--duration", "1e9"], ["time.duration"]),
              (["run", "drag", "--dt", "1e-3"], ["time.dt"]),
              (["run", "tray", "--dt", "5e-324"], ["time.dt"]),
              (["run", "drag", "--duration", "1e-12"], ["time.duration"])]
    for arg, choices in (("--engine", "ansys"), ("--law", "sticky"), ("--reset", "half"),
                         ("--slip-timing", "late")):
        cases += [(["run", "drag", arg, choices], [arg]), (["run", "drag", arg, ""], [arg]),
                  (["run", "drag", arg], [arg])]
    for out, key in bad_outs:
        cases.append((["run", "drag", "--out", out], [key]))
        cases.append((["precision", "drag", "--out", out], [key]))
        cases.append((["thresholds", "--out", out], [key]))
        cases.append((["bench", "--out", out], [key]))
        cases.append((["report", "--out", out], [key]))
    for scene in ("/bin/ls", str(tmp), "/", "nosuch", "", "../../etc/passwd", "/dev/null", str(file_out),
                  "drag.toml/x", "cases/../drag"):
        cases.append((["run", scene], [scene or "''", "scene"]))
        cases.append((["precision", scene], [scene or "''", "scene"]))
    for v in numbers + ["1e-300", "1e-30", "1e300", "1e9"]:
        cases.append((["precision", "drag", "--factors", v], ["--factors"]))
    cases += [(["precision", "drag", "--factors", "1", "nan"], ["--factors"]),
              (["precision", "drag", "--factors"], ["--factors"]),
              (["precision", "drag", "--engine", "ansys"], ["--engine"]),
              (["precision", "drag", "--engine"], ["--engine"]),
              (["precision", "drag", "--slip-timing", "late"], ["--slip-timing"]),
              (["precision", "drag", "--reference", "ansys"], ["--reference"]),
              (["precision", "drag", "--reference"], ["--reference"])]
    for v in numbers + ["101", "1.5", "1e2", "10**3"]:
        cases.append((["bench", "--reps", v], ["--reps"]))
    cases += [(["bench", "--reps"], ["--reps"]), (["report", "--engines", "ansys"], ["--engines"]),
              (["report", "--engines"], ["--engines"]), (["report", "--engines", "pyref", "ansys"], ["--engines"])]
    for cmd in (["run", "drag"], ["precision", "drag"], ["thresholds"], ["bench"], ["report"]):
        cases += [(cmd + ["--frob"], ["--frob"]), (cmd + ["extra", "words"], ["extra"]),
                  (cmd + ["--out"], ["--out"])]
    cases += [([], ["command"]), (["frob"], ["frob"]), ([""], ["command"]), (["run"], ["scene"]),
              (["precision"], ["scene"]), (["--dt", "1", "run", "drag"], ["--dt", "command"]),
              (["run", "drag", "--dt", "1", "--dt", "x"], ["--dt"])]
    return cases


# ---------------------------------------------------------------- harness

class ReachedEngine(BaseException):
    """A stand-in engine or study was called: the input was accepted. (Not an Exception:
    cli.main turns those into a one-line internal error, and this must pass through.)"""


class _Standin:
    NAME = "standin"

    @staticmethod
    def available():
        return None

    @staticmethod
    def run(scene, out_dir, progress=None):
        raise ReachedEngine(scene.name)


def _reached(*a, **k):
    raise ReachedEngine("study")


@pytest.fixture
def standins(monkeypatch):
    """Engines and studies replaced: nothing runs, reaching them is reported."""
    monkeypatch.setattr(adapters, "get", lambda name: _Standin)
    monkeypatch.setattr(adapters, "available", lambda: (["pyref"], {}))
    monkeypatch.setattr(thresholds, "run_thresholds", _reached)
    monkeypatch.setattr(bench_table, "run_bench", _reached)
    monkeypatch.setattr(report, "build_report", _reached)


def listing(root):
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


def call(argv, root):
    """cli.main in this process: (exit status, stdout, stderr, the files it left in root)."""
    before = listing(root)
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            status = cli.main(argv)
        except SystemExit as e:
            status = e.code
        except ReachedEngine:
            status = "reached the engine"
        except BaseException as e:  # noqa: BLE001  a traceback the user would see
            status = f"raised {type(e).__name__}: {e}"
    if "internal error" in err.getvalue():  # cli.main's last resort: a fault, not a refusal
        status = f"internal error: {err.getvalue().strip()}"
    new = sorted(set(listing(root)) - set(before))
    return status, out.getvalue(), err.getvalue(), new


def verdict(status, err, new, expect):
    """None if the call was refused properly, else what was wrong."""
    lines = err.splitlines()
    if status != 2:
        return f"exit status {status!r} (want 2); stderr {err[:300]!r}"
    if "internal error" in err:
        return f"an internal error: {err[:300]!r}"
    if len(lines) != 1 or not lines[0].startswith("stickslip: error: "):
        return f"stderr is not one 'stickslip: error:' line: {err[:400]!r}"
    if "Traceback" in err:
        return "traceback"
    if not any(w in lines[0] for w in expect):
        return f"the message names none of {expect}: {lines[0]!r}"
    if new:
        return f"wrote {new[:5]}"
    return None


def run_scene_cases(cases, root, label):
    scenes = root / "scenes"
    scenes.mkdir()
    work = root / "work"  # the cwd: default output folders (runs/..., precision/...) would land here
    work.mkdir()
    failures = []
    cwd = os.getcwd()
    os.chdir(work)
    try:
        for i, c in enumerate(cases):
            path = scenes / "case.toml"
            path.write_bytes(c.raw if c.raw is not None else dump(c.data).encode())
            argv = [c.command, str(path), "--quiet"] + (["--out", str(work / "out")] if i % 2 else [])
            status, _, err, new = call(argv, work)
            if c.may_pass and status == "reached the engine":
                continue
            why = verdict(status, err, new, c.expect)
            if why:
                failures.append(f"{c.what} [{' '.join(argv[:1])}]: {why}")
    finally:
        os.chdir(cwd)
    assert not failures, f"{label} (seed {SEED}): {len(failures)} of {len(cases)} cases failed:\n" + \
        "\n".join(failures[:40])


# ---------------------------------------------------------------- the tests

def test_unmutated_bases_reach_the_engine(standins, tmp_path):
    """The harness can fail: each base scene as written passes every check."""
    for name, base in BASES.items():
        path = tmp_path / f"{name}.toml"
        path.write_text(dump(base))
        status, _, err, _ = call(["run", str(path), "--quiet", "--out", str(tmp_path / "o")], tmp_path)
        assert status == "reached the engine", (name, status, err)


def test_fuzz_scenes(standins, tmp_path):
    """Every structural mutation and a seeded sample of value mutations: refused at load."""
    rng = random.Random(SEED)
    cases = scene_cases(rng, sample=120)
    assert len(cases) >= 200
    run_scene_cases(cases, tmp_path, "scene fuzz")


def test_fuzz_command_lines(standins, tmp_path):
    """Bad calls of every subcommand: one line naming the argument, nothing written."""
    work = tmp_path / "work"
    work.mkdir()
    (tmp_path / "afile").write_text("not a folder\n")
    cwd = os.getcwd()
    os.chdir(work)
    failures = []
    try:
        cases = cli_cases(tmp_path)
        for argv, expect in cases:
            status, _, err, new = call(argv, tmp_path)
            why = verdict(status, err, new, expect)
            if why:
                failures.append(f"{argv}: {why}")
    finally:
        os.chdir(cwd)
    assert len(cases) >= 100
    assert not failures, f"{len(failures)} of {len(cases)} command lines failed:\n" + "\n".join(failures[:40])


@pytest.mark.slow
def test_fuzz_scenes_all(standins, tmp_path):
    """Every value mutation of every base, and 3000 random double mutations (opt-in)."""
    rng = random.Random(SEED)
    run_scene_cases(scene_cases(rng) + double_cases(rng, 3000), tmp_path, "scene fuzz, full")


def run_for_real(cases, root):
    """Each case through cli.main on pyref: it runs (exit 0, stderr only `stickslip:`
    warnings) or is refused in one line (exit 1 or 2); nothing written outside its --out."""
    failures = []
    for i, c in enumerate(cases):
        path = root / "case.toml"
        path.write_text(dump(c.data))
        out = root / "out" / str(i)
        status, _, err, new = call(["run", str(path), "--quiet", "--out", str(out)], root)
        outside = [p for p in new if not p.startswith("out")]
        lines = err.splitlines()
        if status == 0:
            why = None if all(x.startswith("stickslip: ") for x in lines) else f"stderr {err[:300]!r}"
        elif status in (1, 2):
            ok = len(lines) == 1 and lines[0].startswith("stickslip: error: ") and "internal error" not in err
            why = None if ok else f"exit {status}, stderr {err[:300]!r}"
        else:
            why = f"exit status {status!r}; stderr {err[:300]!r}"
        if outside:
            why = f"wrote {outside[:5]}"
        if why:
            failures.append(f"{c.what}: {why}")
    assert not failures, f"{len(failures)} of {len(cases)} runs failed (seed {SEED}):\n" + "\n".join(failures[:40])


def test_fuzz_odd_scenes_run_on_pyref(tmp_path):
    """Valid but unusual scenes run for 20 steps on pyref, for real: no traceback after
    the scene was accepted (the analysis of a short run, odd outputs, extreme numbers)."""
    run_for_real(odd_cases(random.Random(SEED), sample=30), tmp_path)


@pytest.mark.slow
def test_fuzz_odd_scenes_run_on_pyref_all(tmp_path):
    run_for_real(odd_cases(random.Random(SEED)), tmp_path)


@pytest.mark.parametrize("argv,words", [
    (["run", "/bin/ls"], ["/bin/ls", "UTF-8"]),
    (["run", "drag", "--duration", "inf"], ["--duration"]),
    (["run", "drag", "--dt", "1e-300"], ["time.dt"]),
    (["precision", "drag", "--factors", "nan"], ["--factors"]),
    (["bench", "--reps", "0"], ["--reps"]),
    (["run", "BAD"], ["time.dt"]),
])
def test_real_process_exit_status(argv, words, tmp_path):
    """The real command: exit status 2, one line, no traceback, nothing written."""
    bad = tmp_path / "bad.toml"
    bad.write_text(scene_mod.find("drag").read_text().replace("dt = 2e-6", "dt = 1e-3"))
    argv = [str(bad) if a == "BAD" else a for a in argv]
    work = tmp_path / "work"
    work.mkdir()
    p = subprocess.run([sys.executable, "-m", "stickslip.cli", *argv], capture_output=True, text=True, cwd=work,
                       env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}, timeout=60, check=False)
    assert p.returncode == 2, p.stderr
    assert verdict(p.returncode, p.stderr, listing(work), words) is None, p.stderr
