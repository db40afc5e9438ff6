# SPDX-License-Identifier: GPL-2.0-or-later
"""How the GPU check's parts, parallel processes (tools/deme_gpu_check.py), wait for each
other: a part writes its JSON under the work folder, and the check marks a part that ended
with PART.done."""
import json
import time
from pathlib import Path


def wait_json(path, timeout):
    """The JSON a part wrote, waiting up to `timeout` s for it (None if it never came)."""
    end = time.time() + timeout
    while time.time() < end:
        if path.is_file():
            try:
                return json.loads(path.read_text())
            except json.JSONDecodeError:
                pass
        time.sleep(1.0)
    return None


def wait_parts(args, parts, timeout):
    """True once every part of `parts` has ended (its .done marker), False at the timeout
    (looked at once at least)."""
    end = time.time() + timeout
    while True:
        if all((Path(args.work) / f"{p}.done").exists() for p in parts):
            return True
        if time.time() >= end:
            return False
        time.sleep(1.0)
