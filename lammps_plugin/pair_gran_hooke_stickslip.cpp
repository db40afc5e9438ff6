/* SPDX-License-Identifier: GPL-2.0-or-later
   pair_style gran/hooke/stickslip Kn Kt gamma_n gamma_t xmu dampflag [limit_damping] [keyword value ...]

   Stock gran/hooke/history's arguments with their meaning (xmu is mu_s); the tangential
   force is the stick-slip law (stick_slip_law.h). The normal force, the relative
   velocity, the neighbour list and the history fix are stock's: compute() evaluates them
   with the same operations in the same order as stock, so that the default settings give
   stock's output bit for bit. */

#include "pair_gran_hooke_stickslip.h"

#include "contact_history_fix.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "memory.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"
#include "rigid_mass.h"

#include <cmath>
#include <cstring>
#include <mpi.h>

using namespace LAMMPS_NS;

namespace StickSlip {

const char *const PairGranHookeStickSlip::STYLE = "gran/hooke/stickslip";

namespace {

const std::string CMD = std::string("pair_style ") + PairGranHookeStickSlip::STYLE;

}  // namespace

PairGranHookeStickSlip::PairGranHookeStickSlip(LAMMPS *lmp) :
    PairGranHookeHistory(lmp), history_made(0), mu_s_given(nullptr), mu_k_given(nullptr), coeffs(nullptr)
{
  // svector: stock's 10 values, then with record Fn, slip count and work (single())
  delete[] svector;
  svector = new double[13];
}

PairGranHookeStickSlip::~PairGranHookeStickSlip()
{
  if (copymode) return;
  memory->destroy(mu_s_given);
  memory->destroy(mu_k_given);
  memory->destroy(coeffs);
}

void PairGranHookeStickSlip::allocate_law()
{
  if (!allocated) allocate();
  if (mu_s_given) return;
  const int n = atom->ntypes;
  memory->create(mu_s_given, n + 1, n + 1, "pair:mu_s_given");
  memory->create(mu_k_given, n + 1, n + 1, "pair:mu_k_given");
  memory->create(coeffs, n + 1, n + 1, "pair:stickslip_coeffs");
  for (int i = 0; i <= n; i++)
    for (int j = 0; j <= n; j++) mu_s_given[i][j] = mu_k_given[i][j] = -1.0;
}

/* ---------------------------------------------------------------------- */

void PairGranHookeStickSlip::settings(int narg, char **arg)
{
  if (narg < 6)
    error->all(FLERR, CMD + ": needs Kn Kt gamma_n gamma_t xmu dampflag [limit_damping] [keyword value ...], got " +
                          std::to_string(narg) + " arguments");
  kn = parse_number(lmp, CMD, "Kn", arg[0], "Kn > 0");
  check_range(lmp, CMD, "Kn", kn, kn > 0.0, "Kn > 0");
  if (strcmp(arg[1], "NULL") == 0)
    kt = kn * 2.0 / 7.0;  // stock's default
  else
    kt = parse_number(lmp, CMD, "Kt", arg[1], "Kt > 0 or NULL");
  check_range(lmp, CMD, "Kt", kt, kt > 0.0, "Kt > 0 (or NULL: 2/7 Kn)");
  gamman = parse_number(lmp, CMD, "gamma_n", arg[2], "gamma_n >= 0");
  check_range(lmp, CMD, "gamma_n", gamman, gamman >= 0.0, "gamma_n >= 0");
  if (strcmp(arg[3], "NULL") == 0)
    gammat = 0.5 * gamman;  // stock's default
  else
    gammat = parse_number(lmp, CMD, "gamma_t", arg[3], "gamma_t >= 0 or NULL");
  check_range(lmp, CMD, "gamma_t", gammat, gammat >= 0.0, "gamma_t >= 0 (or NULL: gamma_n/2)");
  xmu = parse_number(lmp, CMD, "xmu", arg[4], "0 <= xmu <= 10000");
  check_range(lmp, CMD, "xmu (mu_s)", xmu, xmu >= 0.0 && xmu <= 10000.0, "0 <= xmu <= 10000 (stock's range)");
  if (strcmp(arg[5], "0") == 0)
    dampflag = 0;
  else if (strcmp(arg[5], "1") == 0)
    dampflag = 1;
  else
    error->all(FLERR, CMD + ": dampflag = '" + arg[5] + "' is not allowed: 0 or 1");
  if (dampflag == 0) gammat = 0.0;  // stock: no tangential damping

  limit_damping = 0;
  int iarg = 6;
  if (iarg < narg && strcmp(arg[iarg], "limit_damping") == 0) {
    limit_damping = 1;
    iarg++;
  }
  Settings s;
  while (iarg < narg) {
    const int used = parse_keyword(lmp, CMD, s, narg, arg, iarg);
    if (!used)
      error->all(FLERR, CMD + ": unknown keyword '" + arg[iarg] + "' (allowed: limit_damping right after dampflag, then " +
                            keyword_list() + ")");
    iarg += used;
  }
  if (s.mu_k >= 0.0) check_kinetic(lmp, CMD, xmu, s.mu_k);
  law = s;

  size_history = law.history_size();
  nondefault_history_transfer = law.record ? 1 : 0;  // Fn, slip count and work keep their sign
  single_extra = law.record ? 13 : 10;
}

/* pair_coeff I J [mu_s V] [mu_k V]: per type pair coefficients (default: the pair_style's). */
void PairGranHookeStickSlip::coeff(int narg, char **arg)
{
  const std::string cmd = std::string("pair_coeff ") + (narg > 0 ? arg[0] : "") + " " + (narg > 1 ? arg[1] : "");
  if (narg < 2) error->all(FLERR, cmd + ": needs I J [mu_s V] [mu_k V]");
  allocate_law();
  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, atom->ntypes, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, atom->ntypes, jlo, jhi, error);
  double ms = -1.0, mk = -1.0;
  for (int iarg = 2; iarg < narg; iarg += 2) {
    const std::string key = arg[iarg];
    if (key != "mu_s" && key != "mu_k")
      error->all(FLERR, cmd + ": unknown keyword '" + key + "' (allowed: mu_s, mu_k)");
    if (iarg + 1 >= narg) error->all(FLERR, cmd + ": keyword " + key + " needs a value");
    const double v = parse_number(lmp, cmd, key, arg[iarg + 1], key == "mu_s" ? "0 <= mu_s <= 10000" : ">= 0");
    if (key == "mu_s") {
      check_range(lmp, cmd, "mu_s", v, v >= 0.0 && v <= 10000.0, "0 <= mu_s <= 10000");
      ms = v;
    } else {
      check_range(lmp, cmd, "mu_k", v, v >= 0.0, "mu_s/2 <= mu_k <= mu_s");
      mk = v;
    }
  }
  int count = 0;
  for (int i = ilo; i <= ihi; i++)
    for (int j = MAX(jlo, i); j <= jhi; j++) {
      setflag[i][j] = 1;
      mu_s_given[i][j] = ms;
      mu_k_given[i][j] = mk;
      double mu_s, mu_k;
      pair_coefficients(i, j, mu_s, mu_k);  // checks mu_k's range now, where it is known
      count++;
    }
  if (count == 0)
    error->all(FLERR, cmd + ": no type pair I <= J in these ranges (give the lower type first)");
}

