/* SPDX-License-Identifier: GPL-2.0-or-later
   fix ID group wall/gran/region/stickslip hooke/history Kn Kt gamma_n gamma_t xmu dampflag
       [limit_damping] region regionID [contacts] [keyword value ...]

   Stock wall/gran/region (its arguments, its region look-up, the region's motion in restart
   files) with the stick-slip law at each contact (wall_contact.h). post_force() follows
   stock's: the region's contacts of each grain, the wall's velocity at each contact's
   nearest surface point (Region::velocity_contact), a history per contact kept by the
   region's wall index, so that the default settings give stock's output bit for bit. */

#include "fix_wall_gran_region_stickslip.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "neighbor.h"
#include "region.h"
#include "update.h"
#include "rigid_mass.h"

#include <cstring>

using namespace LAMMPS_NS;

namespace StickSlip {

const char *const FixWallGranRegionStickSlip::STYLE = "wall/gran/region/stickslip";

/* ---------------------------------------------------------------------- */

RegionWallArguments::RegionWallArguments(LAMMPS *lmp, int narg, char **arg)
{
  const std::string cmd = std::string("fix ") + (narg > 0 ? arg[0] : "") + " " + FixWallGranRegionStickSlip::STYLE;
  auto fail = [&](const std::string &what) { lmp->error->all(FLERR, cmd + ": " + what); };
  auto number = [&](const std::string &name, const char *text, const char *allowed) {
    return parse_number(lmp, cmd, name, text, allowed);
  };
  const char *usage = "needs hooke/history Kn Kt gamma_n gamma_t xmu dampflag [limit_damping] region regionID "
                      "[contacts] [keyword value ...]";
  if (narg < 4) fail(usage);
  if (strcmp(arg[3], "hooke/history") != 0)
    fail(std::string("fstyle '") + arg[3] +
         "' is not allowed: hooke/history (the law is stock's Hookean history wall with the stick-slip friction)");
  if (narg < 12) fail(usage);
  const double kn = number("Kn", arg[4], "Kn > 0");
  check_range(lmp, cmd, "Kn", kn, kn > 0.0, "Kn > 0");
  const double kt = strcmp(arg[5], "NULL") == 0 ? kn * 2.0 / 7.0 : number("Kt", arg[5], "Kt > 0 or NULL");
  check_range(lmp, cmd, "Kt", kt, kt > 0.0, "Kt > 0 (or NULL: 2/7 Kn)");
  const double gn = number("gamma_n", arg[6], "gamma_n >= 0");
  check_range(lmp, cmd, "gamma_n", gn, gn >= 0.0, "gamma_n >= 0");
  if (strcmp(arg[7], "NULL") != 0) {
    const double gt = number("gamma_t", arg[7], "gamma_t >= 0 or NULL");
    check_range(lmp, cmd, "gamma_t", gt, gt >= 0.0, "gamma_t >= 0 (or NULL: gamma_n/2)");
  }
  const double xmu = number("xmu", arg[8], "0 <= xmu <= 10000");
  check_range(lmp, cmd, "xmu (mu_s)", xmu, xmu >= 0.0 && xmu <= 10000.0, "0 <= xmu <= 10000 (stock's range)");
  if (strcmp(arg[9], "0") != 0 && strcmp(arg[9], "1") != 0)
    fail(std::string("dampflag = '") + arg[9] + "' is not allowed: 0 or 1");
  for (int k = 0; k < 10; k++) words.push_back(arg[k]);
  int iarg = 10;
  if (strcmp(arg[iarg], "limit_damping") == 0) words.push_back(arg[iarg++]);

  if (iarg + 2 > narg || strcmp(arg[iarg], "region") != 0)
    fail(std::string("wallstyle '") + (iarg < narg ? arg[iarg] : "") +
         "' is not allowed: region regionID (the primitive walls are wall/gran/stickslip)");
  if (lmp->domain->find_region(arg[iarg + 1]) < 0)
    fail(std::string("region '") + arg[iarg + 1] + "' does not exist (define it with the region command first)");
  words.push_back(arg[iarg]);
  words.push_back(arg[iarg + 1]);
  iarg += 2;

  bool contacts = false;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "contacts") {
      words.push_back(arg[iarg++]);
      contacts = true;
    } else if (key == "wiggle" || key == "shear") {
      fail(key + " is not allowed with a region wall: move or turn the region (region keywords move, rotate)");
    } else {
      const int used = parse_keyword(lmp, cmd, parsed, narg, arg, iarg);
      if (!used) fail("unknown keyword '" + key + "' (allowed: contacts, " + keyword_list() + ")");
      iarg += used;
    }
  }
  if (parsed.mu_k >= 0.0) check_kinetic(lmp, cmd, xmu, parsed.mu_k);
  // record: the per-atom array carries the record, so stock makes it
  if (parsed.record && !contacts) words.push_back("contacts");
  for (std::string &w : words) stock_argv.push_back(&w[0]);
}

