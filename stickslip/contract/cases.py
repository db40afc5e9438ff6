# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's contract (docs/law.md) as a table of one-contact cases, the same on every engine.

Each case holds one contact still (positions and velocities prescribed, nothing
integrated) for a few steps, so that the law alone decides what happens, with numbers
chosen to be exact in binary: Fn = kn*delta = 32 * (1/32) = 1, Ks = 1, dt = 1/16 and
a sliding velocity V whose increment per step, w = V*dt, has exact components. Every
force and spring is then a multiple m*w of that increment (the law only adds w's,
halves or compares them), and the expected multiples are worked out by hand below
from docs/law.md, case by case. They are compared to the ulp: `exact` cases must be
equal bit for bit (every operation on their path is exact), the others within the
ulps stated with their reason.

Geometry (docs/law.md step 1; the normal n points from grain i to j):
- "wall": grain i (radius 1/2) on the floor z = 0, its centre at z = 1/2 - delta;
  n = -z, and its velocity is V (tangential) plus -v_n along z (v_n > 0 closing);
- "pair": grain i at (-d/2, 0, 0), grain j at (+d/2, 0, 0), d = 1 - delta, j at rest;
  n = +x, i moves at V (+ v_n along x).

Engines: stickslip/contract/runners.py has one function per engine that runs a case and
returns what the contact recorded each step (a trace: empty_trace). YADE runs pyref's kernel itself
(yade_law/stickslip_yade/kernel.py imports pyref/laws.py), so it has no entry of its
own: its checks are of its geometry and integration, the law's are pyref's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

R = 0.5  # grain radius (diameter 1)
DELTA = 1.0 / 32  # overlap (scenes refuse overlaps above 0.1 r; 1/32 < 0.05)
KN = 32.0  # Fn = KN*DELTA = 1 exactly
KS = 1.0
DT = 1.0 / 16
DIAGONAL = (3.0 / 16, 4.0 / 16, 0.0)  # |V| = 5/16: w = V dt = (3, 4, 0)/256, |w| = 5/256 exactly
ALONG_X = (4.0 / 16, 0.0, 0.0)  # w = (1/64, 0, 0)
EPS = np.finfo(float).eps


@dataclass(frozen=True)
class Segment:
    """`steps` steps of one state: overlap, velocity of i (j and the wall are still),
    and a rigid turn of the pair about z through its middle at `omega` rad/s (i and j then
    move with it and spin at omega: V_s = 0)."""
    steps: int
    velocity: tuple = ALONG_X
    delta: float = DELTA  # <= 0: apart
    omega: float = 0.0


@dataclass(frozen=True)
class Expect:
    """What the contact holds at the end of a step: Fn, the force on i and the spring as
    multiples of w (F = -f*w, D = d*w; vectors directly when given as tuples), and the
    number of steps that slipped since the contact began. `tol`: an absolute bound for this
    step, derived where it is set, instead of the case's ulps."""
    fn: float
    f: float | tuple
    d: float | tuple
    slips: int
    tol: float | None = None


@dataclass(frozen=True)
class Case:
    name: str
    claim: str  # the line of docs/law.md it pins
    geometry: str  # wall | pair
    segments: tuple
    mu_s: float
    mu_k: float
    nu_s: float = 0.0
    nu_n: float = 0.0
    reset: str = "spring"
    timing: str = "step"
    ulps: int = 0  # 0: bit for bit
    why_ulps: str = ""
    only: tuple = ()  # engines the case applies to (empty: all); see NOT_APPLICABLE

    @property
    def steps(self):
        return sum(s.steps for s in self.segments)


def tangential(case, velocity):
    """The part of i's velocity in the tangent plane (the wall's normal is z, the pair's x)."""
    return (velocity[0], velocity[1], 0.0) if case.geometry == "wall" else (0.0, velocity[1], velocity[2])


def w_of(velocity):
    return np.array(velocity) * DT


def rest_positions(case, delta):
    """The places of the case's grains at overlap `delta` (the module's docstring, Geometry)."""
    if case.geometry == "wall":
        return np.array([[0.0, 0.0, R - delta]])
    d = 2 * R - delta
    return np.array([[-d / 2, 0.0, 0.0], [d / 2, 0.0, 0.0]])


def state(case, seg, k_in_seg, start):
    """Positions, velocities and spins of the case's grains at step k_in_seg (1-based) of a
    segment; `start` holds the positions the segment starts from (a turn starts where the
    grains are)."""
    if seg.omega:
        a = seg.omega * DT * k_in_seg
        c, s = math.cos(a), math.sin(a)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        x = start @ rot.T
        spin = np.array([0.0, 0.0, seg.omega])
        v = np.cross(spin, x)
        return x, v, np.tile(spin, (len(x), 1))
    v = np.zeros((len(start), 3))
    v[0] = seg.velocity
    return rest_positions(case, seg.delta), v, np.zeros((len(start), 3))


