# SPDX-License-Identifier: GPL-2.0-or-later
"""A scene file's TOML tables, read with one-line errors: each value is checked for its type
and range where it is read, and a key nobody read is an unknown key (docs/scene-format.md)."""
from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError

# Numbers in a scene are at most this in magnitude. SI values of a DEM scene are far
# inside it, and it keeps sums and products of a few of them (masses, distances,
# stiffness over mass) inside double precision (1.8e308) instead of overflowing.
MAX_MAGNITUDE = 1e100


class Table:
    """A TOML table that remembers which keys were read, so unknown keys are errors."""

    def __init__(self, data, where):
        if not isinstance(data, dict):
            raise SceneError(f"{where}: expected a table, got {shown(data)}")
        self.data, self.where, self.used = data, where, set()

    def key(self, k):
        return f"{self.where}.{k}" if self.where else k

    def get(self, k, default=None, required=False):
        self.used.add(k)
        if k not in self.data:
            if required:
                raise SceneError(f"{self.key(k)}: missing (required)")
            return default
        return self.data[k]

    def number(self, k, default=None, required=False, lo=None, hi=None, lo_open=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not finite(v):
            raise SceneError(f"{self.key(k)}: expected a finite number (|x| <= {MAX_MAGNITUDE:g}), got {shown(v)}")
        v = float(v)
        if lo is not None and (v < lo or (lo_open and v == lo)):
            rng = f"> {lo:g}" if lo_open else f">= {lo:g}"
            if hi is not None:
                rng += f" and <= {hi:g}"
            raise SceneError(f"{self.key(k)} = {v:g}: must be {rng}")
        if hi is not None and v > hi:
            raise SceneError(f"{self.key(k)} = {v:g}: must be <= {hi:g}")
        return v

    def integer(self, k, default=None, lo=None, hi=None):
        v = self.get(k, default)
        if isinstance(v, bool) or not isinstance(v, int):
            raise SceneError(f"{self.key(k)}: expected a whole number, got {shown(v)}")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise SceneError(f"{self.key(k)} = {v}: must be in [{lo if lo is not None else '-inf'}, "
                             f"{hi if hi is not None else 'inf'}]")
        return v

    def boolean(self, k, default):
        v = self.get(k, default)
        if not isinstance(v, bool):
            raise SceneError(f"{self.key(k)}: expected true or false, got {shown(v)}")
        return v

    def string(self, k, default=None, choices=None, required=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if not isinstance(v, str):
            raise SceneError(f"{self.key(k)}: expected a string, got {shown(v)}")
        if choices and v not in choices:
            raise SceneError(f"{self.key(k)} = {v!r}: must be one of {', '.join(choices)}")
        return v

    def vector(self, k, dim, default=None, required=False):
        v = self.get(k, default, required)
        if v is None:
            return None
        if (not isinstance(v, list) or len(v) != dim
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and finite(x) for x in v)):
            raise SceneError(f"{self.key(k)}: expected {dim} finite numbers (|x| <= {MAX_MAGNITUDE:g}, "
                             f"dimension = {dim}), got {shown(v)}")
        out = np.zeros(3)
        out[:dim] = v
        return out

    def array(self, k):
        """A list (of tables or values); absent = empty."""
        v = self.get(k, [])
        if not isinstance(v, list):
            raise SceneError(f"{self.key(k)}: expected a list, got {shown(v)}")
        return v

    def names(self, k, known, what):
        """A list of names, each one of `known`, each once (a name twice would give its
        columns twice)."""
        v = self.array(k)
        for x in v:
            if not isinstance(x, str) or x not in known:
                raise SceneError(f"{self.key(k)}: {shown(x)} is not {what}")
        unique(v, self.key(k))
        return list(v)

    def done(self):
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise SceneError(f"{self.key(unknown[0])}: unknown key")


def finite(v):
    """A number within MAX_MAGNITUDE (an int too large for a float is not)."""
    try:
        return math.isfinite(v) and abs(v) <= MAX_MAGNITUDE
    except OverflowError:
        return False


def shown(v):
    """A value in an error message, cut short (a whole table would not fit on one line)."""
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def unique(names, what):
    seen = set()
    for n in names:
        if n in seen:
            raise SceneError(f"{what}: {n!r} is used twice")
        seen.add(n)
