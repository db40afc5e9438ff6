# SPDX-License-Identifier: GPL-2.0-or-later
"""The LIGGGHTS plugin against pyref on the paper's cases, through the adapter (issue 3).

LIGGGHTS and pyref integrate the same way (velocity Verlet, forces from x(t) and
v(t - dt/2), the setup force of step 0 without a spring increment), so on the same scene
and dt they differ only by the order of floating-point sums. The tolerances below are
round-off bounds: a quantity of scale F carried over N steps may drift by about
N * eps * F (eps = 2.2e-16); we allow 10 times that (`scale_of` says what F is). Row 0 is left out: LIGGGHTS' record
of a contact is written by the first step, pyref writes the setup force.
"""
import numpy as np
import pytest

from stickslip import analysis
from stickslip import scene as scene_mod
from stickslip.adapters import liggghts as liggghts_adapter
from stickslip.adapters.text_dumps import read_dump
from conftest import needs_engine, paper_case, run_pyref

needs_liggghts = needs_engine("liggghts")
EPS = np.finfo(float).eps


def run_liggghts(name, tmp_path, **kw):
    sc = scene_mod.load(name, **kw)
    return sc, liggghts_adapter.run(sc, tmp_path).timeseries


def roundoff(sc, scale):
    return 10 * sc.steps * EPS * scale


def scale_of(sc, df, col):
    """The size of the terms a column is summed from: a contact's force components are
    of the size of its normal force; a velocity is at least what gravity gives over the
    run (g * duration), since it accumulates force increments."""
    for a, b in sc.output.contacts:
        if col.startswith(f"{a}-{b}_"):
            return np.abs(df[f"{a}-{b}_fn"]).max()
    scale = np.abs(df[col]).max()
    if "_v" in col:
        scale = max(scale, float(np.linalg.norm(sc.gravity)) * sc.duration)
    return scale


def assert_series_agree(sc, dl, dp):
    assert list(dl.columns) == list(dp.columns)
    assert len(dl) == len(dp)
    for col in dl.columns:
        if col.endswith("_slip"):
            continue
        a, b = dl[col].to_numpy()[1:], dp[col].to_numpy()[1:]
        assert np.abs(a - b).max() <= roundoff(sc, scale_of(sc, dp, col)), col
    for a, b in sc.output.contacts:
        c = f"{a}-{b}"
        # LIGGGHTS makes a contact at zero overlap (pyref at > 0): with Fn = 0 it slips
        # with zero force, so slip counts are compared where a normal force acts
        touching = (dl[f"{c}_fn"] > 0) | (dp[f"{c}_fn"] > 0)
        assert (dl[f"{c}_slip"][touching] == dp[f"{c}_slip"][touching])[1:].all(), c


@needs_liggghts
def test_drag_matches_pyref(tmp_path):
    sc, dl = run_liggghts("drag", tmp_path)
    _, dp = paper_case("drag")
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    for k in ("fs_fn_max", "fs_fn_min", "fs_fn_mean", "slip_period_s"):
        assert sl[k] == pytest.approx(sp[k], rel=0.01), k
    assert sl["slip_count"] == sp["slip_count"]
    assert_series_agree(sc, dl, dp)


@pytest.mark.long
@needs_liggghts
def test_tilt_matches_pyref(tmp_path):
    """The turning plate is a mesh wall moved by fix move/mesh rotate/variable."""
    sc, dl = run_liggghts("tilt", tmp_path)
    _, dp = paper_case("tilt")
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    for k in ("tan_beta_first_slip", "accel_stick_slip_mps2", "accel_steady_mps2"):
        assert sl[k] == pytest.approx(sp[k], rel=0.01), k
    # The plate's nodes are turned step by step (rounding accumulates in the mesh), not
    # set from the angle as in pyref: positions keep round-off agreement, forces to the
    # round-off of the contact's overlap (Kn * eps * r per step).
    c = "grain-plate"
    r = sc.grains[0].radius
    for col in ("grain_x", "grain_y", "grain_vx", "grain_vy"):
        assert np.abs(dl[col] - dp[col]).max() <= roundoff(sc, scale_of(sc, dp, col)), col
    dfn = np.abs(dl[f"{c}_fn"] - dp[f"{c}_fn"]).to_numpy()[1:]
    assert dfn.max() <= sc.steps * sc.contact.kn * EPS * r
    assert (dl[f"{c}_slip"] == dp[f"{c}_slip"])[1:].all()


