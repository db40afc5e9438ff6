/* SPDX-License-Identifier: GPL-2.0-or-later
   One grain-wall contact of a Hookean granular wall with the stick-slip law: the normal
   force and relative velocity of stock wall/gran hooke/history (same operations in the
   same order), the tangential force from stick_slip_law.h. Used by fix
   wall/gran/stickslip; written so that a region wall (wall/gran/region/stickslip) can
   call it for each of its contacts, as stock's region wall calls hooke_history. */

#ifndef STICKSLIP_WALL_CONTACT_H
#define STICKSLIP_WALL_CONTACT_H

#include "stick_slip_law.h"

#include <cmath>

namespace StickSlip {

// A wall's coefficients and settings (the fix's arguments).
struct WallLaw {
  Settings law;
  Coeffs coeffs;
  double kn, gamman, gammat;
  int limit_damping;
};

/* The contact of one grain with the wall. rsq, dx, dy, dz: the grain centre's offset from
   the wall's nearest point and its square; vwall: the wall's velocity there; v, omega:
   the grain's; f, torque: its force and torque, added to; radius; meff: its mass (or its
   rigid body's); hist: the contact's history (size w.law.history_size()); contact: stock's
   per-atom output row (null: none): columns 1-3 the total force, and with record 8-13 the
   record (Fn, Fs, slip count, work); dt, update: the step, and whether time passes.
   Mode: RuntimeMode, or the FixedMode of a loop compiled for the settings (stick_slip_law.h). */
template <class Mode = RuntimeMode>
__attribute__((always_inline)) inline void wall_contact(const WallLaw &w, double rsq, double dx, double dy, double dz, const double *vwall,
                         const double *v, double *f, const double *omega, double *torque, double radius, double meff,
                         double *hist, double *contact, double dt, bool update)
{
  const double r = sqrt(rsq);
  const double rinv = 1.0 / r;
  const double rsqinv = 1.0 / rsq;

  // relative translational velocity, its normal and tangential parts
  const double vr1 = v[0] - vwall[0], vr2 = v[1] - vwall[1], vr3 = v[2] - vwall[2];
  const double vnnr = vr1 * dx + vr2 * dy + vr3 * dz;
  const double vn1 = dx * vnnr * rsqinv, vn2 = dy * vnnr * rsqinv, vn3 = dz * vnnr * rsqinv;
  const double vt1 = vr1 - vn1, vt2 = vr2 - vn2, vt3 = vr3 - vn3;

  // rotation: the lever arm (radius, or c = r - delta/2; the wall has none)
  const double c = lever(w.law, radius, radius - r);
  const double wr1 = c * omega[0] * rinv, wr2 = c * omega[1] * rinv, wr3 = c * omega[2] * rinv;

  // normal force (eq. 3), with stock's mass-weighted damping or absolute damping
  const double m = w.law.absolute ? 1.0 : meff;
  const double damp = m * w.gamman * vnnr * rsqinv;
  double ccel = w.kn * (radius - r) * rinv - damp;
  if (w.limit_damping && (ccel < 0.0)) ccel = 0.0;

  // V_s (eq. 6)
  const double vtr[3] = {vt1 - (dz * wr2 - dy * wr3), vt2 - (dx * wr3 - dz * wr1), vt3 - (dy * wr1 - dx * wr2)};
  const double del[3] = {dx, dy, dz};
  double fs[3];
  tangential_force<Mode>(w.law, w.coeffs, del, rsqinv, ccel * r, vtr, m * w.gammat, dt, update, hist, fs);

  // forces and torques
  const double fx = dx * ccel + fs[0], fy = dy * ccel + fs[1], fz = dz * ccel + fs[2];
  f[0] += fx;
  f[1] += fy;
  f[2] += fz;
  if (contact) {
    contact[1] = fx;
    contact[2] = fy;
    contact[3] = fz;
    if (Mode::record(w.law))
      for (int k = 0; k < 6; k++) contact[8 + k] = hist[HIST_FN + k];
  }
  const double tor1 = rinv * (dy * fs[2] - dz * fs[1]);
  const double tor2 = rinv * (dz * fs[0] - dx * fs[2]);
  const double tor3 = rinv * (dx * fs[1] - dy * fs[0]);
  torque[0] -= c * tor1;
  torque[1] -= c * tor2;
  torque[2] -= c * tor3;
}

}  // namespace StickSlip

#endif