/* ---------------------------------------------------------------------- */

FixWallGranRegionStickSlip::FixWallGranRegionStickSlip(LAMMPS *lmp, int narg, char **arg) :
    RegionWallArguments(lmp, narg, arg), FixWallGranRegion(lmp, stock_narg(), stock_args()), ncontacts(nullptr),
    wall_of(nullptr), hist(nullptr)
{
  wall.law = parsed;
  wall.coeffs = make_coeffs(kt, xmu, parsed.mu_k >= 0.0 ? parsed.mu_k : xmu);
  wall.kn = kn;
  wall.gamman = gamman;
  wall.gammat = gammat;
  wall.limit_damping = limit_damping;
  region = domain->regions[domain->find_region(idregion)];
  slots = region->tmax;
  size_history = parsed.history_size();
  if (parsed.record) {
    // the record in per-atom columns 9-14 (as wall/gran/stickslip)
    size_peratom_cols = 14;
    memory->destroy(array_atom);
    array_atom = nullptr;
  }
  FixWallGranRegionStickSlip::grow_arrays(atom->nmax);
  for (int i = 0; i < atom->nlocal; i++) ncontacts[i] = 0;
  if (peratom_flag) clear_stored_contacts();
}

FixWallGranRegionStickSlip::~FixWallGranRegionStickSlip()
{
  memory->destroy(ncontacts);
  memory->destroy(wall_of);
  memory->destroy(hist);
}

/* ---------------------------------------------------------------------- */

void FixWallGranRegionStickSlip::init()
{
  FixWallGranRegion::init();
  // the region may have been deleted and defined again between runs (stock finds it anew)
  region = domain->regions[domain->find_region(idregion)];
  if (region->tmax > slots)
    error->all(FLERR, fmt::format("fix {} {}: region {} can touch a grain {} times, more than the {} of the region "
                                  "the fix was made with: unfix and define the fix again",
                                  id, STYLE, idregion, region->tmax, slots));
}

/* ---------------------------------------------------------------------- */

void FixWallGranRegionStickSlip::post_force(int)
{
  // no history update (no time passes) in a set-up evaluation
  const bool stepping = !update->setupflag;
  history_update = stepping ? 1 : 0;

  // rigid bodies: a grain of a rigid body moves with the body's mass (stock)
  if (neighbor->ago == 0 && fix_rigid) {
    StickSlip::refresh_rigid_mass(lmp, fix_rigid, mass_rigid, nmax, "wall/gran:mass_rigid");
  }

  // the region's place and velocity now (every rank evaluates its variables)
  const bool moving = region->dynamic_check();
  if (moving) {
    region->prematch();
    region->set_velocity();
  }
  double vwall[3] = {0.0, 0.0, 0.0};

  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **atom_omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;

  if (peratom_flag) clear_stored_contacts();

  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    // a centre outside the region: stock leaves its contacts' histories as they are
    if (!region->match(x[i][0], x[i][1], x[i][2])) continue;
    const int nc = region->surface(x[i][0], x[i][1], x[i][2], radius[i]);
    if (nc > slots) error->one(FLERR, fmt::format("fix {} {}: more contacts with region {} than it allows ({})", id,
                                                  STYLE, idregion, slots));
    match_contacts(i, nc);
    for (int ic = 0; ic < nc; ic++) {
      const Region::Contact &c = region->contact[ic];
      const double rsq = c.r * c.r;
      if (moving) region->velocity_contact(vwall, x[i], ic);
      double meff = rmass[i];
      if (fix_rigid && mass_rigid[i] > 0.0) meff = mass_rigid[i];
      double *contact = nullptr;
      if (peratom_flag) {
        contact = array_atom[i];
        contact[0] = 1.0;
        contact[4] = x[i][0] - c.delx;
        contact[5] = x[i][1] - c.dely;
        contact[6] = x[i][2] - c.delz;
        contact[7] = radius[i];
      }
      wall_contact(wall, rsq, c.delx, c.dely, c.delz, vwall, v[i], f[i], atom_omega[i], torque[i], radius[i], meff,
                   hist[i] + ic * size_history, contact, dt, stepping);
    }
  }
}

/* Puts grain i's histories in the order of the region's nc contacts now: a contact with a
   wall the grain touched before keeps its history, a new one starts from zero, one that
   ended is dropped (docs/law.md step 3). */
