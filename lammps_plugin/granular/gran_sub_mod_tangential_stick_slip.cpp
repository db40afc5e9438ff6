/* SPDX-License-Identifier: GPL-2.0-or-later
   ----------------------------------------------------------------------
   stickslip: the stick-slip tangential law of Khellaf & Mansouri (2024) as a tangential
   sub-model of LAMMPS' granular model (docs/law.md; equation numbers are the paper's).

   This file is the law on LAMMPS 2Aug2023 and later. The host computes the geometry, the
   sliding velocity V_s (gm->vtr, with the radii as lever arms), the normal force and its
   damping, and applies the force and torques; this sub-model turns and loads the spring D
   and decides stick or slip. Its step-timing arithmetic is linear_history's operation for
   operation (the turn of D keeping its length included), so that with mu_k = mu_s and
   /total it gives linear_history's run bit for bit. The exact slip timing's
   engine-independent part (E1-E7) is exact_slip_timing.h, shared with the styles of
   lammps_plugin/ for Debian's LAMMPS.
------------------------------------------------------------------------- */

#include "gran_sub_mod_tangential_stick_slip.h"

#include "comm.h"
#include "error.h"
#include "exact_slip_timing.h"
#include "gran_sub_mod_damping.h"
#include "gran_sub_mod_normal.h"
#include "granular_model.h"
#include "math_extra.h"
#include "stickslip_version.h"

#include <cmath>
#include <string>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MathExtra;

// linear_history's and mindlin's: D is turned into the tangent plane only when its normal
// part carries more than EPSILON of the threshold (below that the turn changes nothing a
// force could show)
static constexpr double EPSILON = 1e-10;

/* ---------------------------------------------------------------------- */

GranSubModTangentialStickSlip::GranSubModTangentialStickSlip(GranularModel *gm, LAMMPS *lmp, bool record) :
    GranSubModTangential(gm, lmp), xt(0.0), kin(0.0), ratio(1.0), mindlin(false)
{
  num_coeffs = 4;
  size_history = record ? SIZE_RECORD : SIZE_PLAIN;
  nsvector = record ? NRECORD : 0;
  if (record) {
    // seen from the other body of a pair, D and F_s change sign; Fn, the slip count and the
    // work do not
    nondefault_history_transfer = 1;
    transfer_history_factor = new double[SIZE_RECORD];
    for (int i = 0; i < SIZE_RECORD; i++) transfer_history_factor[i] = -1.0;
    transfer_history_factor[HIST_FN] = transfer_history_factor[HIST_NSLIP] = transfer_history_factor[HIST_WORK] = 1.0;
  }
  // the version, once a process, where LAMMPS writes its own start-up lines
  static bool said = false;
  if (!said && comm->me == 0)
    utils::logmesg(lmp, "stickslip " STICKSLIP_VERSION ": tangential sub-model stick_slip (Khellaf & Mansouri 2024)\n");
  said = true;
}

