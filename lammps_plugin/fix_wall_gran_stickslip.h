/* SPDX-License-Identifier: GPL-2.0-or-later
   fix ID group wall/gran/stickslip hooke/history Kn Kt gamma_n gamma_t xmu dampflag
       [limit_damping] wallstyle args [wiggle|shear ...] [contacts] [keyword value ...]

   Stock wall/gran with its primitive walls (xplane, yplane, zplane, zcylinder) and motion
   keywords; the contact is wall_contact.h (stock's Hookean wall, the stick-slip law).
   Syntax and keywords: lammps_plugin/README.md. */

#ifndef STICKSLIP_FIX_WALL_GRAN_STICKSLIP_H
#define STICKSLIP_FIX_WALL_GRAN_STICKSLIP_H

#include "fix_wall_gran.h"
#include "wall_contact.h"

#include <string>
#include <vector>

namespace StickSlip {

/* The fix's arguments, checked (one error line naming the argument and its allowed range)
   and split: the law's keywords, and the rest for stock's FixWallGran. A base class of the
   fix, so that it is made before FixWallGran reads the arguments. */
class WallArguments {
 protected:
  WallArguments(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg);
  Settings parsed;                  // the law's keywords
  std::vector<std::string> words;   // stock's arguments
  std::vector<char *> stock_argv;   // pointers into words
  int stock_narg() const { return (int) stock_argv.size(); }
  char **stock_args() { return stock_argv.data(); }
};

class FixWallGranStickSlip : private WallArguments, public LAMMPS_NS::FixWallGran {
 public:
  static const char *const STYLE;  // "wall/gran/stickslip"

  FixWallGranStickSlip(LAMMPS_NS::LAMMPS *, int, char **);
  void post_force(int) override;

 protected:
  WallLaw wall;

  template <class Mode> void grains(double wlo, double whi, const double *vmove, bool stepping);
};

}  // namespace StickSlip

#endif