def sawtooth(first_loaded, start, slips_at, fmin, dashpot, reset, n, f_at_slip=None):
    """Step timing, straight-line loading by one w a step (docs/law.md steps 3-5): the
    spring holds `start` + k (k steps into the phase), the trial force spring + dashpot;
    at the steps in `slips_at` (worked out by hand: where the trial force first reaches
    mu_s Fn) the force is Fmin and the spring is reset to Fmin (reset spring) or
    Fmin - dashpot (reset total). Returns Expect for steps first_loaded..n."""
    out, d, slips = [], start, 0
    for k in range(first_loaded, n + 1):
        d += 1
        if k in slips_at:
            slips += 1
            f = fmin if f_at_slip is None else f_at_slip
            d = fmin if reset == "spring" else fmin - dashpot
        else:
            f = d + dashpot
        out.append(Expect(1.0, f, d, slips))
    return out


# ----------------------------------------------------------------- the cases
# In units of w (|w| = 5/256 along DIAGONAL, 1/64 along x): T = mu_s Fn / |w| and
# Fmin = (2 mu_k - mu_s) Fn / |w|. The diagonal cases use T = 24, Fmin = 12: the slip's
# rescaling Fmin/|F_t| is then 1/2, exact.
D24 = 24 * 5 / 256  # mu_s with T = 24 w-units on the diagonal (= 15/32)
D_MU_K = 18 * 5 / 256  # mu_k with Fmin = 2*18 - 24 = 12 units (= 45/128)
X = 1 / 64  # |w| along x


