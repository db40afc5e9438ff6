/* SPDX-License-Identifier: GPL-2.0-or-later
   fix ID group wall/gran/stickslip hooke/history Kn Kt gamma_n gamma_t xmu dampflag
       [limit_damping] wallstyle args [wiggle dim A period | shear dim v] [contacts] [keyword value ...]

   Stock wall/gran (its arguments, walls and motions, its per-atom history and restart
   data) with the stick-slip law at each contact (wall_contact.h). post_force() places the
   wall as stock does, with the same operations, so that the default settings give stock's
   output bit for bit. */

#include "fix_wall_gran_stickslip.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "neighbor.h"
#include "update.h"
#include "rigid_mass.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;

namespace StickSlip {

const char *const FixWallGranStickSlip::STYLE = "wall/gran/stickslip";

namespace {

// FixWallGran's wall styles (fix_wall_gran.cpp: XPLANE=0, YPLANE=1, ZPLANE=2, ZCYLINDER)
enum { XPLANE = 0, YPLANE = 1, ZPLANE = 2, ZCYLINDER = 3 };

struct Checker {
  LAMMPS *lmp;
  std::string cmd;

  [[noreturn]] void fail(const std::string &what) const { lmp->error->all(FLERR, cmd + ": " + what); }

  double number(const std::string &name, const char *text, const char *allowed) const
  {
    return parse_number(lmp, cmd, name, text, allowed);
  }

  void range(const std::string &name, double v, bool ok, const char *allowed) const
  {
    check_range(lmp, cmd, name, v, ok, allowed);
  }