/* mu_s and mu_k of a type pair (i <= j): pair_coeff's, else the pair_style's (mu_k given, or mu_s). */
void PairGranHookeStickSlip::pair_coefficients(int i, int j, double &mu_s, double &mu_k) const
{
  mu_s = mu_s_given[i][j] >= 0.0 ? mu_s_given[i][j] : xmu;
  mu_k = mu_k_given[i][j] >= 0.0 ? mu_k_given[i][j] : (law.mu_k >= 0.0 ? law.mu_k : mu_s);
  if (mu_k_given[i][j] >= 0.0 || mu_s_given[i][j] >= 0.0)
    check_kinetic(lmp,
                  "pair_coeff " + std::to_string(i) + " " + std::to_string(j) +
                      (mu_k_given[i][j] >= 0.0 ? "" : " (mu_k from pair_style)"),
                  mu_s, mu_k);
}

void PairGranHookeStickSlip::init_style()
{
  if (history_made && history_made != size_history)
    error->all(FLERR, CMD + ": record cannot change once the style has run (its contact history holds " +
                          std::to_string(history_made) + " values per contact): issue pair_style none first");
  // stock's set-up, its history fix made as our ContactHistoryFix (same ID and style name:
  // write_restart keeps every contact's history, contact_history_fix.h)
  if (fix_history == nullptr)
    ContactHistoryFix::creating_history_fix(modify, [this] { PairGranHookeHistory::init_style(); });
  else
    PairGranHookeHistory::init_style();
  history_made = size_history;
}

