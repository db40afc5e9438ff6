/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: deme_model/stick_slip.cu compiled on the CPU, one contact and one step per call,
   for tests/deme_shim.py (ctypes). Each function below declares the variables DEM-Engine's
   force kernel gives a custom force model (the same names and types), includes the model's
   text with one set of its options, and hands back what the model wrote.

   Arguments (flat arrays, layouts in deme_shim_layout.h):
     geo   double[GEO_SIZE]  overlapDepth, overlapArea, bodyAPos, bodyBPos
     kin   float[KIN_SIZE]   the contact's geometry and the bodies' motion (A is owner 0, B 1)
     mat   float[MAT_SIZE]   material properties: pairwise [NM][NM] arrays, then E[NM], nu[NM]
     own   float[OWN_SIZE]   owner wildcards, [name][NO] (sweep coefficients, the record)
     wc    float[4]          the contact wildcards ss_dx, ss_dy, ss_dz, ss_slips (in and out)
     out   float[3]          force on A */

#include "deme_shim.h"
#include "deme_shim_layout.h"

#define SHIM_FUNCTION(NAME) \
  extern "C" void NAME(const double *geo, const float *kin, const float *mat, float *own, float *wc, float *out)

#define F3(p) make_float3((p)[0], (p)[1], (p)[2])

#define SHIM_PROLOGUE                                                                                            \
  double overlapDepth = geo[G_OVERLAP], overlapArea = geo[G_AREA];                                              \
  double3 bodyAPos = {geo[G_APOS], geo[G_APOS + 1], geo[G_APOS + 2]};                                            \
  double3 bodyBPos = {geo[G_BPOS], geo[G_BPOS + 1], geo[G_BPOS + 2]};                                            \
  float ARadius = kin[K_ARADIUS];                                                                                \
  float3 B2A = F3(kin + K_B2A), ALinVel = F3(kin + K_ALINVEL), BLinVel = F3(kin + K_BLINVEL);                    \
  float3 ARotVel = F3(kin + K_AROTVEL), BRotVel = F3(kin + K_BROTVEL);                                           \
  float3 locCPA = F3(kin + K_LOCCPA), locCPB = F3(kin + K_LOCCPB);                                               \
  float4 AOriQ = make_float4(kin[K_AORIQ], kin[K_AORIQ + 1], kin[K_AORIQ + 2], kin[K_AORIQ + 3]);                \
  float4 BOriQ = make_float4(kin[K_BORIQ], kin[K_BORIQ + 1], kin[K_BORIQ + 2], kin[K_BORIQ + 3]);                \
  float AOwnerMass = kin[K_AMASS], BOwnerMass = kin[K_BMASS], ts = kin[K_TS], time = kin[K_TIME];                \
  deme::contact_t ContactType = (deme::contact_t)kin[K_CONTACT_TYPE];                                            \
  deme::materialsOffset_t bodyAMatType = (deme::materialsOffset_t)kin[K_AMAT];                                   \
  deme::materialsOffset_t bodyBMatType = (deme::materialsOffset_t)kin[K_BMAT];                                   \
  deme::bodyID_t AOwner = 0, BOwner = 1;                                                                         \
  typedef const float(*Pairwise)[NM];                                                                            \
  Pairwise kn = (Pairwise)(mat + M_KN * NM * NM), nu_n = (Pairwise)(mat + M_NU_N * NM * NM);                     \
  Pairwise ks = (Pairwise)(mat + M_KS * NM * NM), nu_s = (Pairwise)(mat + M_NU_S * NM * NM);                     \
  Pairwise mu = (Pairwise)(mat + M_MU * NM * NM), mu_k = (Pairwise)(mat + M_MU_K * NM * NM);                     \
  Pairwise CoR = (Pairwise)(mat + M_COR * NM * NM);                                                              \
  const float *E = mat + M_E_OFFSET, *nu = mat + M_E_OFFSET + NM;                                                \
  float *ss_mu_s = own + W_MU_S * NO, *ss_mu_k = own + W_MU_K * NO, *ss_nu_n = own + W_NU_N * NO;                \
  float *ss_nu_s = own + W_NU_S * NO, *ss_opts = own + W_OPTS * NO;                                              \
  float *ss_rec_fn = own + R_FN * NO, *ss_rec_fx = own + R_FX * NO, *ss_rec_fy = own + R_FY * NO;                \
  float *ss_rec_fz = own + R_FZ * NO, *ss_rec_dx = own + R_DX * NO, *ss_rec_dy = own + R_DY * NO;                \
  float *ss_rec_dz = own + R_DZ * NO, *ss_rec_slips = own + R_SLIPS * NO, *ss_rec_t = own + R_T * NO;            \
  float ss_dx = wc[0], ss_dy = wc[1], ss_dz = wc[2], ss_slips = wc[3];                                          \
  float3 force = make_float3(0.f, 0.f, 0.f);                                                                     \
  (void)kn, (void)nu_n, (void)ks, (void)nu_s, (void)mu, (void)mu_k, (void)CoR, (void)E, (void)nu;                \
  (void)ss_mu_s, (void)ss_mu_k, (void)ss_nu_n, (void)ss_nu_s, (void)ss_opts, (void)ss_rec_fn, (void)ss_rec_fx;    \
  (void)ss_rec_fy, (void)ss_rec_fz, (void)ss_rec_dx, (void)ss_rec_dy, (void)ss_rec_dz, (void)ss_rec_slips;        \
  (void)ss_rec_t, (void)AOwner, (void)BOwner, (void)time, (void)AOwnerMass, (void)BOwnerMass, (void)overlapArea

#define SHIM_EPILOGUE \
  wc[0] = ss_dx;      \
  wc[1] = ss_dy;      \
  wc[2] = ss_dz;      \
  wc[3] = ss_slips;   \
  out[0] = force.x;   \
  out[1] = force.y;   \
  out[2] = force.z


// Linear normal force, coefficients from the materials: the four (timing, reset) builds
SHIM_FUNCTION(ss_hooke_step_spring)
{
  SHIM_PROLOGUE;
#define STICKSLIP_HOOKE 1
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}

SHIM_FUNCTION(ss_hooke_step_total)
{
  SHIM_PROLOGUE;
#define STICKSLIP_HOOKE 1
#define STICKSLIP_RESET_TOTAL 1
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}

SHIM_FUNCTION(ss_hooke_exact_spring)
{
  SHIM_PROLOGUE;
#define STICKSLIP_HOOKE 1
#define STICKSLIP_EXACT 1
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}

SHIM_FUNCTION(ss_hooke_exact_total)
{
  SHIM_PROLOGUE;
#define STICKSLIP_HOOKE 1
#define STICKSLIP_EXACT 1
#define STICKSLIP_RESET_TOTAL 1
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}

// Linear normal force, coefficients, timing and reset per owner (the sweep), with the record
SHIM_FUNCTION(ss_hooke_sweep_record)
{
  SHIM_PROLOGUE;
#define STICKSLIP_HOOKE 1
#define STICKSLIP_SWEEP 1
#define STICKSLIP_RECORD 1
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}

// The engine's Hertz-Mindlin normal force, coefficients from the materials
SHIM_FUNCTION(ss_hertz_step_spring)
{
  SHIM_PROLOGUE;
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}

// Hertz-Mindlin, mu_s, mu_k and the options per owner, with the record
SHIM_FUNCTION(ss_hertz_sweep_record)
{
  SHIM_PROLOGUE;
#define STICKSLIP_SWEEP 1
#define STICKSLIP_RECORD 1
#include "../stick_slip.cu"
#include "undef_options.h"
  SHIM_EPILOGUE;
}
