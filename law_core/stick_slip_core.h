// SPDX-License-Identifier: GPL-2.0-or-later
/* The engine-free core of the stick-slip friction law of Khellaf & Mansouri (2024), equations
   numbered as in the paper: plain doubles in and out, for one contact and one step. Every C++
   host includes this one file: LIGGGHTS' tangential model, LAMMPS' tangential sub-model
   stick_slip and LAMMPS 2021's styles (lammps_plugin/), and YADE's compiled law (yade_law/).
   Each host turns the spring into its tangent plane, builds the trial force and, in step
   timing, tests the slip its own way (so that, at mu_k = mu_s, it gives its stock model's
   results bit for bit); the rest of the law is here (docs/law.md). tools/lammps_patch.py
   writes it in LAMMPS' own form for a LAMMPS tree. */

#ifndef STICKSLIP_STICK_SLIP_CORE_H
#define STICKSLIP_STICK_SLIP_CORE_H

#include <algorithm>
#include <cmath>

#if defined(__GNUC__)
#define STICK_SLIP_ALWAYS_INLINE inline __attribute__((always_inline))
#define STICK_SLIP_NOINLINE __attribute__((noinline))
#define STICK_SLIP_UNLIKELY(x) __builtin_expect(!!(x), 0)
#else
#define STICK_SLIP_ALWAYS_INLINE inline
#define STICK_SLIP_NOINLINE
#define STICK_SLIP_UNLIKELY(x) (x)
#endif

namespace stickslip {

class StickSlipCore {
 public:
  // exact timing follows slips one by one until the force's part across -V_s is below
  // SETTLED times mu_s Fn (it then changes the slip level by less than round-off,
  // SETTLED^2/2 < 1e-16) or MAX_EXPLICIT_SLIPS slips have been followed in the step; the
  // rest of the step has a closed form (E7)
  static constexpr double SETTLED = 1e-8;
  static constexpr int MAX_EXPLICIT_SLIPS = 100;

  static double dot(const double *a, const double *b)
  {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  }

  // eq. 8: the force after a slip is Fmin = (2 mu_k - mu_s) Fn, whose saw-tooth between Fmin
  // and mu_s Fn averages mu_k Fn; this is its factor
  static double kinetic(double mu_s, double mu_k) { return 2.0 * mu_k - mu_s; }

  // the slip test: the trial force reaches the static threshold mu_s Fn (magnitudes or
  // squares of both)
  static bool slips(double force, double threshold) { return force >= threshold; }

  // fmin / |F| in one division: the rescale of most stock models (drop_to's default)
  static double stock_ratio(double fmin, double mag) { return fmin / mag; }

  /* Step timing's drop at a slip (eq. 8): the trial force F, of length mag, scaled along
     itself to fmin (a zero force stays zero). ratio(fmin, mag) is the host's stock arithmetic
     for fmin / mag: each stock model rounds its rescale its own way, and at mu_k = mu_s the
     host's stock results, bit for bit, need its own. Returns the factor applied. */
  template <class Ratio>
  static STICK_SLIP_ALWAYS_INLINE double drop_to(double *F, double fmin, double mag, Ratio ratio)
  {
    const double s = mag > 0.0 ? ratio(fmin, mag) : 0.0;
    for (int i = 0; i < 3; i++) F[i] *= s;
    return s;
  }

  /* eq. 8: the spring after a slip that applies the force F. The spring alone carries F
     (the paper), or with reset total the spring and the dashpot's force fdamp together:
     Ks D = -(F - fdamp). */
  static STICK_SLIP_ALWAYS_INLINE void reset(const double *F, const double *fdamp, double ks,
                                             bool total, double *D)
  {
    const double back = -1.0 / ks;
    for (int i = 0; i < 3; i++) D[i] = (total ? F[i] - fdamp[i] : F[i]) * back;
  }