def _cases():
    cases = []
    # |F_t| reaches mu_s Fn exactly at step 24 (24 w): it slips (>=), force Fmin = 12 w
    # along the trial force, spring reset to Fmin; then 12 more steps to the next slip.
    cases.append(Case("threshold_reached_slips", "step 5: slip if |F_t| >= mu_s Fn; F_s = Fmin t; eq. 8 (spring)",
                      "wall", (Segment(40, DIAGONAL),), D24, D_MU_K,
                      ))
    # mu_s one ulp above 15/32: |F_t| = 24 w is one ulp below the threshold: it sticks at
    # 24 and slips at 25 (Fmin = 2 mu_k - mu_s then is 12 w less an ulp, and 25 w times
    # Fmin/25w rounds: 2 ulps, one for the quotient and one for the product).
    cases.append(Case("one_ulp_below_threshold_sticks", "step 5: |F_t| < mu_s Fn sticks, to the last ulp",
                      "wall", (Segment(26, DIAGONAL),), math.nextafter(D24, 1.0), D_MU_K, ulps=2,
                      why_ulps="the slip at 25 w rescales by Fmin/|F_t|, not a power of 2: "
                               "one rounding in the quotient, one in the product"))
    # Dashpot nu_s V = 4 w (nu_s = 1/4): the trial force k + 4 reaches 24 at step 20.
    # reset spring: spring 12, next trial 12 + j + 4 -> 24 at j = 8 (step 28);
    # reset total: spring 12 - 4 = 8, next 8 + j + 4 -> 24 at j = 12 (step 32).
    for reset, n in (("spring", 30), ("total", 34)):
        cases.append(Case(f"reset_{reset}_after_slip_step_timing", f"step 5 (eq. 8, reset {reset}), step timing",
                          "wall", (Segment(n, DIAGONAL),), D24, D_MU_K, nu_s=0.25, reset=reset))
    # Exact timing, the threshold met exactly at the end of step 20 (E2: dtheta = 1):
    # the slip restarts the trial force at Fmin + kept (E3), kept = nu_s|V| = 4 (spring)
    # or 0 (total), with no time left: applied force 16 (spring) or 12 (total), spring 12
    # or 8 (the trial force less the dashpot). Along x, where t = F/|F| = -x is exact.
    for reset, n in (("spring", 30), ("total", 34)):
        cases.append(Case(f"reset_{reset}_after_slip_exact_timing", f"E2-E3, E7 (reset {reset}), exact timing",
                          "wall", (Segment(n, ALONG_X),), 24 * X, 18 * X, nu_s=0.25, reset=reset, timing="exact"))
    # Exact timing, a slip inside the step: T = 24.25, Fmin = 12 (mu_k = 18.125 w).
    # Without dashpot: step 25 goes from 24 to 25, crossing T at theta = 1/4; the force
    # restarts at 12 and loads for 3/4: 12.75. Next: 24.25 - 12.75 = 11.5 steps, inside
    # step 37 at theta = 1/2: 12.5.
    for nu_s, reset, n in ((0.0, "spring", 38), (0.25, "spring", 30), (0.25, "total", 34)):
        label = "no_dashpot" if nu_s == 0 else f"reset_{reset}"
        cases.append(Case(f"slip_inside_step_exact_timing_{label}", "E2-E3, E7: the slip at its time inside the step",
                          "wall", (Segment(n, ALONG_X),), 24.25 * X, 18.125 * X, nu_s=nu_s, reset=reset,
                          timing="exact"))
    # Exact timing, a step that starts at the threshold (E0, E2: "at once"): 18 steps load
    # the spring to 18 (T = 24, Fn = 1), then Fn falls to 3/4 (T = 18: the trial force is
    # at it) and the grain turns back: the trial force would fall to 17 by the step's end
    # (the step timing sees no slip), but it slips at theta = 0 to Fmin = 9 along its
    # direction, then unloads by 1 a step: 8, 7, 6 (the spring, -x of the force, follows).
    cases.append(Case("slip_at_step_start_exact_timing", "E0, E2: |F_0| >= mu_s Fn slips at once",
                      "wall", (Segment(18, ALONG_X), Segment(3, (-0.25, 0.0, 0.0), delta=3.0 / 128)),
                      24 * X, 18 * X, timing="exact"))
    # Exact timing, several slips in one step (E7's whole cycles): T = 20, Fmin = 12
    # (mu_k = 16 w) and 32 w a step along x. Step 1 loads from 0 to T at theta = 20/32 =
    # 5/8, then cycles of 8/32 = 1/4 of a step: one whole, and 1/8 left: 12 + 4 = 16.
    # Every later step starts at 16, slips at 1/8 and ends the same way: 16.
    cases.append(Case("several_slips_in_a_step_exact_timing", "E7: the rest of the step in whole cycles",
                      "wall", (Segment(4, (8.0, 0.0, 0.0)),), 20 * X, 16 * X, timing="exact"))
    # The same at 64 w a step (rate = Ks |V| dt = 1 exactly, a value no other test has):
    # step 1 meets T at 20/64 = 5/16, then cycles of 8/64 = 1/8: five whole and 1/16 left,
    # 12 + 4 = 16; every later step starts at 16, slips at 1/16 and ends at 16 again.
    cases.append(Case("several_slips_in_a_step_rate_one_exact_timing", "E7: the rest of the step in whole cycles",
                      "wall", (Segment(4, (16.0, 0.0, 0.0)),), 20 * X, 16 * X, timing="exact"))
    # Exact timing with mu_k = mu_s and no dashpot (E6, plastic flow): 24 steps along +x
    # load the spring to T (the 24th slips at its very end, with no time left), then the
    # grain slides along (3, 4)/5: the force stays on |F| = T and turns towards u = -V/|V|,
    # tan(phi/2) falling by exp(-Ks|V|dt/T) over the step (phi: from F to u).
    cases.append(Case("plastic_flow_exact_timing", "E6: mu_k = mu_s, the force turns on |F| = T",
                      "wall", (Segment(24, ALONG_X), Segment(1, DIAGONAL)), 24 * X, 24 * X, timing="exact",
                      ulps=16, why_ulps="an exponential and a dozen roundings on the turned force's path"))
    # The same turn from a force at T across u (t.u = 0 exactly: loaded along x, then sliding
    # along y): |F + rate theta u| rises above T at once, so it flows from phi = 90 degrees
    # (E6 with t.u >= 0), tan(phi/2) from 1 to exp(-rate/T).
    cases.append(Case("plastic_flow_across_exact_timing", "E6 at t.u = 0: the force flows from 90 degrees",
                      "wall", (Segment(24, ALONG_X), Segment(1, (0.0, 0.25, 0.0))), 24 * X, 24 * X, timing="exact",
                      ulps=16, why_ulps="an exponential and a dozen roundings on the turned force's path"))
    # E6 with a dashpot and reset total (kept = 0), the slip inside the step: nu_s V = 4 w
    # (nu_s = 1/4), the trial force k + 4 meets T = 24 at the end of step 20 (slips, F = T
    # along -x, spring 20); then the diagonal step meets T at theta = 0.71 and flows for the
    # rest (see _flow_after_hit).
    cases.append(Case("plastic_flow_reset_total_inside_step_exact_timing",
                      "E6 with reset total and a dashpot; the flow over the rest of the step after a slip inside it",
                      "wall", (Segment(20, ALONG_X), Segment(1, DIAGONAL)), 24 * X, 24 * X, nu_s=0.25, reset="total",
                      timing="exact", ulps=32,
                      why_ulps="a square root with cancellation (the slip's theta, 20 eps relative), an exponential "
                               "and a dozen roundings on the turned force's path"))
    # E7 after MAX_EXPLICIT_SLIPS slips with a part q across u (docs/law.md E7: the rest of
    # the step in closed form, q shrinking by r a slip). mu_s = 1/2, Fmin = 15/32 (r = 15/16,
    # q not settled after 100 slips: (15/16)^100 q0 = 4e-4 > 1e-8 T): the spring loaded along
    # x to 1/4 (16 steps), then one step along y at rate = Ks |V| dt = 4, ~110 slips in it.
    # Without dashpot the rest is periodic with r^n q (see _max_slips_step); with a dashpot
    # that restarts each slip at exactly T along u (kept = nu_s |V| = T - Fmin = 1/32) the
    # force after each slip stays below T while t != u (|F|^2 = T^2 - 2 Fmin kept (1 - t.u)),
    # so no E4: after 100 slips L = (T - Fmin - kept)/rate = 0 and the contact slides (E7).
    for label, nu_s in (("periodic", 0.0), ("slides", 1.0 / 2048)):
        cases.append(Case(f"max_explicit_slips_{label}_exact_timing",
                          "E7 after MAX_EXPLICIT_SLIPS slips, q not settled: " +
                          ("r^n q in closed form" if nu_s == 0 else "L = 0: slides at Fmin"),
                          "wall", (Segment(16, ALONG_X), Segment(1, (0.0, 64.0, 0.0))), 0.5, 31.0 / 64,
                          nu_s=nu_s, timing="exact"))
    # Exact timing, the dashpot's sliding regime (E4): nu_s V = 16 w with T = 24, Fmin = 12
    # (reset spring): the trial force k + 16 reaches T at the end of step 8; restarted at
    # Fmin + kept = 28 >= T it slides: applied Fmin = 12 along -V, spring 28 - 16 = 12, and
    # so every later step (the step timing's result too: slides at Fmin).
    cases.append(Case("dashpot_keeps_it_sliding_exact_timing", "E4: restarted above T, slides at Fmin",
                      "wall", (Segment(12, ALONG_X),), 24 * X, 18 * X, nu_s=1.0, timing="exact"))
    # Exact timing, nothing moving (E5): 18 steps load the spring to 18 (T = 24), then the
    # grain stops and Fn falls to 3/4 (T = 18, the force is at it): it slips at once to
    # Fmin = 9 and, with no motion, stays there.
    cases.append(Case("slip_without_motion_exact_timing", "E5: rate = 0, the force stays where the slip left it",
                      "wall", (Segment(18, ALONG_X), Segment(3, (0.0, 0.0, 0.0), delta=3.0 / 128)),
                      24 * X, 18 * X, timing="exact"))
    # Fn = 0 (step 2: never tensile). kn delta + nu_n v_n with v_n = -1/2 (grain leaving):
    # nu_n = 2 gives 1 - 1 = 0 exactly, nu_n = 4 gives -1, clipped to 0. No friction:
    # every step slips (0 >= 0), force 0, spring reset: 0 (spring) or -nu_s V/Ks (total:
    # spring + dashpot = Fmin = 0), in both timings (E1).
    for nu_n, reset, timing in ((2.0, "spring", "step"), (4.0, "total", "step"), (2.0, "total", "exact"),
                                (4.0, "spring", "exact")):
        # (along x in the exact timing, where E1's -kept u - nu_s V cancels exactly)
        leaving = (DIAGONAL if timing == "step" else ALONG_X)[:2] + (0.5,)
        cases.append(Case(f"fn_zero_nu_n_{nu_n:g}_{reset}_{timing}", "step 2 (Fn >= 0), step 5 / E1: Fn = 0 slips",
                          "wall", (Segment(3, leaving),), D24, D_MU_K, nu_s=0.25, nu_n=nu_n, reset=reset,
                          timing=timing))
    # Fn = 0 and nothing moving along the plane: |F_t| = 0 >= 0 = mu_s Fn: still a slip.
    cases.append(Case("fn_zero_no_sliding_still_slips", "step 5: 'also when Fn = 0' (0 >= 0)",
                      "wall", (Segment(3, (0.0, 0.0, 0.5)),), D24, D_MU_K, nu_n=2.0))
    # A stuck pair turning rigidly: 4 steps load the spring along y (d = 4 w, w = (0, 1/64,
    # 0)), then the pair turns about z (V_s = 0): D is turned into each new tangent plane
    # keeping its length (step 3). Two rates: 0.01 rad a step (the engines' general
    # path) and 1e-4 (LIGGGHTS' series path for small turns).
    for tag, per_step in (("fast", 0.01), ("slow", 1e-4)):
        cases.append(Case(f"stuck_pair_turning_keeps_length_{tag}", "step 3: D turned into the tangent plane, |D| kept",
                          "pair", (Segment(4, (0.0, 0.25, 0.0)), Segment(100, (0.0, 0.0, 0.0), omega=per_step / DT)),
                          0.5, 0.375, ulps=-1,
                          why_ulps="positions of a turning pair are rounded: |D| and D.n checked to a "
                                   "round-off bound (see check_turning)"))
    # A contact that ends and is made again starts from a zero spring (step 3): 10 steps
    # touching (spring 10 w), one step apart, 5 touching (spring 1..5 w, no slip).
    for geometry, v in (("wall", DIAGONAL), ("pair", (0.0, 3.0 / 16, 4.0 / 16))):
        gap = -1.0 / 16
        cases.append(Case(f"recontact_starts_from_zero_{geometry}", "step 3: D dropped when the contact ends",
                          geometry, (Segment(10, v), Segment(1, v, delta=gap), Segment(5, v)), D24, D_MU_K))
    return cases


