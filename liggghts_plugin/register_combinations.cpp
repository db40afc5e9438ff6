/* SPDX-License-Identifier: GPL-2.0-or-later
   Compiles and registers a share of the pair and wall styles of stick_slip: the
   combinations listed in stick_slip_combinations.h (generated from the library's own
   `tangential history` combinations) whose place in the list is STICK_SLIP_PART modulo
   STICK_SLIP_PARTS. CMakeLists.txt builds this file once per part, so that the
   template instantiations (the bulk of the build time) spread over the build's jobs. */

#include "stick_slip_styles.h"

#ifndef STICK_SLIP_PART
#define STICK_SLIP_PART 0
#define STICK_SLIP_PARTS 1
#endif

namespace {

using namespace LIGGGHTS::StickSlip;

template<bool Mine, int M, int C, int R, int S>
struct AddIf { static void run(bool, bool) {} };

template<int M, int C, int R, int S>
struct AddIf<true, M, C, R, S> { static void run(bool pair, bool wall) { Combination<M, C, R, S>::add(pair, wall); } };

struct RegisterPart {
  RegisterPart()
  {
#define STICK_SLIP_COMBINATION(M, C, R, S, PAIR, WALL) \
    AddIf<(__COUNTER__ % STICK_SLIP_PARTS) == STICK_SLIP_PART, M, C, R, S>::run(PAIR, WALL);
#include "stick_slip_combinations.h"
#undef STICK_SLIP_COMBINATION
  }
};

RegisterPart register_part;

}
