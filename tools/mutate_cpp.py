#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Small deliberate bugs in the C++ law, each built and run against the tests: does the
suite see it? (issue 31 item 5; the README's test section quotes the last result.)

    .venv/bin/python tools/mutate_cpp.py [--engine liggghts|lammps|lammps_granular|yade_cpp|deme] [--only ID ...] [--wide]

For each mutant: copy the engine's source folder, with the law's core beside it, into
build/mutants/<engine>/src (the repository's layout; its files are never touched), apply the
mutant to the copy, rebuild in
build/mutants/<engine>/build, and run the engine's test selection with the adapter
pointed at that build (STICKSLIP_LIGGGHTS_BUILD, STICKSLIP_LAMMPS_BUILD, STICKSLIP_YADE_LAW_BUILD;
DEM-Engine's force model: STICKSLIP_DEME_SHIM_BUILD, its CPU build for the tests). A mutant is found by the
text it changes (a regular expression, whitespace-insensitive, that must match exactly
`count` times), never by line number: a mutant whose text is not found, or found a different
number of times, is an ERROR in the summary and makes the exit status 2, never a silent
skip. Killed = some test failed; survived = the selection passed.

Selections: first the fast one (the law's contract on the engine, ~10 s); a mutant it
does not kill is run against the engine's whole default test selection (`--wide` runs
that for every mutant, to name every test that kills it). The fast selection runs on an -O0
build (3x quicker to compile than the project's; the same IEEE operations without FMA
contraction, so the same numbers: the baseline must pass it first), the wide one on a
Release build as ./run.sh setup makes it (the large scenes run 3-5x faster there).

An engine is one entry in ENGINES: its source folder, the file its part of the law lives in
(a mutant may name another file), the environment variable its adapter reads, its test
selections, its configure arguments, and its mutants: its own (the same kinds, found in its
own text) and the core's (CORE_MUTANTS, law_core/stick_slip_core.h), which every
engine that includes the core must kill. DEM-Engine's float force model is its own copy.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PYTHON = REPO / ".venv" / "bin" / "python"


@dataclass(frozen=True)
class Mutant:
    id: str
    kind: str  # the kind of bug issue 31 names
    find: str  # the text to change (whitespace-insensitive)
    replace: str
    count: int = 1  # how many times `find` must occur (all are changed)
    file: str = ""  # the file mutated, a path in the repository ("": the engine's law_file)


@dataclass(frozen=True)
class Engine:
    source: str  # the folder built (a path in the repository)
    law_file: str  # the file mutated when a mutant names none (a path in the repository)
    build_env: str  # the adapter's variable for the build folder
    fast: tuple  # pytest arguments: the selection every mutant runs
    wide: tuple  # the engine's default-suite tests, for mutants the fast one misses
    mutants: tuple
    cmake_args: tuple = ()  # configure arguments beyond the build type
    builder: object = None  # build(src, out, quick, cmake_args) for an engine built otherwise (None: cmake -S src)
    # folders and files copied beside `source`: the law's core, the project's version header
    copies: tuple = ("lammps_plugin/granular", "law_core", "lammps_plugin/stickslip_version.h")


# The law's engine-free core, included by LIGGGHTS, LAMMPS 2021's styles, the LAMMPS sub-model
# and YADE's compiled law: one list, run on each of the four (`--engine`); each must kill every
# mutant.
CORE = "law_core/stick_slip_core.h"
CORE_MUTANTS = (
    Mutant("core_threshold_gt", "> for >= at the threshold",
           "static bool slips(double force, double threshold) { return force >= threshold; }",
           "static bool slips(double force, double threshold) { return force > threshold; }", file=CORE),
    Mutant("core_fmin_0.3pct", "Fmin off by 0.3 %",
           "static double kinetic(double mu_s, double mu_k) { return 2.0 * mu_k - mu_s; }",
           "static double kinetic(double mu_s, double mu_k) { return (2.0 * mu_k - mu_s) * 1.003; }", file=CORE),
    Mutant("core_reset_spring_sign", "sign error in the spring reset",
           "const double back = -1.0 / ks;", "const double back = 1.0 / ks;", file=CORE),
    Mutant("core_reset_total_sign", "sign error in the spring reset",
           "(total ? F[i] - fdamp[i] : F[i]) * back;", "(total ? F[i] + fdamp[i] : F[i]) * back;", file=CORE),
    Mutant("core_reset_total_ignored", "the reset rule `total` ignored",
           "(total ? F[i] - fdamp[i] : F[i]) * back;", "F[i] * back;", file=CORE),
    Mutant("core_work_spring_sign", "a wrong dissipated work",
           "return -dot(F, vs) * dt - 0.5 * ks * (after2 - before2);",
           "return -dot(F, vs) * dt + 0.5 * ks * (after2 - before2);", file=CORE),
    Mutant("core_exact_start_sign", "sign error in the trial force at the step's start (exact timing)",
           "for (int i = 0; i < 3; i++) F0[i] = F[i] + ksdt * vs[i];",
           "for (int i = 0; i < 3; i++) F0[i] = F[i] - ksdt * vs[i];", file=CORE),
    Mutant("core_exact_misses_slip_at_start", "exact timing that misses a slip inside the step",
           "return end_slips || start_slips;", "return end_slips;", file=CORE),
    Mutant("core_exact_e4_sign", "sign error in the spring reset",
           "D[i] = aks * vs[i];", "D[i] = -aks * vs[i];", file=CORE),
    Mutant("core_exact_e4_condition", "> for >= at the threshold",
           "- 2.0 * fmin * nu_s * dot(F0, vs) >= 0.0", "- 2.0 * fmin * nu_s * dot(F0, vs) > 0.0", file=CORE),
    Mutant("core_exact_end_sign", "sign error in the spring reset",
           "spring[i] = -(trial[i] + nu_s * vs[i]) / ks;", "spring[i] = -(trial[i] - nu_s * vs[i]) / ks;", file=CORE),
    Mutant("core_flow_ignores_reset_total", "the reset rule `total` ignored",
           "ratio == 1.0 && (total || nu_s == 0.0)", "ratio == 1.0 && nu_s == 0.0", file=CORE),
    Mutant("core_threshold_gt_exact_loop", "> for >= at the threshold",
           "if (slips == 0 && F2 >= T * T)", "if (slips == 0 && F2 > T * T)", file=CORE),
    Mutant("core_exact_misses_whole_cycles", "exact timing that misses a slip inside the step",
           "const double n = std::floor(rest / L);", "const double n = 0.0;", file=CORE),
    Mutant("core_exact_slip_late", "exact timing that misses a slip inside the step",
           "dtheta = rate > 0.0 ? gap / rate : INFINITY;", "dtheta = rate > 0.0 ? 1.5 * gap / rate : INFINITY;",
           file=CORE),
    Mutant("core_reset_total_ignored_exact", "the reset rule `total` ignored",
           "const double kept = reset_total ? 0.0 : nu_s * speed;", "const double kept = nu_s * speed;", file=CORE),
    Mutant("core_flow_not_at_right_angle", "E6 (plastic flow) left out at t.u = 0",
           "if (flow_law && along >= 0.0)", "if (flow_law && along > 0.0)", file=CORE),
    Mutant("core_flow_rest_inverted", "E6 (plastic flow) over the wrong share of the step",
           "plastic_flow(F, u, rate * rest / T, T);", "plastic_flow(F, u, rate / rest / T, T);", file=CORE),
    Mutant("core_max_slips_counted_twice", "exact timing's closed form (E7) after 50 slips, not 100",
           "slips++;", "slips += 2;", file=CORE),
    Mutant("core_periodic_across_sign", "E7's closed form with the part across u turned",
           "+ shrink * q[k];", "- shrink * q[k];", file=CORE),
    Mutant("core_slid_at_zero_cycle", "E7 with a cycle of length 0 taken as periodic",
           "if (!(L > 0.0)) {", "if (!(L >= 0.0)) {", file=CORE),
)

# LIGGGHTS: its host part of the law, liggghts_plugin/tangential_model_stick_slip.h (the
# spring's turn, the trial force, the coefficients per type pair, the history's life)
LIGGGHTS_LAW = "liggghts_plugin/tangential_model_stick_slip.h"
LIGGGHTS_MUTANTS = (
    Mutant("fmin_step_0.3pct", "Fmin off by 0.3 %",
           "const double fmin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]) * fn;",
           "const double fmin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]) * fn * 1.003;"),
    Mutant("fmin_exact_0.3pct", "Fmin off by 0.3 %",
           "kin * fn, kin / ms, reset_total,", "kin * fn * 1.003, kin / ms, reset_total,"),
    Mutant("threshold_unsquared", "> for >= at the threshold",
           "bool slip = StickSlipCore::slips(mag2, limit * limit);", "bool slip = StickSlipCore::slips(mag2, limit);"),
    Mutant("dashpot_sign", "sign error in the dashpot",
           "F[k] = -kt * D[k] - gammat * vs[k];", "F[k] = -kt * D[k] + gammat * vs[k];"),
    Mutant("reset_dashpot_sign", "sign error in the spring reset",
           "const double fdamp[3] = { -gammat * vs[0], -gammat * vs[1], -gammat * vs[2] };",
           "const double fdamp[3] = { gammat * vs[0], gammat * vs[1], gammat * vs[2] };"),
    Mutant("turn_loses_length", "a turned history that loses its length",
           "scale = new2 > 0.0 ? std::sqrt(old2 / new2) : 1.0;", "scale = 1.0;"),
    Mutant("turn_series_loses_length", "a turned history that loses its length",
           "double scale = 1.0 + x * (0.5 + 0.375 * x);", "double scale = 1.0;"),
    Mutant("exact_start_ignored", "exact timing that misses a slip inside the step",
           "slip = StickSlipCore::exact_step(slip, F, D, vs, kt, gammat, dt,",
           "slip = StickSlipCore::exact_step(slip, F, D, vs, kt, gammat, 0.0,"),
    Mutant("mu_s_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "const double ms = mu_s[sidata.itype][sidata.jtype];",
           "const double ms = mu_s[sidata.itype][sidata.itype];"),
    Mutant("mu_k_wrong_pair_step", "a per-type-pair coefficient read from the wrong pair",
           "StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]) * fn;",
           "StickSlipCore::kinetic(ms, mu_k[sidata.jtype][sidata.jtype]) * fn;"),
    Mutant("mu_k_wrong_pair_exact", "a per-type-pair coefficient read from the wrong pair",
           "const double kin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.jtype]);",
           "const double kin = StickSlipCore::kinetic(ms, mu_k[sidata.itype][sidata.itype]);"),
    Mutant("recontact_keeps_spring", "re-contact does not start from a zero spring",
           "if (fresh) D[0] = D[1] = D[2] = 0.0;", ""),
    Mutant("wall_close_keeps_spring", "re-contact does not start from a zero spring",
           "hist[0] = hist[1] = hist[2] = 0.0;", ""),
    Mutant("fn_signed", "|Fn| for a tensile Fn",
           "const double fn = std::fabs(sidata.Fn);", "const double fn = sidata.Fn;"),
) + CORE_MUTANTS

# LAMMPS 2021: the styles' part of the law, lammps_plugin/stick_slip_law.h (the turn, the
# trial force, stock's rescale for reset total), and the pair style's and wall's code around
# it (coefficients per type pair, the history dropped when a contact ends)
LAW_H, PAIR_CPP, WALL_CPP = ("lammps_plugin/stick_slip_law.h", "lammps_plugin/pair_gran_hooke_stickslip.cpp",
                             "lammps_plugin/fix_wall_gran_stickslip.cpp")
LAMMPS_MUTANTS = (
    Mutant("fmin_step_0.3pct", "Fmin off by 0.3 %",
           "drop_to(fs, c.kin * fnabs, std::sqrt(sum),", "drop_to(fs, c.kin * fnabs * 1.003, std::sqrt(sum),"),
    Mutant("fmin_exact_0.3pct", "Fmin off by 0.3 %",
           "c.kin * fnabs, c.ratio, s.reset_total, stick);", "c.kin * fnabs * 1.003, c.ratio, s.reset_total, stick);"),
    Mutant("threshold_unsquared", "> for >= at the threshold",
           "bool slipped = stickslip::StickSlipCore::slips(sum, limit * limit);",
           "bool slipped = stickslip::StickSlipCore::slips(sum, limit);"),
    Mutant("reset_total_sign", "sign error in the spring reset",
           "D[k] = ratio * (D[k] + dv) - dv;", "D[k] = ratio * (D[k] + dv) + dv;"),
    Mutant("dashpot_sign", "sign error in the dashpot",
           "fs[0] = -(kt * D[0] + nu_s * vtr[0]); fs[1] = -(kt * D[1] + nu_s * vtr[1]); "
           "fs[2] = -(kt * D[2] + nu_s * vtr[2]);",
           "fs[0] = -(kt * D[0] - nu_s * vtr[0]); fs[1] = -(kt * D[1] - nu_s * vtr[1]); "
           "fs[2] = -(kt * D[2] - nu_s * vtr[2]);"),
    Mutant("turn_loses_length", "a turned history that loses its length",
           "scale = new2 > 0.0 ? std::sqrt(old2 / new2) : 1.0;", "scale = 1.0;"),
    Mutant("turn_series_loses_length", "a turned history that loses its length",
           "double scale = 1.0 + x * (0.5 + 0.375 * x);", "double scale = 1.0;"),
    Mutant("exact_start_ignored", "exact timing that misses a slip inside the step",
           "const double h = update ? dt : 0.0;", "const double h = 0.0;"),
    Mutant("coeffs_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "tangential_force<Mode>(s, coeffs_i[type[j]],", "tangential_force<Mode>(s, coeffs_i[type[i]],",
           file=PAIR_CPP),
    Mutant("mu_s_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "mu_s = mu_s_given[i][j] >= 0.0 ? mu_s_given[i][j] : xmu;",
           "mu_s = mu_s_given[j][j] >= 0.0 ? mu_s_given[j][j] : xmu;", file=PAIR_CPP),
    Mutant("mu_k_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "mu_k = mu_k_given[i][j] >= 0.0 ? mu_k_given[i][j] :",
           "mu_k = mu_k_given[i][i] >= 0.0 ? mu_k_given[i][i] :", file=PAIR_CPP),
    Mutant("single_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "const Coeffs &c = coeffs[itype][jtype];", "const Coeffs &c = coeffs[itype][itype];", file=PAIR_CPP),
    Mutant("reset_total_ignored_step", "the reset rule `total` ignored",
           "if (!s.reset_total) stickslip::StickSlipCore::reset(fs, nullptr, kt, false, D);",
           "stickslip::StickSlipCore::reset(fs, nullptr, kt, false, D);"),
    Mutant("recontact_keeps_spring_pair", "re-contact does not start from a zero spring",
           "for (int m = 0; m < dnum; m++) hist[m] = 0.0; continue;", "continue;", file=PAIR_CPP),
    # (the end of the statement only: the LAMMPS speed work renames the history array)
    Mutant("recontact_keeps_spring_wall", "re-contact does not start from a zero spring",
           "[m] = 0.0; continue;", "[m] += 0.0; continue;", file=WALL_CPP),
    Mutant("fn_signed", "|Fn| for a tensile Fn",
           "const double fnabs = std::fabs(ccel_r);", "const double fnabs = ccel_r;"),
) + CORE_MUTANTS

# DEM-Engine: the force model deme_model/stick_slip.cu, built on the CPU through its shim
# (deme_model/CMakeLists.txt); the same kinds, found in its own text.
DEME_MUTANTS = (
    Mutant("fmin_0.3pct", "Fmin off by 0.3 %",
           "const float ss_fmin = (2.f * ss_mu_k_c - ss_mu_s_c) * ss_fnabs;",
           "const float ss_fmin = (2.f * ss_mu_k_c - ss_mu_s_c) * ss_fnabs * 1.003f;"),
    Mutant("threshold_gt_step", "> for >= at the threshold",
           "bool ss_slipped = ss_F2 >= ss_T * ss_T;", "bool ss_slipped = ss_F2 > ss_T * ss_T;"),
    Mutant("threshold_gt_exact_start", "> for >= at the threshold",
           "ss_slipped = ss_slipped || dot(ss_F0, ss_F0) >= ss_T * ss_T;",
           "ss_slipped = ss_slipped || dot(ss_F0, ss_F0) > ss_T * ss_T;"),
    Mutant("threshold_gt_exact_loop", "> for >= at the threshold",
           "if (ss_n == 0 && ss_f2 >= ss_T * ss_T) {", "if (ss_n == 0 && ss_f2 > ss_T * ss_T) {"),
    Mutant("reset_spring_sign", "sign error in the spring reset",
           ": ss_F / (-ss_ks_c);", ": ss_F / ss_ks_c;"),
    Mutant("reset_total_sign", "sign error in the spring reset",
           "ss_D = ss_total ? (ss_F + ss_nu_s_c * ss_vs) / (-ss_ks_c)",
           "ss_D = ss_total ? (ss_F - ss_nu_s_c * ss_vs) / (-ss_ks_c)"),
    Mutant("reset_exact_end_sign", "sign error in the spring reset",
           "ss_D = (ss_trial + ss_nu_s_c * ss_vs) / (-ss_ks_c);", "ss_D = (ss_trial - ss_nu_s_c * ss_vs) / (-ss_ks_c);"),
    Mutant("dashpot_sign", "sign error in the dashpot",
           "float3 ss_F = -ss_ks_c * ss_D - ss_nu_s_c * ss_vs;", "float3 ss_F = -ss_ks_c * ss_D + ss_nu_s_c * ss_vs;"),
    Mutant("dashpot_sign_exact_start", "sign error in the dashpot",
           "const float3 ss_F0 = -ss_ks_c * ss_D0 - ss_nu_s_c * ss_vs;",
           "const float3 ss_F0 = -ss_ks_c * ss_D0 + ss_nu_s_c * ss_vs;"),
    Mutant("normal_damping_sign", "sign error in the dashpot",
           "kn[bodyAMatType][bodyBMatType] * ss_delta + ss_nu_n_c * ss_vn",
           "kn[bodyAMatType][bodyBMatType] * ss_delta - ss_nu_n_c * ss_vn"),
    Mutant("turn_loses_length", "a turned history that loses its length",
           "ss_D = ss_D * sqrtf(ss_old2 / ss_new2);", "ss_D = ss_D;"),
    Mutant("exact_misses_whole_cycles", "exact timing that misses a slip inside the step",
           "const float ss_whole = floorf(ss_rest / ss_L);", "const float ss_whole = 0.f;"),
    Mutant("exact_misses_slip_at_start", "exact timing that misses a slip inside the step",
           "ss_slipped = ss_slipped || dot(ss_F0, ss_F0) >= ss_T * ss_T;", "ss_slipped = ss_slipped;"),
    Mutant("exact_slip_late", "exact timing that misses a slip inside the step",
           "ss_dtheta = ss_rate > 0.f ? ss_gap / ss_rate : 2.f;", "ss_dtheta = ss_rate > 0.f ? 1.5f * ss_gap / ss_rate : 2.f;"),
    Mutant("mu_s_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "ss_mu_s_c = mu[bodyAMatType][bodyBMatType];", "ss_mu_s_c = mu[bodyAMatType][bodyAMatType];"),
    Mutant("mu_k_wrong_pair", "a per-type-pair coefficient read from the wrong pair",
           "ss_mu_k_c = mu_k[bodyAMatType][bodyBMatType];", "ss_mu_k_c = mu_k[bodyBMatType][bodyBMatType];"),
    Mutant("mu_k_read_from_mu", "mu_k read from the wrong place",
           "ss_mu_k_c = mu_k[bodyAMatType][bodyBMatType];", "ss_mu_k_c = mu[bodyAMatType][bodyBMatType];"),
    Mutant("mu_k_sweep_read_from_mu_s", "mu_k read from the wrong place",
           ": ss_mu_k[AOwner];", ": ss_mu_s[AOwner];"),
    Mutant("mu_sweep_pair_from_a_only", "a per-owner coefficient read from the wrong body",
           "0.5f * (ss_mu_s[AOwner] + ss_mu_s[BOwner])", "0.5f * (ss_mu_s[AOwner] + ss_mu_s[AOwner])"),
    Mutant("reset_total_ignored_step", "the reset rule `total` ignored",
           "ss_D = ss_total ? (ss_F + ss_nu_s_c * ss_vs) / (-ss_ks_c) : ss_F / (-ss_ks_c);",
           "ss_D = ss_F / (-ss_ks_c);"),
    Mutant("reset_total_ignored_exact", "the reset rule `total` ignored",
           "const float ss_kept = ss_total ? 0.f : ss_nu_s_c * ss_speed;", "const float ss_kept = ss_nu_s_c * ss_speed;"),
    Mutant("flow_ignores_reset_total", "the reset rule `total` ignored",
           "const bool ss_flow_law = ss_r == 1.f && (ss_total || ss_nu_s_c == 0.f);",
           "const bool ss_flow_law = ss_r == 1.f && ss_nu_s_c == 0.f;"),
    Mutant("recontact_keeps_spring", "re-contact does not start from a zero spring",
           "ss_dx = 0.f; ss_dy = 0.f; ss_dz = 0.f; ss_slips = 0.f;", "ss_slips = 0.f;"),
    Mutant("fn_signed", "|Fn| for a tensile Fn",
           "const float ss_fnabs = fabsf(ss_fn);", "const float ss_fnabs = ss_fn;"),
    Mutant("wall_point_not_shifted", "a turning wall's velocity at the contact point, not its surface",
           "ss_cpB = ss_cpB + (0.5f * ss_delta) * ss_nB;", ""),
    Mutant("flow_not_at_right_angle", "E6 (plastic flow) left out at t.u = 0",
           "if (ss_flow_law && ss_tu >= 0.f) {", "if (ss_flow_law && ss_tu > 0.f) {"),
    Mutant("flow_rest_inverted", "E6 (plastic flow) over the wrong share of the step",
           "expf(-ss_rate * ss_rest / ss_T)", "expf(-ss_rate / ss_rest / ss_T)"),
    Mutant("max_slips_counted_twice", "exact timing's closed form (E7) after 50 slips, not 100",
           "ss_n++;", "ss_n += 2;"),
    Mutant("periodic_across_sign", "E7's closed form with the part across u turned",
           "+ ss_shrink * ss_q;", "- ss_shrink * ss_q;"),
    Mutant("slid_at_zero_cycle", "E7 with a cycle of length 0 taken as periodic",
           "if (!(ss_L > 0.f)) {", "if (!(ss_L >= 0.f)) {"),
    Mutant("record_b_force_sign", "a sign error in what the record keeps",
           "ss_rec_fy[BOwner] = -ss_F.y;", "ss_rec_fy[BOwner] = ss_F.y;"),
    Mutant("plane_overlap_engines", "a plane's overlap from the engine's float distance",
           "<= 1e-4 * ss_rad) {", "< 0.0) {"),
    Mutant("plane_normal_not_unit", "a plane's distance along the engine's normal as it is",
           "/ sqrt(ss_nx * ss_nx + ss_ny * ss_ny + ss_nz * ss_nz);", ";"),
    Mutant("plane_area_engines", "a plane's contact area from the engine's float distance",
           "ss_area = deme::PI * (ss_rad * ss_rad - ss_dist * ss_dist);", ""),
    Mutant("cylinder_taken_as_plane", "a cylinder's overlap taken as a plane's",
           "<= 1e-4 * ss_rad) {", "<= 1e30 * ss_rad) {"),
)

# The LAMMPS sub-model: its host part, lammps_plugin/granular/gran_sub_mod_tangential_stick_slip.cpp
# (the turn, the trial force, the rescale, the record), compiled into LAMMPS 4 Feb 2025 (whose
# turn is the sub-model's own arithmetic, where 4 Jul 2026 calls its host's helper).
SUB_CPP, SUB_H = ("lammps_plugin/granular/gran_sub_mod_tangential_stick_slip.cpp",
                  "lammps_plugin/granular/gran_sub_mod_tangential_stick_slip.h")
LAMMPS_GRANULAR_MUTANTS = (
    Mutant("fmin_0.3pct", "Fmin off by 0.3 %",
           "dt, Fscrit, fncrit * kin, ratio, reset_total, stick);",
           "dt, Fscrit, fncrit * kin * 1.003, ratio, reset_total, stick);"),
    Mutant("rescale_fmin_0.3pct", "Fmin off by 0.3 %",
           "StickSlipCore::drop_to(F, fncrit * kin, magfs,", "StickSlipCore::drop_to(F, fncrit * kin * 1.003, magfs,"),
    Mutant("dashpot_sign", "sign error in the dashpot",
           "for (int i = 0; i < 3; i++) F[i] = -ks * D[i] + fdamp[i];",
           "for (int i = 0; i < 3; i++) F[i] = -ks * D[i] - fdamp[i];"),
    Mutant("exact_start_ignored", "exact timing that misses a slip inside the step",
           "const double dt = update ? gm->dt : 0.0, mag2 = lensq3(F);",
           "const double dt = 0.0, mag2 = lensq3(F);"),
    Mutant("turn_loses_length", "a turned history that loses its length",
           "scale3(prjmag > 0 ? shrmag / prjmag : 0, v);", ""),
    Mutant("total_name_wrong_class", "the reset rule `total` ignored",
           "GranSubModStyle(stick_slip/total,GranSubModStickSlipTotal,TANGENTIAL);",
           "GranSubModStyle(stick_slip/total,GranSubModTangentialStickSlip,TANGENTIAL);", file=SUB_H),
    Mutant("exact_name_wrong_class", "exact timing that misses a slip inside the step",
           "GranSubModStyle(stick_slip/exact/record,GranSubModStickSlipExactRecord,TANGENTIAL);",
           "GranSubModStyle(stick_slip/exact/record,GranSubModStickSlipRecord,TANGENTIAL);", file=SUB_H),
    Mutant("slip_counted_twice", "a wrong slip count in the record",
           "if (slipped) history[HIST_NSLIP] += 1.0;", "if (slipped) history[HIST_NSLIP] += 2.0;"),
    Mutant("record_fn_unsigned_damping", "the record's Fn not the one applied",
           "history[HIST_FN] = gm->Fntot;", "history[HIST_FN] = gm->Fnormal;"),
    Mutant("mixed_mu_from_one_side", "a per-type-pair coefficient read from the wrong pair",
           "coeffs[i] = mix_geom(icoeffs[i], jcoeffs[i]);", "coeffs[i] = mix_geom(icoeffs[i], icoeffs[i]);"),
    Mutant("slips_negated_across", "a wrong slip count in the record",
           "transfer_history_factor[HIST_FN] = transfer_history_factor[HIST_NSLIP] = 1.0;",
           "transfer_history_factor[HIST_FN] = 1.0;"),
    Mutant("work_negated_across", "a wrong dissipated work in the record",
           "transfer_history_factor[HIST_WORK] = 1.0;", ""),
    Mutant("history_transfer_default", "the spring seen from the other grain with the record's values negated",
           "nondefault_history_transfer = 1;", "nondefault_history_transfer = 0;"),
) + CORE_MUTANTS


def build_lammps_2025(src: Path, out: Path, quick=True, cmake_args=()):
    """The sub-model's files in `src` compiled into a copy of LAMMPS 2025's source (made once
    beside `out` from ./run.sh setup's, build/lammps_2025/source), built in `out`: Release
    always (after the first build a mutant recompiles one file and relinks, ~10 s)."""
    lammps = out.parent / "lammps-source"
    if not (lammps / ".complete").exists():
        shutil.rmtree(lammps, ignore_errors=True)
        shutil.copytree(REPO / "build" / "lammps_2025" / "source", lammps)
    for f in [*src.iterdir(), src.parent.parent / CORE]:  # (the copies keep the repository's layout)
        target = lammps / "src" / "GRANULAR" / f.name
        if not target.exists() or target.read_bytes() != f.read_bytes():
            shutil.copy(f, target)
    if not (out / "CMakeCache.txt").exists():
        subprocess.run(["cmake", "-S", str(lammps / "cmake"), "-B", str(out), "-C",
                        str(lammps / "cmake" / "presets" / "all_off.cmake"), "-D", "PKG_GRANULAR=on", "-D", "PKG_PLUGIN=on",
                        "-D", "BUILD_MPI=on", "-D", "BUILD_SHARED_LIBS=on", "-D", "LAMMPS_EXCEPTIONS=on",
                        "-D", "BUILD_OMP=off", "-D", "CMAKE_BUILD_TYPE=Release"], check=True, capture_output=True)
    proc = subprocess.run(["cmake", "--build", str(out), "-j", "2"], capture_output=True, text=True)
    return proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]


# YADE's compiled law: its host part, yade_law/compiled/StickSlipPM.cpp (the normal force, the
# lever arms, the turn of the spring, the trial force, the record), built against Debian's YADE
# with the headers ./run.sh setup extracted
YADE_CPP = "yade_law/compiled/StickSlipPM.cpp"
YADE_CPP_MUTANTS = (
    Mutant("yade_turn_loses_length", "a turned history that loses its length",
           "if (new2 > 0) D *= std::sqrt(old2 / new2);", ""),
    Mutant("yade_dashpot_sign", "sign error in the dashpot", "F                   = -ks * D - nu_s * Vs;",
           "F                   = -ks * D + nu_s * Vs;"),
    Mutant("yade_fmin_0.3pct", "Fmin off by 0.3 %", "const Real fmin     = Core::kinetic(mu_s, phys.mu_k) * fn;",
           "const Real fmin     = Core::kinetic(mu_s, phys.mu_k) * fn * 1.003;"),
    Mutant("yade_lever_arm_radius", "lever arms at the radius, not midway in the overlap",
           "const Real half = 0.5 * delta;", "const Real half = 0.0;"),
    Mutant("yade_wall_point_centre", "a wall's velocity taken at its centre, not at its surface",
           "a1 = (s2.pos + shift2 - (r2 - delta) * n) - s1.pos;", "a1 = Vector3r::Zero();"),
    Mutant("yade_shift_velocity_sign", "the periodic image's velocity with the wrong sign",
           "vrel = s1.vel - s2.vel - shiftVel;", "vrel = s1.vel - s2.vel + shiftVel;"),
    Mutant("yade_spring_kept_at_zero_overlap", "a contact at zero overlap keeps its spring",
           "D = F = Vector3r::Zero();", "F = Vector3r::Zero();"),
    Mutant("yade_slip_counted_twice", "a wrong slip count in the record", "phys.slips++;", "phys.slips += 2;"),
    Mutant("yade_no_law_torque", "the law's torque left out",
           "addTorque(id1, -c1x.cross(phys.normalForce) + a1.cross(F), scene);",
           "addTorque(id1, -c1x.cross(phys.normalForce), scene);"),
    Mutant("yade_setup_step_loads", "the set-up evaluation loads the springs",
           "const Real dt = scene->iter == setupIter ? Real(0) : scene->dt;", "const Real dt = scene->dt;"),
    Mutant("yade_nan_passes", "a non-finite contact that does not stop the run",
           "if (!std::isfinite(static_cast<double>(fn + F[0] + F[1] + F[2]))) {", "if (false) {"),
) + CORE_MUTANTS


def build_yade_law(src: Path, out: Path, quick=True, cmake_args=()):
    """The compiled YADE law in `src` (yade_law/compiled with law_core beside it) built in `out`
    against the headers ./run.sh setup extracted (build/yade_source/src): Release always (the
    suite's YADE scenes are short; a mutant recompiles one file, ~2 min on 2 cores)."""
    headers = REPO / "build" / "yade_source" / "src"
    if not (out / "CMakeCache.txt").exists():
        subprocess.run(["cmake", "-S", str(src), "-B", str(out), "-DCMAKE_BUILD_TYPE=Release",
                        f"-DYADE_SOURCE={headers}"], check=True, capture_output=True, text=True)
    proc = subprocess.run(["cmake", "--build", str(out), "-j", "2"], capture_output=True, text=True)
    return proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]


ENGINES = {
    "yade_cpp": Engine(
        source="yade_law/compiled", law_file=YADE_CPP, build_env="STICKSLIP_YADE_LAW_BUILD",
        fast=("tests/test_law_contract.py", "-k", "yade_cpp"),
        wide=("tests/test_yade_compiled.py", "tests/test_law_contract.py", "-k", "yade_cpp or compiled"),
        mutants=YADE_CPP_MUTANTS, builder=build_yade_law, copies=("law_core",)),
    "lammps_granular": Engine(
        source="lammps_plugin/granular", law_file=SUB_CPP, build_env="STICKSLIP_LAMMPS_GRANULAR",
        fast=("tests/test_law_contract.py", "-k", "lammps_granular"),
        wide=("tests/test_lammps_granular.py", "tests/test_lammps_granular_dropin.py",
              "tests/test_lammps_granular_restart.py"),
        mutants=LAMMPS_GRANULAR_MUTANTS, builder=build_lammps_2025),
    "liggghts": Engine(
        source="liggghts_plugin", law_file=LIGGGHTS_LAW, build_env="STICKSLIP_LIGGGHTS_BUILD",
        fast=("tests/test_law_contract.py", "-k", "liggghts"),
        wide=("tests/test_liggghts_plugin.py", "tests/test_liggghts_engine.py", "tests/test_liggghts_dropin.py",
              "tests/test_stability_engines.py", "tests/test_drum.py", "tests/test_precision.py",
              "-k", "liggghts"),
        mutants=LIGGGHTS_MUTANTS),
    "lammps": Engine(
        source="lammps_plugin", law_file=LAW_H, build_env="STICKSLIP_LAMMPS_BUILD",
        fast=("tests/test_law_contract.py", "-k", "lammps and not lammps_granular"),
        wide=("tests/test_lammps_plugin.py", "tests/test_lammps_engine.py", "tests/test_lammps_dropin.py",
              "tests/test_lammps_mpi.py", "tests/test_lammps_region_wall.py", "tests/test_lammps_restart.py",
              "tests/test_stability_engines.py", "tests/test_translating_wall.py", "-k", "lammps and not lammps_granular"),
        mutants=LAMMPS_MUTANTS,
        # the LAMMPS headers ./run.sh setup extracted (CMakeLists' default is relative to its source)
        cmake_args=(f"-DLAMMPS_HEADERS={REPO / 'build' / 'lammps_headers' / 'src'}",)),
    "deme": Engine(
        source="deme_model", law_file="deme_model/stick_slip.cu", build_env="STICKSLIP_DEME_SHIM_BUILD", copies=(),
        fast=("tests/test_deme_shim.py",),
        wide=("tests/test_deme_shim.py", "tests/test_deme_adapter.py"),
        mutants=DEME_MUTANTS),
}


def pattern(text):
    """`text` as a regular expression in which any run of whitespace matches any other."""
    return re.compile(r"\s*".join(re.escape(part) for part in text.split()))


def apply(source: str, m: Mutant) -> str:
    """The source with the mutant applied; ValueError (the summary's ERROR) when its text is
    not found exactly m.count times."""
    found = pattern(m.find).findall(source)
    if len(found) != m.count:
        raise ValueError(f"text found {len(found)} times, expected {m.count}: {m.find!r}")
    return pattern(m.find).sub(lambda _: m.replace, source)


def build_with_cmake(src: Path, out: Path, quick=True, cmake_args=()):
    """Configure (once) and build `src` into `out`: -O0 (quick) or Release."""
    if not (out / "CMakeCache.txt").exists():
        kind = ["-DCMAKE_BUILD_TYPE=MutantO0", "-DCMAKE_CXX_FLAGS_MUTANTO0=-O0"] if quick else \
            ["-DCMAKE_BUILD_TYPE=Release"]
        subprocess.run(["cmake", "-S", str(src), "-B", str(out), *kind, *cmake_args], check=True, capture_output=True,
                       text=True)
    proc = subprocess.run(["cmake", "--build", str(out), "-j", "2"], capture_output=True, text=True)
    return proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]


def run_tests(args, env, jobs):
    """pytest on a selection; returns (passed, the failing tests' names, seconds)."""
    t0 = time.perf_counter()
    cmd = [str(PYTHON), "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", "-n", str(jobs), *args]
    proc = subprocess.run(cmd, cwd=REPO, env=env, capture_output=True, text=True)
    failed = sorted(set(re.findall(r"^FAILED (\S+)", proc.stdout, re.M) + re.findall(r"^ERROR (\S+)", proc.stdout, re.M)))
    return proc.returncode == 0, failed, time.perf_counter() - t0, proc.stdout[-1500:]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--engine", choices=sorted(ENGINES), default="liggghts")
    ap.add_argument("--only", nargs="+", help="mutant ids to run (default: all)")
    ap.add_argument("--wide", action="store_true", help="run the wide selection for every mutant")
    ap.add_argument("--jobs", type=int, default=2, help="pytest-xdist workers (default 2)")
    args = ap.parse_args(argv)
    eng = ENGINES[args.engine]
    mutants = [m for m in eng.mutants if not args.only or m.id in args.only]
    work = REPO / "build" / "mutants" / args.engine
    # the copies keep the repository's layout (the LIGGGHTS plugin reaches the core at ../law_core)
    root, out, out_release = work / "src", work / "build", work / "build-release"
    if eng.builder is not None:  # (one build serves both selections)
        out_release = out
    build = eng.builder or build_with_cmake
    if root.exists():
        shutil.rmtree(root)
    for folder in (eng.source, *eng.copies):
        # copied with new times (shutil.copy): a build left by an interrupted run holds a
        # mutant's objects, newer than the repository's files, that make would keep
        if (REPO / folder).is_file():
            (root / folder).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(REPO / folder, root / folder)
        else:
            shutil.copytree(REPO / folder, root / folder, dirs_exist_ok=True, copy_function=shutil.copy)
    src = root / eng.source
    originals = {f: (root / f).read_text() for f in {m.file or eng.law_file for m in mutants}}
    env = dict(os.environ, **{eng.build_env: str(out)})
    env_release = dict(os.environ, **{eng.build_env: str(out_release)})
    t_start = time.perf_counter()

    # every mutant's text must be found before anything is built
    results, texts = [], {}
    for m in mutants:
        file = m.file or eng.law_file
        try:
            texts[m.id] = (file, apply(originals[file], m))
        except ValueError as e:
            results.append((m, "ERROR", f"{file}: {e}", 0.0))
    quick = dict(cmake_args=eng.cmake_args)
    release = dict(quick=False, cmake_args=eng.cmake_args)
    ok, log = build(src, out, **quick)
    if not ok:
        sys.exit(f"mutate_cpp: the unmutated source does not build:\n{log}")
    passed, failed, secs, tail = run_tests(eng.fast, env, args.jobs)
    if not passed:
        sys.exit(f"mutate_cpp: the unmutated build fails the fast selection ({failed}):\n{tail}")
    print(f"baseline: built and passed the fast selection in {secs:.0f} s", flush=True)
    try:
        for m in mutants:
            if m.id not in texts:
                continue
            for file, text in originals.items():  # (the last mutant's file back as it was)
                (root / file).write_text(text)
            file, text = texts[m.id]
            (root / file).write_text(text)
            t0 = time.perf_counter()
            ok, log = build(src, out, **quick)
            if not ok:
                results.append((m, "killed", "does not compile", time.perf_counter() - t0))
                continue
            passed, failed, _, _ = run_tests(eng.fast, env, args.jobs)
            verdict, by = ("killed", "fast: " + ", ".join(failed)) if not passed else ("survived", "")
            if args.wide or passed:
                ok, log = build(src, out_release, **release)
                if not ok:
                    sys.exit(f"mutate_cpp: {m.id} builds at -O0 but not in Release:\n{log}")
                wide_passed, wide_failed, _, _ = run_tests(eng.wide, env_release, args.jobs)
                if not wide_passed:
                    verdict, by = "killed", (by + "; " if by else "") + "wide: " + ", ".join(wide_failed)
            results.append((m, verdict, by, time.perf_counter() - t0))
            print(f"{m.id:28s} {verdict:8s} {time.perf_counter() - t0:5.0f} s  {by}", flush=True)
    finally:
        for file, text in originals.items():
            (root / file).write_text(text)
        build(src, out, **quick)  # leave the copies built as the repository's source
        if out_release.exists():
            build(src, out_release, **release)
    killed = sum(1 for _, v, _, _ in results if v == "killed")
    errors = [r for r in results if r[1] == "ERROR"]
    print(f"\n{args.engine}: {killed} of {len(results) - len(errors)} mutants killed, "
          f"{len(results) - len(errors) - killed} survived, {len(errors)} not found (ERROR); "
          f"{time.perf_counter() - t_start:.0f} s")
    print("| mutant | kind | result | killed by |\n|---|---|---|---|")
    for m, verdict, by, _ in results:
        print(f"| {m.id} | {m.kind} | {verdict} | {by} |")
    return 2 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