@needs_liggghts
def test_tray_matches_pyref(tmp_path):
    sc, dl = run_liggghts("tray", tmp_path, duration=0.5)
    _, dp = paper_case("tray", duration=0.5)
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    assert not sl["reached_bottom"]
    r = sc.grains[0].radius
    assert sl["y1_final_m"] - r == pytest.approx(sp["y1_final_m"] - r, rel=0.01)
    assert sl["time_to_rest_s"] == pytest.approx(sp["time_to_rest_s"], rel=0.01)
    assert_series_agree(sc, dl, dp)


@needs_liggghts
def test_reset_total_matches_pyref(tmp_path):
    """The reset option means the same on both engines (docs/law.md, step 5)."""
    sc, dl = run_liggghts("drag", tmp_path, reset="total", duration=2.5e-3)
    dp, _ = run_pyref(sc)
    assert_series_agree(sc, dl, dp)


@needs_liggghts
def test_effects_off_are_left_out_of_the_script(tmp_path):
    """Only the effects a scene switches on appear in the input script."""
    sc = scene_mod.load("drag", duration=1e-5, effect_gravity=False, effect_normal_damping=False,
                        effect_tangential_damping=False)
    liggghts_adapter.run(sc, tmp_path)
    text = (tmp_path / "liggghts" / "in.scene").read_text()
    assert "gravity" not in text.replace("scene drag", "")
    assert "nve/sphere" not in text  # rotation off: translation only
    assert "gamman_abs peratomtypepair 1 0.0" in text and "gammat_abs peratomtypepair 1 0.0" in text
    sc = scene_mod.load("tilt", duration=1e-5, effect_rotation=True)
    liggghts_adapter.run(sc, tmp_path)
    text = (tmp_path / "liggghts" / "in.scene").read_text()
    assert "fix gravity all gravity" in text and "nve/sphere" in text and "move/mesh" in text


@needs_liggghts
def test_liggghts_error_is_one_line(tmp_path):
    """An error inside LIGGGHTS reaches the user as its one-line message, not a traceback."""
    sc = scene_mod.load("drag", duration=1e-5)
    sc.contact.mu_k = 0.6  # past the scene check, so that LIGGGHTS itself refuses it
    with pytest.raises(ValueError) as e:
        liggghts_adapter.run(sc, tmp_path)
    msg = str(e.value)
    assert "coefficientKineticFriction" in msg and "0.6" in msg and "[0.25, 0.5]" in msg
    assert "\n" not in msg


@needs_liggghts
def test_poured_packing_statistics_match_pyref(tmp_path):
    """120 polydisperse disks poured into a tray (rotation on), on LIGGGHTS and pyref.
    Contact-rich and chaotic: paths part after the first collisions, so only statistics
    can agree (the tolerances of the YADE version of this test, tests/test_yade_engine.py):
    both at rest (kinetic energy < 1 % of its peak), mean height within 2 %, number of
    contacts within 10 %."""
    from test_packing import statistics_pour

    sc, dp = statistics_pour()  # the YADE test's pour: pyref runs it once for both
    dl = liggghts_adapter.run(sc, tmp_path).timeseries
    for df in (dp, dl):
        assert np.isfinite(df.to_numpy()).all()
        assert df["ekin"].iloc[-1] < 0.01 * df["ekin"].max()
    heights = lambda df: np.mean([df[f"{g.name}_y"].iloc[-1] for g in sc.grains])  # noqa: E731
    assert heights(dl) == pytest.approx(heights(dp), rel=0.02)
    assert dl["n_contacts"].iloc[-1] == pytest.approx(dp["n_contacts"].iloc[-1], rel=0.10)


# ---------------------------------------------------------------- exact slip timing (issue 13)

