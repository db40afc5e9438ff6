/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   Copyright (2003) Sandia Corporation.  Under the terms of Contract
   DE-AC04-94AL85000 with Sandia Corporation, the U.S. Government retains
   certain rights in this software.  This software is distributed under
   the GNU General Public License.

   See the README file in the top-level LAMMPS directory.
------------------------------------------------------------------------- */

/* ----------------------------------------------------------------------
   Contributing authors: the stickslip developers
   Stick-slip friction of Khellaf and Mansouri, Technology Audit and
   Production Reserves 4(1(78)), 17-25 (2024), equations numbered as there
------------------------------------------------------------------------- */

#include "gran_sub_mod_tangential_stick_slip.h"

#include "citeme.h"
#include "error.h"
#include "gran_sub_mod_damping.h"
#include "gran_sub_mod_normal.h"
#include "granular_model.h"
#include "math_extra.h"
#include "stick_slip_core.h"

#include <cmath>
#include <type_traits>
#include <utility>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MathExtra;
using stickslip::StickSlipCore;    // (the law's core; tools/lammps_patch.py puts it in Granular_NS)

// as linear_history and mindlin: the spring is turned into the tangent plane only when its
// normal part carries more than EPSILON of the threshold
static constexpr double EPSILON = 1e-10;
// exact timing: a contact whose bound |F| + Ks dt |V_s| on the step's trial force (at both
// ends) is below the threshold by more than this share of it sticks without the step's start
// force; the bound takes a dozen rounded operations and GranularModel's |V_s| (vrel) a few
// more, each within 1.1e-16 of its value: the margin, ~90 such roundings, keeps round-off
// from hiding a slip
static constexpr double STICK_MARGIN = 1e-14;

static const char cite_stick_slip[] =
    "tangential stick_slip: doi:10.15587/2706-5448.2024.310428\n\n"
    "@Article{khellaf2024stickslip,\n"
    " author =  {Khellaf, Abdelghani and Mansouri, Mouloud},\n"
    " title =   {Development of the stick-slip friction model for discrete elements modeling},\n"
    " journal = {Technology Audit and Production Reserves},\n"
    " year =    {2024},\n"
    " volume =  {4},\n"
    " number =  {1(78)},\n"
    " pages =   {17--25},\n"
    " doi =     {10.15587/2706-5448.2024.310428}\n"
    "}\n\n";

/* ----------------------------------------------------------------------
   The host release. LAMMPS after 4 Feb 2025 has synchronized verlet
   (GranularModel::synchronized_verlet and nx_unrotated, GranSubMod::allow_synchronization),
   turns a vector into the tangent plane with GranSubMod::rotate_rescale_vec, and its stock
   sub-models rescale a force by Fscrit / |F|. LAMMPS 4 Feb 2025 has none of these, writes
   the same turn out in each sub-model, and rescales by Fscrit * (1 / |F|). These helpers ask
   the host which it is, so that at mu_k = mu_s the sub-model does that release's
   linear_history (mindlin) arithmetic, and follows a later release's helper. (LAMMPS' own
   tree takes the sub-model with the current members used directly: tools/lammps_form.py.)
------------------------------------------------------------------------- */

