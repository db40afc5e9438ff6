/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: the stick-slip tangential contact law of Khellaf & Mansouri (2024) on LAMMPS.

   The styles' part of the law (the pair style and the walls call it): the settings, the
   spring's turn and the trial force as stock gran/hooke/history computes them, and stock's
   rescale for reset total; the rest of the law (the slip test, eq. 8's reset to Fmin, exact
   timing E0-E7, the energy) is the engine-free core, law_core/stick_slip_core.h, that the
   granular sub-model and the LIGGGHTS plugin share.

   With the default settings (reset total, slip_timing step, history_rotation project,
   damping mass, lever_arm radius) and mu_k = mu_s the arithmetic is stock
   gran/hooke/history's, operation for operation, so that renaming the styles changes no
   bit of a run (lammps_plugin/README.md says where the law differs from stock). */

#ifndef STICKSLIP_LAMMPS_LAW_H
#define STICKSLIP_LAMMPS_LAW_H

#include "stick_slip_core.h"

#include "error.h"
#include "lammps.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace StickSlip {

/* Per-contact history: the spring D (3 values, stock's shear), and with `record yes` what
   the law last applied and what the contact has done since it began. Every value but D and
   Fs is the same seen from either body of a pair (transfer_history). */
enum {
  HIST_D = 0,       // D, the spring elongation (eq. 7), 3 values
  SIZE_PLAIN = 3,   // without record: stock's 3 values
  HIST_FN = 3,      // Fn applied, signed (> 0 pushes the bodies apart), force units
  HIST_FS = 4,      // tangential force applied on this body, 3 values
  HIST_NSLIP = 7,   // steps in which the contact slipped (the adapters' c_slip)
  HIST_WORK = 8,    // work the tangential law dissipated (docs/law.md "Energy")
  SIZE_RECORD = 9
};

// The law's keywords (lammps_plugin/README.md). Defaults: stock gran/hooke/history.
struct Settings {
  double mu_k = -1.0;          // kinetic coefficient; < 0: not given, mu_k = mu_s (stock)
  bool reset_total = true;     // eq. 8: spring + dashpot hold Fmin (stock's rescale); false: the spring alone
  bool exact = false;          // slip_timing exact: every slip at its time in the step (E0-E7)
  bool project = true;         // history_rotation project (stock); false: keep_length (docs/law.md step 3)
  bool absolute = false;       // damping absolute: gamma_n, gamma_t are nu_n, nu_s; false: meff * gamma
  bool contact_lever = false;  // lever_arm contact: c = r - delta/2; false: the radius (stock)
  bool record = false;         // keep Fn, Fs, slip count and work in the contact history

  int history_size() const { return record ? SIZE_RECORD : SIZE_PLAIN; }
};

/* A number argument, or one error line naming it and its allowed range. */
inline double parse_number(LAMMPS_NS::LAMMPS *lmp, const std::string &cmd, const std::string &name, const char *text,
                           const char *allowed)
{
  char *end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno || !std::isfinite(v))
    lmp->error->all(FLERR, cmd + ": " + name + " = '" + text + "' is not a number (allowed: " + allowed + ")");
  return v;
}

/* One error line when a value is outside its allowed range. */
inline void check_range(LAMMPS_NS::LAMMPS *lmp, const std::string &cmd, const std::string &name, double v, bool ok,
                        const char *allowed)
{
  if (ok) return;
  char value[40];
  snprintf(value, sizeof value, "%g", v);
  lmp->error->all(FLERR, cmd + ": " + name + " = " + value + " is outside its allowed range: " + allowed);
}

/* Reads one of the law's keywords at arg[iarg] into s. Returns the number of words used;
   0 if arg[iarg] is not a law keyword. Errors name the command, the keyword and the
   allowed values. */
