/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: forget the options of deme_model/stick_slip.cu after one build of it
   (contact_step.cpp builds it several times, each with its own options). No include
   guard: it is meant to be included again. */
#undef STICKSLIP_HOOKE
#undef STICKSLIP_SWEEP
#undef STICKSLIP_EXACT
#undef STICKSLIP_RESET_TOTAL
#undef STICKSLIP_RECORD
