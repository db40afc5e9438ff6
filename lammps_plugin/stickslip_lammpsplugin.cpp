/* SPDX-License-Identifier: GPL-2.0-or-later
   pair_style gran/hooke/stickslip as a plugin of LAMMPS 2023 and later (LAMMPS' PLUGIN
   package): `plugin load .../libstickslip_lammps2025.so` registers the style, and
   `plugin list` shows it. The pair style's source is the one Debian's LAMMPS runs
   (pair_gran_hooke_stickslip.cpp; lammps_api.h says where the two APIs differ). The wall
   fixes are not part of it: on these versions `fix wall/gran granular ... tangential
   stick_slip` (lammps_plugin/granular/) gives the law on walls (lammps_plugin/README.md,
   "On LAMMPS built from source"). Built by lammps_plugin/CMakeLists.txt with LAMMPS_2025_DIR. */

#include "pair_gran_hooke_stickslip.h"
#include "stickslip_version.h"

#include "version.h"

// lammpsplugin_init is looked up by dlsym: visible, while the rest of the library is hidden
#pragma GCC visibility push(default)
#include "lammpsplugin.h"
#pragma GCC visibility pop

using namespace LAMMPS_NS;

namespace {

Pair *make_pair(LAMMPS *lmp) { return new StickSlip::PairGranHookeStickSlip(lmp); }

}  // namespace

extern "C" void lammpsplugin_init(void *lmp, void *handle, void *regfunc)
{
  lammpsplugin_t plugin;
  plugin.version = LAMMPS_VERSION;  // the LAMMPS it was built for (LAMMPS prints both if they differ)
  plugin.style = "pair";
  plugin.name = StickSlip::PairGranHookeStickSlip::STYLE;
  plugin.info = "stickslip " STICKSLIP_VERSION ": gran/hooke/stickslip (Khellaf & Mansouri 2024)";
  plugin.author = "the stickslip project";
  plugin.creator.v1 = (lammpsplugin_factory1 *) &make_pair;
  plugin.handle = handle;
  (*(lammpsplugin_regfunc) regfunc)(&plugin, lmp);
}
