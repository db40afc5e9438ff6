# SPDX-License-Identifier: GPL-2.0-or-later
"""A stand-in for DEM-Engine's `deme` module that records every call, for the code that drives
the engine (the adapter, deme_model/'s helper and example) on a machine without a GPU."""
import numpy as np


class Recorder:
    """Records every method call as (name, args); named methods return stand-ins."""

    def __init__(self, log, label):
        self._log, self._label = log, label

    def __getattr__(self, name):
        def call(*args, **kw):
            self._log.append((self._label, name, args, kw))
            return self._returns(name, args)
        return call

    def _returns(self, name, args):
        return None


class FakeSolver(Recorder):
    def __init__(self, log, record=None, positions=None):
        super().__init__(log, "solver")
        self.t, self.dt, self.steps = 0.0, None, 0
        self.record = record or (lambda fam, name, step: 0.0)
        self.positions = positions

    def _returns(self, name, args):
        if name == "DefineContactForceModel":
            return Recorder(self._log, "model")
        if name == "AddClumps":
            return Recorder(self._log, "batch")
        if name == "AddExternalObject":
            return Recorder(self._log, "wall")
        if name == "Track":
            return FakeTracker(self)
        if name == "SetTimeStepSize":
            self.dt = args[0]
        if name == "DoDynamicsThenSync":  # (the engine's loop: while elapsed < duration, += float(dt))
            h, elapsed = float(np.float32(self.dt)), 0.0
            while elapsed < args[0]:
                self.steps, elapsed = self.steps + 1, elapsed + h
        if name == "GetFamilyOwnerWildcardValue":
            return [self.record(args[0], args[1], self.steps)]
        return name


class FakeTracker:
    def __init__(self, solver):
        self.solver = solver

    def Pos(self):
        return [0.0, 0.002, 0.0] if self.solver.positions is None else self.solver.positions(self.solver.steps)

    def Vel(self):
        return [1e-5, 0.0, 0.0]


class FakeDeme:
    def __init__(self, **kw):
        self.log, self.kw, self.solvers = [], kw, []

    def DEMSolver(self, *args):
        s = FakeSolver(self.log, **self.kw)
        self.solvers.append(s)
        return s

    def calls(self, label, name):
        return [args for lab, n, args, _ in self.log if lab == label and n == name]