  int axis(const char *keyword, const char *text) const
  {
    if (strcmp(text, "x") == 0) return 0;
    if (strcmp(text, "y") == 0) return 1;
    if (strcmp(text, "z") == 0) return 2;
    fail(std::string(keyword) + " direction '" + text + "' is not allowed: x, y or z");
  }
};

}  // namespace

WallArguments::WallArguments(LAMMPS *lmp, int narg, char **arg)
{
  const Checker check{lmp, std::string("fix ") + (narg > 0 ? arg[0] : "") + " " + FixWallGranStickSlip::STYLE};
  const char *usage = "needs hooke/history Kn Kt gamma_n gamma_t xmu dampflag [limit_damping] wallstyle args "
                      "[wiggle dim A period | shear dim v] [contacts] [keyword value ...]";
  if (narg < 4) check.fail(usage);
  if (strcmp(arg[3], "hooke/history") != 0)
    check.fail(std::string("fstyle '") + arg[3] +
               "' is not allowed: hooke/history (the law is stock's Hookean history wall with the stick-slip friction)");
  if (narg < 11) check.fail(usage);
  const double kn = check.number("Kn", arg[4], "Kn > 0");
  check.range("Kn", kn, kn > 0.0, "Kn > 0");
  const double kt = strcmp(arg[5], "NULL") == 0 ? kn * 2.0 / 7.0 : check.number("Kt", arg[5], "Kt > 0 or NULL");
  check.range("Kt", kt, kt > 0.0, "Kt > 0 (or NULL: 2/7 Kn)");
  const double gn = check.number("gamma_n", arg[6], "gamma_n >= 0");
  check.range("gamma_n", gn, gn >= 0.0, "gamma_n >= 0");
  if (strcmp(arg[7], "NULL") != 0) {
    const double gt = check.number("gamma_t", arg[7], "gamma_t >= 0 or NULL");
    check.range("gamma_t", gt, gt >= 0.0, "gamma_t >= 0 (or NULL: gamma_n/2)");
  }
  const double xmu = check.number("xmu", arg[8], "0 <= xmu <= 10000");
  check.range("xmu (mu_s)", xmu, xmu >= 0.0 && xmu <= 10000.0, "0 <= xmu <= 10000 (stock's range)");
  if (strcmp(arg[9], "0") != 0 && strcmp(arg[9], "1") != 0)
    check.fail(std::string("dampflag = '") + arg[9] + "' is not allowed: 0 or 1");

  for (int k = 0; k < 10; k++) words.push_back(arg[k]);
  int iarg = 10;
  if (strcmp(arg[iarg], "limit_damping") == 0) words.push_back(arg[iarg++]);

  // the wall
  if (iarg >= narg) check.fail(usage);
  const std::string style = arg[iarg];
  const bool two_d = lmp->domain->dimension == 2;
  int wallstyle = -1;
  if (style == "xplane" || style == "yplane" || style == "zplane") {
    wallstyle = style[0] - 'x';
    if (iarg + 3 > narg) check.fail(style + " needs lo hi (a number or NULL each)");
    const bool has_lo = strcmp(arg[iarg + 1], "NULL") != 0, has_hi = strcmp(arg[iarg + 2], "NULL") != 0;
    const double lo = has_lo ? check.number(style + " lo", arg[iarg + 1], "a number or NULL") : 0.0;
    const double hi = has_hi ? check.number(style + " hi", arg[iarg + 2], "a number or NULL") : 0.0;
    if (has_lo && has_hi && !(lo < hi)) check.fail(style + " lo must be below hi (or NULL)");
    if (!has_lo && !has_hi) check.fail(style + " needs lo or hi (both NULL is no wall)");
    if (two_d && wallstyle == ZPLANE)
      check.fail("zplane is meaningless with dimension 2 (the grains move in the xy plane); allowed in 2D: "
                 "xplane, yplane, zcylinder");
    for (int k = 0; k < 3; k++) words.push_back(arg[iarg + k]);
    iarg += 3;
  } else if (style == "zcylinder") {
    wallstyle = ZCYLINDER;
    if (iarg + 2 > narg) check.fail("zcylinder needs its radius");
    const double radius = check.number("zcylinder radius", arg[iarg + 1], "> 0");
    check.range("zcylinder radius", radius, radius > 0.0, "> 0");
    for (int k = 0; k < 2; k++) words.push_back(arg[iarg + k]);
    iarg += 2;
  } else if (style == "region") {
    check.fail("wallstyle region is not offered by this fix (a region wall is wall/gran/region); allowed: "
               "xplane, yplane, zplane, zcylinder");
  } else {
    check.fail("wallstyle '" + style + "' is not allowed: xplane, yplane, zplane or zcylinder");
  }
  const int periodic[3] = {lmp->domain->xperiodic, lmp->domain->yperiodic, lmp->domain->zperiodic};
  if (wallstyle <= ZPLANE && periodic[wallstyle])
    check.fail(style + " lies across a periodic dimension: make " + std::string(1, "xyz"[wallstyle]) +
               " non-periodic (boundary f, s or m)");
  if (wallstyle == ZCYLINDER && (periodic[0] || periodic[1]))
    check.fail("zcylinder needs x and y non-periodic (boundary f, s or m)");

  // motion, output, the law's keywords
  bool wiggle = false, shear = false, contacts = false;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "wiggle") {
      if (iarg + 4 > narg) check.fail("wiggle needs dim amplitude period");
      const int axis = check.axis("wiggle", arg[iarg + 1]);
      check.number("wiggle amplitude", arg[iarg + 2], "a number");
      const double period = check.number("wiggle period", arg[iarg + 3], "> 0");
      check.range("wiggle period", period, period > 0.0, "> 0");
      if (wallstyle == ZCYLINDER && axis != 2) check.fail("wiggle of a zcylinder must be along z");
      if (two_d && axis == 2) check.fail("wiggle along z is meaningless with dimension 2 (allowed: x or y)");
      for (int k = 0; k < 4; k++) words.push_back(arg[iarg + k]);
      wiggle = true;
      iarg += 4;
    } else if (key == "shear") {
      if (iarg + 3 > narg) check.fail("shear needs dim velocity");
      const int axis = check.axis("shear", arg[iarg + 1]);
      check.number("shear velocity", arg[iarg + 2], "a number");
      if (wallstyle == axis) check.fail("shear of a plane must be along the plane (not along its normal)");
      if (two_d && axis == 2) check.fail("shear along z is meaningless with dimension 2 (allowed: x or y)");
      for (int k = 0; k < 3; k++) words.push_back(arg[iarg + k]);
      shear = true;
      iarg += 3;
    } else if (key == "contacts") {
      words.push_back(arg[iarg++]);
      contacts = true;
    } else {
      const int used = parse_keyword(lmp, check.cmd, parsed, narg, arg, iarg);
      if (!used)
        check.fail("unknown keyword '" + key + "' (allowed: wiggle, shear, contacts, " + keyword_list() + ")");
      iarg += used;
    }
  }
  if (wiggle && shear) check.fail("wiggle and shear cannot be combined");
  if (parsed.mu_k >= 0.0) check_kinetic(lmp, check.cmd, xmu, parsed.mu_k);
  // record: the per-atom array carries the record, so stock makes it
  if (parsed.record && !contacts) words.push_back("contacts");
  for (std::string &w : words) stock_argv.push_back(&w[0]);
}

/* ---------------------------------------------------------------------- */

FixWallGranStickSlip::FixWallGranStickSlip(LAMMPS *lmp, int narg, char **arg) :
    WallArguments(lmp, narg, arg), FixWallGran(lmp, stock_narg(), stock_args())
{
  wall.law = parsed;
  wall.coeffs = make_coeffs(kt, xmu, parsed.mu_k >= 0.0 ? parsed.mu_k : xmu);
  wall.kn = kn;
  wall.gamman = gamman;
  wall.gammat = gammat;
  wall.limit_damping = limit_damping;
  if (parsed.record) {
    // the record in the history (stick_slip_law.h) and in per-atom columns 9-14
    size_history = parsed.history_size();
    size_peratom_cols = 14;
    memory->destroy(history_one);
    memory->destroy(array_atom);
    history_one = nullptr;
    array_atom = nullptr;
    FixWallGran::grow_arrays(atom->nmax);
    for (int i = 0; i < atom->nlocal; i++)
      for (int m = 0; m < size_history; m++) history_one[i][m] = 0.0;
    clear_stored_contacts();
  }
}

