/* stickslip: the stick-slip tangential contact law of Khellaf & Mansouri (2024)
   as a LIGGGHTS 3.8 tangential model, `tangential stick_slip`.

   This file is the only place the law lives on LIGGGHTS; it follows
   docs/law.md (the contract shared with pyref and the YADE law) step by step.
   Built as a plugin against the installed Debian headers (see CMakeLists.txt). */

#ifdef TANGENTIAL_MODEL
// id 23: unused by LIGGGHTS 3.8 (off 0, no_history 1, history 2, tan_luding 4); ids must be < 64
TANGENTIAL_MODEL(TANGENTIAL_STICK_SLIP,stick_slip,23)
#else
#ifndef TANGENTIAL_MODEL_STICK_SLIP_H_
#define TANGENTIAL_MODEL_STICK_SLIP_H_

#include "contact_models.h"
#include "tangential_model_base.h"
#include "global_properties.h"
#include "fix_property_global.h"
#include "modify.h"
#include "update.h"
#include "error.h"
#include "neighbor.h"
#include <cmath>
#include <cstdio>

namespace LIGGGHTS {
namespace ContactModels {

namespace StickSlip {
  static const char * const KINETIC = "coefficientKineticFriction";

  /* mu_k per type pair. Checked here, where both coefficients are known, so that the
     error names the property, the type pair and the allowed range [mu_s/2, mu_s]. */
  inline MatrixProperty * createKineticFriction(PropertyRegistry & registry, const char * caller, bool)
  {
    LAMMPS * lmp = registry.getLAMMPS();
    if (!lmp->modify->find_fix_property(KINETIC, "property/global", "peratomtypepair", 0, 0, caller, false))
      lmp->error->all(FLERR, "tangential stick_slip needs the kinetic friction coefficient: "
                             "fix ID all property/global coefficientKineticFriction peratomtypepair N "
                             "mu_k(1,1) ... with coefficientFriction/2 <= mu_k <= coefficientFriction");
    MatrixProperty * mu_k = MODEL_PARAMS::createPerTypePairProperty(registry, KINETIC, caller);
    MatrixProperty * mu_s = MODEL_PARAMS::createCoeffFrict(registry, caller, false);
    const int ntypes = registry.max_type();
    for (int i = 1; i <= ntypes; i++)
      for (int j = 1; j <= ntypes; j++) {
        const double ms = mu_s->data[i][j], mk = mu_k->data[i][j];
        char msg[400];
        if (!(ms > 0.0)) {
          snprintf(msg, sizeof msg, "tangential stick_slip: coefficientFriction (mu_s) = %g for types %d %d; "
                   "allowed range: mu_s > 0", ms, i, j);
          lmp->error->all(FLERR, msg);
        }
        if (!(mk >= 0.5 * ms && mk <= ms)) {
          snprintf(msg, sizeof msg, "tangential stick_slip: coefficientKineticFriction (mu_k) = %g for types %d %d; "
                   "allowed range: mu_s/2 <= mu_k <= mu_s, i.e. [%g, %g] (coefficientFriction = %g)",
                   mk, i, j, 0.5 * ms, ms, ms);
          lmp->error->all(FLERR, msg);
        }
      }
    delete mu_s;
    return mu_k;
  }
}

template<>
class TangentialModel<TANGENTIAL_STICK_SLIP> : public TangentialModelBase
{
  double ** mu_s;
  double ** mu_k;
  int history_offset;   // D: the spring elongation, 3 values (the same memory as `tangential history`)
  int record_offset;    // optional diagnostics: Fn, F_s (3), slip count
  bool reset_total;     // eq. 8: false = spring alone carries Fmin (paper), true = spring + dashpot
  bool record;

public:
  TangentialModel(LAMMPS * lmp, IContactHistorySetup * hsetup, class ContactModelBase * c) :
    TangentialModelBase(lmp, hsetup, c), mu_s(NULL), mu_k(NULL), history_offset(-1), record_offset(-1),
    reset_total(false), record(false)
  {
    // "1": the value changes sign when the pair is seen from the other grain
    history_offset = hsetup->add_history_value("shearx", "1");
    hsetup->add_history_value("sheary", "1");
    hsetup->add_history_value("shearz", "1");
  }

  inline void registerSettings(Settings & settings)
  {
    settings.registerOnOff("slip_reset_total", reset_total, false);
    settings.registerOnOff("stick_slip_record", record, false);
  }

  inline void postSettings(IContactHistorySetup * hsetup, ContactModelBase *)
  {
    if (record) {
      // what the contact last applied, for output via compute pair/gran/local or the
      // per-atom history of a primitive wall (re-evaluating a contact would not give it)
      record_offset = hsetup->add_history_value("stick_slip_fn", "0");
      hsetup->add_history_value("stick_slip_fsx", "1");
      hsetup->add_history_value("stick_slip_fsy", "1");
      hsetup->add_history_value("stick_slip_fsz", "1");
      hsetup->add_history_value("stick_slip_nslip", "0");
    }
  }

