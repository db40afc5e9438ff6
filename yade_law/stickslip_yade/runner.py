"""The PyRunner that runs the law each step, between YADE's InteractionLoop and
NewtonIntegrator, and what its command calls.

The command does not rely on a name defined by the user's script: it imports stickslip_yade
from its own folder if the process has not (a scene loaded by O.load in a new process), and
the law named by its token is rebuilt there from the parameters saved with the scene
(checkpoints.py) and published as `builtins.stickslip_law`.
"""
import builtins
import os

from . import checkpoints
from .law import StickSlipLaw

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # yade_law/, where stickslip_yade is found


def step(token):
    """What the law's PyRunner runs each step."""
    law = checkpoints.LAWS.get(token)
    if law is None:
        law = law_from_scene(token)
    law.step()


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


def command(token):
    """One expression, compiled by PyRunner every step (so kept short): this module, imported
    from its own folder if the process has not imported it yet (O.load in a new process),
    runs the law named by `token`."""
    return (f"(__import__('sys').modules.get('stickslip_yade') or (__import__('sys').path.append({HERE!r}), "
            f"__import__('stickslip_yade'))[1]).step({token!r})")


def stickslip_runner(ks, nu_s, mu_s, mu_k, reset="spring", slip_timing="step", rotation=True, check=False):
    """The law's PyRunner, for an engine list of your own: place it right after the
    InteractionLoop and before NewtonIntegrator (yade_law/README.md, "Your own engine list").
    The law object is published as `builtins.stickslip_law`."""
    from yade import PyRunner

    law = StickSlipLaw(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation=rotation, check=check)
    publish(law)
    # initRun=True: otherwise the first step runs without the tangential force.
    return PyRunner(command=command(law.token), iterPeriod=1, initRun=True, updateGlobals=False,
                    label="stickslip_runner")