namespace {
template <class T, class = void> struct HasSynchronizedVerlet : std::false_type {
};
template <class T>
struct HasSynchronizedVerlet<T, std::void_t<decltype(T::synchronized_verlet)>> : std::true_type {
};

template <class T, class = void> struct HasAllowSynchronization : std::false_type {
};
template <class T>
struct HasAllowSynchronization<T, std::void_t<decltype(T::allow_synchronization)>> :
    std::true_type {
};

template <class T, class = void> struct HasRotateRescale : std::false_type {
};
template <class T>
struct HasRotateRescale<
    T, std::void_t<decltype(std::declval<T &>().rotate_rescale_vec(nullptr, nullptr))>> :
    std::true_type {
};

template <class Model> int synchronized(const Model *gm)
{
  if constexpr (HasSynchronizedVerlet<Model>::value)
    return gm->synchronized_verlet == 1;
  else
    return 0;
}

template <class Model> double *full_step_normal(Model *gm)
{
  if constexpr (HasSynchronizedVerlet<Model>::value)
    return gm->nx_unrotated;
  else
    return gm->nx;
}

template <class Sub> void set_allow_synchronization(Sub *sub, int flag)
{
  if constexpr (HasAllowSynchronization<Sub>::value) sub->allow_synchronization = flag;
}

// turn v into the plane normal to the unit vector n, keeping its length
template <class Sub> STICK_SLIP_ALWAYS_INLINE void rotate_rescale(Sub *sub, double *v, double *n)
{
  if constexpr (HasRotateRescale<Sub>::value) {
    sub->rotate_rescale_vec(v, n);
  } else {
    const double rsht = dot3(v, n), shrmag = len3(v);
    double temp[3];
    scale3(rsht, n, temp);
    sub3(v, temp, v);
    const double prjmag = len3(v);
    scale3(prjmag > 0 ? shrmag / prjmag : 0, v);
  }
}

// the factor that brings a force of magnitude magfs to target
template <class Model> double rescale_factor(const Model *, double target, double magfs)
{
  if constexpr (HasSynchronizedVerlet<Model>::value)
    return target / magfs;
  else
    return target * (1.0 / magfs);
}
}    // namespace

/* ---------------------------------------------------------------------- */

GranSubModTangentialStickSlip::GranSubModTangentialStickSlip(GranularModel *gm, LAMMPS *lmp,
                                                             int options) :
    GranSubModTangential(gm, lmp),
    reset_total(options & TOTAL), exact_timing(options & EXACT), record(options & RECORD),
    mindlin(0), xt(0.0), kin(0.0), ratio(1.0)
{
  if (lmp->citeme) lmp->citeme->add(cite_stick_slip);

  num_coeffs = 4;
  size_history = record ? SIZE_RECORD : 3;
  nsvector = record ? 6 : 0;
  // exact timing integrates the spring along one tangent plane over the step; synchronized
  // verlet turns it twice within the step
  set_allow_synchronization(this, !exact_timing);
  if (record) {
    // seen from the other body of a pair the spring and the force change sign; the normal
    // force, the slip count and the work do not
    nondefault_history_transfer = 1;
    transfer_history_factor = new double[size_history];
    for (int i = 0; i < size_history; i++) transfer_history_factor[i] = -1.0;
    transfer_history_factor[HIST_FN] = transfer_history_factor[HIST_NSLIP] = 1.0;
    transfer_history_factor[HIST_WORK] = 1.0;
  }
}

