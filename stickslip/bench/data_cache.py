# SPDX-License-Identifier: GPL-2.0-or-later
"""The benchmarks' starting states (a settled packing, a poured bed) as data files made once
and kept: each is named by a hash of the input script that makes it, so a changed script
makes a new one, and it is written under a temporary name first, so an interrupted build
leaves nothing that looks finished."""
from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path


def cached_data(cache: Path, stem, script, make):
    """cache/STEM-KEY.data (KEY: from `script`), made by make(folder) if it is not there yet;
    make runs the engine in an empty folder and returns the path of the data file it wrote."""
    key = hashlib.sha1(script.encode()).hexdigest()[:12]
    data = cache / f"{stem}-{key}.data"
    if data.is_file():
        return data
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=cache) as tmp:
        os.replace(make(Path(tmp)), data)
    return data
