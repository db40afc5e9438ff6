/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: counts of the paths through tangential stick_slip, for the cost analysis of
   where a contact-step's time goes (stickslip/bench/liggghts_paths.py). Never in the default
   build: the law's files carry no counter; the analysis build (liggghts_variants.py) writes
   copies of them with a STICK_SLIP_COUNT statement on each path and this file included,
   and is configured with `-DSTICK_SLIP_PATH_COUNTS=ON`. Every path taken by an evaluation that updates
   the history adds one to its counter, and the counts are written when the program ends, one
   "name count" line each, to the file named by the environment variable
   STICK_SLIP_PATH_COUNTS (else stderr). */

#ifndef STICK_SLIP_PATH_COUNTS_H_
#define STICK_SLIP_PATH_COUNTS_H_

#ifdef STICK_SLIP_PATH_COUNTS
#include <cstdio>
#include <cstdlib>

namespace LIGGGHTS {
namespace ContactModels {
namespace StickSlipPaths {

#define STICK_SLIP_PATHS(X) \
  X(CALL_PAIR)          /* law evaluations with a history update, grain pairs */ \
  X(CALL_WALL)          /* ... grain-wall */ \
  X(CALL_NO_UPDATE)     /* re-evaluations without history update (setup, computes) */ \
  X(STAMP_FRESH)        /* pair contact new at this pass: the stamp restarts its spring */ \
  X(TURN_NONE)          /* D already in the tangent plane (dn = 0: new springs, 2D) */ \
  X(TURN_SERIES)        /* keep-length turn by the series (x < 1e-6) */ \
  X(TURN_SQRT)          /* keep-length turn by the square root */ \
  X(STEP_STICK)         /* step timing: below the threshold */ \
  X(STEP_SLIP)          /* step timing: slip at the end of the step */ \
  X(EXACT_START_OVER)   /* exact timing: at or above the threshold at the step's start */ \
  X(EXACT_NO_SLIP)      /* exact timing E0: below the threshold at both ends */ \
  X(EXACT_E4_START)     /* exact timing: E4 at the step's start, decided in the law */ \
  X(EXACT_GENERAL)      /* exact timing: the general routine exact_slips */ \
  X(GEN_E1)             /* exact_slips: Fn = 0 */ \
  X(GEN_SLIP)           /* exact_slips: each slip followed (E3) */ \
  X(GEN_STICK_TO_END)   /* exact_slips: sticks to the end of the step after its last slip */ \
  X(GEN_E4)             /* exact_slips: slides after a slip (E4) */ \
  X(GEN_E5)             /* exact_slips: rate = 0 */ \
  X(GEN_E6)             /* exact_slips: plastic flow */ \
  X(GEN_E7)             /* exact_slips: settled or MAX_EXPLICIT_SLIPS, closed form */

enum Path {
#define STICK_SLIP_PATH_ENUM(name) name,
  STICK_SLIP_PATHS(STICK_SLIP_PATH_ENUM)
#undef STICK_SLIP_PATH_ENUM
  NPATHS
};

inline unsigned long long counts[NPATHS];
inline bool counting = false;  // set by the law: only evaluations that update the history count

struct Report {
  ~Report()
  {
    static const char * const names[] = {
#define STICK_SLIP_PATH_NAME(name) #name,
      STICK_SLIP_PATHS(STICK_SLIP_PATH_NAME)
#undef STICK_SLIP_PATH_NAME
    };
    const char * path = std::getenv("STICK_SLIP_PATH_COUNTS");
    FILE * f = path ? std::fopen(path, "w") : stderr;
    if (!f) f = stderr;
    for (int k = 0; k < NPATHS; k++) std::fprintf(f, "%s %llu\n", names[k], counts[k]);
    if (f != stderr) std::fclose(f);
  }
};
inline Report report;

}
}
}

#define STICK_SLIP_COUNTING(on) (LIGGGHTS::ContactModels::StickSlipPaths::counting = (on))
#define STICK_SLIP_COUNT(path) \
  (LIGGGHTS::ContactModels::StickSlipPaths::counts[LIGGGHTS::ContactModels::StickSlipPaths::path] += \
   LIGGGHTS::ContactModels::StickSlipPaths::counting)
#endif

#endif