/* ----------------------------------------------------------------------
   coefficients: Ks (or NULL), x_gamma,t, mu_s, mu_k; each bad one stops the run with one
   line naming it and its allowed range (docs/law.md "Parameter rules")
------------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::coeffs_to_local()
{
  const double ks = coeffs[0], mu_k = coeffs[3];
  xt = coeffs[1];
  mu = coeffs[2];

  mindlin = ks == -1.0;    // NULL
  if (!mindlin && !(ks > 0.0 && std::isfinite(ks)))
    error->all(FLERR,
               "tangential {}: Ks = {} is outside its allowed range: > 0, or NULL (Mindlin's 8 G* a, with a "
               "normal model of material properties)",
               name, ks);
  if (!(xt >= 0.0 && std::isfinite(xt)))
    error->all(FLERR, "tangential {}: x_gamma,t = {} is outside its allowed range: >= 0", name, xt);
  if (!(mu > 0.0 && std::isfinite(mu)))
    error->all(FLERR, "tangential {}: mu_s = {} is outside its allowed range: > 0", name, mu);
  if (!(mu_k >= 0.5 * mu && mu_k <= mu))
    error->all(FLERR, "tangential {}: mu_k = {} is outside its allowed range [mu_s/2, mu_s] = [{}, {}]", name,
               mu_k, 0.5 * mu, mu);

  if (mindlin) {
    if (!gm->normal_model->get_material_properties())
      error->all(FLERR,
                 "tangential {}: Ks = NULL needs a normal model with material properties (hertz/material, dmt, "
                 "jkr, mdr); give Ks instead",
                 name);
    const double Emod = gm->normal_model->get_emod(), poiss = gm->normal_model->get_poiss();
    // Mindlin's stiffness per unit contact radius, as the mindlin sub-model's
    k = 8.0 * (gm->contact_type == PAIR ? mix_stiffnessG(Emod, Emod, poiss, poiss) : mix_stiffnessG_wall(Emod, poiss));
  } else {
    k = ks;
  }
  contact_radius_flag = mindlin ? 1 : 0;

  kin = 2.0 * mu_k - mu;    // Fmin = (2 mu_k - mu_s) Fn: mean mu_k Fn over a saw-tooth
  ratio = kin / mu;
}

/* ---------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::mix_coeffs(double *icoeffs, double *jcoeffs)
{
  // geometric means, as the other sub-models (they keep mu_s/2 <= mu_k <= mu_s); NULL
  // (Mindlin's stiffness) if either side has it
  coeffs[0] = (icoeffs[0] == -1.0 || jcoeffs[0] == -1.0) ? -1.0 : mix_geom(icoeffs[0], jcoeffs[0]);
  for (int i = 1; i < num_coeffs; i++) coeffs[i] = mix_geom(icoeffs[i], jcoeffs[i]);
  coeffs_to_local();
}

/* ----------------------------------------------------------------------
   with /record: the contact's record as the sub-model's output values (compute pair/local
   p13-p18, the wall fixes' per-atom columns 9-14)
------------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::report_record(const double *history)
{
  double *out = &gm->svector[index_svector];
  out[0] = history[HIST_FN];
  for (int k = 0; k < 3; k++) out[1 + k] = history[HIST_FS + k];
  out[4] = history[HIST_NSLIP];
  out[5] = history[HIST_WORK];
}

/* ----------------------------------------------------------------------
   docs/law.md steps 3-5 (and E0-E7 with EXACT) at one contact for one force evaluation
------------------------------------------------------------------------- */