inline int parse_keyword(LAMMPS_NS::LAMMPS *lmp, const std::string &cmd, Settings &s, int narg, char **arg, int iarg)
{
  struct Choice {
    const char *keyword, *yes, *no;
    bool Settings::*flag;
  };
  static const Choice choices[] = {
      {"reset", "total", "spring", &Settings::reset_total},
      {"slip_timing", "exact", "step", &Settings::exact},
      {"history_rotation", "project", "keep_length", &Settings::project},
      {"damping", "absolute", "mass", &Settings::absolute},
      {"lever_arm", "contact", "radius", &Settings::contact_lever},
      {"record", "yes", "no", &Settings::record},
  };
  const std::string key = arg[iarg];
  if (key == "mu_k") {
    if (iarg + 1 >= narg) lmp->error->all(FLERR, cmd + ": keyword mu_k needs a value (mu_s/2 <= mu_k <= mu_s)");
    s.mu_k = parse_number(lmp, cmd, "mu_k", arg[iarg + 1], "mu_s/2 <= mu_k <= mu_s");
    check_range(lmp, cmd, "mu_k", s.mu_k, s.mu_k >= 0.0, "mu_s/2 <= mu_k <= mu_s");
    return 2;
  }
  for (const Choice &c : choices) {
    if (key != c.keyword) continue;
    const std::string allowed = std::string(c.yes) + " or " + c.no;
    if (iarg + 1 >= narg) lmp->error->all(FLERR, cmd + ": keyword " + key + " needs a value: " + allowed);
    const std::string value = arg[iarg + 1];
    if (value == c.yes)
      s.*c.flag = true;
    else if (value == c.no)
      s.*c.flag = false;
    else
      lmp->error->all(FLERR, cmd + ": " + key + " '" + value + "' is not allowed: " + allowed);
    return 2;
  }
  return 0;
}

// the keywords parse_keyword knows, for the message about an unknown one
inline const char *keyword_list()
{
  return "mu_k, reset, slip_timing, history_rotation, damping, lever_arm, record";
}

/* mu_s/2 <= mu_k <= mu_s (docs/law.md), so that 0 <= Fmin = (2 mu_k - mu_s) Fn <= mu_k Fn. */
inline void check_kinetic(LAMMPS_NS::LAMMPS *lmp, const std::string &where, double mu_s, double mu_k)
{
  if (mu_k >= 0.5 * mu_s && mu_k <= mu_s) return;
  char msg[200];
  snprintf(msg, sizeof msg, ": mu_k = %g is outside its allowed range [mu_s/2, mu_s] = [%g, %g] (mu_s = %g)", mu_k,
           0.5 * mu_s, mu_s, mu_s);
  lmp->error->all(FLERR, where + msg);
}

/* The coefficients of one kind of contact (a type pair, or a wall). */
struct Coeffs {
  double kt;     // Ks (eq. 5)
  double mu_s;   // static coefficient: threshold mu_s |Fn| (stock's xmu)
  double kin;    // 2 mu_k - mu_s: Fmin = kin |Fn|; exactly mu_s when mu_k = mu_s
  double ratio;  // Fmin/T = (2 mu_k - mu_s)/mu_s, exactly 1 iff mu_k = mu_s (exact timing)
};

inline Coeffs make_coeffs(double kt, double mu_s, double mu_k)
{
  Coeffs c;
  c.kt = kt;
  c.mu_s = mu_s;
  c.kin = stickslip::StickSlipCore::kinetic(mu_s, mu_k);
  c.ratio = mu_s > 0.0 ? c.kin / mu_s : 1.0;
  return c;
}

/* Which of the law's branches the tangential force tests at run time. RuntimeMode reads the
   settings (the region wall); FixedMode<EXACT, PROJECT, RECORD> fixes the three that shape
   the contact's code (the pair style and the primitive walls compile their contact loop once
   per combination, so that a contact-step carries no test of them). */
struct RuntimeMode {
  static bool exact(const Settings &s) { return s.exact; }
  static bool project(const Settings &s) { return s.project; }
  static bool record(const Settings &s) { return s.record; }
};

template <bool EXACT, bool PROJECT, bool RECORD> struct FixedMode {
  static constexpr bool exact(const Settings &) { return EXACT; }
  static constexpr bool project(const Settings &) { return PROJECT; }
  static constexpr bool record(const Settings &) { return RECORD; }
};

/* Calls loop(FixedMode<...>()) with the mode of the settings s: the one place that turns
   the run-time settings into a compiled loop (the caller's generic lambda instantiates its
   loop once per mode). */
