/* SPDX-License-Identifier: GPL-2.0-or-later
   The LAMMPS API the styles compile against. One source serves two LAMMPS versions:
   - Debian 12's LAMMPS (29 Sep 2021): the default, nothing defined;
   - LAMMPS 2 Aug 2023 and later (the granular refactor; built and tested here with 4 Feb 2025),
     as a plugin: lammps_plugin/CMakeLists.txt with LAMMPS_2025_DIR defines
     STICKSLIP_LAMMPS_VERSION (yyyymmdd, read from that LAMMPS' src/version.h).
   Where the two differ (pair_gran_hooke_stickslip.{h,cpp}):
   - Pair::transfer_history takes the two atoms' types too (2023: (double *, double *, int, int));
   - Comm::forward_comm_pair(Pair *) became the overload Comm::forward_comm(Pair *);
   - stock gran/hooke/history weighs each pair by special_lj (bonded grains, BPM package): a
     factor of 0 skips the pair, others scale its force and torque (1 for every pair that is not
     bonded, which changes no bit). */

#ifndef STICKSLIP_LAMMPS_API_H
#define STICKSLIP_LAMMPS_API_H

#ifndef STICKSLIP_LAMMPS_VERSION
#define STICKSLIP_LAMMPS_VERSION 20210929
#endif

#define STICKSLIP_MODERN_LAMMPS (STICKSLIP_LAMMPS_VERSION >= 20230802)

#endif
