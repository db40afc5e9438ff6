# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's state saved with the scene and restored when a scene is loaded.

The state (per contact: the spring D, the slip counter, kn, cn, the last forces; the
parameters) lives in Python, which YADE does not serialise. So YADE's savers O.save,
O.saveTmp and O.sceneToString are wrapped to write it first into O.tags["stickslip_law"],
stamped with O.iter; YADE saves the tags with the scene. At its next step a law whose scene
was replaced takes the state saved with the scene, if saved at that very iteration, and
refuses to continue otherwise (a silent restart of every spring would be a wrong answer).
"""
import base64
import json
import os
import re

import numpy as np

from .checks import fail

LAWS = {}  # token -> StickSlipLaw, the laws of this process (the token names a law in its runner's command)
TAG = "stickslip_law"  # the key in O.tags
SCALARS = ("last_iter", "min_dissipation", "max_fn_error", "checked")  # the law's own, saved too
HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # yade_law/, where stickslip_yade is found


# The runner's command comes in two forms. PyRunner compiles its command at every step, which
# costs about 1 us per 10 characters: while the law runs in this process its runner carries
# the short form (a name this package puts in builtins); a saved scene carries the robust
# form, which imports stickslip_yade from its own folder if the process has not (a scene
# loaded by O.load in a new process) and, once run, gives its runner the short form again.
def short_command(token):
    return f"_stickslip_step({token!r})"


def robust_command(token):
    return (f"(__import__('sys').modules.get('stickslip_yade') or (__import__('sys').path.append({HERE!r}), "
            f"__import__('stickslip_yade'))[1]).resume({token!r})")


def token_of(command):
    """The token of the law a runner's command runs (any form, older ones included), or None."""
    m = re.search(r"(?:_stickslip_step|stickslip_yade'\)\)\[1\]\)\.(?:step|resume))\('([0-9a-f]{16})'\)$", command)
    return m.group(1) if m else None


def saved_state(law, O, fresh=False):
    """The law's state as a string for O.tags (`fresh`: the parameters only)."""
    c = law.contacts
    arrays = {} if fresh else {k: getattr(c, k) for k in c.ARRAYS}
    return json.dumps({
        "version": 2, "token": law.token, "params": law.params_dict(), "iter": O.iter,
        "scalars": {"last_iter": -1} if fresh else {k: getattr(law, k) for k in SCALARS},
        "arrays": {k: [a.dtype.str, a.shape, base64.b64encode(np.ascontiguousarray(a).tobytes()).decode()]
                   for k, a in arrays.items()}})


def saved_params(O):
    """The parameters of the law saved with the scene, or None."""
    return json.loads(O.tags[TAG])["params"] if TAG in O.tags.keys() else None


def adopt(law, O, scene):
    """The scene is not the one the law's state belongs to: first step, or the scene was
    replaced (O.load, O.loadTmp, O.reload, O.reset). Take the state saved with the scene if
    it was saved at this very iteration; otherwise start afresh only where nothing is lost,
    else refuse."""
    saved = O.tags[TAG] if TAG in O.tags.keys() else None
    st = json.loads(saved) if saved else None
    ran = law.scene is not None and law.last_iter >= 0
    law.contacts.clear()
    if st is not None and st["iter"] == O.iter:
        for k, (dtype, shape, data) in st["arrays"].items():
            setattr(law.contacts, k, np.frombuffer(base64.b64decode(data), dtype=dtype).reshape(shape).copy())
        for k, v in st["scalars"].items():
            setattr(law, k, v)
    elif ran and O.iter > 0:
        why = (f"its stick-slip state was saved at iteration {st['iter']}" if st else
               f"it carries no stick-slip state (O.tags['{TAG}'])")
        fail(f"the scene was replaced (O.load/loadTmp/reload?) and is at iteration {O.iter}, but {why}: "
             f"it was saved by a path that bypasses stickslip_yade's save hook (O.save, O.saveTmp, "
             f"O.sceneToString are hooked); the springs cannot be restored")
    else:  # a new law, or a new scene from iteration 0: nothing to continue
        law.last_iter = -1
    law.scene = scene
    law.bodies = None  # body data is the new scene's


def store_state():
    """Before YADE serialises the scene: put the state of the law that runs in it into
    O.tags, with the iteration, so that any load can check it belongs to the scene, and give
    its runner the robust command. Returns [(runner, command)] to put back after saving."""
    from yade import O, PyRunner

    put_back = []
    for e in O.engines:
        token = token_of(e.command) if isinstance(e, PyRunner) else None
        if token is None:
            continue
        if e.command == short_command(token):
            put_back.append((e, e.command))
            e.command = robust_command(token)
        law = LAWS.get(token)
        if law is None:  # a loaded scene whose law has not run here: its saved state still holds
            continue
        fresh = law.scene is None or not O._sceneObj == law.scene
        O.tags[TAG] = saved_state(law, O, fresh=fresh)
    return put_back


def install_save_hooks():
    """YADE's own savers (O.save, O.saveTmp, O.sceneToString) store the law's state first."""
    import yade.wrapper

    Omega = yade.wrapper.Omega
    if getattr(Omega, "_stickslip_hooked", False):
        return
    for name in ("save", "saveTmp", "sceneToString"):
        original = getattr(Omega, name)

        def hooked(self, *args, _original=original, **kw):
            put_back = store_state()
            try:
                return _original(self, *args, **kw)
            finally:
                for runner, command in put_back:
                    runner.command = command

        hooked.__doc__ = original.__doc__
        setattr(Omega, name, hooked)
    Omega._stickslip_hooked = True