/* ----------------------------------------------------------------------
   coefficients: Ks (or NULL), x_gamma,t, mu_s, mu_k
------------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::coeffs_to_local()
{
  const double ks = coeffs[0], mu_k = coeffs[3];
  xt = coeffs[1];
  mu = coeffs[2];

  mindlin = (ks == -1.0);
  if (!mindlin && !(ks > 0.0 && std::isfinite(ks)))
    error->all(FLERR,
               "Tangential {}: Ks = {} is outside its allowed range: > 0, or NULL (Mindlin's "
               "8 G* a, with a normal model of material properties)",
               name, ks);
  if (!(xt >= 0.0 && std::isfinite(xt)))
    error->all(FLERR, "Tangential {}: x_gamma,t = {} is outside its allowed range: >= 0", name, xt);
  if (!(mu > 0.0 && std::isfinite(mu)))
    error->all(FLERR, "Tangential {}: mu_s = {} is outside its allowed range: > 0", name, mu);
  if (!(mu_k >= 0.5 * mu && mu_k <= mu))
    error->all(FLERR,
               "Tangential {}: mu_k = {} is outside its allowed range [mu_s/2, mu_s] = [{}, {}]",
               name, mu_k, 0.5 * mu, mu);

  if (mindlin) {
    if (!gm->normal_model->get_material_properties())
      error->all(FLERR,
                 "Tangential {}: Ks = NULL needs a normal model with material properties "
                 "(hertz/material, dmt, jkr, mdr); give Ks instead",
                 name);
    const double Emod = gm->normal_model->get_emod(), poiss = gm->normal_model->get_poiss();
    // Mindlin's stiffness per unit contact radius, as the mindlin sub-model's
    if (gm->contact_type == PAIR)
      k = 8.0 * mix_stiffnessG(Emod, Emod, poiss, poiss);
    else
      k = 8.0 * mix_stiffnessG_wall(Emod, poiss);
  } else {
    k = ks;
  }
  contact_radius_flag = mindlin;

  kin = StickSlipCore::kinetic(mu, mu_k);
  ratio = kin / mu;
}

/* ---------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::mix_coeffs(double *icoeffs, double *jcoeffs)
{
  // geometric means, as the other sub-models (they keep mu_s/2 <= mu_k <= mu_s); Mindlin's
  // stiffness if either side has it
  if (icoeffs[0] == -1.0 || jcoeffs[0] == -1.0)
    coeffs[0] = -1.0;
  else
    coeffs[0] = mix_geom(icoeffs[0], jcoeffs[0]);
  for (int i = 1; i < num_coeffs; i++) coeffs[i] = mix_geom(icoeffs[i], jcoeffs[i]);
  coeffs_to_local();
}

/* ----------------------------------------------------------------------
   with /record: the contact's record as the sub-model's output values
------------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::report_record(const double *history)
{
  double *out = &gm->svector[index_svector];
  out[0] = history[HIST_FN];
  for (int i = 0; i < 3; i++) out[1 + i] = history[HIST_FS + i];
  out[4] = history[HIST_NSLIP];
  out[5] = history[HIST_WORK];
}

/* ---------------------------------------------------------------------- */