CASES = _cases()


def expected(case: Case, dtype=np.float64):
    """Per step (1..steps): Expect, or None where the contact is apart (not compared).
    dtype: the engine's floating type (its rounding sets the bound of _max_slips_step)."""
    n = case.steps
    name = case.name
    if name == "threshold_reached_slips":
        return sawtooth(1, 0, {24, 36}, 12, 0, "spring", n)
    if name == "one_ulp_below_threshold_sticks":
        fmin = (2 * case.mu_k - case.mu_s) / (5 / 256)  # 12 w less an ulp of the force
        return sawtooth(1, 0, {25}, fmin, 0, "spring", n)
    if name.startswith("reset_") and case.timing == "step":
        return sawtooth(1, 0, {20, 28} if case.reset == "spring" else {20, 32}, 12, 4, case.reset, n)
    if name.startswith("reset_") and case.timing == "exact":
        # the threshold met exactly at the end of the step: the slip restarts the trial
        # force at Fmin + kept with nothing of the step left (E3, E7): applied 16 with
        # reset spring (kept = nu_s|V| = 4), 12 with total (kept = 0, which is then the
        # step timing's result); the spring holds Fmin (spring) or Fmin - dashpot (total)
        if case.reset == "spring":
            return sawtooth(1, 0, {20, 28}, 12, 4, "spring", n, f_at_slip=16)
        return sawtooth(1, 0, {20, 32}, 12, 4, "total", n)
    if name.startswith("slip_inside_step"):
        return _inside_step(case)
    if name == "dashpot_keeps_it_sliding_exact_timing":
        return sawtooth(1, 0, set(range(8, n + 1)), 12, 16, "spring", n)
    if name == "slip_without_motion_exact_timing":
        still = [Expect(0.75, (9 * X, 0.0, 0.0), (9 * X, 0.0, 0.0), 1) for _ in range(3)]
        return [Expect(1.0, k, k, 0) for k in range(1, 19)] + still
    if name == "several_slips_in_a_step_exact_timing":
        return [Expect(1.0, 0.5, 0.5, k) for k in range(1, n + 1)]  # 16 X = w/2 (w = 32 X)
    if name == "several_slips_in_a_step_rate_one_exact_timing":
        return [Expect(1.0, 0.25, 0.25, k) for k in range(1, n + 1)]  # 16 X = w/4 (w = 64 X)
    if name == "plastic_flow_across_exact_timing":
        # F = -T x at T, u = -y: phi = 90 degrees, tan(phi/2) = 1, the part across u along -x
        T = 24 * X
        F = _flow(T, (0.0, -1.0, 0.0), (-1.0, 0.0, 0.0), 1.0, X / T)
        return [Expect(1.0, k, k, 0) for k in range(1, 24)] + [Expect(1.0, 24, 24, 1),
                                                                Expect(1.0, tuple(-F), tuple(-F), 2)]
    if name == "plastic_flow_reset_total_inside_step_exact_timing":
        loading = [Expect(1.0, k + 4, k, 0) for k in range(1, 20)] + [Expect(1.0, 24, 20, 1)]
        return loading + [_flow_after_hit()]
    if name.startswith("max_explicit_slips"):
        dashpot = case.nu_s * ALONG_X[0] / X  # nu_s V along x, in units of w (exact: 1/128)
        return [Expect(1.0, k + dashpot, k, 0) for k in range(1, 17)] + [_max_slips_step(case, np.finfo(dtype).eps)]
    if name == "plastic_flow_exact_timing":
        return [Expect(1.0, k, k, 0) for k in range(1, 24)] + [Expect(1.0, 24, 24, 1), _plastic_flow_step()]
    if name == "slip_at_step_start_exact_timing":
        turned = [Expect(0.75, (f * X, 0.0, 0.0), (f * X, 0.0, 0.0), 1) for f in (8, 7, 6)]
        return [Expect(1.0, k, k, 0) for k in range(1, 19)] + turned
    if name.startswith("fn_zero"):
        leaving_d = 0.0 if case.reset == "spring" else -4.0  # total: D = -nu_s V/Ks = -4 w
        if name == "fn_zero_no_sliding_still_slips":
            leaving_d = 0.0
        return [Expect(0.0, 0.0, leaving_d, k) for k in range(1, n + 1)]
    if name.startswith("recontact"):
        first = [Expect(1.0, k, k, 0) for k in range(1, 11)]
        return first + [None] + [Expect(1.0, k, k, 0) for k in range(1, 6)]
    if name.startswith("stuck_pair_turning"):
        return None  # checked by check_turning
    raise KeyError(name)