template <bool TOTAL, bool EXACT, bool RECORD> void GranSubModTangentialStickSlip::step()
{
  // (the contact's vectors in locals: stores through `history` could alias the model's
  // arrays, and the compiler would load them again after each)
  damp = xt * gm->damping_model->get_damp_prefactor();    // nu_s
  const double fncrit = gm->normal_model->get_fncrit();      // |Fn| (adhesive models: their own)
  const double Fscrit = fncrit * mu;                         // T = mu_s |Fn|
  const double ks = mindlin ? k * gm->contact_radius : k;
  double *history = &gm->history[history_index];
  const double v[3] = {gm->vtr[0], gm->vtr[1], gm->vtr[2]};    // V_s (eq. 6)
  double D[3] = {history[0], history[1], history[2]};
  const double before2 = RECORD ? lensq3(D) : 0.0;
  double *fs = gm->fs;

  const bool update = gm->history_update;    // false: a set-up evaluation, no time passes
  if (update) {
    // step 3: turn D into the current tangent plane keeping its length (linear_history's
    // arithmetic)
    const double *nx = gm->nx;
    const double rsht = dot3(D, nx);
    if (fabs(rsht) * ks > EPSILON * Fscrit) {
      const double shrmag = len3(D);
      for (int i = 0; i < 3; i++) D[i] = D[i] - rsht * nx[i];
      const double prjmag = len3(D);
      scale3(prjmag > 0 ? shrmag / prjmag : 0, D);
    }
    // eq. 7: D += V_s dt
    const double dt = gm->dt;
    for (int i = 0; i < 3; i++) D[i] = D[i] + dt * v[i];
  } else if (gm->contact_type == PAIR && gm->calculate_svector) {
    // pair granular's single() (compute pair/local): report, change nothing
    if (RECORD) {
      copy3(&history[HIST_FS], fs);
      report_record(history);
    } else {
      // the force the law would apply now, with no time passing
      for (int i = 0; i < 3; i++) fs[i] = -ks * D[i] - damp * v[i];
      const double magfs = len3(fs);
      if (magfs >= Fscrit) scale3(magfs > 0.0 && lensq3(D) != 0.0 ? fncrit * kin / magfs : 0.0, fs);
    }
    return;
  }

  // eq. 5: the trial force, spring + dashpot
  double F[3], dv[3];
  for (int i = 0; i < 3; i++) {
    dv[i] = damp * v[i];
    F[i] = -ks * D[i] - dv[i];
  }

  // step 5: slip if |F_t| >= mu_s |Fn|
  const double magfs = len3(F);
  bool slipped = magfs >= Fscrit;
  if (EXACT) {
    // E0: |F| moves on a line in the step and is convex, so the step has no slip iff the
    // trial force is below T at both ends; then the result is the step timing's. The
    // trial force at the start holds the spring before its increment: F + Ks dt V_s (a set-up
    // evaluation is a step of length 0).
    const double ksdt = update ? ks * gm->dt : 0.0;
    const double start[3] = {F[0] + ksdt * v[0], F[1] + ksdt * v[1], F[2] + ksdt * v[2]};
    const double start2 = lensq3(start);
    slipped = slipped || start2 >= Fscrit * Fscrit;
    if (slipped) {
      const double fmin = fncrit * kin;    // Fmin (eq. 8)
      const double vs2 = lensq3(v), damp2 = damp * damp;
      if (!TOTAL && start2 >= Fscrit * Fscrit && Fscrit > 0.0 && damp2 * vs2 > 0.0 &&
          (fmin * fmin + damp2 * vs2 - Fscrit * Fscrit) * sqrt(start2) - 2.0 * fmin * damp * dot3(start, v) >= 0.0) {
        // E4 at the step's start, the common slipping case of a flowing bed: the force is at
        // or above T at theta = 0, and after the slip the dashpot alone keeps it there,
        // |Fmin t0 + nu_s |V_s| u| >= T (t0 = F0/|F0|, u = -V_s/|V_s|; expanded: one square
        // root, no division). It slides at Fmin u all step; the spring holds the trial force
        // (Fmin + nu_s |V_s|) u less the dashpot (eq. 5). exact_slips' closed form, inline.
        const double a = fmin / sqrt(vs2), aks = a / ks;
        for (int i = 0; i < 3; i++) {
          F[i] = -a * v[i];
          D[i] = aks * v[i];
        }
      } else {
        // E1-E7 (exact_slip_timing.h); E6 when nothing is added at a reset
        const bool flow_law = ratio == 1.0 && (TOTAL || damp == 0.0);
        double applied[3], trial[3], stick;
        stickslip::exact_slips(start, v, Fscrit, fmin, ratio, ks, damp, update ? gm->dt : 0.0, TOTAL, flow_law, applied,
                               trial, stick);
        // the spring holds the trial force at the end less the dashpot (eq. 5)
        for (int i = 0; i < 3; i++) {
          F[i] = applied[i];
          D[i] = -(trial[i] + dv[i]) / ks;
        }
      }
    }
  } else if (slipped) {
    if (len3(D) != 0.0) {
      // the force drops to Fmin along the trial force; eq. 8 resets the spring to hold
      // Fmin alone, or with /total spring + dashpot (linear_history's rescale)
      const double fmin = fncrit * kin;    // Fmin (eq. 8)
      const double scale = magfs > 0.0 ? fmin * (1.0 / magfs) : 0.0;
      const double back = -1.0 / ks;
      for (int i = 0; i < 3; i++) {
        D[i] = scale * F[i];
        if (TOTAL) D[i] = D[i] + dv[i];
        D[i] = back * D[i];
        F[i] = scale * F[i];
      }
    } else {
      // linear_history's rule: a zero spring (a new contact in a set-up evaluation) gets no
      // tangential force when the dashpot alone reaches the threshold
      F[0] = F[1] = F[2] = 0.0;
    }
  }

  copy3(D, history);
  copy3(F, fs);
  if (RECORD) {
    if (update) {
      // docs/law.md "Energy": the work the contact received, -F_s.V_s dt, less the increase
      // of the spring energy Ks |D|^2/2
      history[HIST_WORK] += -dot3(F, v) * gm->dt - 0.5 * ks * (lensq3(D) - before2);
      if (slipped) history[HIST_NSLIP] += 1.0;
    }
    history[HIST_FN] = gm->Fntot;
    copy3(F, &history[HIST_FS]);
    if (gm->calculate_svector) report_record(history);    // (walls with per-atom output)
  }
}

/* ---------------------------------------------------------------------- */

template <bool TOTAL, bool EXACT, bool RECORD>
void GranSubModTangentialStickSlipWith<TOTAL, EXACT, RECORD>::calculate_forces()
{
  this->template step<TOTAL, EXACT, RECORD>();
}

// the eight names of the header
namespace LAMMPS_NS {
namespace Granular_NS {
  template class GranSubModTangentialStickSlipWith<false, false, false>;
  template class GranSubModTangentialStickSlipWith<false, false, true>;
  template class GranSubModTangentialStickSlipWith<false, true, false>;
  template class GranSubModTangentialStickSlipWith<false, true, true>;
  template class GranSubModTangentialStickSlipWith<true, false, false>;
  template class GranSubModTangentialStickSlipWith<true, false, true>;
  template class GranSubModTangentialStickSlipWith<true, true, false>;
  template class GranSubModTangentialStickSlipWith<true, true, true>;
}    // namespace Granular_NS
}    // namespace LAMMPS_NS
