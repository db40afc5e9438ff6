/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: the stick-slip tangential contact law of Khellaf & Mansouri (2024)
   as a LIGGGHTS 3.8 tangential model, `tangential stick_slip`.

   This file is the only place the law lives on LIGGGHTS; it follows
   docs/law.md (the contract shared with pyref and the YADE law) step by step.
   Built two ways from this one file: as a plugin against the installed Debian headers
   (CMakeLists.txt, which registers the model itself), or dropped alone into LIGGGHTS'
   src/ and built with `make auto`, whose style scan registers it as LIGGGHTS' own
   tangential models (README.md, "Build into LIGGGHTS"). */

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
#include "atom.h"
#include "fix_property_atom.h"
// the law's engine-free core, shared with LAMMPS and YADE (law_core/)
#include "stick_slip_core.h"
#include <algorithm>
#include <cmath>
#include <cstdio>

// A loop over x, y, z, unrolled where GCC still decides which values live in registers:
// left as loops, the law's small arrays (D, F, V_s, ...) stayed on the stack, and every
// contact's D and F went there and back on the chain that decides the slip (issue 32,
// time against the control build: with the loops vectorised, pairs read back from single
// stores, 1.13; not vectorised (CMakeLists.txt), 1.03; unrolled too, 1.01 and no stack
// access on the common path). The same operations in the same order: the same bits.
#define FOR_XYZ(k) _Pragma("GCC unroll 3") for (int k = 0; k < 3; k++)

namespace LIGGGHTS {
namespace ContactModels {

using stickslip::StickSlipCore;

namespace StickSlip {
  static const char * const KINETIC = "coefficientKineticFriction";