def _plastic_flow_step():
    """E6 by hand: F = -T x at the start (T = 24/64), u = -(3, 4, 0)/5: the angle phi from F
    to u has cos 3/5, sin 4/5, tan(phi/2) = (4/5)/(1 + 3/5) = 1/2; the part of F across u
    points along p = (-4, 3, 0)/5. Over the step tan(phi/2) falls to s = exp(-rate/T)/2,
    rate = Ks |V| dt = 5/256, and F = T ((1 - s^2) u + 2 s p)/(1 + s^2); D = -F/Ks."""
    T = 24 * X
    s = 0.5 * math.exp(-(5 / 256) / T)
    u, p = np.array([-0.6, -0.8, 0.0]), np.array([-0.8, 0.6, 0.0])
    F = T * ((1 - s * s) * u + 2 * s * p) / (1 + s * s)
    return Expect(1.0, tuple(-F), tuple(-F), 2)


def _flow(T, u, p, tan_half, k_rest):
    """E6's closed form: the force on |F| = T at angle phi from u (tan(phi/2) = tan_half, the
    part across u along p) after the rest of a step with rate*rest/T = k_rest."""
    s = tan_half * math.exp(-k_rest)
    return T * ((1 - s * s) * np.array(u) + 2 * s * np.array(p)) / (1 + s * s)