double PairGranHookeStickSlip::init_one(int i, int j)
{
  allocate_law();
  const double cut = PairGranHookeHistory::init_one(i, j);
  double mu_s, mu_k;
  pair_coefficients(i, j, mu_s, mu_k);
  coeffs[i][j] = coeffs[j][i] = make_coeffs(kt, mu_s, mu_k);
  return cut;
}

/* ---------------------------------------------------------------------- */

void PairGranHookeStickSlip::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);

  // rigid bodies: a grain of a rigid body moves with the body's mass (stock)
  if (fix_rigid && neighbor->ago == 0) {
    StickSlip::refresh_rigid_mass(lmp, fix_rigid, mass_rigid, nmax, "pair:mass_rigid");
#if STICKSLIP_MODERN_LAMMPS
    comm->forward_comm(this);
#else
    comm->forward_comm_pair(this);
#endif
  }

  // the contact loop compiled for this combination of the law's settings, and for a step
  // or a set-up evaluation (a step then tests no flag of it per contact)
  with_fixed_mode(law, [this](auto mode) {
    if (update->setupflag)
      contacts<decltype(mode), false>();
    else
      contacts<decltype(mode), true>();
  });
  if (vflag_fdotr) virial_fdotr_compute();
}

/* Every grain pair of the neighbour list for one force evaluation (docs/law.md steps 1-6):
   the normal force and relative velocity as stock computes them (same operations, same
   order), the tangential force from the law, forces and torques on both grains.
   Everything a contact reads is copied into locals first: the compiler then keeps it in
   registers across the loop (members and LAMMPS' arrays could change in any call, such as
   ev_tally_xyz, and would be loaded again for every contact). */
