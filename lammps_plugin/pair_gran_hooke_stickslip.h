/* SPDX-License-Identifier: GPL-2.0-or-later
   pair_style gran/hooke/stickslip: stock gran/hooke/history's arguments and meaning,
   with the stick-slip law (stick_slip_law.h) for the tangential force.
   Syntax and keywords: lammps_plugin/README.md. */

#ifndef STICKSLIP_PAIR_GRAN_HOOKE_STICKSLIP_H
#define STICKSLIP_PAIR_GRAN_HOOKE_STICKSLIP_H

#include "lammps_api.h"
#include "pair_gran_hooke_history.h"
#include "stick_slip_law.h"

namespace StickSlip {

class PairGranHookeStickSlip : public LAMMPS_NS::PairGranHookeHistory {
 public:
  static const char *const STYLE;  // "gran/hooke/stickslip"

  explicit PairGranHookeStickSlip(LAMMPS_NS::LAMMPS *);
  ~PairGranHookeStickSlip() override;
  void compute(int, int) override;
  void settings(int, char **) override;
  void coeff(int, char **) override;
  void init_style() override;
  double init_one(int, int) override;
  void write_restart(FILE *) override;
  void read_restart(FILE *) override;
  void write_restart_settings(FILE *) override;
  void read_restart_settings(FILE *) override;
  double single(int, int, int, int, double, double, double, double &) override;
#if STICKSLIP_MODERN_LAMMPS
  void transfer_history(double *, double *, int, int) override;
#else
  void transfer_history(double *, double *) override;
#endif

 protected:
  Settings law;
  int history_made;  // values per contact of the history fix once made (0: not yet)
  // per type pair: mu_s and mu_k given by pair_coeff (< 0: not given), and the coefficients
  // in use (init_one)
  double **mu_s_given, **mu_k_given;
  Coeffs **coeffs;

  template <class Mode, bool STEPPING> void contacts();
  void allocate_law();
  void pair_coefficients(int i, int j, double &mu_s, double &mu_k) const;
  double *find_history(int i, int j, double &sign) const;
};

}  // namespace StickSlip

#endif