void FixWallGranRegionStickSlip::match_contacts(int i, int nc)
{
  const int n = size_history, old = ncontacts[i];
  bool same = nc == old;
  for (int ic = 0; same && ic < nc; ic++) same = wall_of[i][ic] == region->contact[ic].iwall;
  if (same) return;  // the usual case: the same walls in the same order
  scratch.assign(hist[i], hist[i] + old * n);
  scratch_walls.assign(wall_of[i], wall_of[i] + old);
  for (int ic = 0; ic < nc; ic++) {
    const int iwall = region->contact[ic].iwall;
    int m = 0;
    while (m < old && scratch_walls[m] != iwall) m++;
    for (int k = 0; k < n; k++) hist[i][ic * n + k] = m < old ? scratch[m * n + k] : 0.0;
    wall_of[i][ic] = iwall;
  }
  ncontacts[i] = nc;
}

/* ---------------------------------------------------------------------- per-atom arrays */

double FixWallGranRegionStickSlip::memory_usage()
{
  const double nmax_atoms = atom->nmax;
  double bytes = nmax_atoms * (sizeof(int) + slots * sizeof(int) + slots * size_history * sizeof(double));
  if (fix_rigid) bytes += nmax_atoms * sizeof(double);
  if (peratom_flag) bytes += nmax_atoms * size_peratom_cols * sizeof(double);
  return bytes;
}

void FixWallGranRegionStickSlip::grow_arrays(int nmax_atoms)
{
  memory->grow(ncontacts, nmax_atoms, "wall/gran/region/stickslip:ncontacts");
  memory->grow(wall_of, nmax_atoms, slots, "wall/gran/region/stickslip:wall_of");
  memory->grow(hist, nmax_atoms, slots * size_history, "wall/gran/region/stickslip:hist");
  if (peratom_flag) memory->grow(array_atom, nmax_atoms, size_peratom_cols, "wall/gran/region/stickslip:array_atom");
}

void FixWallGranRegionStickSlip::copy_arrays(int i, int j, int)
{
  ncontacts[j] = ncontacts[i];
  for (int c = 0; c < ncontacts[i]; c++) wall_of[j][c] = wall_of[i][c];
  for (int k = 0; k < ncontacts[i] * size_history; k++) hist[j][k] = hist[i][k];
  if (peratom_flag)
    for (int m = 0; m < size_peratom_cols; m++) array_atom[j][m] = array_atom[i][m];
}

void FixWallGranRegionStickSlip::set_arrays(int i)
{
  ncontacts[i] = 0;
  if (peratom_flag)
    for (int m = 0; m < size_peratom_cols; m++) array_atom[i][m] = 0.0;
}

// an atom's values as they travel (exchange, restart): contacts, then per contact its wall
// index and history
int FixWallGranRegionStickSlip::pack_exchange(int i, double *buf)
{
  int n = 0;
  buf[n++] = ubuf(ncontacts[i]).d;
  for (int c = 0; c < ncontacts[i]; c++) {
    buf[n++] = ubuf(wall_of[i][c]).d;
    for (int k = 0; k < size_history; k++) buf[n++] = hist[i][c * size_history + k];
  }
  if (peratom_flag)
    for (int m = 0; m < size_peratom_cols; m++) buf[n++] = array_atom[i][m];
  return n;
}

int FixWallGranRegionStickSlip::unpack_exchange(int i, double *buf)
{
  int n = 0;
  ncontacts[i] = (int) ubuf(buf[n++]).i;
  for (int c = 0; c < ncontacts[i]; c++) {
    wall_of[i][c] = (int) ubuf(buf[n++]).i;
    for (int k = 0; k < size_history; k++) hist[i][c * size_history + k] = buf[n++];
  }
  if (peratom_flag)
    for (int m = 0; m < size_peratom_cols; m++) array_atom[i][m] = buf[n++];
  return n;
}

// restart: buf[0] is the count of values including itself (the fixes' shared convention)
int FixWallGranRegionStickSlip::pack_restart(int i, double *buf)
{
  int n = 1;
  buf[n++] = ubuf(ncontacts[i]).d;
  for (int c = 0; c < ncontacts[i]; c++) {
    buf[n++] = ubuf(wall_of[i][c]).d;
    for (int k = 0; k < size_history; k++) buf[n++] = hist[i][c * size_history + k];
  }
  buf[0] = n;
  return n;
}

void FixWallGranRegionStickSlip::unpack_restart(int i, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[i][m]);
  m++;
  ncontacts[i] = (int) ubuf(extra[i][m++]).i;
  if (ncontacts[i] > slots)
    error->one(FLERR, fmt::format("fix {} {}: the restart file has {} contacts for a grain, region {} allows {}", id,
                                  STYLE, ncontacts[i], idregion, slots));
  for (int c = 0; c < ncontacts[i]; c++) {
    wall_of[i][c] = (int) ubuf(extra[i][m++]).i;
    for (int k = 0; k < size_history; k++) hist[i][c * size_history + k] = extra[i][m++];
  }
}

int FixWallGranRegionStickSlip::size_restart(int i) { return 2 + ncontacts[i] * (size_history + 1); }

int FixWallGranRegionStickSlip::maxsize_restart() { return 2 + slots * (size_history + 1); }

}  // namespace StickSlip
