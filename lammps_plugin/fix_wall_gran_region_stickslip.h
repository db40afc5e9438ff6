/* SPDX-License-Identifier: GPL-2.0-or-later
   fix ID group wall/gran/region/stickslip hooke/history Kn Kt gamma_n gamma_t xmu dampflag
       [limit_damping] region regionID [contacts] [keyword value ...]

   Stock wall/gran/region with a Hookean history wall whose tangential force is the
   stick-slip law (wall_contact.h, the same contact as wall/gran/stickslip). Any region
   style, moving or turning (`region ... move v_x v_y v_z`, `rotate v_theta P R`): LAMMPS'
   Region gives each contact its nearest surface point and the wall's rigid velocity there.
   Syntax and keywords: lammps_plugin/README.md. */

#ifndef STICKSLIP_FIX_WALL_GRAN_REGION_STICKSLIP_H
#define STICKSLIP_FIX_WALL_GRAN_REGION_STICKSLIP_H

#include "fix_wall_gran_region.h"
#include "wall_contact.h"

#include <string>
#include <vector>

namespace StickSlip {

/* The fix's arguments, checked (one error line naming the argument and its allowed range)
   and split: the law's keywords, and the rest for stock's FixWallGranRegion. A base class
   of the fix, so that it is made before stock reads the arguments. */
class RegionWallArguments {
 protected:
  RegionWallArguments(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg);
  Settings parsed;
  std::vector<std::string> words;
  std::vector<char *> stock_argv;
  int stock_narg() const { return (int) stock_argv.size(); }
  char **stock_args() { return stock_argv.data(); }
};

/* Stock FixWallGranRegion keeps its contacts' histories in private arrays that its own
   post_force() fills; this fix keeps its own (a history of the law's size per contact,
   keyed by the region's wall index as stock keys them) and does everything per atom that
   touches them: growing, copying, migrating between ranks, restart files. From stock it
   takes the arguments, the region look-up and check at init, and the region's motion in
   restart files. */
class FixWallGranRegionStickSlip : private RegionWallArguments, public LAMMPS_NS::FixWallGranRegion {
 public:
  static const char *const STYLE;  // "wall/gran/region/stickslip"

  FixWallGranRegionStickSlip(LAMMPS_NS::LAMMPS *, int, char **);
  ~FixWallGranRegionStickSlip() override;
  void init() override;
  void post_force(int) override;
  double memory_usage() override;
  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

 protected:
  WallLaw wall;
  LAMMPS_NS::Region *region;
  int slots;        // contacts one grain can have with the region (its tmax)
  int *ncontacts;   // per atom: contacts with history
  int **wall_of;    // per atom and contact: the region's wall index (Region::Contact::iwall)
  double **hist;    // per atom: slots x size_history values
  // one atom's histories and walls while they are matched to its new contacts
  std::vector<double> scratch;
  std::vector<int> scratch_walls;

  void match_contacts(int i, int nc);
};

}  // namespace StickSlip

#endif