template <class Mode, bool STEPPING> void PairGranHookeStickSlip::contacts()
{
  const Settings s = law;
  constexpr bool stepping = STEPPING;  // false: a set-up evaluation (no time passes, no history update)
  const double kn_ = kn, gamman_ = gamman, gammat_ = gammat, dt_ = dt;
  const bool limit = limit_damping;
  const int freeze = freeze_group_bit;
  const double *rigid = fix_rigid ? mass_rigid : nullptr;
  Coeffs *const *const pair_coeffs = coeffs;

  double **x = atom->x, **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask, *type = atom->type;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  const bool tally = evflag;
  constexpr int dnum = Mode::record(Settings()) ? SIZE_RECORD : SIZE_PLAIN;
  // bonded grains: LAMMPS 2023 and later weigh each pair's force and torque by special_lj, as
  // stock does there (lammps_api.h); before, every pair counts fully (1: no code)
  constexpr bool special_weights = STICKSLIP_MODERN_LAMMPS;
  const double *special_lj = force->special_lj;

  const int inum = list->inum;
  const int *ilist = list->ilist, *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;
  int **firsttouch = fix_history->firstflag;
  double **firsthist = fix_history->firstvalue;

  for (int ii = 0; ii < inum; ii++) {
    const int i = ilist[ii];
    const double xi = x[i][0], yi = x[i][1], zi = x[i][2];
    const double radi = radius[i];
    int *touch = firsttouch[i];
    double *allhist = firsthist[i];
    const int *jlist = firstneigh[i];
    const int jnum = numneigh[i];
    const Coeffs *coeffs_i = pair_coeffs[type[i]];

    for (int jj = 0; jj < jnum; jj++) {
      const double factor = special_weights ? special_lj[sbmask(jlist[jj])] : 1.0;
      if (factor == 0.0) continue;  // (stock: the pair is skipped, its history kept)
      const int j = jlist[jj] & NEIGHMASK;
      const double del[3] = {xi - x[j][0], yi - x[j][1], zi - x[j][2]};
      const double rsq = del[0] * del[0] + del[1] * del[1] + del[2] * del[2];
      const double radj = radius[j];
      const double radsum = radi + radj;
      double *hist = &allhist[dnum * jj];

      if (rsq >= radsum * radsum) {
        // apart: the contact has ended, its history is dropped (docs/law.md step 3)
        touch[jj] = 0;
        for (int m = 0; m < dnum; m++) hist[m] = 0.0;
        continue;
      }
      touch[jj] = 1;

      const double r = sqrt(rsq);
      const double rinv = 1.0 / r;
      const double rsqinv = 1.0 / rsq;

      // relative translational velocity, its normal and tangential parts
      const double vr1 = v[i][0] - v[j][0], vr2 = v[i][1] - v[j][1], vr3 = v[i][2] - v[j][2];
      const double vnnr = vr1 * del[0] + vr2 * del[1] + vr3 * del[2];
      const double vn1 = del[0] * vnnr * rsqinv, vn2 = del[1] * vnnr * rsqinv, vn3 = del[2] * vnnr * rsqinv;
      const double vt1 = vr1 - vn1, vt2 = vr2 - vn2, vt3 = vr3 - vn3;

      // rotation: lever arms to the contact (radii, or c = r - delta/2)
      const double ci = lever(s, radi, radsum - r), cj = lever(s, radj, radsum - r);
      const double wr1 = (ci * omega[i][0] + cj * omega[j][0]) * rinv;
      const double wr2 = (ci * omega[i][1] + cj * omega[j][1]) * rinv;
      const double wr3 = (ci * omega[i][2] + cj * omega[j][2]) * rinv;

      // damping per unit mass times the pair's effective mass (stock), or absolute
      double meff = 1.0;
      if (!s.absolute) {
        double mi = rmass[i], mj = rmass[j];
        if (rigid) {
          if (rigid[i] > 0.0) mi = rigid[i];
          if (rigid[j] > 0.0) mj = rigid[j];
        }
        meff = mi * mj / (mi + mj);
        if (mask[i] & freeze) meff = mj;
        if (mask[j] & freeze) meff = mi;
      }

      // normal force (eq. 3): Fn = ccel * r along del
      const double damp = meff * gamman_ * vnnr * rsqinv;
      double ccel = kn_ * (radsum - r) * rinv - damp;
      if (limit && (ccel < 0.0)) ccel = 0.0;

      // V_s (eq. 6): tangential velocity of i's contact point relative to j's
      const double vtr[3] = {vt1 - (del[2] * wr2 - del[1] * wr3), vt2 - (del[0] * wr3 - del[2] * wr1),
                             vt3 - (del[1] * wr1 - del[0] * wr2)};

      double fs[3];
      tangential_force<Mode>(s, coeffs_i[type[j]], del, rsqinv, ccel * r, vtr, meff * gammat_, dt_, stepping, hist,
                             fs);

      // forces and torques (docs/law.md step 6)
      const double fx = (del[0] * ccel + fs[0]) * factor, fy = (del[1] * ccel + fs[1]) * factor,
                   fz = (del[2] * ccel + fs[2]) * factor;
      f[i][0] += fx;
      f[i][1] += fy;
      f[i][2] += fz;
      const double tor1 = rinv * (del[1] * fs[2] - del[2] * fs[1]) * factor;
      const double tor2 = rinv * (del[2] * fs[0] - del[0] * fs[2]) * factor;
      const double tor3 = rinv * (del[0] * fs[1] - del[1] * fs[0]) * factor;
      torque[i][0] -= ci * tor1;
      torque[i][1] -= ci * tor2;
      torque[i][2] -= ci * tor3;
      if (newton_pair || j < nlocal) {
        f[j][0] -= fx;
        f[j][1] -= fy;
        f[j][2] -= fz;
        torque[j][0] -= cj * tor1;
        torque[j][1] -= cj * tor2;
        torque[j][2] -= cj * tor3;
      }
      if (tally) ev_tally_xyz(i, j, nlocal, newton_pair, 0.0, 0.0, fx, fy, fz, del[0], del[1], del[2]);
    }
  }
}

