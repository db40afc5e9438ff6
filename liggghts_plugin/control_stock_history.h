/* SPDX-License-Identifier: GPL-2.0-or-later
   A control for the overhead benchmark (issue 32), never the shipped model: built with
   -DSTICK_SLIP_CONTROL_STOCK, `tangential stick_slip` runs LIGGGHTS' own `tangential
   history` (its class from Debian's header, unchanged), compiled into this plugin as the
   law is. Timed against the stock model in Debian's library, it shows what the plugin's
   build and place (compiler flags, a separate shared object, its own template instances
   of the pair loop) cost without any of the law's arithmetic:
     cmake -S liggghts_plugin -B build/liggghts_control -DCMAKE_CXX_FLAGS=-DSTICK_SLIP_CONTROL_STOCK
     python -m stickslip.bench.liggghts --control build/liggghts_control/liggghts-stickslip
   The settings stick_slip alone has (exact_slip_timing, ...) are refused by this build. */

template<>
class TangentialModel<TANGENTIAL_STICK_SLIP> : public TangentialModel<TANGENTIAL_HISTORY>
{
public:
  TangentialModel(LAMMPS * lmp, IContactHistorySetup * hsetup, class ContactModelBase * c) :
    TangentialModel<TANGENTIAL_HISTORY>(lmp, hsetup, c) {}
};
