/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: the project's version, for the C++ plugins' start-up line (LIGGGHTS and LAMMPS).
   pyproject.toml holds the version; this copy is there because the C++ needs it at compile
   time, and tests/test_release.py checks that the two agree. */

#ifndef STICKSLIP_VERSION_H
#define STICKSLIP_VERSION_H

#define STICKSLIP_VERSION "1.0.0"

#endif