@needs_liggghts
def test_drag_exact_timing_matches_pyref(tmp_path):
    """docs/law.md E0-E7 on both engines: the drag case in exact mode, step for step, to the
    round-off tolerance of the step mode (the floor is fixed: both engines see the same
    overlap, so the slips' phases start from the same numbers)."""
    sc, dl = run_liggghts("drag", tmp_path, slip_timing="exact")
    assert "exact_slip_timing on" in (tmp_path / "liggghts" / "in.scene").read_text()
    _, dp = paper_case("drag", slip_timing="exact")
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    for k in ("fs_fn_max", "fs_fn_min", "fs_fn_mean", "slip_period_s"):
        assert sl[k] == pytest.approx(sp[k], rel=0.01), k
    assert sl["slip_count"] == sp["slip_count"] > 5
    assert_series_agree(sc, dl, dp)


@needs_liggghts
def test_tilt_exact_timing_matches_pyref(tmp_path):
    """The tilt case in exact mode (~1.5 s on LIGGGHTS, ~25 s on pyref). Tolerances as in
    test_tilt_matches_pyref (the plate's nodes are turned step by step on LIGGGHTS: each
    step's overlap differs by round-off, Kn*eps*r in force), with one addition: in exact mode
    a slip inside a step leaves the spring at a level that depends continuously on when it
    happened, so a perturbation is carried from slip to slip instead of being erased by the
    step mode's reset at the end of a step. Positions are then bounded by what the velocity
    bound integrates to, x = sum v dt: duration * (velocity bound), on top of their own
    round-off."""
    sc, dl = run_liggghts("tilt", tmp_path, slip_timing="exact")
    _, dp = paper_case("tilt", slip_timing="exact")
    sl, sp = analysis.summarise(sc, dl), analysis.summarise(sc, dp)
    for k in ("tan_beta_first_slip", "accel_stick_slip_mps2", "accel_steady_mps2"):
        assert sl[k] == pytest.approx(sp[k], rel=0.01), k
    c = "grain-plate"
    r = sc.grains[0].radius
    for axis in ("x", "y"):
        v_col = f"grain_v{axis}"
        v_tol = roundoff(sc, scale_of(sc, dp, v_col))
        assert np.abs(dl[v_col] - dp[v_col]).max() <= v_tol, v_col
        col = f"grain_{axis}"
        x_tol = roundoff(sc, scale_of(sc, dp, col)) + sc.duration * v_tol
        assert np.abs(dl[col] - dp[col]).max() <= x_tol, col
    dfn = np.abs(dl[f"{c}_fn"] - dp[f"{c}_fn"]).to_numpy()[1:]
    assert dfn.max() <= sc.steps * sc.contact.kn * EPS * r
    assert (dl[f"{c}_slip"] == dp[f"{c}_slip"])[1:].all()
    assert dp[f"{c}_slip"].sum() > 1000


INCLINE = """
name = "incline3d"
dimension = 3
gravity = [0.0, 0.0, -9.81]
[effects]
gravity = true
rotation = false
normal_damping = true
tangential_damping = {damped}
[contact]
kn = 1e5
nu_n = 0.5
ks = 8e4
nu_s = {nu_s}
mu_s = 0.5
mu_k = {mu_k}
slip_timing = "exact"
[time]
dt = 5e-6
duration = {duration}
[output]
every = 1
grains = ["g"]
contacts = [["g", "plane"]]
[[grain]]
name = "g"
radius = 0.005
density = 2600
position = {pos}
velocity = [{v0}, 0.0, 0.0]
[[wall]]
name = "plane"
point = [0.0, 0.0, 0.0]
normal = {normal}
"""


def incline_scene(mu_k, nu_s, v0, duration, tan_beta=0.3):
    """A sphere launched across a plane inclined by tan(beta) (a fixed mesh wall on LIGGGHTS),
    rotation locked, resting at its static overlap: gravity pulls it down the slope while
    friction opposes its sliding velocity, so V_s (and the friction) turns during sliding."""
    import math
    import tomllib

    b = math.atan(tan_beta)
    n = [0.0, -math.sin(b), math.cos(b)]
    r, m = 0.005, 2600 * 4 / 3 * math.pi * 0.005**3
    d = r - m * 9.81 * math.cos(b) / 1e5
    text = INCLINE.format(damped=str(nu_s > 0).lower(), nu_s=nu_s if nu_s > 0 else 0.1, mu_k=mu_k,
                          duration=duration, pos=[0.0, d * n[1], d * n[2]], v0=v0, normal=n)
    return scene_mod.parse(tomllib.loads(text))


