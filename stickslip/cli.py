# SPDX-License-Identifier: GPL-2.0-or-later
"""The `stickslip` command: parses its arguments and calls the module that does the work.

run -> runner.py, report -> report.py, bench -> bench/table.py, precision, thresholds,
drum-study and drum-engines -> studies/precision.py, thresholds.py, drum_study.py,
drum_engines.py; study-3d and calibrate -> studies/granular3d.py, calibrate.py. Bad arguments or a bad scene: one line on
stderr, exit status 2; an engine that fails, a file that cannot be written, or an internal
fault: one line, exit status 1 (STICKSLIP_TRACEBACK=1 shows the traceback of a fault).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

from . import __version__
from . import scene as scene_mod
from .adapters import ENGINES, OPTIONAL_ENGINES, SOURCE_BUILT
from .errors import EngineError, SceneError


class _Parser(argparse.ArgumentParser):
    """argparse, but a bad argument is one line on stderr and exit status 2."""

    def error(self, message):
        sys.stderr.write(f"stickslip: error: {message}\n")
        sys.exit(2)


def _number(text, kind, ok, allowed):
    """`text` as a `kind` (float or int) for which ok(v) holds, else argparse's one-line error
    naming what is allowed."""
    try:
        v = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a {'whole number' if kind is int else 'number'}") from None
    if not ok(v):
        raise argparse.ArgumentTypeError(f"{text!r} must be {allowed}")
    return v


def _positive(text):
    return _number(text, float, lambda v: v > 0 and math.isfinite(v), "a finite number > 0")


def _count(text):
    return _number(text, int, lambda v: 1 <= v <= 100, "in [1, 100]")


def _target(name):
    """The type of calibrate's option for target `name`: a number within calibrate_fit.ALLOWED."""
    from .studies.calibrate_fit import ALLOWED

    lo, hi, what = ALLOWED[name]
    return lambda text: _number(text, float, lambda v: lo < v < hi, f"{what}, in ({lo:g}, {hi:g})")


def _nonnegative(text):
    return _number(text, float, lambda v: 0 <= v < 90, "a standard error in [0, 90)")