  inline void connectToProperties(PropertyRegistry & registry)
  {
    registry.registerProperty("coeffFrict", &MODEL_PARAMS::createCoeffFrict);
    registry.registerProperty("coeffKineticFrict", &StickSlip::createKineticFriction);
    registry.connect("coeffFrict", mu_s, "tangential_model stick_slip");
    registry.connect("coeffKineticFrict", mu_k, "tangential_model stick_slip");
    // docs/law.md step 3: D must be dropped when a contact opens. LIGGGHTS calls
    // surfacesClose() only for pairs closer than contactDistanceFactor * (r_i + r_j)
    // (1 by default, i.e. never for an opened pair, whose history would then survive
    // until the next neighbour-list rebuild). 1.01, as LIGGGHTS' own hooke model uses
    // for its elastic energy: a contact opens by |v_n| dt per step, far below 1 % of
    // r_i + r_j at any stable time step, so every opening is seen.
    neighbor->register_contact_dist_factor(1.01);
  }

  inline void surfacesIntersect(const SurfacesIntersectData & sidata, ForceData & i_forces, ForceData & j_forces)
  {
    if (sidata.contact_flags) *sidata.contact_flags |= CONTACT_TANGENTIAL_MODEL;

    const double * const en = sidata.en;
    const double vs[3] = { sidata.vtr1, sidata.vtr2, sidata.vtr3 };  // V_s, eq. 6
    const double kt = sidata.kt, gammat = sidata.gammat;             // Ks, nu_s from the normal model
    if (!(kt > 0.0))
      error->one(FLERR, "tangential stick_slip needs a tangential stiffness kt > 0 from the normal model "
                        "(e.g. model hooke/stiffness with kt > 0)");
    const double fn = sidata.Fn > 0.0 ? sidata.Fn : 0.0;              // eq. 3, never tensile
    const bool update_history = sidata.computeflag && sidata.shearupdate;

    double * const hist = &sidata.contact_history[history_offset];
    double D[3] = { hist[0], hist[1], hist[2] };
    if (update_history) {
      // 3D form: turn D into the current tangent plane, keeping its length
      const double dn = D[0]*en[0] + D[1]*en[1] + D[2]*en[2];
      if (dn != 0.0) {
        const double old2 = D[0]*D[0] + D[1]*D[1] + D[2]*D[2];
        for (int k = 0; k < 3; k++) D[k] -= dn * en[k];
        const double new2 = D[0]*D[0] + D[1]*D[1] + D[2]*D[2];
        if (new2 > 0.0) {
          const double scale = std::sqrt(old2 / new2);
          for (int k = 0; k < 3; k++) D[k] *= scale;
        }
      }
      const double dt = update->dt;
      for (int k = 0; k < 3; k++) D[k] += vs[k] * dt;  // eq. 7
    }

    // eq. 5: trial force = spring + dashpot
    double F[3];
    for (int k = 0; k < 3; k++) F[k] = -kt * D[k] - gammat * vs[k];
    const double mag2 = F[0]*F[0] + F[1]*F[1] + F[2]*F[2];
    const double ms = mu_s[sidata.itype][sidata.jtype];
    const double limit = ms * fn;
    // static threshold reached (Fn = 0 always slips); squared, so that a sticking step
    // (the common case) needs no square root
    const bool slip = mag2 >= limit * limit;
    if (slip) {
      // kinematic phase: the force drops to Fmin = (2 mu_k - mu_s) Fn along the trial force
      const double fmin = (2.0 * mu_k[sidata.itype][sidata.jtype] - ms) * fn;
      const double scale = mag2 > 0.0 ? fmin / std::sqrt(mag2) : 0.0;
      for (int k = 0; k < 3; k++) F[k] *= scale;
      // eq. 8: reset the spring so that it carries Fmin (or spring + dashpot do)
      for (int k = 0; k < 3; k++)
        D[k] = reset_total ? -(F[k] + gammat * vs[k]) / kt : -F[k] / kt;
    }

    if (update_history) {
      for (int k = 0; k < 3; k++) hist[k] = D[k];
      if (record) {
        double * const rec = &sidata.contact_history[record_offset];
        rec[0] = fn;
        for (int k = 0; k < 3; k++) rec[1 + k] = F[k];
        if (slip) rec[4] += 1.0;
      }
    }

    // torques from the lever arms r*n (cri, crj: distance from the centres to the contact)
    const double tor[3] = { en[1]*F[2] - en[2]*F[1], en[2]*F[0] - en[0]*F[2], en[0]*F[1] - en[1]*F[0] };
    if (sidata.is_wall) {
      const double a = sidata.area_ratio;
      for (int k = 0; k < 3; k++) {
        i_forces.delta_F[k] += F[k] * a;
        i_forces.delta_torque[k] += -sidata.cri * tor[k] * a;
      }
    } else {
      for (int k = 0; k < 3; k++) {
        i_forces.delta_F[k] += F[k];
        j_forces.delta_F[k] -= F[k];
        i_forces.delta_torque[k] += -sidata.cri * tor[k];
        j_forces.delta_torque[k] += -sidata.crj * tor[k];
      }
    }
  }

  inline void surfacesClose(SurfacesCloseData & scdata, ForceData &, ForceData &)
  {
    // the contact has ended: its history starts from zero when it is made again
    if (scdata.contact_flags) *scdata.contact_flags &= ~CONTACT_TANGENTIAL_MODEL;
    if (!scdata.contact_history) return;
    double * const hist = &scdata.contact_history[history_offset];
    hist[0] = hist[1] = hist[2] = 0.0;
    if (record) {
      double * const rec = &scdata.contact_history[record_offset];
      for (int k = 0; k < 5; k++) rec[k] = 0.0;
    }
  }

  inline void beginPass(SurfacesIntersectData &, ForceData &, ForceData &) {}
  inline void endPass(SurfacesIntersectData &, ForceData &, ForceData &) {}
};

}
}

#endif
#endif
