# SPDX-License-Identifier: GPL-2.0-or-later
"""The compiler definitions that make YADE's headers describe the installed YADE.

YADE's classes change their members with its build's features (YADE_OPENMP adds per-thread
force buffers, YADE_MPI a body's subdomain, ...), so a plugin must be compiled with the
definitions the installed YADE was built with. The installed YADE says which features it has
(its config.py: `features`, the precision); FEATURES maps each to the definitions YADE's own
CMakeLists.txt adds for it. A feature missing from the table stops the build: a new feature
may change a class, and guessing would make a plugin that reads the wrong members.

Run with the system's python3 (no YADE import, which would start YADE):
    python3 yade_law/compiled/yade_flags.py [--config PATH] [--without FEATURE]
prints the definitions, one per line (the CMake build reads them); --version prints the
installed version, --libdir where its plugins are, below its prefix. --without leaves a feature's definitions out (the layout check's test
builds a plugin for the wrong YADE that way).
"""
import argparse
import importlib.util
import os
import sys

CONFIG = "/usr/lib/x86_64-linux-gnu/yade-double/py/yade/config.py"

# YADE's CMakeLists.txt (2025.2.0): each configured feature and the definitions it adds
FEATURES = {
    "LOGGER": ["YADE_BOOST_LOG", "BOOST_LOG_DYN_LINK"],
    "USEFUL_ERRORS": [],  # compiler warnings only
    "COMPLEX_MP": ["YADE_COMPLEX_MP"],
    "VTK": ["YADE_VTK"],
    "OPENMP": ["YADE_OPENMP"],
    "GTS": ["YADE_GTS"],
    "QT5": ["YADE_OPENGL", "YADE_QT5", "QT_NO_KEYWORDS"],
    "CGAL": ["YADE_CGAL", "CGAL_DISABLE_ROUNDING_MATH_CHECK"],
    "PFVFLOW": ["FLOW_ENGINE"],
    "LINSOLV": ["LINSOLV"],
    "MPI": ["YADE_MPI"],
    "TWOPHASEFLOW": ["TWOPHASEFLOW"],
    "SPH": ["YADE_SPH"],
    "LS_DEM": ["YADE_LS_DEM"],
    "DEFORM": ["YADE_DEFORM"],
    "FEMLIKE": ["YADE_FEM"],
    "LIQMIGRATION": ["YADE_LIQMIGRATION"],
    "GL2PS": ["YADE_GL2PS"],
    "LBMFLOW": ["LBM_ENGINE"],
    "MASK_ARBITRARY": ["YADE_MASK_ARBITRARY"],
    "THERMAL": ["THERMAL"],
    "PARTIALSAT": ["PARTIALSAT"],
    "PROFILING": ["USE_TIMING_DELTAS", "ISC_TIMING"],
    "POTENTIAL_PARTICLES": ["YADE_POTENTIAL_PARTICLES"],
    "POTENTIAL_BLOCKS": ["YADE_POTENTIAL_BLOCKS"],
    "MPFR": ["YADE_MPFR"],
    "VECTORIZE": [],  # (its absence adds the three EIGEN_ definitions below)
}
# Always, in YADE's CMakeLists.txt: Boost's odeint is found (Boost >= 1.53) and the log level
# is the default's; without VECTORIZE Eigen's vectors are unaligned (3 doubles, as YADE's
# ForceContainer asserts)
ALWAYS = ["YADE_ODEINT", "MAX_LOG_LEVEL=5"]
NOT_VECTORIZED = ["EIGEN_DONT_VECTORIZE", "EIGEN_DONT_ALIGN", "EIGEN_DISABLE_UNALIGNED_ARRAY_ASSERT"]


def read_config(path=CONFIG):
    """The installed YADE's config.py, read as a plain module (importing the yade package
    would start YADE)."""
    spec = importlib.util.spec_from_file_location("yade_installed_config", path)
    module = importlib.util.module_from_spec(spec)
    os.environ.setdefault("HOME", "/tmp")  # (config.py reads it)
    spec.loader.exec_module(module)
    return module


def definitions(config, without=()):
    """The -D definitions for the installed YADE's features (ValueError for a feature the
    table does not know)."""
    features = [f for f in config.features if f]
    unknown = sorted(set(features) - set(FEATURES))
    if unknown:
        raise ValueError(f"the installed YADE {config.version} has feature(s) {', '.join(unknown)} that "
                         f"yade_law/compiled/yade_flags.py does not know: add the definitions YADE's "
                         f"CMakeLists.txt gives them to FEATURES")
    out = []
    for f in dict.fromkeys(features):  # (config lists PFVFLOW twice)
        if f not in without:
            out += FEATURES[f]
    if "VECTORIZE" not in features:
        out += NOT_VECTORIZED
    out += ALWAYS
    out += [f"YADE_REAL_BIT={config.highPrecisionBits}", f"YADE_REAL_DEC={config.highPrecisionDecimalPlaces}"]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=CONFIG, help="the installed YADE's config.py")
    ap.add_argument("--without", action="append", default=[], metavar="FEATURE",
                    help="leave this feature's definitions out (a plugin for another YADE)")
    ap.add_argument("--version", action="store_true", help="print the installed YADE's version")
    ap.add_argument("--libdir", action="store_true",
                    help="print the folder of the installed YADE's plugins, relative to its prefix")
    a = ap.parse_args(argv)
    if not os.path.exists(a.config):
        print(f"yade_flags: no YADE installed ({a.config} not found)", file=sys.stderr)
        return 2
    config = read_config(a.config)
    if a.version:
        print(config.version)
        return 0
    if a.libdir:  # (config.libDir is prefix + libPATH + /yade + suffix; YADE_PREFIX moves the prefix)
        print(f"{config.libPATH}/yade{config.suffix}")
        return 0
    try:
        print("\n".join(definitions(config, set(a.without))))
    except ValueError as e:
        print(f"yade_flags: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
