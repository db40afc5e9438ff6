/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: exact slip timing of the stick-slip law of Khellaf & Mansouri (2024),
   docs/law.md "Exact slip timing", steps E1-E7, for one contact and one step.

   Engine-independent (no LAMMPS or LIGGGHTS header): plain doubles and 3-vectors, so
   that every C++ engine plugin can share it. pyref/laws.py (_exact_slips) is the
   reference: same branch order and constants. The caller does E0 (is there a slip in
   this step at all?) and, for speed, may test E4 at the step's start itself. */

#ifndef STICKSLIP_EXACT_SLIP_TIMING_H
#define STICKSLIP_EXACT_SLIP_TIMING_H

#include <algorithm>
#include <cmath>

namespace stickslip {

// Slips are followed one by one until the force's part across -V_s is below SETTLED times
// mu_s Fn (it then changes the slip level by less than round-off, SETTLED^2/2 < 1e-16) or
// MAX_EXPLICIT_SLIPS slips have been followed in the step; the rest has a closed form (E7).
const double SETTLED = 1e-8;
const int MAX_EXPLICIT_SLIPS = 100;

inline double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* E6: mu_k = mu_s, the force stays on |F| = T and turns towards u. With phi the angle
   between F and u, d(phi)/d(theta) = -(rate/T) sin(phi), so tan(phi/2) falls as
   exp(-rate*theta/T): over the rest of the step by exp(-k_rest). F becomes the force at
   the end of the step. */
inline void plastic_flow(double *F, const double *u, double k_rest, double T)
{
  const double f = dot3(F, u);
  double q[3];
  for (int k = 0; k < 3; k++) q[k] = F[k] - f * u[k];
  const double qn = std::sqrt(dot3(q, q));
  const double s = qn / (T + f) * std::exp(-k_rest);  // tan(phi/2) at the end (f >= 0 here)
  const double c = (1.0 - s * s) / (1.0 + s * s), sn = 2.0 * s / (1.0 + s * s);
  for (int k = 0; k < 3; k++) F[k] = (T * c) * u[k] + (T * sn) * (qn > 0.0 ? q[k] / qn : 0.0);
}

/* One step of a contact in which at least one slip happens (eqs. 5, 7, 8 integrated over
   the step). V_s and Fn are constant over the step, so the trial force F = -Ks D - nu_s V_s
   moves along u = -V_s/|V_s| at rate = Ks |V_s| dt per unit of step fraction theta.
   In: F0, the trial force at theta = 0 (spring before the step's increment); vs = V_s;
   T = mu_s Fn; fmin = (2 mu_k - mu_s) Fn; r = fmin/T as a parameter, (2 mu_k - mu_s)/mu_s;
   ks, nu_s; dt (0 for an evaluation in which no time passes); reset_total (eq. 8's
   `total`); flow_law: E6 applies (r == 1 and nothing added at the reset).
   Out: applied, the force at the end of the step (the one applied, as in a step without
   slip); trial, the trial force (spring + dashpot) at the end, so that the spring is
   D = -(trial + nu_s V_s)/Ks; stick, the share of the step spent sticking.
   Kept out of line: it runs only in steps that slip, and inlined it would crowd the
   common sticking step's code. */
__attribute__((noinline)) inline void exact_slips(const double *F0, const double *vs, double T, double fmin,
                                                  double r, double ks, double nu_s, double dt, bool reset_total,
                                                  bool flow_law, double *applied, double *trial, double &stick)
{
  const double speed = std::sqrt(dot3(vs, vs));
  double u[3];
  for (int k = 0; k < 3; k++) u[k] = speed > 0.0 ? -vs[k] / speed : 0.0;
  const double rate = ks * speed * dt;
  // after a slip the trial force restarts from Fmin t + kept u (E3): the spring holds Fmin
  // and the dashpot adds nu_s |V_s| (reset spring), or both hold Fmin (reset total)
  const double kept = reset_total ? 0.0 : nu_s * speed;
  stick = 0.0;
  if (!(T > 0.0)) {  // E1: no normal force, no friction; the spring keeps what the reset leaves
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
    const double f = dot3(F, u), F2 = dot3(F, F);
    double dtheta;
    if (slips == 0 && F2 >= T * T)
      dtheta = 0.0;
    else {
      const double gap = std::max(std::sqrt(std::max(T * T - (F2 - f * f), 0.0)) - f, 0.0);
      dtheta = rate > 0.0 ? gap / rate : INFINITY;
    }
    if (!(theta + dtheta <= 1.0)) {  // sticks to the end of the step
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
    const double hn = std::sqrt(dot3(hit, hit));
    double t[3];
    for (int k = 0; k < 3; k++) t[k] = hit[k] / hn;
    slips++;
    for (int k = 0; k < 3; k++) F[k] = fmin * t[k] + kept * u[k];
    const double rest = 1.0 - theta;
    // E4: the restarted force is at or above T again: slips follow without end and turn t
    // onto u, the contact slides at Fmin u for the rest of the step
    if (kept > 0.0 && dot3(F, F) >= T * T) {
      for (int k = 0; k < 3; k++) {
        trial[k] = (fmin + kept) * u[k];
        applied[k] = fmin * u[k];
      }
      return;
    }
    if (rate == 0.0) {  // E5: nothing moves, the force stays where the slip left it
      for (int k = 0; k < 3; k++) applied[k] = trial[k] = F[k];
      stick += rest;
      return;
    }
    const double along = dot3(t, u);
    // (t.u = 0 too: |F + rate theta u| = T sqrt(1 + (rate theta/T)^2) rises at once, so the
    // force flows from phi = 90 degrees; only t.u < 0 unloads into the cone and sticks)
    if (flow_law && along >= 0.0) {  // E6: plastic flow on |F| = T
      plastic_flow(F, u, rate * rest / T, T);
      for (int k = 0; k < 3; k++) applied[k] = trial[k] = F[k];
      return;
    }
    // E7: settled along u (or followed MAX_EXPLICIT_SLIPS times): the remaining slips of the
    // step repeat one cycle (Fmin + kept) u -> T u, of length L in theta; the part q of the
    // force across u shrinks by r at each slip
    const double fu = dot3(F, u);
    double q[3];
    for (int k = 0; k < 3; k++) q[k] = F[k] - fu * u[k];
    if ((std::sqrt(dot3(q, q)) <= SETTLED * T && along > 0.0) || slips >= MAX_EXPLICIT_SLIPS) {
      const double low = fmin + kept;
      const double L = (T - low) / rate;
      if (!(L > 0.0)) {  // restarts at T: slides, as E4
        for (int k = 0; k < 3; k++) {
          trial[k] = low * u[k];
          applied[k] = fmin * u[k];
        }
        return;
      }
      const double n = std::floor(rest / L);
      const double part = rest - n * L;
      const double shrink = n == 0.0 ? 1.0 : std::pow(r, n);  // (no whole cycle left: the common case)
      for (int k = 0; k < 3; k++) applied[k] = trial[k] = (low + rate * part) * u[k] + shrink * q[k];
      stick += rest;
      return;
    }
  }
}

}  // namespace stickslip

#endif