def _flow_after_hit():
    """plastic_flow_reset_total_inside_step, the diagonal step, by hand in units of X = 1/64:
    the spring holds 20 along x; the trial force starts at F0 = -(20 + 3, 4, 0) (the dashpot
    nu_s V = (3, 4, 0)), u = -(3, 4, 0)/5, rate = Ks |V| dt = 5/4. Along u: f = F0.u = 17,
    across: q = F0 - f u = (-12.8, 9.6, 0), |q| = 16. |F| meets T = 24 where f + rate theta =
    sqrt(24^2 - 16^2) = sqrt(320): theta = (sqrt(320) - 17)/(5/4). There it slips to T t
    (r = 1, kept = 0) and flows for 1 - theta: tan(phi/2) = |q|/(T + sqrt(320)) falls by
    exp(-rate (1 - theta)/T). Spring at the end: D = -(F + nu_s V)/Ks (reset total holds
    spring + dashpot = Fmin, the force being applied)."""
    T, rate, f, qn = 24.0, 5.0 / 4, 17.0, 16.0
    u, p = np.array([-0.6, -0.8, 0.0]), np.array([-0.8, 0.6, 0.0])
    a_hit = math.sqrt(T * T - qn * qn)
    theta = (a_hit - f) / rate
    F = _flow(T, u, p, qn / (T + a_hit), rate * (1 - theta) / T) * X
    D = -(F + 0.25 * np.array(DIAGONAL)) / KS
    return Expect(1.0, tuple(-F), tuple(D), 2)


def max_slips_follow(case):
    """The diagonal-free 2D picture of max_explicit_slips_*'s sliding step, followed by hand
    from docs/law.md: a = F.u along u = -y, q across it (along -x), the force loading along u
    at `rate` per unit theta. A slip happens where a^2 + q^2 = T^2 (E2), a = sqrt(T^2 - q^2);
    it restarts the force at Fmin t + kept u (E3): a <- r a + kept, q <- r q. After
    MAX_EXPLICIT_SLIPS slips the rest, 1 - theta, is E7's: with low = Fmin + kept and L =
    (T - low)/rate, n = floor(rest/L) whole cycles and `part` left (L = 0: slides).
    Returns (theta of the last followed slip, a and q after it, rest, L)."""
    from pyref.laws import MAX_EXPLICIT_SLIPS
    T, fmin = case.mu_s, 2 * case.mu_k - case.mu_s
    r, V = fmin / T, case.segments[1].velocity[1]
    rate, kept = KS * V * DT, case.nu_s * V
    a, q = case.nu_s * V, 16 * X * KS  # F0 = -(Ks D + nu_s V): D = 16 X along x, the dashpot along y
    theta = 0.0
    for _ in range(MAX_EXPLICIT_SLIPS):
        hit = math.sqrt(T * T - q * q)
        assert hit > a  # below T after every slip (no E4), worked out in the case's comment
        theta += (hit - a) / rate
        a, q = r * hit + kept, r * q
        assert (r * hit + kept) ** 2 + q * q < T * T  # (E4 would slide at once)
    assert theta < 1 and q > 1e-8 * T  # all 100 inside the step, q not settled (E7's other way in)
    return theta, a, q, 1.0 - theta, (T - fmin - kept) / rate


