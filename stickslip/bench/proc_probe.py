# SPDX-License-Identifier: GPL-2.0-or-later
"""The shell probes the engine benchmarks run from inside an engine (its `shell` command).

`shell` runs a script through sh, so the engine's process is an ancestor of the script,
not its parent: the probe walks up /proc/PID/stat until it finds the engine's name. Shell
built-ins only, so that the probe itself costs next to nothing."""


def probe_script(process, action):
    """A /bin/sh script that runs `action` (lines of sh, with $p the engine's pid) in the
    nearest ancestor whose name in /proc/PID/stat starts with `process` (Linux keeps 15
    characters of it), and exits 1 if there is none."""
    body = "".join(f"      {line}\n" for line in action.strip().splitlines())
    return ("#!/bin/sh\n"
            "p=$PPID\n"
            'while [ "$p" -gt 1 ]; do\n'
            "  read -r line < /proc/$p/stat\n"
            '  case "$line" in\n'
            f'    *"({process}"*)\n'
            f"{body}"
            "      exit 0;;\n"
            "  esac\n"
            "  set -- ${line##*) }\n"
            "  p=$2\n"
            "done\n"
            "exit 1\n")