def friction_turn_deg(df, c, rows):
    ft = df[[f"{c}_ftx", f"{c}_fty", f"{c}_ftz"]].to_numpy()[rows]
    angle = np.unwrap(np.arctan2(ft[:, 1], ft[:, 0]))
    return np.degrees(angle.max() - angle.min())


@needs_liggghts
@pytest.mark.parametrize("regime", ["plastic_flow", "dashpot_slide"])
def test_exact_timing_3d_turning_slip_matches_pyref(tmp_path, regime):
    """3D, exact mode, V_s turning while the contact slides (the friction turns by > 45
    degrees), LIGGGHTS against pyref step for step, in the two regimes where the exact
    mode keeps no slip phase from step to step (so round-off is not carried on, see
    test_tilt_exact_timing_matches_pyref):
    - plastic_flow: mu_k = mu_s, no tangential dashpot: every slipping step ends on
      |F| = mu_s Fn turned towards -V_s by the closed form E6;
    - dashpot_slide: nu_s |V_s| >= 2 (mu_s - mu_k) Fn: every slipping step slides at
      Fmin along -V_s (E4) after its first slip, whose direction t is not -V_s's.
      Compared while that holds (until the grain has slowed below the dashpot threshold);
      afterwards the stick-slip tail is checked for |Fs| <= mu_s Fn only.
    Tolerances: the mesh plane's overlap differs between the engines by round-off in each
    step (Kn*eps*r in force, accumulated over the steps, as in the tilt test); the friction
    force follows the normal force through mu_s; velocities and positions as in
    assert_series_agree (N eps times the velocity gravity gives over the run)."""
    mu_k, nu_s = (0.5, 0.0) if regime == "plastic_flow" else (0.45, 0.1)
    sc = incline_scene(mu_k, nu_s, v0=0.05, duration=0.03)
    dl = liggghts_adapter.run(sc, tmp_path).timeseries
    dp, _ = run_pyref(sc)
    c = "g-plane"
    fn, v = dp[f"{c}_fn"].to_numpy(), dp[["g_vx", "g_vy", "g_vz"]].to_numpy()
    n = sc.walls[0].normal
    speed = np.linalg.norm(v - np.outer(v @ n, n), axis=1)
    if regime == "dashpot_slide":
        sliding = sc.contact.nu_s * speed >= 2 * (sc.contact.mu_s - sc.contact.mu_k) * fn
        end = int(np.argmin(sliding[1:])) + 1  # first row below the dashpot threshold
    else:
        end = len(dp)
    rows = slice(1, end)
    slipping = np.nonzero(dp[f"{c}_slip"].to_numpy()[rows] > 0)[0] + 1
    turn = friction_turn_deg(dp, c, slipping)
    print(f"\n[3D exact, {regime}] rows compared 1..{end - 1} of {len(dp) - 1}; slipping rows there "
          f"{len(slipping)}; friction turned by {turn:.1f} deg while slipping")
    assert len(slipping) > 500 and turn > 45
    fn_tol = sc.steps * sc.contact.kn * EPS * sc.grains[0].radius
    gT = float(np.linalg.norm(sc.gravity)) * sc.duration
    for col in dl.columns:
        if col.endswith("_slip") or col == "t":
            continue
        a, b = dl[col].to_numpy()[rows], dp[col].to_numpy()[rows]
        if col.startswith(f"{c}_f"):
            tol = (1.0 if col == f"{c}_fn" else sc.contact.mu_s) * fn_tol + roundoff(sc, np.abs(fn).max())
        elif col.startswith("g_v"):
            tol = roundoff(sc, max(np.abs(b).max(), gT))
        else:
            tol = roundoff(sc, np.abs(b).max())
        diff = np.abs(a - b).max()
        print(f"  {col:10s} max |LIGGGHTS - pyref| {diff:.2e} (tolerance {tol:.2e})")
        assert diff <= tol, col
    if regime == "dashpot_slide":
        # E4 slips in every step: the flags agree (with mu_k = mu_s the flag is a tie at
        # |F| = mu_s Fn, decided by round-off, and the force is continuous across it)
        assert (dl[f"{c}_slip"] == dp[f"{c}_slip"]).to_numpy()[rows].all()
    for df in (dl, dp):
        assert np.isfinite(df.to_numpy(dtype=float)).all()
        assert (df[f"{c}_fs"] <= sc.contact.mu_s * df[f"{c}_fn"] * (1 + 1e-9)).all()