def _max_slips_step(case, eps=EPS):
    """max_explicit_slips_*: the force at the end of the sliding step (units: absolute).
    Slides (L = 0): Fmin u applied, trial (Fmin + kept) u, spring -(trial + nu_s V)/Ks =
    Fmin along +y, all exact in binary. Periodic: trial = (Fmin + rate part) u + r^n q, with
    q along -x. Its tolerance: each followed slip rounds its theta (a square root of
    T^2 - q^2 formed with cancellation, a division, a sum: <= 8 eps (T + rate) in rate*theta),
    so over 100 slips the force along u may be off by 100 * 8 eps (T + rate); the values of
    the mutants this row is for differ by >1e-7 (closed form after 50 slips, or none)."""
    T, fmin = case.mu_s, 2 * case.mu_k - case.mu_s
    V = case.segments[1].velocity[1]
    rate, u = KS * V * DT, np.array([0.0, -1.0, 0.0])
    theta, a, q, rest, L = max_slips_follow(case)
    if L == 0:
        applied, trial = fmin * u, (fmin + case.nu_s * V) * u
        return Expect(1.0, tuple(-applied), tuple(-(trial + case.nu_s * np.array([0.0, V, 0.0])) / KS), 1)
    n = math.floor(rest / L)
    part = rest - n * L
    bound = 100 * 8 * eps * (T + rate)
    assert bound < rate * min(part, L - part)  # n is not on the edge of a rounding
    F = (fmin + rate * part) * u + (fmin / T) ** n * q * np.array([-1.0, 0.0, 0.0])
    return Expect(1.0, tuple(-F), tuple(-F / KS), 1, tol=bound)


def _inside_step(case):
    """Exact timing, T = 24.25 and Fmin = 12 (w units), one w a step along x. A slip at
    step fraction theta restarts the trial force at Fmin + kept and loads it by 1 - theta
    (E3, E7); the spring holds the trial force less the dashpot (4 with nu_s = 1/4)."""
    dash = 4 if case.nu_s else 0
    kept = dash if case.reset == "spring" else 0
    out, trial, slips = [], 0.0 + dash, 0
    # worked out by hand: (step, theta) of each slip
    slips_at = {(0, "spring"): {25: 0.25, 37: 0.5}, (4, "spring"): {21: 0.25, 29: 0.5},
                (4, "total"): {21: 0.25, 33: 0.5}}[(dash, case.reset)]
    for k in range(1, case.steps + 1):
        if k in slips_at:
            slips += 1
            trial = 12 + kept + (1 - slips_at[k])
        else:
            trial += 1
        out.append(Expect(1.0, trial, trial - dash, slips))
    return out


def check_turning(case, trace, eps=EPS):
    """Step 3 on a rigidly turning stuck pair: |D| stays |D_0| = 4/64 and D stays in the
    tangent plane. Round-off bound: each step's turn rounds |D| by a few ulps (a dot
    product, a square root, a quotient: <= 8 eps relative) and V_s, zero in exact
    arithmetic, is the difference of velocities ~ omega d rounded to ~eps omega d, which
    adds eps omega d dt to D per step; over N steps |D| may drift by
    N (8 eps |D| + 4 eps omega d dt). A history projected without keeping its length
    loses |D| (1 - cos(omega dt)) ~ |D| (omega dt)^2/2 a step instead: 5e-5 |D| (fast) and
    5e-9 |D| (slow) a step, 1e6 and 1e2 times that bound after 100 steps. eps: the engine's
    rounding (float: 2^-23, where the slow row's loss is below the bound: only the fast row
    tells the rules apart)."""
    d0 = 4 * X
    loaded = case.segments[0].steps
    turn = case.segments[1]
    normal = trace["n"]
    # an engine whose record has no spring (LAMMPS): here F = -Ks D - nu_s V_s with nu_s = 0
    # and Ks = 1, so -F is D to the last bit (a negation and a division by 1)
    assert case.nu_s == 0 and KS == 1.0
    D = trace["D"] if trace["D"] is not None else -trace["F"] / KS
    assert np.allclose(np.linalg.norm(D[loaded - 1]), d0, rtol=0, atol=4 * eps * d0)
    bound_per_step = 8 * eps * d0 + 4 * eps * abs(turn.omega) * (2 * R) * DT
    for k in range(loaded, len(D)):
        drift = abs(np.linalg.norm(D[k]) - d0)
        assert drift <= (k - loaded + 1) * bound_per_step, (k, drift, bound_per_step)
        assert abs(D[k] @ normal[k]) <= (k - loaded + 1) * bound_per_step, (k, D[k] @ normal[k])
    assert not trace["slips"].any()
    # it did turn: the normal moved by omega dt a step
    total = abs(turn.omega) * DT * turn.steps
    cos = normal[loaded - 1] @ normal[-1]
    assert math.isclose(math.acos(min(1.0, cos)), total, rel_tol=1e-6), (math.acos(min(1.0, cos)), total)


