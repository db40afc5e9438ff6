/* SPDX-License-Identifier: GPL-2.0-or-later
   Grains of a rigid body collide with the body's mass (the stock granular styles' rule for
   the normal damping's effective mass). At each neighbour-list build the pair style and
   both walls refresh, for each owned grain, its body's mass (0: in no body) from the rigid
   fix's "body" and "masstotal". */

#ifndef STICKSLIP_RIGID_MASS_H
#define STICKSLIP_RIGID_MASS_H

#include "atom.h"
#include "fix.h"
#include "memory.h"
#include "pointers.h"

namespace StickSlip {

// mass_rigid (of size nmax) grows with the atom arrays; `name` labels it in LAMMPS' memory log
inline void refresh_rigid_mass(LAMMPS_NS::LAMMPS *lmp, LAMMPS_NS::Fix *fix_rigid, double *&mass_rigid, int &nmax,
                               const char *name)
{
  int unused;
  const int *body = (const int *) fix_rigid->extract("body", unused);
  const double *mass_body = (const double *) fix_rigid->extract("masstotal", unused);
  if (lmp->atom->nmax > nmax) {
    lmp->memory->destroy(mass_rigid);
    nmax = lmp->atom->nmax;
    lmp->memory->create(mass_rigid, nmax, name);
  }
  for (int i = 0; i < lmp->atom->nlocal; i++) mass_rigid[i] = body[i] >= 0 ? mass_body[body[i]] : 0.0;
}

}  // namespace StickSlip

#endif
