# SPDX-License-Identifier: GPL-2.0-or-later
"""Row-wise vector arithmetic of pyref's solver on (K, 3) arrays: cross products, scatter-adds
into per-grain rows, finiteness and rotations about a fixed axis, each written for the few
rows a step of a small scene has, where numpy's general forms cost more than the arithmetic."""
from __future__ import annotations

import math

import numpy as np

from .laws import _count_nonzero

ZERO = np.zeros(())  # numpy compares with a 0-d array faster than with the float 0.0

# Component k of a x b is a[k+1] b[k+2] - a[k+2] b[k+1] (indices mod 3).
_NEXT, _AFTER_NEXT = np.array([1, 2, 0]), np.array([2, 0, 1])


def cross(a, b):
    """Row-wise cross product of (K, 3) arrays (np.cross, without its axis juggling);
    `a` may be a single row, broadcast over b's."""
    return a.take(_NEXT, 1) * b.take(_AFTER_NEXT, 1) - a.take(_AFTER_NEXT, 1) * b.take(_NEXT, 1)


def all_finite(a):
    """np.isfinite(a).all(), faster on a few grains."""
    return _count_nonzero(np.isfinite(a)) == a.size


def scatter(flat, values, n):
    """Sum the rows of `values` (K, 3) into n rows, component k of row r going to flat
    place flat[3r + k], in the rows' order from zero (np.bincount adds in that order,
    as np.add.at does, and is faster even on a few rows)."""
    if not len(flat):
        return np.zeros((n, 3))  # (np.bincount would give integers)
    return np.bincount(flat, values.ravel(), 3 * n).reshape(n, 3)


class Rotation:
    """Rotations about one fixed unit axis, by Rodrigues' formula; the last matrix is
    kept (a wall that has stopped turning asks for the same angle every step)."""

    def __init__(self, axis):
        k = np.asarray(axis, float)
        self.K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        self.I = np.eye(3)
        self.angle, self.R = None, None

    def matrix(self, angle):
        """R = I + sin(angle) K + (1 - cos(angle)) K K (Rodrigues' formula)."""
        if angle != self.angle:
            K = self.K
            self.angle, self.R = angle, self.I + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
        return self.R
