# SPDX-License-Identifier: GPL-2.0-or-later
"""Whether the compiled law reads YADE's classes where the installed YADE keeps them.

The plugin is compiled with YADE's headers of another release (Debian serves no source for its
own YADE), with definitions read from the installed YADE (yade_flags.py). A class whose
members moved between the two, or a definition that does not match the build of the installed
YADE, would make the law read the wrong memory, silently. So before YADE starts with the
plugin (build/yade_law/yade-stickslip runs this), layout_probe.py runs in a YADE of its own:
for every member the law reads or writes it sets a value through YADE's Python attributes
(YADE's own compiled code) and reads it back through the plugin. The verdict is kept beside
the plugin, keyed by the plugin and YADE's libraries, so it runs once per build.

    python3 layout_check.py PREFIX     # nothing and exit 0 when they match; else one line, exit 1

PREFIX: the private YADE prefix the build made (build/yade_law/prefix).
"""
import hashlib
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
PROBE = os.path.join(HERE, "layout_probe.py")
CACHE = "layout_check.json"  # in PREFIX
SECONDS = 120  # the probe starts YADE (1-2 s) and runs one step: far less


def build_info(prefix):
    """What the build recorded (CMakeLists.txt): the headers' and the installed YADE's versions,
    the plugin's path below the prefix."""
    with open(os.path.join(prefix, "stickslip_build.json")) as f:
        return json.load(f)


def key(prefix, info):
    """The plugin's bytes and the identity of the YADE libraries it was checked against."""
    plugin = os.path.join(prefix, info["plugin"])
    h = hashlib.sha256()
    with open(plugin, "rb") as f:
        h.update(f.read())
    folder = os.path.dirname(plugin)
    for name in sorted(os.listdir(folder)):
        path = os.path.realpath(os.path.join(folder, name))
        if name.endswith(".so") and name != os.path.basename(plugin):
            st = os.stat(path)
            h.update(f"{name} {st.st_size} {st.st_mtime_ns}".encode())
    return h.hexdigest()


def probe(prefix, info):
    """Run layout_probe.py in YADE with the plugin; None if every member matches, else the
    one line that says which does not."""
    headers = f"headers of YADE {info['headers']}, installed YADE {info['yade']}"
    with tempfile.TemporaryDirectory() as tmp:
        env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "HOME": tmp, "YADE_PREFIX": prefix,
               "OMP_NUM_THREADS": "1"}
        try:
            p = subprocess.run(["yade", "-n", "-x", PROBE], cwd=tmp, env=env, capture_output=True, text=True,
                               timeout=SECONDS)
        except subprocess.TimeoutExpired:
            return f"stick-slip law: the compiled law's layout check did not finish in {SECONDS} s ({headers})"
    lines = [x for x in p.stdout.splitlines() if x.startswith("RESULT ")]
    if p.returncode != 0 or not lines:
        died = f"signal {-p.returncode}" if p.returncode < 0 else f"exit status {p.returncode}"
        last = (p.stderr.strip().splitlines() or p.stdout.strip().splitlines() or [""])[-1][:200]
        return (f"stick-slip law: the compiled law's layout check failed in YADE ({died}: {last}); it was built "
                f"with {headers}: rebuild it (./run.sh setup)")
    wrong = json.loads(lines[-1][7:])["mismatches"]
    if not wrong:
        return None
    first = wrong[0]
    more = f" (and {len(wrong) - 1} more)" if len(wrong) > 1 else ""
    return (f"stick-slip law: the compiled law reads {first['member']} as {shown(first, 'plugin')} where YADE has "
            f"{shown(first, 'yade')}{more}: its {headers} do not match this YADE's build; the compiled law is "
            f"refused (backend = 'python' runs the same law)")


# the pointer members the probe reads first (layout_probe.py): their values are addresses
POINTERS = ("Interaction.geom", "Interaction.phys", "Body.state", "Body.shape", "Scene.cell", "Scene.energy")


def shown(mismatch, side):
    """One side's value of a mismatch as the verdict prints it (an address in hex)."""
    value = mismatch[side]
    return hex(value) if mismatch["member"] in POINTERS and isinstance(value, int) else value


def verdict(prefix):
    """None if the plugin in PREFIX matches the installed YADE, else the one line saying why
    not. Checked once per build (the verdict is kept in PREFIX)."""
    if not prefix or not os.path.exists(os.path.join(prefix, "stickslip_build.json")):
        return ("stick-slip law: the compiled law's YADE prefix is not set (YADE_PREFIX): start YADE with "
                "build/yade_law/yade-stickslip")
    info = build_info(prefix)
    k = key(prefix, info)
    path = os.path.join(prefix, CACHE)
    try:
        with open(path) as f:
            kept = json.load(f)
        if kept["key"] == k:
            return kept["verdict"]
    except (OSError, ValueError, KeyError):
        pass
    v = probe(prefix, info)
    with open(path, "w") as f:
        json.dump({"key": k, "verdict": v}, f)
    return v


def main(argv):
    if len(argv) != 2:
        print("usage: python3 layout_check.py PREFIX", file=sys.stderr)
        return 2
    v = verdict(os.path.abspath(argv[1]))
    if v:
        print(v, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