  /* The work the contact received in the step, -F.V_s dt, less the increase of the
     spring's energy Ks |D|^2 / 2 (before2, after2: |D|^2 at the step's start and end): what
     the dashpot and the slips dissipated. */
  static double dissipated(const double *F, const double *vs, double dt, double ks, double before2,
                           double after2)
  {
    return -dot(F, vs) * dt - 0.5 * ks * (after2 - before2);
  }

  /* Exact slip timing, E0-E7, for a step of length dt (0: a set-up evaluation, no time
     passes) in which V_s and Fn are held. F: in, the trial force at the step's end (the
     spring after its increment, plus the dashpot's force -nu_s V_s); out, the force applied.
     end_slips: the host's slip test of that trial force. T = mu_s Fn, fmin = Fmin, ratio =
     Fmin/T. Returns whether the step slips; then D (out) is the spring at its end, else
     the host's spring and F stand. stick: the share of the step spent sticking.
     It is E0 (start_force, step_slips) and, in a step that slips, slip_step: a host may call
     the three itself, so that a sticking step evaluates none of slip_step's arguments. */
  static STICK_SLIP_ALWAYS_INLINE bool exact_step(bool end_slips, double *F, double *D,
                                                  const double *vs, double ks, double nu_s,
                                                  double dt, double T, double fmin, double ratio,
                                                  bool total, double &stick)
  {
    double F0[3];
    const double start2 = start_force(F, vs, ks * dt, F0);
    const bool start_slips = slips(start2, T * T);
    stick = 1.0;
    // (most steps stick: the slipping code is laid out of the sticking path)
    if (STICK_SLIP_UNLIKELY(step_slips(end_slips, start_slips))) {
      slip_step(start_slips, F0, start2, F, D, vs, ks, nu_s, dt, T, fmin, ratio, total, stick);
      return true;
    }
    return false;
  }

  /* E0: F: the trial force at the step's end; F0 (out): at its start, where the spring lacks
     its increment Ks V_s dt (ksdt = Ks dt). Returns |F0|^2. */
  static STICK_SLIP_ALWAYS_INLINE double start_force(const double *F, const double *vs, double ksdt,
                                                     double *F0)
  {
    for (int i = 0; i < 3; i++) F0[i] = F[i] + ksdt * vs[i];
    return dot(F0, F0);
  }

  // E0: |F| moves on a line in the step and is convex, so the step has no slip iff the trial
  // force is below T at both ends (end_slips, start_slips: slips() of each)
  static bool step_slips(bool end_slips, bool start_slips) { return end_slips || start_slips; }

  /* E1-E7 for a step that E0 found slipping: start_slips, F0 and start2 = |F0|^2 are E0's
     (start_force), the rest as exact_step's. */
  static STICK_SLIP_ALWAYS_INLINE void slip_step(bool start_slips, const double *F0, double start2,
                                                 double *F, double *D, const double *vs, double ks,
                                                 double nu_s, double dt, double T, double fmin,
                                                 double ratio, bool total, double &stick)
  {
    stick = 0.0;
    const double vs2 = dot(vs, vs), damp2 = nu_s * nu_s;
    if (start_slips && T > 0.0 && !total && damp2 * vs2 > 0.0 &&
        (fmin * fmin + damp2 * vs2 - T * T) * std::sqrt(start2) - 2.0 * fmin * nu_s * dot(F0, vs) >=
            0.0) {
      // E4 at the step's start, the common slipping case of a flowing bed: the force is at or
      // above T at its start, and after the slip the dashpot alone keeps it there,
      // |Fmin t0 + nu_s |V_s| u| >= T (t0 = F0/|F0|, u = -V_s/|V_s|; squared: one square root,
      // no division). It slides at Fmin u all step; the spring holds the trial force
      // (Fmin + nu_s |V_s|) u less the dashpot
      const double a = fmin / std::sqrt(vs2), aks = a / ks;
      for (int i = 0; i < 3; i++) {
        F[i] = -a * vs[i];
        D[i] = aks * vs[i];
      }
      return;
    }
    // the general case, out of line on copies (an address taken here would keep the common
    // path's vectors in memory, and values live across a call would leave the registers)
    const double f0[3] = {F0[0], F0[1], F0[2]}, v[3] = {vs[0], vs[1], vs[2]};
    double applied[3], spring[3];
    stick = exact_general(f0, v, T, fmin, ratio, ks, nu_s, dt, total, applied, spring);
    for (int i = 0; i < 3; i++) {
      F[i] = applied[i];
      D[i] = spring[i];
    }
  }