@needs_liggghts
def test_exact_timing_thousands_of_slips_per_step(tmp_path):
    """Exact mode where each step holds thousands of saw-tooth cycles: cycles per step =
    Ks V dt / (mu_s Fn - Fmin) (no dashpot), from the parameters, > 1000 here. The cost is
    bounded (E7 closes the cycles in one formula; in 3D at most MAX_EXPLICIT_SLIPS = 100
    are followed one by one), every value stays finite and |Fs| <= mu_s Fn (1e-9: text
    dumps). The applied force samples the saw-tooth at the end of each step, at a phase
    that round-off scrambles, so only the mean is compared: the samples are uniform on
    [Fmin, mu_s Fn), mean mu_k Fn, standard error (mu_s - Fmin/Fn)/sqrt(12 N) of the ratio;
    LIGGGHTS and pyref within 4 standard errors (sqrt 2 for the difference of two) of it.
    - 2D: the drag at 1 m/s (mu_s = 0.5, mu_k = 0.4999: the drop is 2e-4 Fn), force along -V_s;
    - 3D: the inclined plane at 1 m/s across the slope, V_s turning: the part of the
      force across -V_s shrinks by r = Fmin/(mu_s Fn) = 0.9996 per slip, so the step
      follows 100 slips before closing the rest (MAX_EXPLICIT_SLIPS)."""
    mu_s, mu_k = 0.5, 0.4999
    sc2 = scene_mod.load("drag", slip_timing="exact", effect_tangential_damping=False, mu_k=mu_k, duration=2e-3)
    sc2.grains[0].velocity = np.array([1.0, 0.0, 0.0])
    sc3 = incline_scene(mu_k, 0.0, v0=1.0, duration=1e-3)
    for label, sc, c in (("2D drag", sc2, "grain-floor"), ("3D incline", sc3, "g-plane")):
        fn0 = sc.grain_mass(sc.grains[0]) * 9.81 * (1.0 if sc.dimension == 2 else 1 / np.hypot(1, 0.3))
        cycles = sc.contact.ks * 1.0 * sc.dt / (2 * (mu_s - mu_k) * fn0)
        assert cycles > 1000, cycles
        dl = liggghts_adapter.run(sc, tmp_path / label.replace(" ", "_")).timeseries
        dp, _ = run_pyref(sc)
        means = []
        for df in (dl, dp):
            assert np.isfinite(df.to_numpy(dtype=float)).all()
            fn, fs = df[f"{c}_fn"].to_numpy()[1:], df[f"{c}_fs"].to_numpy()[1:]
            assert (fn > 0).all() and (fs <= mu_s * fn * (1 + 1e-9)).all()
            assert (df[f"{c}_slip"].to_numpy()[1:] == 1).all()
            means.append((fs / fn).mean())
        se = (mu_s - (2 * mu_k - mu_s)) / np.sqrt(12 * sc.steps)
        print(f"\n[thousands of slips, {label}] ~{cycles:.0f} cycles per step; mean |Fs|/Fn LIGGGHTS "
              f"{means[0]:.6f}, pyref {means[1]:.6f}, mu_k {mu_k} (standard error {se:.1e})")
        assert abs(means[0] - means[1]) <= 4 * np.sqrt(2) * se
        assert abs(means[0] - mu_k) <= 4 * se


# ---------------------------------------------------------------- output (issue 15 section 4)

