# SPDX-License-Identifier: GPL-2.0-or-later
"""Variants of the LIGGGHTS tutorials that Debian ships (package liggghts-doc), derived at
test time: the scripts are read from the installed package, never copied into the
repository.

`variant(name, ...)` copies a tutorial's folder (meshes, data) into a working directory
and writes `in.variant`: the tutorial's own script with
- `tangential history` swapped for another tangential model (and settings appended to
  the pair_style / fix wall/gran lines that carry it),
- the kinetic friction coefficient added next to coefficientFriction (times a factor),
- the time step optionally scaled (to measure the round-off floor),
- its runs cut to a budget of steps, its own dumps removed, and one dump of every atom
  (full precision, sorted by id) every `every` steps instead.
"""
from __future__ import annotations

import re
import shutil
from pathlib import Path

TUTORIALS = Path("/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public")
SCRIPTS = {  # tutorial folder -> its input script
    "packing": "in.packing",
    "conveyor": "in.conveyor",
    "meshGran": "in.meshGran",
    "movingMeshGran": "in.movingMeshGran",
    "chute_wear": "in.chute_wear",
    "insert_stream": "in.insert_stream",
    "multisphere_stone_restitution": "in.multisphere",
    "cohesion": "in.cohesion",
    "hysteresis": "in.hysteresis",
    "hydrogel_multicontact": "in.hydrogel_multicontact",
}
DUMP_COLS = "id x y z vx vy vz omegax omegay omegaz"


def available(name):
    return (TUTORIALS / name / SCRIPTS[name]).is_file()


def _logical_lines(text):
    """Input lines with comments removed and '&' continuations joined."""
    out, cur = [], ""
    for raw in text.split("\n"):
        line = raw.split("#", 1)[0].rstrip()
        if line.endswith("&"):
            cur += line[:-1] + " "
            continue
        cur += line
        out.append(cur.strip())
        cur = ""
    if cur:
        out.append(cur.strip())
    return [x for x in out if x]


def variant(name, work: Path, tangential="history", settings="", mu_k_factor=1.0, dt_factor=1.0,
            steps=2000, every=100, extra_settings_all="", lost_error=False):
    """Write the variant into `work` (created); returns the path of its input script.
    `settings` are appended where the tangential model is given; `extra_settings_all` to
    every pair_style gran and fix wall/gran line (e.g. "tangential_damping off");
    `lost_error`: a lost atom stops the run (thermo_modify lost error) instead of being ignored."""
    src = TUTORIALS / name
    if work.exists():
        shutil.rmtree(work)
    shutil.copytree(src, work, ignore=shutil.ignore_patterns("post", "*.gz"))
    (work / "post").mkdir(exist_ok=True)
    lines = _logical_lines((src / SCRIPTS[name]).read_text())
    out, done, dumped, variables = [], 0, False, {}
    for line in lines:
        words = line.split()
        cmd = words[0]
        if cmd == "variable" and len(words) == 4 and words[2] in ("equal", "index"):
            variables[words[1]] = words[3]
        if cmd in ("dump", "dump_modify", "undump"):
            continue  # the tutorial's own output (VTK needs a LIGGGHTS built with VTK)
        if cmd == "thermo_modify" and lost_error and "lost" in words:
            line = re.sub(r"\blost\s+\w+", "lost error", line)
        if cmd == "timestep" and dt_factor != 1.0:
            line = f"timestep {float(words[1]) * dt_factor!r}"
        is_gran = (cmd == "pair_style" and "gran" in words) or (cmd == "fix" and len(words) > 3 and
                                                                 words[3].startswith("wall/gran"))
        if is_gran:
            if "tangential" in words and words[words.index("tangential") + 1] == "history":
                line = re.sub(r"\btangential\s+history\b", f"tangential {tangential}", line)
                if tangential != "history" and settings:
                    line += " " + settings
            if extra_settings_all:
                line += " " + extra_settings_all
        if cmd == "fix" and len(words) > 5 and words[4] == "coefficientFriction" and tangential != "history":
            values = words[5:]
            head, nums = [], []
            for w in values:
                try:
                    nums.append(float(w))
                except ValueError:
                    head.append(w)
            # peratomtypepair N v11 v12 ...: N is the first number
            n, vals = nums[0], nums[1:]
            kin = " ".join(repr(v * mu_k_factor) for v in vals)
            out.append(line)
            out.append(f"fix mukin all property/global coefficientKineticFriction {' '.join(head)} {int(n)} {kin}")
            continue
        if cmd == "run":
            target = int(float(re.sub(r"\$\{(\w+)\}", lambda m: variables[m.group(1)], words[1])))
            upto = "upto" in words[2:]
            length = target - done if upto else target
            if done >= steps:
                continue
            if not dumped and length > 1:
                out.append(f"dump cmp all custom {every} dump.cmp {DUMP_COLS}")
                out.append('dump_modify cmp sort id format "%d' + " %.17g" * 9 + '"')
                dumped = True
            length = min(length, steps - done)
            done += length
            line = f"run {length}"
        out.append(line)
    script = work / "in.variant"
    script.write_text("\n".join(out) + "\n")
    return script
