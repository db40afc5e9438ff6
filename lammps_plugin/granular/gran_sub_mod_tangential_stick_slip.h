/* -*- c++ -*- ----------------------------------------------------------
   SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: the stick-slip tangential law of Khellaf & Mansouri (2024) as a tangential
   sub-model of LAMMPS' granular model (LAMMPS 2Aug2023 and later): `tangential stick_slip`
   in pair_style granular, fix wall/gran granular and fix wall/gran/region granular.
   Copy this folder's files into LAMMPS' src/GRANULAR/ before building LAMMPS
   (lammps_plugin/doc/gran_sub_mod_tangential_stick_slip.md).
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
// The name's suffixes, in this order, choose the law's options, each combination a class of
// its own (the options fixed when it is compiled, so that a contact-step tests none of them):
//   /total   eq. 8's reset holds spring + dashpot at Fmin (default: the spring alone)
//   /exact   every slip at its time inside the step (default: tested at the step's end)
//   /record  the contact keeps what the law applied, its slip count and dissipated work
GranSubModStyle(stick_slip,GranSubModTangentialStickSlipPlain,TANGENTIAL);
GranSubModStyle(stick_slip/record,GranSubModTangentialStickSlipRecord,TANGENTIAL);
GranSubModStyle(stick_slip/exact,GranSubModTangentialStickSlipExact,TANGENTIAL);
GranSubModStyle(stick_slip/exact/record,GranSubModTangentialStickSlipExactRecord,TANGENTIAL);
GranSubModStyle(stick_slip/total,GranSubModTangentialStickSlipTotal,TANGENTIAL);
GranSubModStyle(stick_slip/total/record,GranSubModTangentialStickSlipTotalRecord,TANGENTIAL);
GranSubModStyle(stick_slip/total/exact,GranSubModTangentialStickSlipTotalExact,TANGENTIAL);
GranSubModStyle(stick_slip/total/exact/record,GranSubModTangentialStickSlipTotalExactRecord,TANGENTIAL);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_TANGENTIAL_STICK_SLIP_H
#define GRAN_SUB_MOD_TANGENTIAL_STICK_SLIP_H

#include "gran_sub_mod_tangential.h"

namespace LAMMPS_NS {
namespace Granular_NS {

  /* Coefficients (the sub-model's argument list): Ks (force/distance, or NULL: Mindlin's
     8 G* a from the normal model's material properties), x_gamma,t (the tangential dashpot
     as a multiple of the damping model's prefactor, as linear_history's), mu_s, mu_k. */
  class GranSubModTangentialStickSlip : public GranSubModTangential {
   public:
    // record: the history keeps the record too (/record); the other options are step()'s
    GranSubModTangentialStickSlip(class GranularModel *, class LAMMPS *, bool record);
    void coeffs_to_local() override;
    void mix_coeffs(double *, double *) override;

    // the contact's history: the spring D, then with /record what the law last applied
    enum { HIST_D = 0, SIZE_PLAIN = 3, HIST_FN = 3, HIST_FS = 4, HIST_NSLIP = 7, HIST_WORK = 8, SIZE_RECORD = 9 };
    // with /record, the values each contact reports (compute pair/local p13-p18, the
    // wall fixes' per-atom columns 9-14): Fn, F_s on i (3), slips, work
    enum { NRECORD = 6 };

   protected:
    double xt;                                // tangential damping, a multiple of the damping prefactor
    double kin;                               // 2 mu_k - mu_s: Fmin = kin Fn (eq. 8; exactly mu_s when mu_k = mu_s)
    double ratio;                             // Fmin/T = kin/mu_s (exact timing)
    bool mindlin;                             // Ks = k * contact radius (coefficient NULL)

    // one force evaluation with the options fixed (the .cpp compiles the eight)
    template <bool TOTAL, bool EXACT, bool RECORD> void step();
    void report_record(const double *history);
  };

  /* The sub-model with the options of its name (GranSubModStyle above). */
  template <bool TOTAL, bool EXACT, bool RECORD>
  class GranSubModTangentialStickSlipWith : public GranSubModTangentialStickSlip {
   public:
    GranSubModTangentialStickSlipWith(class GranularModel *gm, class LAMMPS *lmp) :
        GranSubModTangentialStickSlip(gm, lmp, RECORD)
    {
    }
    void calculate_forces() override;
  };

  // (one name each: the style registry's macro takes no template arguments)
  typedef GranSubModTangentialStickSlipWith<false, false, false> GranSubModTangentialStickSlipPlain;
  typedef GranSubModTangentialStickSlipWith<false, false, true> GranSubModTangentialStickSlipRecord;
  typedef GranSubModTangentialStickSlipWith<false, true, false> GranSubModTangentialStickSlipExact;
  typedef GranSubModTangentialStickSlipWith<false, true, true> GranSubModTangentialStickSlipExactRecord;
  typedef GranSubModTangentialStickSlipWith<true, false, false> GranSubModTangentialStickSlipTotal;
  typedef GranSubModTangentialStickSlipWith<true, false, true> GranSubModTangentialStickSlipTotalRecord;
  typedef GranSubModTangentialStickSlipWith<true, true, false> GranSubModTangentialStickSlipTotalExact;
  typedef GranSubModTangentialStickSlipWith<true, true, true> GranSubModTangentialStickSlipTotalExactRecord;

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