/* ----------------------------------------------------------------------
   compute pair/local: p1-p10 as stock (tangential force on i, its magnitude, normal and
   tangential relative velocity); with record also p11 Fn, p12 slip count, p13 dissipated
   work. With record the forces are those the law last applied (kept in the history); stock
   re-evaluates the contact instead, which at a slip reports a force never applied.
   Without record p1-p4 are such a re-evaluation (trial force, capped at Fmin at or above
   the threshold).
------------------------------------------------------------------------- */

double PairGranHookeStickSlip::single(int i, int j, int itype, int jtype, double rsq, double, double,
                                      double &fforce)
{
  const double radi = atom->radius[i], radj = atom->radius[j], radsum = radi + radj;
  fforce = 0.0;
  for (int m = 0; m < single_extra; m++) svector[m] = 0.0;
  if (rsq >= radsum * radsum) return 0.0;

  const double r = sqrt(rsq), rinv = 1.0 / r, rsqinv = 1.0 / rsq;
  double **x = atom->x, **v = atom->v, **omega = atom->omega;
  const double del[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
  const double vr[3] = {v[i][0] - v[j][0], v[i][1] - v[j][1], v[i][2] - v[j][2]};
  const double vnnr = vr[0] * del[0] + vr[1] * del[1] + vr[2] * del[2];
  double vn[3], vt[3];
  for (int k = 0; k < 3; k++) {
    vn[k] = del[k] * vnnr * rsqinv;
    vt[k] = vr[k] - vn[k];
  }
  for (int k = 0; k < 3; k++) {
    svector[4 + k] = vn[k];
    svector[7 + k] = vt[k];
  }

  double sign = 1.0;
  const double *hist = find_history(i, j, sign);

  if (law.record) {
    // what the law applied at the last force evaluation
    if (!hist) return 0.0;
    double fs2 = 0.0;
    for (int k = 0; k < 3; k++) {
      svector[k] = sign * hist[HIST_FS + k];
      fs2 += svector[k] * svector[k];
    }
    svector[3] = sqrt(fs2);
    svector[10] = hist[HIST_FN];
    svector[11] = hist[HIST_NSLIP];
    svector[12] = hist[HIST_WORK];
    fforce = hist[HIST_FN] * rinv;
    return 0.0;
  }

  // re-evaluation from the stored spring, as stock's single()
  const double ci = lever(law, radi, radsum - r), cj = lever(law, radj, radsum - r);
  double wr[3];
  for (int k = 0; k < 3; k++) wr[k] = (ci * omega[i][k] + cj * omega[j][k]) * rinv;
  double meff = 1.0;
  if (!law.absolute) {
    double mi = atom->rmass[i], mj = atom->rmass[j];
    if (fix_rigid) {
      if (mass_rigid[i] > 0.0) mi = mass_rigid[i];
      if (mass_rigid[j] > 0.0) mj = mass_rigid[j];
    }
    meff = mi * mj / (mi + mj);
    if (atom->mask[i] & freeze_group_bit) meff = mj;
    if (atom->mask[j] & freeze_group_bit) meff = mi;
  }
  double ccel = kn * (radsum - r) * rinv - meff * gamman * vnnr * rsqinv;
  if (limit_damping && (ccel < 0.0)) ccel = 0.0;
  fforce = ccel;
  if (!hist) return 0.0;
  const double vtr[3] = {vt[0] - (del[2] * wr[1] - del[1] * wr[2]), vt[1] - (del[0] * wr[2] - del[2] * wr[0]),
                         vt[2] - (del[1] * wr[0] - del[0] * wr[1])};
  const Coeffs &c = coeffs[itype][jtype];
  double fs[3], fs2 = 0.0;
  for (int k = 0; k < 3; k++) {
    fs[k] = -(c.kt * sign * hist[k] + meff * gammat * vtr[k]);
    fs2 += fs[k] * fs[k];
  }
  const double fnabs = std::fabs(ccel * r);
  if (fs2 >= (c.mu_s * fnabs) * (c.mu_s * fnabs)) {
    const double ratio = stickslip::StickSlipCore::drop_to(fs, c.kin * fnabs, sqrt(fs2),
                                                           stickslip::StickSlipCore::stock_ratio);
    fs2 *= ratio * ratio;
  }
  for (int k = 0; k < 3; k++) svector[k] = fs[k];
  svector[3] = sqrt(fs2);
  return 0.0;
}

/* The history of the contact i-j: under i in the pair's neighbour list, or, for two owned
   atoms, possibly under j (then seen from j: sign = -1 for its vectors). */
double *PairGranHookeStickSlip::find_history(int i, int j, double &sign) const
{
  const int dnum = size_history;
  const int *jlist = list->firstneigh[i];
  for (int jj = 0; jj < list->numneigh[i]; jj++)
    if ((jlist[jj] & NEIGHMASK) == j) {
      sign = 1.0;
      return &fix_history->firstvalue[i][dnum * jj];
    }
  if (j < atom->nlocal) {
    const int *ilist = list->firstneigh[j];
    for (int jj = 0; jj < list->numneigh[j]; jj++)
      if ((ilist[jj] & NEIGHMASK) == i) {
        sign = -1.0;
        return &fix_history->firstvalue[j][dnum * jj];
      }
  }
  return nullptr;
}

/* The history seen from the other body (record only; stock negates every value): D and
   the tangential force change sign, Fn, the slip count and the work do not. */
#if STICKSLIP_MODERN_LAMMPS
void PairGranHookeStickSlip::transfer_history(double *source, double *target, int, int)
#else
void PairGranHookeStickSlip::transfer_history(double *source, double *target)
#endif
{
  for (int m = 0; m < size_history; m++) target[m] = source[m];
  for (int k = 0; k < 3; k++) {
    target[HIST_D + k] = -source[HIST_D + k];
    target[HIST_FS + k] = -source[HIST_FS + k];
  }
}

/* ----------------------------------------------------------------------
   restart files: stock's settings, then limit_damping, the law's settings and the
   per-type-pair coefficients
------------------------------------------------------------------------- */

void PairGranHookeStickSlip::write_restart_settings(FILE *fp)
{
  PairGranHookeHistory::write_restart_settings(fp);
  const int flags[7] = {limit_damping, law.reset_total, law.exact, law.project, law.absolute, law.contact_lever,
                        law.record};
  fwrite(flags, sizeof(int), 7, fp);
  fwrite(&law.mu_k, sizeof(double), 1, fp);
}

void PairGranHookeStickSlip::read_restart_settings(FILE *fp)
{
  PairGranHookeHistory::read_restart_settings(fp);
  int flags[7];
  if (comm->me == 0) {
    utils::sfread(FLERR, flags, sizeof(int), 7, fp, nullptr, error);
    utils::sfread(FLERR, &law.mu_k, sizeof(double), 1, fp, nullptr, error);
  }
  MPI_Bcast(flags, 7, MPI_INT, 0, world);
  MPI_Bcast(&law.mu_k, 1, MPI_DOUBLE, 0, world);
  limit_damping = flags[0];
  law.reset_total = flags[1];
  law.exact = flags[2];
  law.project = flags[3];
  law.absolute = flags[4];
  law.contact_lever = flags[5];
  law.record = flags[6];
  size_history = law.history_size();
  nondefault_history_transfer = law.record ? 1 : 0;
  single_extra = law.record ? 13 : 10;
}

void PairGranHookeStickSlip::write_restart(FILE *fp)
{
  write_restart_settings(fp);
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      fwrite(&setflag[i][j], sizeof(int), 1, fp);
      fwrite(&mu_s_given[i][j], sizeof(double), 1, fp);
      fwrite(&mu_k_given[i][j], sizeof(double), 1, fp);
    }
}

void PairGranHookeStickSlip::read_restart(FILE *fp)
{
  read_restart_settings(fp);
  allocate_law();
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (comm->me == 0) {
        utils::sfread(FLERR, &setflag[i][j], sizeof(int), 1, fp, nullptr, error);
        utils::sfread(FLERR, &mu_s_given[i][j], sizeof(double), 1, fp, nullptr, error);
        utils::sfread(FLERR, &mu_k_given[i][j], sizeof(double), 1, fp, nullptr, error);
      }
      MPI_Bcast(&setflag[i][j], 1, MPI_INT, 0, world);
      MPI_Bcast(&mu_s_given[i][j], 1, MPI_DOUBLE, 0, world);
      MPI_Bcast(&mu_k_given[i][j], 1, MPI_DOUBLE, 0, world);
    }
}

}  // namespace StickSlip