template <class Loop> inline void with_fixed_mode(const Settings &s, Loop &&loop)
{
  switch ((s.exact ? 4 : 0) + (s.project ? 2 : 0) + (s.record ? 1 : 0)) {
    case 0: loop(FixedMode<false, false, false>()); break;
    case 1: loop(FixedMode<false, false, true>()); break;
    case 2: loop(FixedMode<false, true, false>()); break;
    case 3: loop(FixedMode<false, true, true>()); break;
    case 4: loop(FixedMode<true, false, false>()); break;
    case 5: loop(FixedMode<true, false, true>()); break;
    case 6: loop(FixedMode<true, true, false>()); break;
    default: loop(FixedMode<true, true, true>()); break;
  }
}

/* The tangential law at one contact for one force evaluation (docs/law.md steps 3-5).
   del: x_i - x_j (for a wall, the body's offset from the wall), rsqinv = 1/|del|^2;
   ccel_r = Fn, signed as stock computes it (ccel*r: > 0 pushes apart; it is tensile only
   where stock's damping makes it so, and the threshold uses |Fn| as stock does);
   vtr = V_s (eq. 6), the velocity of i's contact point relative to j's; nu_s: the
   tangential damping (meff * gamma_t, or gamma_t with damping absolute);
   update: a step (false: a set-up evaluation, no time passes and D is not loaded);
   hist: the contact's history (layout above). Out: fs, the tangential force on i.
   (Always inlined: it runs for every contact of every step, and a call would cost the
   caller's registers; the rare paths it calls are out of line.) */