def _folder(text):
    """An output folder; an empty one would silently be the current folder."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; give a folder")
    return Path(text)


def build_parser():
    p = _Parser(prog="stickslip", description="Stick-slip friction (Khellaf & Mansouri 2024) on DEM engines.")
    p.add_argument("--version", action="version", version=f"stickslip {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    r = sub.add_parser("run", help="run one scene on one engine")
    r.add_argument("scene", help="a case name in cases/ (drag, tray, tilt, ...) or a path to a .toml scene")
    r.add_argument("--engine", default="pyref", choices=ENGINES + OPTIONAL_ENGINES)
    r.add_argument("--dt", type=_positive, help="time step, s (default: the scene's)")
    r.add_argument("--duration", type=_positive, help="simulated time, s (default: the scene's)")
    r.add_argument("--law", choices=scene_mod.LAWS, help="tangential law (default: the scene's)")
    r.add_argument("--reset", choices=scene_mod.RESETS, help="spring reset rule at a slip (default: the scene's)")
    r.add_argument("--slip-timing", choices=scene_mod.SLIP_TIMINGS, dest="slip_timing",
                   help="step: slip tested at the end of each step (the paper); exact: each slip at its "
                        "time inside the step (docs/law.md); default: the scene's")
    r.add_argument("--out", type=_folder, help="output folder (default: runs/SCENE/ENGINE)")
    r.add_argument("--ranks", type=_count, default=1, help="MPI processes (LIGGGHTS and LAMMPS; default 1)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")

    pr = sub.add_parser("precision", help="error vs wall time over a ladder of time steps")
    pr.add_argument("scene", help="a case name or a scene path")
    pr.add_argument("--engine", nargs="+", default=["pyref"], choices=ENGINES, dest="engines")
    pr.add_argument("--factors", nargs="+", type=_positive,
                    help="dt multipliers (default: 8 4 2 1 0.5 0.25)")
    pr.add_argument("--slip-timing", nargs="+", choices=scene_mod.SLIP_TIMINGS, dest="slip_timings",
                    default=list(scene_mod.SLIP_TIMINGS), help="modes to run (default: both)")
    pr.add_argument("--reference", default="pyref", choices=ENGINES,
                    help="engine whose exact-timing run at the finest step is the reference (default: pyref)")
    pr.add_argument("--out", type=_folder, help="output folder (default: precision/SCENE)")
    pr.add_argument("--quiet", action="store_true", help="no progress bars")

    th = sub.add_parser("thresholds", help="measure the speed above which every step slips, vs the formula")
    th.add_argument("--out", type=_folder, default=Path("thresholds"), help="output folder (default: thresholds)")

    be = sub.add_parser("bench", help="performance figures (pyref, and engines that provide a benchmark)")
    be.add_argument("--out", type=_folder, default=Path("bench"), help="output folder (default: bench)")
    be.add_argument("--reps", type=_count, default=3, help="repetitions per figure (median quoted)")
    be.add_argument("--report", action="store_true", help="also time `stickslip report` (all engines and studies)")
    be.add_argument("--engines", nargs="+", choices=ENGINES,
                    help="engines whose own benchmarks run besides pyref's (default: every available one)")

    ds = sub.add_parser("drum-study", help="avalanches in a turning drum on LIGGGHTS: history vs stick-slip "
                                           "(docs/drum.md); resumes an interrupted study")
    ds.add_argument("--scene", default="drum", help="the drum scene (default: cases/drum.toml)")
    ds.add_argument("--out", type=_folder, default=Path("docs/drum"), help="tables and figures (default: docs/drum)")
    ds.add_argument("--runs", type=_folder, default=Path("runs/drum_study"),
                    help="the runs, kept for resuming (default: runs/drum_study)")
    ds.add_argument("--rate", type=_positive, help="drum rate, rad/s (default: the scene's)")
    ds.add_argument("--duration", type=_positive, default=180.0, help="simulated time per run, s (default: 180)")
    ds.add_argument("--fill", type=_positive, help="share of the drum filled (default: the scene's grain count)")
    ds.add_argument("--seed", type=int, help="the fill's random seed (default: the scene's)")
    ds.add_argument("--only", nargs="+", help="run only these runs of the matrix (labels)")
    ds.add_argument("--no-checks", action="store_true", help="leave out the half-rate and half-dt runs")
    # runs side by side beat MPI ranks on one run (docs/drum.md, measured on 2 cores: 2 runs at
    # once 1.7e7 grain-steps/s with their dumps read, 2 ranks on one run 1.4e7, speed-up 1.6)
    ds.add_argument("--ranks", type=_count, default=1, help="MPI ranks of each run (default: 1)")
    ds.add_argument("--jobs", type=_count, default=os.cpu_count() or 1,
                    help="runs side by side (default: every core)")
    ds.add_argument("--tables-only", action="store_true",
                    help="write the tables and figures of the runs finished so far; run nothing")
    ds.add_argument("--keep-timeseries", action="store_true",
                    help="keep each run's full time series and engine files (gigabytes a run)")
    ds.add_argument("--quiet", action="store_true", help="no progress bars")

    de = sub.add_parser("drum-engines", help="the drum across engines: costs, how long trajectories agree, "
                                             "avalanche statistics of each engine (docs/drum.md)")
    de.add_argument("--out", type=_folder, default=Path("docs/drum"), help="tables and figures (default: docs/drum)")
    de.add_argument("--runs", type=_folder, default=Path("runs/drum_study"),
                    help="the runs, kept for resuming (default: runs/drum_study)")
    de.add_argument("--engines", nargs="+", choices=ENGINES, default=[e for e in ENGINES if e not in SOURCE_BUILT],
                    help="engines to compare (default: all but those built from source)")
    de.add_argument("--duration", type=_positive, default=40.0,
                    help="simulated time of the statistics runs, s (default: 40)")
    de.add_argument("--parts", nargs="+", choices=("costs", "divergence", "statistics"),
                    default=["costs", "divergence", "statistics"], help="which parts to run (default: all)")
    de.add_argument("--quiet", action="store_true", help="no progress bars")

    g3 = sub.add_parser("study-3d", help="what mu_s and mu_k do to a bed of spheres: incline and heap, history vs "
                                          "stick-slip, on LIGGGHTS and LAMMPS (docs/granular-3d.md); resumes")
    g3.add_argument("--out", type=_folder, default=Path("docs/granular-3d"),
                    help="tables, figures and summary (default: docs/granular-3d)")
    g3.add_argument("--runs", type=_folder, default=Path("runs/granular3d"),
                    help="the runs, kept for resuming (default: runs/granular3d)")
    g3.add_argument("--fills", type=_count, default=3, help="fills (random beds) per point (default: 3)")
    g3.add_argument("--only", nargs="+", help="run only the runs whose label holds one of these strings")
    g3.add_argument("--groups", nargs="+", choices=("sweep", "validation", "check", "engines", "coverage", "shear"),
                    default=["sweep", "validation", "check", "engines", "coverage", "shear"],
                    help="run only these groups of the study: the map (sweep), the validation, its checks, LAMMPS "
                         "(engines), calibrate's round trip (coverage), the sheared layer (shear); default: all")
    g3.add_argument("--no-checks", action="store_true", help="leave out the check with Silbert et al.'s stiffer "
                                                              "contact (~1 CPU hour)")
    g3.add_argument("--engines", nargs="+", choices=("liggghts", "lammps"), default=["liggghts", "lammps"],
                    help="LAMMPS repeats the validation and two stick-slip points (default: both)")
    g3.add_argument("--jobs", type=_count, default=2, help="runs side by side (default: 2)")
    g3.add_argument("--tables-only", action="store_true", help="tables and figures of the runs on disk; run nothing")
    g3.add_argument("--cost-only", action="store_true", help="say what the study would run and its CPU hours, per "
                                                             "group; run nothing, write nothing")
    g3.add_argument("--from-csv", action="store_true",
                    help="redraw the tables, figures and summary from OUT/runs.csv alone (the committed results)")
    g3.add_argument("--smoke", action="store_true", help="a study of a few seconds on small scenes (the test suite's)")
    g3.add_argument("--keep-engine-files", action="store_true", help="keep each run's dumps (megabytes a run)")
    g3.add_argument("--quiet", action="store_true", help="no progress bar")

    cal = sub.add_parser("calibrate", help="mu_s and mu_k for target angles of a bed of spheres, from the measured "
                                           "map of study-3d (docs/granular-3d.md)",
                         description="Answers mu_s and mu_k, the stick-slip law's static and kinetic friction "
                                     "coefficients, for a material of spheres, each with its 68 % range, read on the "
                                     "map stickslip study-3d measured (docs/granular-3d.md, 'A calibration you can "
                                     "apply'). It needs at least two targets measured on the material: two or more "
                                     "of the options below (its angles on an incline and a heap, a sheared layer's "
                                     "figures) or a --measurements file. An end of a range that the map's edge or one "
                                     "of the law's bounds cuts is said to be one.")
    shear = "needs a map that measured it"
    for name, what in (("theta_start", "angle at which a bed starts to flow, deg"),
                       ("theta_stop", "angle at which a flowing bed stops on an incline held still, deg (read on an "
                                      "incline turning down: add ~1 deg)"),
                       ("theta_heap", "angle of repose of a heap on a plate, deg"),
                       ("shear_peak", f"peak shear over normal stress of a shear cell (kind shear3d; {shear})"),
                       ("shear_steady", f"steady shear over normal stress of a shear cell (kind shear3d; {shear})"),
                       ("shear_dilation", f"rise of a shear cell's lid under shear, in grain diameters (kind shear3d; "
                                          f"{shear})")):
        option = "--" + name.replace("_", "-")
        cal.add_argument(option, type=_target(name), help=what)
        cal.add_argument(f"{option}-se", type=_nonnegative, help=f"standard error of {option} (default 0: exact)")
    cal.add_argument("--measurements", type=Path, help="CSV of repeated measurements: a column per target "
                                                       "(theta_start, theta_stop, theta_heap, shear_peak, "
                                                       "shear_steady, shear_dilation), a row per "
                                                       "repeat, n >= 2; mean and standard error from them")
    cal.add_argument("--interpolation", choices=("auto", "linear", "quadratic"), default="auto",
                     help="the map's interpolation (default auto: the one of smaller leave-one-out error)")
    cal.add_argument("--region-png", type=Path, help="draw the answer's chi2 region on the map (PNG)")
    cal.add_argument("--rolling", type=float, default=0.0, help="rolling resistance coefficient (LIGGGHTS' epsd2) "
                                                                 "of the material: one the map measured, 0 or 0.1 on "
                                                                 "the committed map (default: 0)")
    cal.add_argument("--map", type=Path, help="the measured map, points.csv (default: docs/granular-3d/points.csv)")
    out = cal.add_mutually_exclusive_group()
    out.add_argument("--details", action="store_true", help="also the statistics behind the answer")
    out.add_argument("--json", action="store_true", help="the whole answer as JSON (for scripts), nothing else")

    rep = sub.add_parser("report", help="run the paper's cases on every available engine; figures + report.md")
    rep.add_argument("--out", type=_folder, default=Path("report"), help="output folder (default: report)")
    rep.add_argument("--engines", nargs="+", choices=ENGINES, help="engines to use (default: every available one)")
    rep.add_argument("--quiet", action="store_true", help="no progress bars")
    rep.add_argument("--no-precision", action="store_true",
                     help="skip the studies (time-step ladders, friction vs speed, thresholds)")
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return COMMANDS[args.command](args)
    except SceneError as e:
        sys.stderr.write(f"stickslip: error: {e}\n")
        return 2
    except EngineError as e:
        sys.stderr.write(f"stickslip: error: {e}\n")
        return 1
    except OSError as e:  # the file system refused (a full disk, a folder gone during the run)
        where = f"{e.filename}: " if e.filename else ""
        sys.stderr.write(f"stickslip: error: {where}{e.strerror or e}\n")
        return 1
    except MemoryError:
        sys.stderr.write("stickslip: error: out of memory (the scene or its output is too big for this "
                         "machine: fewer grains, a shorter run or a larger output.every)\n")
        return 1
    except KeyboardInterrupt:
        sys.stderr.write("stickslip: interrupted\n")
        return 130
    except Exception as e:  # an internal fault: one line for the user, the traceback on request
        if os.environ.get("STICKSLIP_TRACEBACK"):
            raise
        sys.stderr.write(f"stickslip: error: internal error ({type(e).__name__}: {' '.join(str(e).split())[:200]}); "
                         f"please report it (STICKSLIP_TRACEBACK=1 shows where)\n")
        return 1


def cmd_run(args):
    from .runner import run_scene

    overrides = {k: getattr(args, k) for k in ("dt", "duration", "law", "reset", "slip_timing")}
    sc = scene_mod.load(args.scene, **overrides)
    out = args.out or Path("runs") / sc.name / args.engine
    summary, _ = run_scene(sc, args.engine, out, progress=not args.quiet, ranks=args.ranks)
    shown = {k: v for k, v in summary.items() if k not in ("effects", "notes", "avalanche_list")}
    print(json.dumps(shown, indent=2))
    print(f"wrote {out / 'timeseries.csv'} and {out / 'summary.json'}")
    return 0


def cmd_precision(args):
    from . import kinds
    from .studies.precision import DEFAULT_FACTORS, ladder, run_precision, warned_line
    from .runner import prepare_output

    sc = scene_mod.load(args.scene)  # validate first: a bad scene is a one-line error
    # Every run of the ladder is checked before the first starts (a factor of 1e-30 would
    # otherwise be refused only when its turn comes, or never end).
    duration = kinds.get(sc.analysis["kind"]).PRECISION_DURATION
    dts = ladder(sc, args.factors or DEFAULT_FACTORS)
    if not dts:
        raise SceneError(f"--factors: no time step of the ladder is below 0.9 of the stability limit "
                         f"({0.9 * sc.critical_dt():.3g} s = {0.9 * sc.critical_dt() / sc.dt:.3g} x the scene's dt)")
    for dt in dts:
        try:
            scene_mod.load(args.scene, dt=dt, duration=duration)
        except SceneError as e:
            raise SceneError(f"--factors {dt / sc.dt:g} (dt = {dt:.3g} s): {e}") from None
    out = prepare_output(args.out or Path("precision") / sc.name)
    csv_path, orders = run_precision(args.scene, args.engines, out, args.factors and tuple(args.factors),
                                     progress=not args.quiet, reference=args.reference,
                                     timings=tuple(args.slip_timings))
    for (eng, timing, measure), p in sorted(orders.items()):
        print(f"{eng:9s} {timing:6s} {measure:18s} convergence order {p:.2f}")
    print(warned_line(csv_path))
    print(f"wrote {csv_path} and the diagrams in {out}")
    return 0


def cmd_thresholds(args):
    from .runner import prepare_output
    from .studies.thresholds import run_thresholds

    out = prepare_output(args.out)
    for r in run_thresholds(out):
        print(f"dt={r['dt_s']:.2e} s  nu_s={r['nu_s']:6.2f}  V* measured {r['v_star_measured_mps']:.4e} m/s"
              f"  formula {r['v_star_formula_mps']:.4e}  ({r['rel_diff']:+.2%})")
    print(f"wrote {out / 'thresholds.csv'} and {out / 'thresholds.png'}")
    return 0


def cmd_bench(args):
    from .bench.table import run_bench
    from .runner import prepare_output

    run_bench(prepare_output(args.out), reps=args.reps, engines=args.engines, report=args.report)
    return 0


def cmd_drum_study(args):
    import tomllib

    from .studies.drum_study import run_study

    path = scene_mod.find(args.scene)
    rate = args.rate or abs(tomllib.loads(path.read_text()).get("gravity_rate", 0.0)) or None
    if rate is None:
        raise SceneError(f"--scene {args.scene}: not a turning drum (no gravity_rate); give --rate")
    run_study(path, args.out, args.runs, rate, args.duration, fill=args.fill, seed=args.seed, labels=args.only,
              full=not args.no_checks, ranks=args.ranks, jobs_at_once=args.jobs, keep_timeseries=args.keep_timeseries,
              progress=not args.quiet, tables_only=args.tables_only)
    return 0


def cmd_drum_engines(args):
    from .studies import drum_engines

    drum_engines.run(args.out, args.runs, args.engines, args.duration, args.parts, progress=not args.quiet)
    return 0


def cmd_study_3d(args):
    from .studies import granular3d

    if args.from_csv:
        if not (args.out / "runs.csv").is_file():
            raise SceneError(f"--from-csv: {args.out / 'runs.csv'} not found (run the study first)")
        granular3d.write_results(args.out)
        return 0
    smoke = {"jobs": granular3d.smoke_jobs(), "scenes": granular3d.SMOKE_SCENES} if args.smoke else {}
    granular3d.run_study(args.out, args.runs, fills=tuple(range(1, args.fills + 1)), checks=not args.no_checks,
                         engines=tuple(args.engines), only=args.only, jobs_at_once=args.jobs,
                         progress=not args.quiet, tables_only=args.tables_only,
                         keep_engine_files=args.keep_engine_files, groups=tuple(args.groups), cost_only=args.cost_only,
                         **smoke)
    return 0


def cmd_calibrate(args):
    from .studies import calibrate

    calibrate.main(args)
    return 0


def cmd_report(args):
    from .report import build_report
    from .runner import prepare_output

    return build_report(prepare_output(args.out), args.engines, progress=not args.quiet,
                        studies=not args.no_precision)


COMMANDS = {"run": cmd_run, "precision": cmd_precision, "thresholds": cmd_thresholds, "bench": cmd_bench,
            "report": cmd_report, "drum-study": cmd_drum_study, "study-3d": cmd_study_3d, "calibrate": cmd_calibrate,
            "drum-engines": cmd_drum_engines}

if __name__ == "__main__":
    sys.exit(main())