template <int OPTIONS> void GranSubModTangentialStickSlip::forces()
{
  constexpr bool reset_total = OPTIONS & TOTAL, exact_timing = OPTIONS & EXACT,
                 record = OPTIONS & RECORD;

  damp = xt * gm->damping_model->get_damp_prefactor();    // nu_s
  const double fncrit = gm->normal_model->get_fncrit();
  const double Fscrit = fncrit * mu;
  const double ks = mindlin ? k * gm->contact_radius : k;
  // the spring D is the history's first 3 values, worked on in place (as linear_history's);
  // V_s in locals (a store through the history pointer could alias the model's arrays, and
  // the compiler would load them again after each)
  double *history = &gm->history[history_index];
  double *D = history;
  const double v[3] = {gm->vtr[0], gm->vtr[1], gm->vtr[2]};    // V_s, eq. 6
  const double before2 = record ? lensq3(D) : 0.0;
  double *fs = gm->fs;

  const int update = gm->history_update;    // 0: a set-up evaluation, no time passes
  const int sync = synchronized(gm);
  int frame_update = 0;
  if (update) {
    // turn the spring into the current tangent plane keeping its length, load it (eq. 7),
    // and with synchronized verlet turn it into the full step's plane (as linear_history)
    double *nx = gm->nx;
    double rsht = dot3(D, nx);
    frame_update = fabs(rsht) * ks > EPSILON * Fscrit;
    if (frame_update) rotate_rescale(this, D, nx);
    const double dt = gm->dt;
    for (int i = 0; i < 3; i++) D[i] = D[i] + dt * v[i];
    if (sync) {
      double *nx_full = full_step_normal(gm);
      rsht = dot3(D, nx_full);
      frame_update = fabs(rsht) * ks > EPSILON * Fscrit;
      if (frame_update) rotate_rescale(this, D, nx_full);
    }
  } else if (gm->contact_type == PAIR && gm->calculate_svector) {
    // pair granular's single(): report, change nothing
    if (record) {
      copy3(&history[HIST_FS], fs);
      report_record(history);
    } else {
      // the force the law would apply now, with no time passing
      for (int i = 0; i < 3; i++) fs[i] = -ks * D[i] - damp * v[i];
      const double magfs = len3(fs);
      if (StickSlipCore::slips(magfs, Fscrit))    // (a zero spring: no force, as the step below)
        StickSlipCore::drop_to(fs, fncrit * kin, lensq3(D) != 0.0 ? magfs : 0.0,
                               StickSlipCore::stock_ratio);
    }
    return;
  }

  // eq. 5: the trial force, spring + dashpot
  double fdamp[3], F[3];
  if (frame_update && sync) {
    double vturned[3] = {v[0], v[1], v[2]};
    rotate_rescale(this, vturned, full_step_normal(gm));
    scale3(-damp, vturned, fdamp);
  } else {
    scale3(-damp, v, fdamp);
  }
  for (int i = 0; i < 3; i++) F[i] = -ks * D[i] + fdamp[i];

  // the slip test, then eq. 8 (stick_slip_core.h); with exact timing the slip test of the
  // step's end in squares (no square root: the step timing's rescale needs |F|, this does not)
  int slipped = 0;
  if constexpr (exact_timing) {
    // most contacts stick through the step: |F| + Ks dt |V_s| bounds the trial force at both
    // of its ends (|V_s| is GranularModel's vrel), so below the threshold by more than round-off
    // no slip happens and E0 need not build the step's start force
    const double dt = update ? gm->dt : 0.0, mag2 = lensq3(F);
    if (!(sqrt(mag2) + ks * dt * gm->vrel < Fscrit * (1.0 - STICK_MARGIN))) {
      double stick;
      slipped =
          StickSlipCore::exact_step(StickSlipCore::slips(mag2, Fscrit * Fscrit), F, D, v, ks, damp,
                                    dt, Fscrit, fncrit * kin, ratio, reset_total, stick);
    }
  } else {
    const double magfs = len3(F);
    slipped = StickSlipCore::slips(magfs, Fscrit);
    if (slipped) {
      if (lensq3(D) != 0.0) {
        // the force drops to Fmin along the trial force (rescaled as the host's stock does)
        StickSlipCore::drop_to(F, fncrit * kin, magfs, [this](double fmin, double mag) {
          return rescale_factor(gm, fmin, mag);
        });
        StickSlipCore::reset(F, fdamp, ks, reset_total, D);
      } else {
        // as linear_history: a zero spring (a new contact in a set-up evaluation) gets no
        // tangential force when the dashpot alone reaches the threshold
        zero3(F);
      }
    }
  }

  copy3(F, fs);
  if (record) {
    if (update) {
      // the work the contact received, -F_s.V_s dt, less the increase of the spring's
      // energy Ks |D|^2 / 2
      history[HIST_WORK] += StickSlipCore::dissipated(F, v, gm->dt, ks, before2, lensq3(D));
      if (slipped) history[HIST_NSLIP] += 1.0;
    }
    history[HIST_FN] = gm->Fntot;
    copy3(F, &history[HIST_FS]);
    if (gm->calculate_svector) report_record(history);
  }
}

/* ---------------------------------------------------------------------- */

void GranSubModTangentialStickSlip::calculate_forces()
{
  forces<0>();
}

// each variant compiled with its options as constants, so that a contact's force tests none of
// them (read at run time, they cost a flowing bed 3 % more instructions per step)
void GranSubModStickSlipRecord::calculate_forces()
{
  forces<RECORD>();
}
void GranSubModStickSlipExact::calculate_forces()
{
  forces<EXACT>();
}
void GranSubModStickSlipExactRecord::calculate_forces()
{
  forces<EXACT | RECORD>();
}
void GranSubModStickSlipTotal::calculate_forces()
{
  forces<TOTAL>();
}
void GranSubModStickSlipTotalRecord::calculate_forces()
{
  forces<TOTAL | RECORD>();
}
void GranSubModStickSlipTotalExact::calculate_forces()
{
  forces<TOTAL | EXACT>();
}
void GranSubModStickSlipTotalExactRecord::calculate_forces()
{
  forces<TOTAL | EXACT | RECORD>();
}
