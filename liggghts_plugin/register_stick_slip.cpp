/* Registers `tangential stick_slip` with the installed LIGGGHTS library when this
   shared object is loaded (static initializer): the model name, and one pair style and
   one wall style for every combination of surface, normal, cohesion and rolling model
   that the library itself offers with stock `tangential history`. That list is read
   from the library's symbols when the plugin is configured (CMakeLists.txt writes it to
   stick_slip_combinations.h); the styles are compiled and registered in register_combinations.cpp.
   Every other combination with stick_slip is registered too, as a creator that stops
   with an error naming the refused part and the command that asked for it (the library
   would otherwise say only "Unknown tangential model"). */

#include "stick_slip_styles.h"
#include <cstdio>
#include <set>
#include <string>

using namespace LIGGGHTS;
using namespace LIGGGHTS::ContactModels;

namespace {

struct Named { int id; const char * name; };

const Named NORMAL[] = {
#define NORMAL_MODEL(CONST, NAME, ID) { CONST, #NAME },
#include "style_normal_model.h"
#undef NORMAL_MODEL
};
const Named COHESION[] = {
#define COHESION_MODEL(CONST, NAME, ID) { CONST, #NAME },
#include "style_cohesion_model.h"
#undef COHESION_MODEL
};
const Named ROLLING[] = {
#define ROLLING_MODEL(CONST, NAME, ID) { CONST, #NAME },
#include "style_rolling_model.h"
#undef ROLLING_MODEL
};
const Named SURFACE[] = {
#define SURFACE_MODEL(CONST, NAME, ID) { CONST, #NAME },
#include "style_surface_model.h"
#undef SURFACE_MODEL
};

template<size_t N>
std::string name_of(const Named (&list)[N], int id, const char * off)
{
  for (size_t k = 0; k < N; k++)
    if (list[k].id == id) return list[k].name;
  return off;
}

struct Combo { int m, c, r, s; bool pair, wall; };

// the library's own combinations with tangential history (generated at configure time)
const Combo SUPPORTED[] = {
#define STICK_SLIP_COMBINATION(M, C, R, S, PAIR, WALL) { M, C, R, S, PAIR, WALL },
#include "stick_slip_combinations.h"
#undef STICK_SLIP_COMBINATION
};
const size_t NSUPPORTED = sizeof SUPPORTED / sizeof *SUPPORTED;

/* The part of a refused combination that stock history never comes with (or the
   combination itself when each part does, but not together). */
std::string refused_part(int64_t hash, bool wall)
{
  const int m = hash & 63, c = (hash >> 12) & 63, r = (hash >> 18) & 63, s = (hash >> 24) & 63;
  bool m_ok = false, c_ok = false, r_ok = false, s_ok = false;
  for (size_t k = 0; k < NSUPPORTED; k++) {
    const Combo & x = SUPPORTED[k];
    if (!(wall ? x.wall : x.pair)) continue;
    m_ok |= x.m == m; c_ok |= x.c == c; r_ok |= x.r == r; s_ok |= x.s == s;
  }
  const std::string M = "model " + name_of(NORMAL, m, "off"), C = "cohesion " + name_of(COHESION, c, "off"),
                    R = "rolling_friction " + name_of(ROLLING, r, "off"), S = "surface " + name_of(SURFACE, s, "default");
  std::string parts;
  if (!m_ok) parts += (parts.empty() ? "" : ", ") + M;
  if (!c_ok) parts += (parts.empty() ? "" : ", ") + C;
  if (!r_ok) parts += (parts.empty() ? "" : ", ") + R;
  if (!s_ok) parts += (parts.empty() ? "" : ", ") + S;
  if (!parts.empty()) return parts + " (not built with tangential history in this LIGGGHTS either)";
  return "the combination " + M + ", " + C + ", " + R + ", " + S +
         " (each part exists, but this LIGGGHTS has no tangential history built with them together)";
}

void refuse(LAMMPS * lmp, const std::string & command, int64_t hash, bool wall)
{
  const std::string msg = command + ": tangential stick_slip cannot be combined with " + refused_part(hash, wall) +
      "; it supports the combinations this LIGGGHTS builds with tangential history";
  lmp->error->all(FLERR, msg.c_str());
}

PairStyles::IGranularPairStyle * unsupported_pair(LAMMPS * lmp, PairGran *, int64_t hash)
{
  refuse(lmp, "pair_style gran", hash, false);
  return NULL;
}

Walls::IGranularWall * unsupported_wall(LAMMPS * lmp, FixWallGran * parent, int64_t hash)
{
  refuse(lmp, std::string("fix ") + parent->id + " " + parent->style, hash, true);
  return NULL;
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
    // every other combination with stick_slip stops with an error
    for (size_t m = 0; m <= sizeof NORMAL / sizeof *NORMAL; m++)
      for (size_t c = 0; c <= sizeof COHESION / sizeof *COHESION; c++)
        for (size_t r = 0; r <= sizeof ROLLING / sizeof *ROLLING; r++)
          for (size_t s = 0; s < sizeof SURFACE / sizeof *SURFACE; s++) {
            const int mid = m ? NORMAL[m - 1].id : NORMAL_OFF, cid = c ? COHESION[c - 1].id : COHESION_OFF,
                      rid = r ? ROLLING[r - 1].id : ROLLING_OFF;
            const int64_t hash = Utils::generate_gran_hashcode(mid, TANGENTIAL_STICK_SLIP, cid, rid, SURFACE[s].id);
            if (!pair.count(hash)) PairStyles::Factory::instance().addStyle("gran", hash, &unsupported_pair);
            if (!wall.count(hash)) Walls::Factory::instance().addStyle("gran", hash, &unsupported_wall);
          }
  }
};

RegisterStickSlip register_stick_slip;

}