  /* mu_k per type pair. Checked here, where both coefficients are known, so that the
     error names the property, the type pair and the allowed range [mu_s/2, mu_s]. */
  inline MatrixProperty * createKineticFriction(PropertyRegistry & registry, const char * caller, bool)
  {
    LAMMPS * lmp = registry.getLAMMPS();
    if (!lmp->modify->find_fix_property(KINETIC, "property/global", "peratomtypepair", 0, 0, caller, false)) {
      // given, but not as a matrix (scalar, vector): say so, rather than that it is missing
      if (lmp->modify->find_fix_property(KINETIC, "property/global", "scalar", 0, 0, caller, false) ||
          lmp->modify->find_fix_property(KINETIC, "property/global", "vector", 0, 0, caller, false))
        lmp->error->all(FLERR, "tangential stick_slip: coefficientKineticFriction has the wrong form: it must be "
                               "peratomtypepair N followed by the N x N values mu_k(i,j), e.g. "
                               "fix ID all property/global coefficientKineticFriction peratomtypepair 1 0.45");
      lmp->error->all(FLERR, "tangential stick_slip needs the kinetic friction coefficient: "
                             "fix ID all property/global coefficientKineticFriction peratomtypepair N "
                             "mu_k(1,1) ... with coefficientFriction/2 <= mu_k <= coefficientFriction");
    }
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

  // internal on/off settings behind the keywords history_rotation and history_on_separation
  static const char * const ROTATION_PROJECT = "stick_slip_history_project";
  static const char * const SEPARATION_KEEP = "stick_slip_keep_separated";
}

template<>
class TangentialModel<TANGENTIAL_STICK_SLIP> : public TangentialModelBase
{
  double ** mu_s;
  double ** mu_k;
  int history_offset;   // D: the spring elongation, 3 values (the same values as `tangential history`)
  int record_offset;    // optional diagnostics: Fn, F_s (3), slip count
  int stamp_offset;     // pair contacts: the time step at which the contact last touched
  double this_pass, last_pass;  // time steps of this and of the previous pass that updated histories
  double touched_last;  // the stamp of a pair contact that touched at the previous pass (beginPass)
  bool reset_total;     // eq. 8: false = spring alone carries Fmin (paper), true = spring + dashpot
  bool record;
  bool exact;           // slips at their exact time inside the step (docs/law.md E0-E7)
  bool project;         // history_rotation project: stock history's rule (increment, then project)
  bool keep_separated;  // history_on_separation keep: stock history's rule (see postSettings)
  // LIGGGHTS' energy and heat bookkeeping, as for `tangential history`
  bool heating, heating_track, elasticpot, dissipated;
  bool energy_books;    // any of heating, elasticpot, dissipated (set once the settings are final)
  int elastic_potential_offset;
  FixPropertyAtom * fix_dissipated;
  ContactModelBase * cmb;

public:
  TangentialModel(LAMMPS * lmp, IContactHistorySetup * hsetup, class ContactModelBase * c) :
    TangentialModelBase(lmp, hsetup, c), mu_s(NULL), mu_k(NULL), history_offset(-1), record_offset(-1),
    stamp_offset(-1), this_pass(-1.0), last_pass(-1.0), touched_last(-2.0), reset_total(false), record(false), exact(false),
    project(false), keep_separated(false),
    heating(false), heating_track(false), elasticpot(false), dissipated(false), energy_books(false),
    elastic_potential_offset(-1), fix_dissipated(NULL), cmb(c)
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
    settings.registerOnOff("exact_slip_timing", exact, false);
    // `history_rotation keep_length|project` and `history_on_separation drop|keep` are
    // turned into these by the settings check of the pair and wall styles (stick_slip_styles.h)
    settings.registerOnOff(StickSlip::ROTATION_PROJECT, project, false);
    settings.registerOnOff(StickSlip::SEPARATION_KEEP, keep_separated, false);
    // the stock model's options (tangential_model_history.h), same names
    settings.registerOnOff("heating_tangential_history", heating, false);
    settings.registerOnOff("heating_tracking", heating_track, false);
    settings.registerOnOff("computeElasticPotential", elasticpot, false);
    settings.registerOnOff("computeDissipatedEnergy", dissipated, false);
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
    // docs/law.md step 3: D is dropped when a contact ends. Walls do it themselves (LIGGGHTS
    // zeroes a wall contact's history once it is apart). A grain pair's history survives
    // until the next neighbour-list rebuild (LIGGGHTS tells a model that a pair has opened
    // only within contactDistanceFactor * (r_i + r_j), 1 by default), so each pair contact
    // carries the step at which it last touched: one that did not touch at the previous
    // pass is a new contact and starts from zero. (Raising contactDistanceFactor instead
    // widens the neighbour cutoff, which changes the spatial sort of the atoms on each
    // process and with it the order of force sums: results then depend on the number of
    // processes where stock history's do not.)
    // `history_on_separation keep` leaves the stale spring, as stock history does.
    if (!keep_separated && !cmb->is_wall())
      stamp_offset = hsetup->add_history_value("stick_slip_step", "0");
    // as stock history: the normal model keeps the contact's elastic force, the surface
    // model the per-atom dissipated_energy property
    if (elasticpot) {
      elastic_potential_offset = cmb->get_history_offset("elastic_potential_normal");
      if (elastic_potential_offset == -1)
        error->all(FLERR, "tangential stick_slip: computeElasticPotential needs a normal model that computes "
                          "the elastic potential (model hooke, hooke/stiffness, hertz or hertz/stiffness)");
    }
    if (dissipated && !cmb->is_wall()) {
      fix_dissipated = static_cast<FixPropertyAtom*>(modify->find_fix_property("dissipated_energy", "property/atom", "vector", 0, 0, "dissipated energy", false));
      if (!fix_dissipated)
        error->all(FLERR, "tangential stick_slip: computeDissipatedEnergy: the surface model did not create "
                          "the per-atom property dissipated_energy");
    }
  }

  inline void connectToProperties(PropertyRegistry & registry)
  {
    registry.registerProperty("coeffFrict", &MODEL_PARAMS::createCoeffFrict);
    registry.registerProperty("coeffKineticFrict", &StickSlip::createKineticFriction);
    registry.connect("coeffFrict", mu_s, "tangential_model stick_slip");
    registry.connect("coeffKineticFrict", mu_k, "tangential_model stick_slip");
    if ((elasticpot || dissipated) && cmb->is_wall()) {
      // as stock history: LIGGGHTS-PUBLIC 3.8 has no wall energy bookkeeping to feed
      error->warning(FLERR, "tangential stick_slip: computeElasticPotential/computeDissipatedEnergy are "
                            "ignored for walls, as for tangential history");
      elasticpot = dissipated = false;
    }
    energy_books = heating || elasticpot || dissipated;
  }

