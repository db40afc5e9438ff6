# SPDX-License-Identifier: GPL-2.0-or-later
"""The two errors a user can get from stickslip, each a one-line message."""


class SceneError(ValueError):
    """A scene (or a command-line value) that cannot be run; the message names the key
    and the allowed range. No engine ever sees an invalid scene."""


class EngineError(RuntimeError):
    """An engine that is not available or failed; the message says why."""