  /* exact_slips for a step from its start (E6 when nothing is added at a reset): the force
     applied at its end, the spring there, which holds the trial force less the dashpot
     (eq. 5); returns the share of the step spent sticking. */
  static STICK_SLIP_NOINLINE double exact_general(const double *F0, const double *vs, double T,
                                                  double fmin, double ratio, double ks, double nu_s,
                                                  double dt, bool total, double *applied,
                                                  double *spring)
  {
    double trial[3], stick;
    exact_slips(F0, vs, T, fmin, ratio, ks, nu_s, dt, total, ratio == 1.0 && (total || nu_s == 0.0),
                applied, trial, stick);
    for (int i = 0; i < 3; i++) spring[i] = -(trial[i] + nu_s * vs[i]) / ks;
    return stick;
  }

  /* E6: mu_k = mu_s, the force stays on |F| = T and turns towards u. With phi the angle
     between F and u, d(phi)/d(theta) = -(rate/T) sin(phi), so tan(phi/2) falls as
     exp(-rate*theta/T): over the rest of the step by exp(-k_rest). F becomes the force at the
     end of the step. */
  static void plastic_flow(double *F, const double *u, double k_rest, double T)
  {
    const double f = dot(F, u);
    double q[3];
    for (int k = 0; k < 3; k++) q[k] = F[k] - f * u[k];
    const double qn = std::sqrt(dot(q, q));
    const double s = qn / (T + f) * std::exp(-k_rest);    // tan(phi/2) at the end (f >= 0 here)
    const double c = (1.0 - s * s) / (1.0 + s * s), sn = 2.0 * s / (1.0 + s * s);
    for (int k = 0; k < 3; k++) F[k] = (T * c) * u[k] + (T * sn) * (qn > 0.0 ? q[k] / qn : 0.0);
  }