@needs_liggghts
def test_output_is_proportional_to_what_the_scene_records(tmp_path):
    """A 600-disk pour (test_packing's) recording two grains, their contact, one wall contact
    and the stats: the atoms dump holds the two grains only, the pair dump only contacts
    between recorded grains, the stats one row per output step (reduced in LIGGGHTS); the
    files grow with the rows recorded, not with the grains. The stats must be what the
    adapter computed before from full dumps: the same run recording every grain gives the
    kinetic energy (1/2 m v^2 + 1/2 I w^2, disks) from the grains' own columns to 1e-12
    relative (summation order), and the contact count from the dumped positions exactly
    (pairs and walls overlapping)."""
    from test_packing import pour

    sc = pour(30, 20, duration=0.02)
    names = [g.name for g in sc.grains]
    sc.output.every = 400
    sc.output.stats = True
    sc.output.grains = names[:2]
    sc.output.contacts = [[names[0], names[1]], [names[0], sc.walls[0].name]]
    small = liggghts_adapter.run(sc, tmp_path / "small").timeseries
    work = tmp_path / "small" / "liggghts"
    atoms = read_dump(work / "atoms.dump")
    assert all(len(f) == 2 for f in atoms.values())
    pairs = read_dump(work / "pairs.dump")
    assert all(set(f[:, :2].astype(int).ravel()) <= {1, 2} for f in pairs.values() if len(f))
    stats = read_dump(work / "stats.dump")
    assert sorted(stats) == sorted(atoms) and all(len(f) == 1 for f in stats.values())
    size_small = sum(p.stat().st_size for p in work.glob("*.dump"))

    sc.output.grains = names
    full = liggghts_adapter.run(sc, tmp_path / "full").timeseries
    size_full = sum(p.stat().st_size for p in (tmp_path / "full" / "liggghts").glob("*.dump"))
    print(f"\n[output] {len(names)} grains, {len(small)} rows: dumps {size_small} bytes recording 2 grains, "
          f"{size_full} bytes recording all")
    assert size_small * 20 < size_full
    for col in small.columns:
        assert np.array_equal(small[col], full[col]), col
    m = np.array([sc.grain_mass(g) for g in sc.grains])
    inertia = np.array([sc.grain_inertia(g) for g in sc.grains])
    r = np.array([g.radius for g in sc.grains])
    v2 = np.array([full[f"{n}_vx"] ** 2 + full[f"{n}_vy"] ** 2 for n in names])
    w2 = np.array([full[f"{n}_wz"] ** 2 for n in names])
    ekin = 0.5 * (m[:, None] * v2).sum(axis=0) + 0.5 * (inertia[:, None] * w2).sum(axis=0)
    assert np.allclose(full["ekin"], ekin, rtol=1e-12, atol=0)
    for k in range(len(full)):
        x = np.array([[full[f"{n}_x"][k], full[f"{n}_y"][k]] for n in names])
        d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
        n_pairs = int(np.triu(d <= r[:, None] + r[None, :], 1).sum())
        n_walls = sum(int((r - ((x - w.point[:2]) @ w.normal[:2]) > 0).sum()) for w in sc.walls)
        assert full["n_contacts"][k] == n_pairs + n_walls, k


@needs_liggghts
def test_non_finite_output_fails_loudly(tmp_path):
    """A run whose output holds a NaN or an infinity must not come back as a time series:
    the adapter raises one clear error naming the column, time and step."""
    sc = scene_mod.load("drag", duration=1e-4)
    sc.output.every = 10
    work = tmp_path / "liggghts"
    work.mkdir()
    script = liggghts_adapter._Script(sc, work)
    liggghts_adapter.run(sc, tmp_path)  # a real run writes the dumps ...
    text = (work / "atoms.dump").read_text().split("\n")
    k = max(i for i, line in enumerate(text) if line.startswith("1 "))
    fields = text[k].split()
    fields[5] = "nan"  # ... then one velocity becomes NaN in the last row
    text[k] = " ".join(fields)
    (work / "atoms.dump").write_text("\n".join(text))
    with pytest.raises(RuntimeError) as e:
        liggghts_adapter._timeseries(script, work)
    msg = str(e.value)
    print(f"\n[non-finite] {msg}")
    assert "non-finite" in msg and "grain_vy" in msg and "step 50" in msg and "\n" not in msg
