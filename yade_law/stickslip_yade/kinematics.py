# SPDX-License-Identifier: GPL-2.0-or-later
"""The bodies as the law reads them from YADE: which ids exist, which are spheres and their
radii (redone only when bodies are appended or erased), their positions, velocities and
spins in one C++ call per step, and the periodic cell's motion."""
import array
import math
from itertools import chain

import numpy as np

from .checks import finite_bodies


def rows(vectors):
    """Vector3s -> (n, 3) array. __getinitargs__() gives the three components in one
    call (0.3 us); v[0], v[1], v[2] costs 0.7 us and tuple(v) over 10 us."""
    t = [v.__getinitargs__() for v in vectors]
    return np.fromiter(chain.from_iterable(t), float, 3 * len(t)).reshape(-1, 3)  # 3x faster than np.array(t)


def cross(a, b):
    """Row-wise a x b; np.cross costs about ten times more on (K, 3) arrays."""
    c = np.empty_like(a)
    c[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    c[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    c[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return c


def finite_sum(x):
    """True if the sum of x's values is finite (it is only if all of them are), as a dot
    product with ones: numpy's sum is a reduction, 2-3 us on a few values."""
    global _ONES
    x = x.ravel()
    if len(_ONES) < len(x):
        _ONES = np.ones(2 * len(x))
    return math.isfinite(x.dot(_ONES[:len(x)]))


_ONES = np.ones(64)  # for finite_sum


class Bodies:
    """Per-body data that does not change during a run: which ids exist, which bodies are
    spheres, their radii, the shapes present (the first body of each)."""

    def __init__(self, O):
        from yade import Sphere

        n = len(O.bodies)
        exists, sphere, radius = np.zeros(n, bool), np.zeros(n, bool), np.zeros(n)
        self.states = [None] * n  # for the reader of last resort
        self.shapes = {}  # shape class name -> the first body with it
        for b in O.bodies:
            if b is None:
                continue
            exists[b.id] = True
            self.states[b.id] = b.state
            self.shapes.setdefault(type(b.shape).__name__, b.id)
            if isinstance(b.shape, Sphere):
                sphere[b.id], radius[b.id] = True, b.shape.radius
        self.sphere, self.radius = sphere, radius
        self.ids = np.flatnonzero(exists)
        self.idlist = self.ids.tolist()
        self.n, self.nexisting = n, len(self.ids)
        self.nspheres = int(sphere.sum())
        try:  # one C++ call reads pos, vel, angVel (and ori) of listed bodies (YADE's MPI helper)
            from yade.wrapper import Subdomain

            self.reader = Subdomain().getStateValuesFromIds
        except ImportError:
            self.reader = None

    def changed(self, O):
        """Appended (the length grows) or erased since this was read. The bulk reader must
        never be handed an erased id (YADE aborts). YADE's BodyContainer turns on
        `useRedirection` at the first erase (while `enableRedirection`, the default): until
        then nothing was erased; after it, count the bodies that exist every step
        (coordsAndDisplacements skips erased ones, one C++ call)."""
        bodies = O.bodies
        if len(bodies) != self.n:
            return True
        if bodies.enableRedirection and not bodies.useRedirection:
            return False
        import yade._utils as yu

        return len(yu.coordsAndDisplacements(0)[0]) != self.nexisting

    def states_now(self, it):
        """x(t), v(t - dt/2), omega(t - dt/2) of every body, as (n, 3) arrays (zero rows for
        erased ids); a non-finite value stops the run naming the body (iteration `it`)."""
        nb, k = self.n, len(self.idlist)
        if self.reader is not None:
            A = np.frombuffer(array.array("d", self.reader(self.idlist)), float).reshape(k, 13)  # (faster than fromiter)
        else:
            st = [self.states[i] for i in self.idlist]
            A = np.hstack([rows([s.pos for s in st]), rows([s.vel for s in st]), rows([s.angVel for s in st])])
        if k == nb:
            P, V, W = A[:, 0:3], A[:, 3:6], A[:, 6:9]
        else:
            P, V, W = np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3))
            P[self.ids], V[self.ids], W[self.ids] = A[:, 0:3], A[:, 3:6], A[:, 6:9]
        if not finite_sum(A):  # (the culprit is looked for only if needed)
            finite_bodies(it, P, V, W)
        return P, V, W


def cell_motion(O):
    """Periodic cell: (hSize, velGrad @ prevHSize), so that id2's image across the boundary
    sits at x2 + hSize @ cellDist and moves with v2 + velGrad @ prevHSize @ cellDist (the
    cell's own motion over the last step, as YADE's Cell::intrShiftVel); None otherwise."""
    if not O.periodic:
        return None
    c = O.cell
    H, G, Hp = (np.array(c.hSize), np.array(c.velGrad), np.array(c.prevHSize))
    return H, G @ Hp
