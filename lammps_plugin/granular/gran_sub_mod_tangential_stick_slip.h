/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   Copyright (2003) Sandia Corporation.  Under the terms of Contract
   DE-AC04-94AL85000 with Sandia Corporation, the U.S. Government retains
   certain rights in this software.  This software is distributed under
   the GNU General Public License.

   See the README file in the top-level LAMMPS directory.
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
GranSubModStyle(stick_slip,GranSubModTangentialStickSlip,TANGENTIAL);
GranSubModStyle(stick_slip/record,GranSubModStickSlipRecord,TANGENTIAL);
GranSubModStyle(stick_slip/exact,GranSubModStickSlipExact,TANGENTIAL);
GranSubModStyle(stick_slip/exact/record,GranSubModStickSlipExactRecord,TANGENTIAL);
GranSubModStyle(stick_slip/total,GranSubModStickSlipTotal,TANGENTIAL);
GranSubModStyle(stick_slip/total/record,GranSubModStickSlipTotalRecord,TANGENTIAL);
GranSubModStyle(stick_slip/total/exact,GranSubModStickSlipTotalExact,TANGENTIAL);
GranSubModStyle(stick_slip/total/exact/record,GranSubModStickSlipTotalExactRecord,TANGENTIAL);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_TANGENTIAL_STICK_SLIP_H
#define GRAN_SUB_MOD_TANGENTIAL_STICK_SLIP_H

#include "gran_sub_mod_tangential.h"

namespace LAMMPS_NS::Granular_NS {

class GranSubModTangentialStickSlip : public GranSubModTangential {
 public:
  // options of the style's name: /total, /exact, /record
  enum { TOTAL = 1, EXACT = 2, RECORD = 4 };

  GranSubModTangentialStickSlip(class GranularModel *, class LAMMPS *, int options = 0);
  void coeffs_to_local() override;
  void mix_coeffs(double *, double *) override;
  void calculate_forces() override;

  // history: the spring (3 values), then with /record the last normal force, the last
  // tangential force (3 values), the number of slips and the dissipated work
  enum { HIST_FN = 3, HIST_FS = 4, HIST_NSLIP = 7, HIST_WORK = 8, SIZE_RECORD = 9 };

 protected:
  int reset_total, exact_timing, record;
  int mindlin;     // Ks given as NULL: k is Mindlin's stiffness per unit contact radius
  double xt;       // tangential damping as a multiple of the damping prefactor
  double kin;      // 2 mu_k - mu_s: the force after a slip is kin Fn
  double ratio;    // kin / mu_s

  void report_record(const double *);
  // the force for one contact, the options as compile-time constants (each variant's
  // calculate_forces)
  template <int OPTIONS> void forces();
};

/* ----------------------------------------------------------------------
     the variants of the style's name (their names leave out "Tangential", for 100 columns)
  ------------------------------------------------------------------------- */

class GranSubModStickSlipRecord : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipRecord(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, RECORD){};
  void calculate_forces() override;
};

class GranSubModStickSlipExact : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipExact(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, EXACT){};
  void calculate_forces() override;
};

class GranSubModStickSlipExactRecord : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipExactRecord(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, EXACT | RECORD){};
  void calculate_forces() override;
};

class GranSubModStickSlipTotal : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipTotal(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, TOTAL){};
  void calculate_forces() override;
};

class GranSubModStickSlipTotalRecord : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipTotalRecord(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, TOTAL | RECORD){};
  void calculate_forces() override;
};

class GranSubModStickSlipTotalExact : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipTotalExact(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, TOTAL | EXACT){};
  void calculate_forces() override;
};

class GranSubModStickSlipTotalExactRecord : public GranSubModTangentialStickSlip {
 public:
  GranSubModStickSlipTotalExactRecord(class GranularModel *gm, class LAMMPS *lmp) :
      GranSubModTangentialStickSlip(gm, lmp, TOTAL | EXACT | RECORD){};
  void calculate_forces() override;
};

}    // namespace LAMMPS_NS::Granular_NS

#endif
#endif