  inline void surfacesIntersect(const SurfacesIntersectData & sidata, ForceData & i_forces, ForceData & j_forces)
  {
    if (sidata.contact_flags) *sidata.contact_flags |= CONTACT_TANGENTIAL_MODEL;
    // the law compiled once per slip timing, and again for the common case (a step that
    // updates the history, none of the options history_rotation project,
    // stick_slip_record, energy books), whose copy has no tests of them
    const bool plain = sidata.computeflag && sidata.shearupdate && !project && !record && !energy_books;
    if (exact) {
      if (plain) law<true, true>(sidata, i_forces, j_forces);
      else law<true, false>(sidata, i_forces, j_forces);
    } else {
      if (plain) law<false, true>(sidata, i_forces, j_forces);
      else law<false, false>(sidata, i_forces, j_forces);
    }
  }

  // (inlined into the dispatch above, four copies of the law crowd the pair loop's registers:
  // 1 % more instructions a step, measured; kept out of line by the compiler)
  template<bool EXACT, bool PLAIN>
  inline void law(const SurfacesIntersectData & sidata, ForceData & i_forces, ForceData & j_forces)
  {
    const bool exact = EXACT, project = !PLAIN && this->project, record = !PLAIN && this->record;
    const double * const en = sidata.en;
    const double vs[3] = { sidata.vtr1, sidata.vtr2, sidata.vtr3 };  // V_s, eq. 6
    const double kt = sidata.kt, gammat = sidata.gammat;             // Ks, nu_s from the normal model
    if (!(kt > 0.0))
      error->one(FLERR, "tangential stick_slip needs a tangential stiffness kt > 0 from the normal model "
                        "(e.g. model hooke/stiffness with kt > 0)");
    // eq. 3: Fn as the host's normal (and cohesion) models give it; where the host allows a
    // tensile Fn (limitForce off, adhesive models) the threshold uses |Fn| as LIGGGHTS'
    // tangential history does
    const double fn = std::fabs(sidata.Fn);
    const bool update_history = PLAIN || (sidata.computeflag && sidata.shearupdate);
    const bool energy = !PLAIN && update_history && energy_books;

    double * const hist = &sidata.contact_history[history_offset];
    // a pair that did not touch at the previous pass is a new contact (see postSettings).
    // (Only read here: the stamp is written with the history at the end, so that no store
    // into the history comes before the law's arithmetic.)
    bool fresh = false;
    if (update_history && stamp_offset >= 0)
      fresh = sidata.contact_history[stamp_offset] != touched_last;
    double D[3] = { hist[0], hist[1], hist[2] };
    if (fresh) D[0] = D[1] = D[2] = 0.0;
    const double before2 = energy ? StickSlipCore::dot(D, D) : 0.0;  // |D|^2 at the step's start
    // a re-evaluation without history update (run setup, computes) is a step of length 0
    const double dt = update_history ? update->dt : 0.0;
    if (update_history) {
      if (project) {
        // stock history: increment, then project onto the current tangent plane
        FOR_XYZ(k) D[k] += vs[k] * dt;
        const double dn = StickSlipCore::dot(D, en);
        FOR_XYZ(k) D[k] -= dn * en[k];
        // (exact timing: the step starts from D - V_s dt, the increment projected with D)
      } else {
        // 3D form: turn D into the current tangent plane, keeping its length (docs/law.md
        // step 3): D <- (D - dn n) * sqrt(old2/new2) with new2 = old2 (1 - x), x = dn^2/old2
        const double dn = D[0]*en[0] + D[1]*en[1] + D[2]*en[2];
        if (dn != 0.0) {
          const double old2 = D[0]*D[0] + D[1]*D[1] + D[2]*D[2];
          const double x = dn * dn / old2;  // sin^2 of the angle between D and the plane
          FOR_XYZ(k) D[k] -= dn * en[k];
          // the contact turns by less than 1e-3 rad in a step (nearly always): the series of
          // (1 - x)^(-1/2), whose first dropped term, 5x^3/16 < 4e-19, is below round-off;
          // it spares the square root on the path every contact takes (1-2 % of a step, measured)
          double scale = 1.0 + x * (0.5 + 0.375 * x);
          if (!(x < 1e-6)) {
            const double new2 = D[0]*D[0] + D[1]*D[1] + D[2]*D[2];
            scale = new2 > 0.0 ? std::sqrt(old2 / new2) : 1.0;
          }
          FOR_XYZ(k) D[k] *= scale;
        }
        FOR_XYZ(k) D[k] += vs[k] * dt;  // eq. 7
      }
    }

    // eq. 5: trial force = spring + dashpot
    double F[3];
    FOR_XYZ(k) F[k] = -kt * D[k] - gammat * vs[k];
    const double mag2 = F[0]*F[0] + F[1]*F[1] + F[2]*F[2];
    const double ms = mu_s[sidata.itype][sidata.jtype];
    const double limit = ms * fn;
    // static threshold reached (Fn = 0 always slips); squared, so that a sticking step
    // (the common case) needs no square root
    bool slip = StickSlipCore::slips(mag2, limit * limit);
    double stick = slip ? 0.0 : 1.0;  // share of the step spent sticking (energy: the dashpot's share)
    if (exact) {
      // E0-E7 (stick_slip_core.h)
      const double kin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]);
      slip = StickSlipCore::exact_step(slip, F, D, vs, kt, gammat, dt, limit, kin * fn, kin / ms, reset_total,
                                       stick);
    } else if (slip) {
      // kinematic phase: the force drops to Fmin = (2 mu_k - mu_s) Fn along the trial force
      const double fmin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]) * fn;
      StickSlipCore::drop_to(F, fmin, std::sqrt(mag2), StickSlipCore::stock_ratio);
      // eq. 8: reset the spring so that it carries Fmin (or spring + dashpot do)
      const double fdamp[3] = { -gammat * vs[0], -gammat * vs[1], -gammat * vs[2] };
      StickSlipCore::reset(F, fdamp, kt, reset_total, D);
    }

    if (update_history) {
      FOR_XYZ(k) hist[k] = D[k];
      if (stamp_offset >= 0) sidata.contact_history[stamp_offset] = this_pass;
      if (record) {
        double * const rec = &sidata.contact_history[record_offset];
        rec[0] = fn;
        FOR_XYZ(k) rec[1 + k] = F[k];
        rec[4] = (fresh ? 0.0 : rec[4]) + (slip ? 1.0 : 0.0);
      }
    }

    // torques from the lever arms r*n (cri, crj: distance from the centres to the contact)
    const double tor[3] = { en[1]*F[2] - en[2]*F[1], en[2]*F[0] - en[0]*F[2], en[0]*F[1] - en[1]*F[0] };
    if (energy) {
      const double Fc[3] = { F[0], F[1], F[2] }, Dc[3] = { D[0], D[1], D[2] }, vc[3] = { vs[0], vs[1], vs[2] };
      account_energy(sidata, Fc, Dc, vc, kt, gammat, before2, stick);  // (on copies: see StickSlipCore::exact_step)
    }
    if (sidata.is_wall) {
      const double a = sidata.area_ratio;
      FOR_XYZ(k) {
        i_forces.delta_F[k] += F[k] * a;
        i_forces.delta_torque[k] += -sidata.cri * tor[k] * a;
      }
    } else {
      FOR_XYZ(k) {
        i_forces.delta_F[k] += F[k];
        j_forces.delta_F[k] -= F[k];
        i_forces.delta_torque[k] += -sidata.cri * tor[k];
        j_forces.delta_torque[k] += -sidata.crj * tor[k];
      }
    }
  }

  /* docs/law.md "Energy": the work the contact received this step, -F_s.V_s dt, less the
     increase of the spring energy Ks|D|^2/2, was dissipated; of it the dashpot took
     nu_s |V_s|^2 dt times the share of the step spent sticking, the slips the rest.
     Reported the way stock history reports its own (tangential_model_history.h): power
     into sidata.P_diss and the heat tallies (1 dashpot, 2 slips), the elastic force into
     the normal model's elastic-potential history, the dissipative part of the force into
     the per-atom dissipated_energy property; the energy itself is added to that
     property's first value, "energy" (half to each grain of a pair). */
  __attribute__((noinline)) void account_energy(const SurfacesIntersectData & sidata, const double * F, const double * D,
                             const double * vs, double kt, double gammat, double before2, double stick)
  {
    const double dt = update->dt;
    const double a = sidata.is_wall ? sidata.area_ratio : 1.0;
    const double total = StickSlipCore::dissipated(F, vs, dt, kt, before2, StickSlipCore::dot(D, D)) * a;
    const double dashpot = gammat * StickSlipCore::dot(vs, vs) * dt * stick * a;
    const double slips = total - dashpot;
    if (heating) {
      sidata.P_diss += total / dt;
      if (heating_track) {
        if (sidata.is_wall) {
          cmb->tally_pw(dashpot / dt, sidata.i, sidata.jtype, 1);
          cmb->tally_pw(slips / dt, sidata.i, sidata.jtype, 2);
        } else {
          cmb->tally_pp(dashpot / dt, sidata.i, sidata.j, 1);
          cmb->tally_pp(slips / dt, sidata.i, sidata.j, 2);
        }
      }
    }
    // the spring part of the applied force, and the rest (dashpot, slip)
    double Fela[3], Fdiss[3];
    FOR_XYZ(k) {
      Fela[k] = -kt * D[k];
      Fdiss[k] = F[k] - Fela[k];
    }
    const double * const en = sidata.en;
    const double tela[3] = { en[1]*Fela[2] - en[2]*Fela[1], en[2]*Fela[0] - en[0]*Fela[2], en[0]*Fela[1] - en[1]*Fela[0] };
    const double tdis[3] = { en[1]*Fdiss[2] - en[2]*Fdiss[1], en[2]*Fdiss[0] - en[0]*Fdiss[2], en[0]*Fdiss[1] - en[1]*Fdiss[0] };
    if (elasticpot) {
      double * const ep = &sidata.contact_history[elastic_potential_offset];
      FOR_XYZ(k) {
        ep[1 + k] -= Fela[k];
        ep[4 + k] -= -sidata.cri * tela[k];
        ep[7 + k] -= -sidata.crj * tela[k];
      }
    }
    if (dissipated) {
      double * const di = fix_dissipated->array_atom[sidata.i];
      di[0] += 0.5 * total;
      FOR_XYZ(k) {
        di[1 + k] += -Fdiss[k];
        di[4 + k] += sidata.cri * tdis[k];
      }
      // with newton off a pair across processors is computed by both; each books its own grain
      if (sidata.j < atom->nlocal) {
        double * const dj = fix_dissipated->array_atom[sidata.j];
        dj[0] += 0.5 * total;
        FOR_XYZ(k) {
          dj[1 + k] -= -Fdiss[k];
          dj[4 + k] += sidata.crj * tdis[k];
        }
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

  inline void beginPass(SurfacesIntersectData & sidata, ForceData &, ForceData &)
  {
    // (called before each pass over the grain pairs; walls do not call it)
    if (!(sidata.computeflag && sidata.shearupdate)) return;
    const double step = static_cast<double>(update->ntimestep);
    if (step != this_pass) {
      last_pass = this_pass;
      this_pass = step;
    }
    // the first pass of this model (after read_restart, a new pair_style) takes step - 1
    touched_last = last_pass >= 0.0 ? last_pass : this_pass - 1.0;
  }
  inline void endPass(SurfacesIntersectData &, ForceData &, ForceData &) {}
};

}
}

#undef FOR_XYZ

#endif
#endif
