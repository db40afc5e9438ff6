/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: the layout of the flat arrays contact_step.cpp's functions take; tests/deme_shim.py
   reads these numbers from this file, so that the two cannot differ. */

#ifndef STICKSLIP_DEME_SHIM_LAYOUT_H
#define STICKSLIP_DEME_SHIM_LAYOUT_H

enum {
  NM = 4,  // material types (the contract's per-type-pair rows use 1..3)
  NO = 4   // owners: A is 0, B is 1
};

// kin: the contact and the bodies (vectors global, as the engine's kernel has them)
enum {
  K_B2A = 0,        // unit normal from B to A
  K_ALINVEL = 3,
  K_BLINVEL = 6,
  K_AROTVEL = 9,    // angular velocity in the body's own frame
  K_BROTVEL = 12,
  K_LOCCPA = 15,    // contact point relative to A's centre, in A's frame
  K_LOCCPB = 18,
  K_AORIQ = 21,     // orientation quaternion x, y, z, w
  K_BORIQ = 25,
  K_AMASS = 29,
  K_BMASS = 30,
  K_TS = 31,        // time step
  K_TIME = 32,      // time at the step's start
  K_CONTACT_TYPE = 33,
  K_AMAT = 34,
  K_BMAT = 35,
  K_ARADIUS = 36,   // A's radius (float, as the engine keeps it)
  KIN_SIZE = 37
};

// geo (double): the overlap and its area as the engine computed them, then A's centre and
// B's point (a plane's point; a sphere's centre), global
enum { G_OVERLAP = 0, G_AREA = 1, G_APOS = 2, G_BPOS = 5, GEO_SIZE = 8 };

// mat: pairwise properties [NM][NM] in this order, then E[NM] and nu[NM]
enum { M_KN = 0, M_NU_N, M_KS, M_NU_S, M_MU, M_MU_K, M_COR, M_PAIRWISE };
enum { M_E_OFFSET = M_PAIRWISE * NM * NM, MAT_SIZE = M_E_OFFSET + 2 * NM };

// own: owner wildcards [name][NO]: the sweep's coefficients, then the record
enum { W_MU_S = 0, W_MU_K, W_NU_N, W_NU_S, W_OPTS, R_FN, R_FX, R_FY, R_FZ, R_DX, R_DY, R_DZ, R_SLIPS, R_T, OWN_NAMES };
enum { OWN_SIZE = OWN_NAMES * NO };

#endif
