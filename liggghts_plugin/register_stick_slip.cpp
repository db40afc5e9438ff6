/* SPDX-License-Identifier: GPL-2.0-or-later
   Registers `tangential stick_slip` with the installed LIGGGHTS library when this
   shared object is loaded (static initializer): the model name, and one pair style and
   one wall style for every combination of surface, normal, cohesion and rolling model
   that the library itself offers with stock `tangential history`. That list is read
   from the library's symbols when the plugin is configured (CMakeLists.txt writes it to
   stick_slip_combinations.h); the styles are compiled and registered in register_combinations.cpp.
   Every other combination with stick_slip runs through LIGGGHTS' generic contact model,
   as stock history's do (model off, which cannot work, stops with an error naming it and
   the command that asked for it). */

#include "stick_slip_styles.h"
#include <cstdio>
#include <set>
#include <string>

using namespace LIGGGHTS;
using namespace LIGGGHTS::ContactModels;

namespace {

// the model ids this LIGGGHTS knows (its installed model headers)
const int NORMAL[] = {
#define NORMAL_MODEL(CONST, NAME, ID) CONST,
#include "style_normal_model.h"
#undef NORMAL_MODEL
};
const int COHESION[] = {
#define COHESION_MODEL(CONST, NAME, ID) CONST,
#include "style_cohesion_model.h"
#undef COHESION_MODEL
};
const int ROLLING[] = {
#define ROLLING_MODEL(CONST, NAME, ID) CONST,
#include "style_rolling_model.h"
#undef ROLLING_MODEL
};
const int SURFACE[] = {
#define SURFACE_MODEL(CONST, NAME, ID) CONST,
#include "style_surface_model.h"
#undef SURFACE_MODEL
};

struct Combo { int m, c, r, s; bool pair, wall; };

// the library's own combinations with tangential history (generated at configure time)
const Combo SUPPORTED[] = {
#define STICK_SLIP_COMBINATION(M, C, R, S, PAIR, WALL) { M, C, R, S, PAIR, WALL },
#include "stick_slip_combinations.h"
#undef STICK_SLIP_COMBINATION
};
const size_t NSUPPORTED = sizeof SUPPORTED / sizeof *SUPPORTED;

/* A combination the library has no compiled-in version of: LIGGGHTS runs those through its
   generic contact model, which picks each part at run time (and warns that it is slower);
   stock history does so for every combination outside its list. stick_slip does the same
   with its own copy of the generic model (it knows stick_slip). The one combination that
   cannot work is the one without a normal model: stick_slip takes Fn, Ks and nu_s from it. */
typedef ContactModel<GranStyle<> > Generic;

void refuse_without_normal_model(LAMMPS * lmp, const std::string & command)
{
  const std::string msg = command + ": tangential stick_slip cannot be combined with model off (no normal "
      "model): it takes Fn, kt and the tangential damping from the normal model";
  lmp->error->all(FLERR, msg.c_str());
}

PairStyles::IGranularPairStyle * generic_pair(LAMMPS * lmp, PairGran * parent, int64_t hash)
{
  if ((hash & 63) == NORMAL_OFF) refuse_without_normal_model(lmp, "pair_style gran");
  return new LIGGGHTS::StickSlip::PairStyle<Generic>(lmp, parent, hash);
}

Walls::IGranularWall * generic_wall(LAMMPS * lmp, FixWallGran * parent, int64_t hash)
{
  if ((hash & 63) == NORMAL_OFF) refuse_without_normal_model(lmp, std::string("fix ") + parent->id + " " + parent->style);
  return new LIGGGHTS::StickSlip::WallStyle<Generic>(lmp, parent, hash);
}

struct RegisterStickSlip {
  RegisterStickSlip()
  {
    // LIGGGHTS stops on an error of one process with MPI_Abort, which drops what is still
    // buffered: with stdout redirected to a file or pipe the ERROR line would be lost.
    // Line buffering writes each line out at once (nothing has been printed yet here).
    setvbuf(stdout, NULL, _IOLBF, BUFSIZ);

    Factory::instance().addTangentialModel("stick_slip", TANGENTIAL_STICK_SLIP);
    // the supported combinations register themselves (register_combinations.cpp)

    std::set<int64_t> pair, wall;
    for (size_t k = 0; k < NSUPPORTED; k++) {
      const Combo & x = SUPPORTED[k];
      const int64_t hash = Utils::generate_gran_hashcode(x.m, TANGENTIAL_STICK_SLIP, x.c, x.r, x.s);
      if (x.pair) pair.insert(hash);
      if (x.wall) wall.insert(hash);
    }
    // every other combination with stick_slip: the generic model (or an error, see above)
    for (size_t m = 0; m <= sizeof NORMAL / sizeof *NORMAL; m++)
      for (size_t c = 0; c <= sizeof COHESION / sizeof *COHESION; c++)
        for (size_t r = 0; r <= sizeof ROLLING / sizeof *ROLLING; r++)
          for (size_t s = 0; s < sizeof SURFACE / sizeof *SURFACE; s++) {
            const int mid = m ? NORMAL[m - 1] : NORMAL_OFF, cid = c ? COHESION[c - 1] : COHESION_OFF,
                      rid = r ? ROLLING[r - 1] : ROLLING_OFF;
            const int64_t hash = Utils::generate_gran_hashcode(mid, TANGENTIAL_STICK_SLIP, cid, rid, SURFACE[s]);
            if (!pair.count(hash)) PairStyles::Factory::instance().addStyle("gran", hash, &generic_pair);
            if (!wall.count(hash)) Walls::Factory::instance().addStyle("gran", hash, &generic_wall);
          }
  }
};

RegisterStickSlip register_stick_slip;

}