/* ---------------------------------------------------------------------- */

void FixWallGranStickSlip::post_force(int)
{
  // no history update (no time passes) in a set-up evaluation
  const bool stepping = !update->setupflag;
  history_update = stepping ? 1 : 0;

  // rigid bodies: a grain of a rigid body moves with the body's mass (stock)
  if (neighbor->ago == 0 && fix_rigid) {
    StickSlip::refresh_rigid_mass(lmp, fix_rigid, mass_rigid, nmax, "wall/gran:mass_rigid");
  }

  // the wall's place and velocity now (wiggle: a cosine from its start; shear: constant)
  double wlo = lo, whi = hi;
  double vmove[3] = {0.0, 0.0, 0.0};
  if (wiggle) {
    const double phase = omega * (update->ntimestep - time_origin) * dt;
    if (wallstyle == axis) {
      wlo = lo + amplitude - amplitude * cos(phase);
      whi = hi + amplitude - amplitude * cos(phase);
    }
    vmove[axis] = amplitude * omega * sin(phase);
  } else if (wshear)
    vmove[axis] = vshear;

  if (peratom_flag) clear_stored_contacts();
  // the grains' loop compiled for this combination of the law's settings
  with_fixed_mode(wall.law, [&](auto mode) { grains<decltype(mode)>(wlo, whi, vmove, stepping); });
}

/* Every grain of the group against the wall placed at wlo, whi (planes) moving at vmove.
   The members it reads are copied into locals first, so that they stay in registers. */
template <class Mode> void FixWallGranStickSlip::grains(double wlo, double whi, const double *vmove, bool stepping)
{
  constexpr int dnum = Mode::record(Settings()) ? SIZE_RECORD : SIZE_PLAIN;  // history values per grain
  const WallLaw w = wall;
  const int style = wallstyle, along = axis, bit = groupbit;
  const bool spinning = wshear && axis != 2, contacts = peratom_flag;
  const double cyl = cylradius, vsh = vshear, dt_ = dt;
  const double *rigid = fix_rigid ? mass_rigid : nullptr;
  double **hist = history_one, **out = array_atom;

  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **atom_omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;

  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & bit)) continue;
    // the grain centre's offset from the wall's nearest point
    double dx = 0.0, dy = 0.0, dz = 0.0;
    double vwall[3] = {vmove[0], vmove[1], vmove[2]};
    if (style == XPLANE || style == YPLANE || style == ZPLANE) {
      const double below = x[i][style] - wlo, above = whi - x[i][style];
      const double d = below < above ? below : -above;
      if (style == XPLANE)
        dx = d;
      else if (style == YPLANE)
        dy = d;
      else
        dz = d;
    } else {  // ZCYLINDER, about the z axis
      const double delxy = sqrt(x[i][0] * x[i][0] + x[i][1] * x[i][1]);
      const double delr = cyl - delxy;
      if (delr > radius[i])
        dz = cyl;  // far from the wall
      else {
        dx = -delr / delxy * x[i][0];
        dy = -delr / delxy * x[i][1];
        // a spinning cylinder (shear x or y; clockwise for vshear > 0): its surface's
        // velocity at the grain, as stock's documentation says. (Stock's code adds it to a
        // translation vshear along x or y and to the wall velocity of every earlier grain
        // in contact in the step: lammps_plugin/README.md.)
        if (spinning) {
          vwall[0] = vsh * x[i][1] / delxy;
          vwall[1] = -vsh * x[i][0] / delxy;
          vwall[2] = 0.0;
        }
      }
    }
    const double rsq = dx * dx + dy * dy + dz * dz;
    if (rsq > radius[i] * radius[i]) {
      // apart: the contact has ended, its history is dropped
      for (int m = 0; m < dnum; m++) hist[i][m] = 0.0;
      continue;
    }
    double meff = rmass[i];
    if (rigid && rigid[i] > 0.0) meff = rigid[i];
    double *contact = nullptr;
    if (contacts) {
      contact = out[i];
      contact[0] = 1.0;
      contact[4] = x[i][0] - dx;
      contact[5] = x[i][1] - dy;
      contact[6] = x[i][2] - dz;
      contact[7] = radius[i];
    }
    wall_contact<Mode>(w, rsq, dx, dy, dz, vwall, v[i], f[i], atom_omega[i], torque[i], radius[i], meff, hist[i],
                       contact, dt_, stepping);
  }
}

}  // namespace StickSlip
