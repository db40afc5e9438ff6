// SPDX-License-Identifier: GPL-2.0-or-later
// stickslip: the stick-slip tangential contact law of Khellaf & Mansouri (2024) as a
// DEM-Engine (PyPI `deme` 3.0) custom force model: this text is the body DEM-Engine
// compiles into its force kernels (DefineContactForceModel), step by step as docs/law.md
// states it. The only place the law lives for DEM-Engine; deme_model/README.md says how
// to attach it (deme_model/stickslip_deme.py does it in one call) and
// deme_model/shim/ compiles this same file on the CPU for the tests. It is the float twin
// of the C++ engines' core (lammps_plugin/granular/stick_slip_core.h), kept apart because
// the engine compiles this text alone, in float, into its kernels; the law's contract run
// through the shim (tests/test_deme_shim.py) holds it to the same answers.
//
// Options, set by #define before this text (stickslip_deme.model_text writes them):
//   STICKSLIP_HOOKE        1: linear normal force Fn = max(0, kn delta + nu_n v_n) (eq. 3),
//                          Ks and nu_s given; 0: the engine's Hertz-Mindlin normal force,
//                          Ks and nu_s Mindlin's (as its frictional model computes them)
//   STICKSLIP_SWEEP        1: mu_s, mu_k (and with Hooke nu_n, nu_s) and the slip timing and
//                          reset read per owner (owner wildcards): changed between runs
//                          without a new JIT compile; 0: material properties (literals)
//   STICKSLIP_EXACT        1: slip_timing exact (docs/law.md E0-E7), else step
//   STICKSLIP_RESET_TOTAL  1: reset total (spring + dashpot = Fmin), else spring (eq. 8)
//   STICKSLIP_RECORD       1: each body keeps its last contact's Fn, F_s, D, slip count and
//                          evaluation time in owner wildcards (a body with one contact:
//                          the paper's scenes, the contract's rows)
// Everything is float, as the engine's force kernels are, but the distance to a plane
// (step 0). Names without the ss_ prefix are the engine's (FullHertzianForceModel.cu lists
// them; bodyAPos, bodyBPos and ARadius are its force kernel's locals).

#ifndef STICKSLIP_HOOKE
#define STICKSLIP_HOOKE 0
#endif
#ifndef STICKSLIP_SWEEP
#define STICKSLIP_SWEEP 0
#endif
#ifndef STICKSLIP_EXACT
#define STICKSLIP_EXACT 0
#endif
#ifndef STICKSLIP_RESET_TOTAL
#define STICKSLIP_RESET_TOTAL 0
#endif
#ifndef STICKSLIP_RECORD
#define STICKSLIP_RECORD 0
#endif

// ---- step 0: the overlap. On an analytical plane the engine's overlapDepth is r less a
// distance it rounds to float (planeSignedDistance: steps of ulp(r)), taken along a normal
// turned by a float quaternion (a turning plane's is 1 +- ~2e-7 long, anew each step). The
// paper's overlaps are ~3e-5 r, so each moves Fn by up to ~1 % (deme_model/README.md,
// "Geometry in float"). The distance is taken again here in double, along the normal made
// unit. For a plane the two differ by less than 1e-6 r; where they differ by more than
// 1e-4 r, B is not a plane (a cylinder, whose B is on its axis: they differ by its radius)
// and the engine's overlap stays.
double ss_overlap = overlapDepth, ss_area = overlapArea;
if (ContactType == deme::SPHERE_ANALYTICAL_CONTACT) {
    const double ss_nx = B2A.x, ss_ny = B2A.y, ss_nz = B2A.z;
    const double ss_dist = ((bodyAPos.x - bodyBPos.x) * ss_nx + (bodyAPos.y - bodyBPos.y) * ss_ny +
                            (bodyAPos.z - bodyBPos.z) * ss_nz) /
                           sqrt(ss_nx * ss_nx + ss_ny * ss_ny + ss_nz * ss_nz);
    const double ss_rad = ARadius;
    if (fabs(ss_dist - (ss_rad - overlapDepth)) <= 1e-4 * ss_rad) {
        ss_overlap = ss_rad - ss_dist;
        ss_area = deme::PI * (ss_rad * ss_rad - ss_dist * ss_dist);  // the engine's circle
    }
}

