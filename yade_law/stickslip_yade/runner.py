# SPDX-License-Identifier: GPL-2.0-or-later
"""The PyRunner that runs the law each step, between YADE's InteractionLoop and
NewtonIntegrator, and what its command calls.

While the law runs, its runner's command is `_stickslip_step(token)` (this module puts the
name in builtins: a PyRunner's command runs in __main__, and it is compiled every step, so
it is kept short). A saved scene carries a robust command instead (checkpoints.py), which
needs no name from the user's script: it imports stickslip_yade from its own folder if the
process has not (O.load in a new process), where the law named by its token is rebuilt from
the parameters saved with the scene and published as `builtins.stickslip_law`.
"""
import builtins

from . import checkpoints
from .law import StickSlipLaw


def step(token):
    """What the law's PyRunner runs each step."""
    law = checkpoints.LAWS.get(token)
    if law is None:
        law = law_from_scene(token)
    law.step()


builtins._stickslip_step = step  # the short command's name


def resume(token):
    """What a saved scene's runner runs (checkpoints.robust_command): the law's step, then the
    runner gets the short command for the steps that follow."""
    from yade import O, PyRunner

    step(token)
    for e in O.engines:
        if isinstance(e, PyRunner) and checkpoints.token_of(e.command) == token:
            e.command = checkpoints.short_command(token)


def law_from_scene(token):
    from yade import O

    params = checkpoints.saved_params(O)
    if params is None:
        raise RuntimeError(f"stick-slip law: this scene's runner names law {token}, which this process has not "
                           f"built, and the scene carries no saved law (O.tags['{checkpoints.TAG}']): it was "
                           f"saved by a path that bypasses stickslip_yade's save hook; the springs cannot be "
                           f"restored")
    law = StickSlipLaw(**params)
    law.token = token  # the name the saved runner uses
    publish(law)
    return law


def publish(law):
    """Register the law under its token (the runner's command finds it there, the save hook
    too) and as `builtins.stickslip_law` (a PyRunner's command runs in __main__)."""
    checkpoints.LAWS[law.token] = law
    builtins.stickslip_law = law


def publish_view(view):
    """The compiled law's view (compiled.CompiledLaw) as `builtins.stickslip_law`, where a
    script finds the Python law too."""
    builtins.stickslip_law = view


def stickslip_runner(ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True, check=False):
    """The law's PyRunner, for an engine list of your own: place it right after the
    InteractionLoop and before NewtonIntegrator (yade_law/README.md, "Your own engine list").
    The law object is published as `builtins.stickslip_law`."""
    from yade import PyRunner

    law = StickSlipLaw(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    publish(law)
    # initRun=True: otherwise the first step runs without the tangential force.
    return PyRunner(command=checkpoints.short_command(law.token), iterPeriod=1, initRun=True, updateGlobals=False,
                    label="stickslip_runner")