  /* E1-E7: a step in which at least one slip happens (eqs. 5, 7, 8 integrated over the
     step). The trial force F = -Ks D - nu_s V_s moves along u = -V_s/|V_s| at rate =
     Ks |V_s| dt per unit of step fraction theta. In: F0, the trial force at theta = 0;
     vs = V_s; T, fmin, r = fmin/T; ks, nu_s, dt; reset_total; flow_law (E6 applies).
     Out: applied, the force at the end of the step; trial, the trial force there (the
     spring is -(trial + nu_s V_s)/Ks); stick, the share of the step spent sticking.
     Out of line: it runs only in steps that slip. */
  static STICK_SLIP_NOINLINE void exact_slips(const double *F0, const double *vs, double T,
                                              double fmin, double r, double ks, double nu_s,
                                              double dt, bool reset_total, bool flow_law,
                                              double *applied, double *trial, double &stick)
  {
    const double speed = std::sqrt(dot(vs, vs));
    double u[3];
    for (int k = 0; k < 3; k++) u[k] = speed > 0.0 ? -vs[k] / speed : 0.0;
    const double rate = ks * speed * dt;
    // after a slip the trial force restarts from Fmin t + kept u (E3): the spring holds Fmin
    // and the dashpot adds nu_s |V_s| (reset spring), or both hold Fmin (reset total)
    const double kept = reset_total ? 0.0 : nu_s * speed;
    stick = 0.0;
    if (!(T > 0.0)) {    // E1: no normal force, no friction; the spring keeps what the reset leaves
      for (int k = 0; k < 3; k++) {
        applied[k] = 0.0;
        trial[k] = kept * u[k];
      }
      return;
    }
    double F[3] = {F0[0], F0[1], F0[2]};
    double theta = 0.0;
    for (int slips = 0;;) {
      // E2: the next slip, where |F + rate dtheta u| reaches T (the larger root); before the
      // step's first slip the force may already be at or above T (Fn fell): slip at once
      const double f = dot(F, u), F2 = dot(F, F);
      double dtheta;
      if (slips == 0 && F2 >= T * T)
        dtheta = 0.0;
      else {
        const double gap = std::max(std::sqrt(std::max(T * T - (F2 - f * f), 0.0)) - f, 0.0);
        dtheta = rate > 0.0 ? gap / rate : INFINITY;
      }
      if (!(theta + dtheta <= 1.0)) {    // sticks to the end of the step
        const double rest = 1.0 - theta;
        for (int k = 0; k < 3; k++) applied[k] = trial[k] = F[k] + (rate * rest) * u[k];
        stick += rest;
        return;
      }
      double hit[3];
      for (int k = 0; k < 3; k++) hit[k] = F[k] + (rate * dtheta) * u[k];
      stick += dtheta;
      theta += dtheta;
      // E3: the slip; the force drops to Fmin along its direction t, the spring is reset (eq. 8)
      const double hn = std::sqrt(dot(hit, hit));
      double t[3];
      for (int k = 0; k < 3; k++) t[k] = hit[k] / hn;
      slips++;
      for (int k = 0; k < 3; k++) F[k] = fmin * t[k] + kept * u[k];
      const double rest = 1.0 - theta;
      // E4: the restarted force is at or above T again: slips follow without end and turn t
      // onto u, the contact slides at Fmin u for the rest of the step
      if (kept > 0.0 && dot(F, F) >= T * T) {
        for (int k = 0; k < 3; k++) {
          trial[k] = (fmin + kept) * u[k];
          applied[k] = fmin * u[k];
        }
        return;
      }
      if (rate == 0.0) {    // E5: nothing moves, the force stays where the slip left it
        for (int k = 0; k < 3; k++) applied[k] = trial[k] = F[k];
        stick += rest;
        return;
      }
      const double along = dot(t, u);
      // (t.u = 0 too: |F + rate theta u| = T sqrt(1 + (rate theta/T)^2) rises at once, so the
      // force flows from phi = 90 degrees; only t.u < 0 unloads into the cone and sticks)
      if (flow_law && along >= 0.0) {    // E6: plastic flow on |F| = T
        plastic_flow(F, u, rate * rest / T, T);
        for (int k = 0; k < 3; k++) applied[k] = trial[k] = F[k];
        return;
      }
      // E7: settled along u (or followed MAX_EXPLICIT_SLIPS times): the remaining slips of the
      // step repeat one cycle (Fmin + kept) u -> T u, of length L in theta; the part q of the
      // force across u shrinks by r at each slip
      const double fu = dot(F, u);
      double q[3];
      for (int k = 0; k < 3; k++) q[k] = F[k] - fu * u[k];
      if ((std::sqrt(dot(q, q)) <= SETTLED * T && along > 0.0) || slips >= MAX_EXPLICIT_SLIPS) {
        const double low = fmin + kept;
        const double L = (T - low) / rate;
        if (!(L > 0.0)) {    // restarts at T: slides, as E4
          for (int k = 0; k < 3; k++) {
            trial[k] = low * u[k];
            applied[k] = fmin * u[k];
          }
          return;
        }
        const double n = std::floor(rest / L);
        const double part = rest - n * L;
        const double shrink = n == 0.0 ? 1.0 : std::pow(r, n);    // (no whole cycle left: common)
        for (int k = 0; k < 3; k++)
          applied[k] = trial[k] = (low + rate * part) * u[k] + shrink * q[k];
        stick += rest;
        return;
      }
    }
  }
};

}    // namespace stickslip

#endif