template <class Mode = RuntimeMode>
__attribute__((always_inline)) inline void tangential_force(const Settings &s, const Coeffs &c, const double *del,
                                                            double rsqinv, double ccel_r, const double *vtr,
                                                            double nu_s, double dt, bool update, double *hist,
                                                            double *fs)
{
  const double kt = c.kt;
  double D[3] = {hist[0], hist[1], hist[2]};
  double incremented[3];  // history_rotation project: D after the increment (stock's rule at a slip, below)
  if (Mode::project(s)) {
    // stock: increment (eq. 7), then project onto the current tangent plane
    if (update) {
      D[0] += vtr[0] * dt;
      D[1] += vtr[1] * dt;
      D[2] += vtr[2] * dt;
    }
    for (int k = 0; k < 3; k++) incremented[k] = D[k];
    double rsht = D[0] * del[0] + D[1] * del[1] + D[2] * del[2];
    rsht *= rsqinv;
    if (update) {
      D[0] -= rsht * del[0];
      D[1] -= rsht * del[1];
      D[2] -= rsht * del[2];
    }
  } else if (update) {
    // docs/law.md step 3: turn D into the current tangent plane keeping its length,
    // D <- (D - dn n) * sqrt(old2/new2), new2 = old2 (1 - x), x = dn^2/old2 (n = del/|del|)
    const double dd = D[0] * del[0] + D[1] * del[1] + D[2] * del[2];
    if (dd != 0.0) {
      const double old2 = D[0] * D[0] + D[1] * D[1] + D[2] * D[2];
      const double x = dd * dd * rsqinv / old2;  // sin^2 of the angle between D and the plane
      const double rsht = dd * rsqinv;
      for (int k = 0; k < 3; k++) D[k] -= rsht * del[k];
      // the contact turns by less than 1e-3 rad in a step (nearly always): the series of
      // (1 - x)^(-1/2), whose first dropped term, 5x^3/16 < 4e-19, is below round-off,
      // spares the square root on the path every contact takes
      double scale = 1.0 + x * (0.5 + 0.375 * x);
      if (!(x < 1e-6)) {
        const double new2 = D[0] * D[0] + D[1] * D[1] + D[2] * D[2];
        scale = new2 > 0.0 ? std::sqrt(old2 / new2) : 1.0;
      }
      for (int k = 0; k < 3; k++) D[k] *= scale;
    }
    for (int k = 0; k < 3; k++) D[k] += vtr[k] * dt;  // eq. 7
  }
  // the spring is stored now (without record, which reads the old one below): a sticking step
  // leaves it so, and it need not stay in registers through the slip test; a slip stores
  // the reset spring at the end
  if (!Mode::record(s)) {
    hist[0] = D[0];
    hist[1] = D[1];
    hist[2] = D[2];
  }

  // eq. 5: trial force = spring + dashpot
  fs[0] = -(kt * D[0] + nu_s * vtr[0]);
  fs[1] = -(kt * D[1] + nu_s * vtr[1]);
  fs[2] = -(kt * D[2] + nu_s * vtr[2]);

  // slip test (docs/law.md step 5): |F_t| >= mu_s |Fn|, squared so that a sticking step
  // (the common case) needs no square root
  const double fnabs = std::fabs(ccel_r);
  const double limit = c.mu_s * fnabs;
  const double sum = fs[0] * fs[0] + fs[1] * fs[1] + fs[2] * fs[2];
  bool slipped = stickslip::StickSlipCore::slips(sum, limit * limit);
  if (Mode::exact(s)) {
    // E0-E7 (stick_slip_core.h's exact_step, called in its parts: a sticking step then
    // evaluates none of slip_step's arguments, whose loads and products would otherwise take
    // registers from the contact loop); an evaluation without update (set-up) is a step of
    // length 0
    const double h = update ? dt : 0.0;
    double F0[3];
    const double start2 = stickslip::StickSlipCore::start_force(fs, vtr, kt * h, F0);
    const bool start_slips = stickslip::StickSlipCore::slips(start2, limit * limit);
    if (STICK_SLIP_UNLIKELY(stickslip::StickSlipCore::step_slips(slipped, start_slips))) {
      double stick;
      stickslip::StickSlipCore::slip_step(start_slips, F0, start2, fs, D, vtr, kt, nu_s, h, limit, c.kin * fnabs,
                                          c.ratio, s.reset_total, stick);
      slipped = true;
    }
  } else if (slipped) {
    // (stock's |D| after the increment, tested only here, at a slip)
    if (Mode::project(s) && incremented[0] * incremented[0] + incremented[1] * incremented[1] +
                                    incremented[2] * incremented[2] ==
                                0.0) {
      // stock's rule: a contact whose spring is zero (a new contact in a set-up pass) gets no
      // tangential force when the dashpot alone exceeds the threshold; D stays zero
      fs[0] = fs[1] = fs[2] = 0.0;
    } else {
      // kinematic phase: the force drops to Fmin = (2 mu_k - mu_s) |Fn| along the trial force
      const double ratio = stickslip::StickSlipCore::drop_to(fs, c.kin * fnabs, std::sqrt(sum),
                                                             stickslip::StickSlipCore::stock_ratio);
      if (s.reset_total) {
        // reset total: spring + dashpot = Fmin in stock's rescale of the shear, so that with
        // mu_k = mu_s the renamed styles are stock bit for bit
        for (int k = 0; k < 3; k++) {
          const double dv = nu_s * vtr[k] / kt;
          D[k] = ratio * (D[k] + dv) - dv;
        }
      }
      // eq. 8, reset spring (the paper): Ks |D| = Fmin
      if (!s.reset_total) stickslip::StickSlipCore::reset(fs, nullptr, kt, false, D);
    }
  }

  if (Mode::record(s)) {
    if (update) {
      // docs/law.md "Energy": the work the contact received this step, -F_s.V_s dt, less
      // the increase of the spring energy Ks |D|^2/2
      const double before = hist[0] * hist[0] + hist[1] * hist[1] + hist[2] * hist[2];
      const double after = D[0] * D[0] + D[1] * D[1] + D[2] * D[2];
      hist[HIST_WORK] += stickslip::StickSlipCore::dissipated(fs, vtr, dt, kt, before, after);
      if (slipped) hist[HIST_NSLIP] += 1.0;
    }
    hist[HIST_FN] = ccel_r;
    for (int k = 0; k < 3; k++) hist[HIST_FS + k] = fs[k];
  }
  if (Mode::record(s) || slipped) {
    hist[0] = D[0];
    hist[1] = D[1];
    hist[2] = D[2];
  }
}

/* The lever arm from a body's centre to the contact: its radius (stock), or with
   lever_arm contact the distance to the middle of the overlap, c = r - delta/2 (docs/law.md
   step 1). */
inline double lever(const Settings &s, double radius, double overlap)
{
  return s.contact_lever ? radius - 0.5 * overlap : radius;
}

}  // namespace StickSlip

#endif