if (ss_overlap > 0) {
    // A grain pair (A, B spheres) or a grain on a wall (B analytical or a mesh). The law's
    // n points from A to B: n = -B2A (B2A is the engine's normal, from B to A).
    const bool ss_pair = ContactType == deme::SPHERE_SPHERE_CONTACT;
    const float ss_delta = (float)ss_overlap;

    // ---- coefficients of this contact
    float ss_mu_s_c, ss_mu_k_c;
    bool ss_exact, ss_total;
#if STICKSLIP_SWEEP
    // per owner: a grain pair takes the mean of its two bodies' values (exact when they are
    // equal), a wall contact its grain's (A's)
    ss_mu_s_c = ss_pair ? 0.5f * (ss_mu_s[AOwner] + ss_mu_s[BOwner]) : ss_mu_s[AOwner];
    ss_mu_k_c = ss_pair ? 0.5f * (ss_mu_k[AOwner] + ss_mu_k[BOwner]) : ss_mu_k[AOwner];
    {
        const int ss_o = (int)ss_opts[AOwner];  // 1: slip_timing exact, 2: reset total
        ss_exact = (ss_o & 1) != 0;
        ss_total = (ss_o & 2) != 0;
    }
#else
    ss_mu_s_c = mu[bodyAMatType][bodyBMatType];
    ss_mu_k_c = mu_k[bodyAMatType][bodyBMatType];
    ss_exact = STICKSLIP_EXACT;
    ss_total = STICKSLIP_RESET_TOTAL;
#endif

    // ---- step 1: relative velocity of A's contact point to B's. The engine's contact point
    // is midway in the overlap (lever arms r - delta/2); a wall's velocity is taken at its
    // surface point nearest A's centre, half the overlap from there towards A.
    float3 ss_cpB = locCPB;
    if (ContactType == deme::SPHERE_ANALYTICAL_CONTACT) {
        float3 ss_nB = B2A;  // into B's own frame, where locCPB is
        applyOriQToVector3(ss_nB, make_float4(-BOriQ.x, -BOriQ.y, -BOriQ.z, BOriQ.w));
        ss_cpB = ss_cpB + (0.5f * ss_delta) * ss_nB;
    }
    float3 ss_wA = cross(ARotVel, locCPA);
    float3 ss_wB = cross(BRotVel, ss_cpB);
    applyOriQToVector3(ss_wA, AOriQ);
    applyOriQToVector3(ss_wB, BOriQ);
    const float3 ss_vrel = (ALinVel + ss_wA) - (BLinVel + ss_wB);
    const float ss_vn = -dot(ss_vrel, B2A);        // v_n = v_rel.n, > 0 closing
    const float3 ss_vs = ss_vrel + ss_vn * B2A;    // V_s = v_rel - v_n n (eq. 6)

    // ---- step 2: normal force (on A: Fn B2A), and the tangential spring and dashpot
    float ss_fn, ss_ks_c, ss_nu_s_c;
#if STICKSLIP_HOOKE
    {
        float ss_nu_n_c;
#if STICKSLIP_SWEEP
        ss_nu_n_c = ss_pair ? 0.5f * (ss_nu_n[AOwner] + ss_nu_n[BOwner]) : ss_nu_n[AOwner];
        ss_nu_s_c = ss_pair ? 0.5f * (ss_nu_s[AOwner] + ss_nu_s[BOwner]) : ss_nu_s[AOwner];
#else
        ss_nu_n_c = nu_n[bodyAMatType][bodyBMatType];
        ss_nu_s_c = nu_s[bodyAMatType][bodyBMatType];
#endif
        ss_ks_c = ks[bodyAMatType][bodyBMatType];
        // eq. 3, never tensile
        ss_fn = fmaxf(0.f, kn[bodyAMatType][bodyBMatType] * ss_delta + ss_nu_n_c * ss_vn);
    }
#else
    {
        // the engine's Hertz-Mindlin normal force and Mindlin's tangential stiffness and
        // damping, as FullHertzianForceModel.cu computes them (it may be tensile while the
        // bodies part: the threshold and Fmin then use |Fn|, docs/law.md step 2)
        float ss_E, ss_G;
        matProxy2ContactParam<float>(ss_E, ss_G, E[bodyAMatType], nu[bodyAMatType], E[bodyBMatType],
                                     nu[bodyBMatType]);
        const float ss_cor = CoR[bodyAMatType][bodyBMatType];
        const float ss_meff = (AOwnerMass * BOwnerMass) / (AOwnerMass + BOwnerMass);
        const float ss_a = sqrtf(ss_area / deme::PI);  // contact radius
        const float ss_Sn = 2.f * ss_E * ss_a;
        const float ss_loge = (ss_cor < DEME_TINY_FLOAT) ? logf(DEME_TINY_FLOAT) : logf(ss_cor);
        const float ss_beta = ss_loge / sqrtf(ss_loge * ss_loge + deme::PI_SQUARED);
        const float ss_kn_h = (2.f / 3.f) * ss_Sn;
        const float ss_gn = (2.f * sqrtf(5.f / 6.f)) * ss_beta * sqrtf(ss_Sn * ss_meff);
        ss_fn = ss_kn_h * ss_delta - ss_gn * ss_vn;  // the engine's k_n delta + gamma_n (v_rel.B2A)
        ss_ks_c = 8.f * ss_G * ss_a;
        ss_nu_s_c = -2.f * sqrtf(5.f / 3.f) * ss_beta * sqrtf(ss_meff * ss_ks_c);
    }
#endif
    force += ss_fn * B2A;
    const float ss_fnabs = fabsf(ss_fn);
    const float ss_T = ss_mu_s_c * ss_fnabs;                       // slip threshold mu_s |Fn|
    const float ss_fmin = (2.f * ss_mu_k_c - ss_mu_s_c) * ss_fnabs;  // Fmin = (2 mu_k - mu_s)|Fn|

    // ---- step 3: the spring D, turned into the current tangent plane keeping its length,
    // then incremented (eq. 7)
    float3 ss_D = make_float3(ss_dx, ss_dy, ss_dz);
    {
        const float ss_dn = dot(ss_D, B2A);
        if (ss_dn != 0.f) {
            const float ss_old2 = dot(ss_D, ss_D);
            ss_D = ss_D - ss_dn * B2A;
            const float ss_new2 = dot(ss_D, ss_D);
            if (ss_new2 > 0.f)
                ss_D = ss_D * sqrtf(ss_old2 / ss_new2);
        }
    }
    const float3 ss_D0 = ss_D;  // (the exact timing's spring at the step's start)
    ss_D = ss_D + ts * ss_vs;

    // ---- step 4: trial force on A (eq. 5); step 5: the slip test, |F_t| >= mu_s |Fn|
    float3 ss_F = -ss_ks_c * ss_D - ss_nu_s_c * ss_vs;
    const float ss_F2 = dot(ss_F, ss_F);
    bool ss_slipped = ss_F2 >= ss_T * ss_T;
    if (!ss_exact) {
        if (ss_slipped) {
            // the force drops to Fmin along the trial force (t = 0 if |F_t| = 0)
            const float ss_mag = sqrtf(ss_F2);
            const float ss_ratio = ss_mag > 0.f ? ss_fmin / ss_mag : 0.f;
            ss_F = ss_ratio * ss_F;
            // eq. 8: reset spring, Ks |D| = Fmin; reset total, spring + dashpot = Fmin
            ss_D = ss_total ? (ss_F + ss_nu_s_c * ss_vs) / (-ss_ks_c) : ss_F / (-ss_ks_c);
        }
    } else {
        // ---- exact slip timing (docs/law.md E0-E7). E0: |F| moves on a line during the
        // step and is convex in it, so the step has a slip iff it is at or above T at an end.
        const float3 ss_F0 = -ss_ks_c * ss_D0 - ss_nu_s_c * ss_vs;
        ss_slipped = ss_slipped || dot(ss_F0, ss_F0) >= ss_T * ss_T;
        if (ss_slipped) {
            const float ss_speed = sqrtf(dot(ss_vs, ss_vs));
            const float3 ss_u = ss_speed > 0.f ? ss_vs / (-ss_speed) : make_float3(0.f, 0.f, 0.f);
            const float ss_rate = ss_ks_c * ss_speed * ts;
            // after a slip the trial force restarts from Fmin t + kept u (E3)
            const float ss_kept = ss_total ? 0.f : ss_nu_s_c * ss_speed;
            const float ss_r = ss_mu_s_c > 0.f ? (2.f * ss_mu_k_c - ss_mu_s_c) / ss_mu_s_c : 1.f;
            // E6 applies when nothing is added at the reset
            const bool ss_flow_law = ss_r == 1.f && (ss_total || ss_nu_s_c == 0.f);
            float3 ss_applied, ss_trial;
            if (!(ss_T > 0.f)) {  // E1: no normal force, no friction
                ss_applied = make_float3(0.f, 0.f, 0.f);
                ss_trial = ss_kept * ss_u;
            } else {
                float3 ss_f = ss_F0;
                float ss_theta = 0.f;
                int ss_n = 0;  // slips followed in this step
                for (;;) {
                    // E2: the next slip, where |F + rate dtheta u| reaches T (the larger root);
                    // before the step's first slip the force may already be at or above T
                    const float ss_along_f = dot(ss_f, ss_u), ss_f2 = dot(ss_f, ss_f);
                    float ss_dtheta;
                    if (ss_n == 0 && ss_f2 >= ss_T * ss_T) {
                        ss_dtheta = 0.f;
                    } else {
                        const float ss_gap =
                            fmaxf(sqrtf(fmaxf(ss_T * ss_T - (ss_f2 - ss_along_f * ss_along_f), 0.f)) - ss_along_f, 0.f);
                        ss_dtheta = ss_rate > 0.f ? ss_gap / ss_rate : 2.f;  // (2: never within the step)
                    }
                    if (!(ss_theta + ss_dtheta <= 1.f)) {  // sticks to the end of the step
                        ss_applied = ss_trial = ss_f + (ss_rate * (1.f - ss_theta)) * ss_u;
                        break;
                    }
                    const float3 ss_hit = ss_f + (ss_rate * ss_dtheta) * ss_u;
                    ss_theta += ss_dtheta;
                    // E3: the slip; the force drops to Fmin along its direction t (eq. 8)
                    const float3 ss_t = ss_hit / sqrtf(dot(ss_hit, ss_hit));
                    ss_n++;
                    ss_f = ss_fmin * ss_t + ss_kept * ss_u;
                    const float ss_rest = 1.f - ss_theta;
                    // E4: restarted at or above T: slides at Fmin u for the rest of the step
                    if (ss_kept > 0.f && dot(ss_f, ss_f) >= ss_T * ss_T) {
                        ss_trial = (ss_fmin + ss_kept) * ss_u;
                        ss_applied = ss_fmin * ss_u;
                        break;
                    }
                    if (ss_rate == 0.f) {  // E5: nothing moves
                        ss_applied = ss_trial = ss_f;
                        break;
                    }
                    const float ss_tu = dot(ss_t, ss_u);
                    if (ss_flow_law && ss_tu >= 0.f) {
                        // E6: plastic flow on |F| = T, tan(phi/2) falling by exp(-rate rest/T)
                        const float ss_a = dot(ss_f, ss_u);
                        const float3 ss_q = ss_f - ss_a * ss_u;
                        const float ss_qn = sqrtf(dot(ss_q, ss_q));
                        const float ss_s = ss_qn / (ss_T + ss_a) * expf(-ss_rate * ss_rest / ss_T);
                        const float ss_c = (1.f - ss_s * ss_s) / (1.f + ss_s * ss_s);
                        const float ss_sn = 2.f * ss_s / (1.f + ss_s * ss_s);
                        ss_applied = (ss_T * ss_c) * ss_u +
                                     (ss_T * ss_sn) * (ss_qn > 0.f ? ss_q / ss_qn : make_float3(0.f, 0.f, 0.f));
                        ss_trial = ss_applied;
                        break;
                    }
                    // E7: settled along u, or 100 slips followed: the rest of the step repeats
                    // one cycle (Fmin + kept) u -> T u of length L, the part q across u shrinking
                    // by r a slip. Settled: |q| <= 1e-4 T, where q changes the slip level by
                    // |q|^2/(2T) < 1e-8 T, below float's rounding (docs/law.md's 1e-8 is for
                    // double: in float it would never be reached)
                    const float ss_fu = dot(ss_f, ss_u);
                    const float3 ss_q = ss_f - ss_fu * ss_u;
                    if ((sqrtf(dot(ss_q, ss_q)) <= 1e-4f * ss_T && ss_tu > 0.f) || ss_n >= 100) {
                        const float ss_low = ss_fmin + ss_kept;
                        const float ss_L = (ss_T - ss_low) / ss_rate;
                        if (!(ss_L > 0.f)) {  // restarts at T: slides, as E4
                            ss_trial = ss_low * ss_u;
                            ss_applied = ss_fmin * ss_u;
                            break;
                        }
                        const float ss_whole = floorf(ss_rest / ss_L);
                        const float ss_part = ss_rest - ss_whole * ss_L;
                        const float ss_shrink = ss_whole == 0.f ? 1.f : powf(ss_r, ss_whole);
                        ss_applied = ss_trial = (ss_low + ss_rate * ss_part) * ss_u + ss_shrink * ss_q;
                        break;
                    }
                }
            }
            ss_F = ss_applied;
            ss_D = (ss_trial + ss_nu_s_c * ss_vs) / (-ss_ks_c);  // the spring holds the trial force less the dashpot
        }
    }

    // ---- step 6: the tangential force on A (the engine applies -force on B and the torques
    // from the contact point)
    force += ss_F;
    ss_dx = ss_D.x;
    ss_dy = ss_D.y;
    ss_dz = ss_D.z;
    if (ss_slipped)
        ss_slips += 1.f;  // steps in which this contact slipped since it began (exact to 2^24)
#if STICKSLIP_RECORD
    ss_rec_fn[AOwner] = ss_fn;
    ss_rec_fx[AOwner] = ss_F.x;
    ss_rec_fy[AOwner] = ss_F.y;
    ss_rec_fz[AOwner] = ss_F.z;
    ss_rec_dx[AOwner] = ss_D.x;
    ss_rec_dy[AOwner] = ss_D.y;
    ss_rec_dz[AOwner] = ss_D.z;
    ss_rec_slips[AOwner] = ss_slips;
    ss_rec_t[AOwner] = time;
    if (ss_pair) {  // B sees the opposite force and spring
        ss_rec_fn[BOwner] = ss_fn;
        ss_rec_fx[BOwner] = -ss_F.x;
        ss_rec_fy[BOwner] = -ss_F.y;
        ss_rec_fz[BOwner] = -ss_F.z;
        ss_rec_dx[BOwner] = -ss_D.x;
        ss_rec_dy[BOwner] = -ss_D.y;
        ss_rec_dz[BOwner] = -ss_D.z;
        ss_rec_slips[BOwner] = ss_slips;
        ss_rec_t[BOwner] = time;
    }
#endif
} else {
    // Listed by the contact detection (its margin) but not touching: no force, and the
    // contact begins afresh when they touch again (docs/law.md step 3)
    ss_dx = 0.f;
    ss_dy = 0.f;
    ss_dz = 0.f;
    ss_slips = 0.f;
}