def vector(value, w):
    return np.array(value, float) if isinstance(value, tuple) else value * w


def empty_trace(n):
    """A trace of n steps with the contact apart at each: what an engine's driver fills in
    (stickslip/contract/runners.py) and compare() reads. Per step, what the contact recorded
    at its end: "fn" (N,), "F" (N, 3) the force on i, "D" (N, 3) the spring (None for the whole
    trace where the engine's record has no spring: LAMMPS), "slips" (N,) the steps that slipped
    since the contact began, "n" (N, 3) the normal from i to j; NaN (slips: -1) while apart."""
    return {"fn": np.full(n, np.nan), "F": np.full((n, 3), np.nan), "D": np.full((n, 3), np.nan),
            "slips": np.full(n, -1), "n": np.full((n, 3), np.nan)}


def compare(case, trace, dtype=np.float64):
    """Each step's recorded Fn, force, spring and slip count against expected(case). dtype:
    the engine's floating type; a case's ulps are ulps of it (the count of roundings on the
    path is the same in any binary format), its exact cases exact in it too."""
    if case.name.startswith("stuck_pair_turning"):
        return check_turning(case, trace, np.finfo(dtype).eps)
    exp = expected(case, dtype)
    assert len(exp) == case.steps
    k0 = 0
    for seg in case.segments:
        w = w_of(tangential(case, seg.velocity))
        for k in range(k0, k0 + seg.steps):
            e = exp[k]
            if e is None:
                continue
            F, D = -vector(e.f, w), vector(e.d, w)
            tol = e.tol if e.tol is not None else case.ulps * float(np.spacing(dtype(max(np.abs(F).max(),
                                                                                      np.abs(D).max()))))
            got = {q: None if trace[q] is None else trace[q][k] for q in ("fn", "F", "D", "slips")}
            where = f"{case.name}: step {k + 1}"
            assert got["fn"] == e.fn, (where, "Fn", got["fn"], e.fn)
            assert np.all(np.abs(got["F"] - F) <= tol), (where, "force", got["F"], F)
            if got["D"] is not None:  # (None: the engine's record has no spring; empty_trace)
                assert np.all(np.abs(got["D"] - D) <= tol), (where, "spring", got["D"], D)
            assert got["slips"] == e.slips, (where, "slips since the contact began", got["slips"], e.slips)
        k0 += seg.steps


# ----------------------------------------------------------------- per type pair
# mu_s and mu_k differ for every pair of types (1: the wall's material, 2 and 3: grains),
# so a coefficient read from another pair moves the first slip or the force after it.
# In units of X (one w a step along the tangent): T = mu_s Fn and Fmin; mu_k = (T + Fmin)/2.
TYPE_PAIRS = {(1, 1): (18, 12), (1, 2): (8, 2), (1, 3): (10, 4), (2, 2): (14, 8), (2, 3): (12, 6), (3, 3): (16, 10)}
TYPE_PAIR_STEPS = 20


def type_pair_coefficients():
    """{(i, j): (mu_s, mu_k)} for the types 1..3."""
    return {p: (t * X, (t + fmin) / 2 * X) for p, (t, fmin) in TYPE_PAIRS.items()}


def expected_type_pair(pair):
    """Step timing, no dashpot: slips where the spring reaches T, then every T - Fmin steps."""
    t, fmin = TYPE_PAIRS[pair]
    slips_at = set(range(t, TYPE_PAIR_STEPS + 1, t - fmin))
    return sawtooth(1, 0, slips_at, fmin, 0, "spring", TYPE_PAIR_STEPS)


def compare_type_pair(pair, trace, w, dtype=np.float64):
    """As compare(), within 1 ulp (of dtype, the engine's floating type): the slip's rescaling
    Fmin/|F_t| is not always a power of 2."""
    for k, e in enumerate(expected_type_pair(pair)):
        F, D = -e.f * w, e.d * w
        tol = float(np.spacing(dtype(max(np.abs(F).max(), np.abs(D).max()))))
        where = f"types {pair}: step {k + 1}"
        assert trace["fn"][k] == e.fn, (where, trace["fn"][k])
        assert np.all(np.abs(trace["F"][k] - F) <= tol), (where, "force", trace["F"][k], F)
        if trace["D"] is not None:  # (None: the engine's record has no spring)
            assert np.all(np.abs(trace["D"][k] - D) <= tol), (where, "spring", trace["D"][k], D)
        assert trace["slips"][k] == e.slips, (where, "slips", trace["slips"][k], e.slips)
