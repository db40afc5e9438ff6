"""The `stickslip` command: run a scene on an engine, or build the report."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import scene as scene_mod
from .adapters import ENGINES


class _Parser(argparse.ArgumentParser):
    """argparse, but a bad argument is one line on stderr and exit status 2."""

    def error(self, message):
        sys.stderr.write(f"stickslip: error: {message}\n")
        sys.exit(2)


def _positive(text):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not v > 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be > 0")
    return v


def build_parser():
    p = _Parser(prog="stickslip", description="Stick-slip friction (Khellaf & Mansouri 2024) on DEM engines.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    r = sub.add_parser("run", help="run one scene on one engine")
    r.add_argument("scene", help="a case name in cases/ (drag, tray, tilt, ...) or a path to a .toml scene")
    r.add_argument("--engine", default="pyref", choices=ENGINES)
    r.add_argument("--dt", type=_positive, help="time step, s (default: the scene's)")
    r.add_argument("--duration", type=_positive, help="simulated time, s (default: the scene's)")
    r.add_argument("--law", choices=scene_mod.LAWS, help="tangential law (default: the scene's)")
    r.add_argument("--reset", choices=scene_mod.RESETS, help="spring reset rule at a slip (default: the scene's)")
    r.add_argument("--out", type=Path, help="output folder (default: runs/SCENE/ENGINE)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")

    pr = sub.add_parser("precision", help="error vs wall time over a ladder of time steps")
    pr.add_argument("scene", help="a case name or a scene path")
    pr.add_argument("--engine", nargs="+", default=["pyref"], choices=ENGINES, dest="engines")
    pr.add_argument("--factors", nargs="+", type=_positive,
                    help="dt multipliers (default: 8 4 2 1 0.5 0.25)")
    pr.add_argument("--reference", default="pyref", choices=ENGINES,
                    help="engine whose finest run is the reference (default: pyref)")
    pr.add_argument("--out", type=Path, help="output folder (default: precision/SCENE)")
    pr.add_argument("--quiet", action="store_true", help="no progress bars")

    th = sub.add_parser("thresholds", help="measure the speed above which every step slips, vs the formula")
    th.add_argument("--out", type=Path, default=Path("thresholds"), help="output folder (default: thresholds)")

    be = sub.add_parser("bench", help="performance figures (pyref, and engines that provide a benchmark)")
    be.add_argument("--out", type=Path, default=Path("bench"), help="output folder (default: bench)")
    be.add_argument("--reps", type=int, default=3, help="repetitions per figure (median quoted)")

    rep = sub.add_parser("report", help="run the paper's cases on every available engine; figures + report.md")
    rep.add_argument("--out", type=Path, default=Path("report"), help="output folder (default: report)")
    rep.add_argument("--engines", nargs="+", choices=ENGINES, help="engines to use (default: every available one)")
    rep.add_argument("--quiet", action="store_true", help="no progress bars")
    rep.add_argument("--no-precision", action="store_true", help="skip the time-step ladders (issue 5 diagrams)")
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        if args.command == "run":
            return cmd_run(args)
        if args.command == "precision":
            return cmd_precision(args)
        if args.command == "thresholds":
            from .thresholds import run_thresholds
            for r in run_thresholds(args.out):
                print(f"dt={r['dt_s']:.2e} s  nu_s={r['nu_s']:6.2f}  V* measured {r['v_star_measured_mps']:.4e} m/s"
                      f"  formula {r['v_star_formula_mps']:.4e}  ({r['rel_diff']:+.2%})")
            print(f"wrote {args.out / 'thresholds.csv'} and {args.out / 'thresholds.png'}")
            return 0
        if args.command == "bench":
            from .bench import run_bench
            run_bench(args.out, reps=max(1, args.reps))
            return 0
        if args.command == "report":
            from .report import build_report
            return build_report(args.out, args.engines, progress=not args.quiet, precision=not args.no_precision)
    except scene_mod.SceneError as e:
        sys.stderr.write(f"stickslip: error: {e}\n")
        return 2
    except EngineError as e:
        sys.stderr.write(f"stickslip: error: {e}\n")
        return 1
    return 0


class EngineError(RuntimeError):
    """An engine that is not available or failed; the message says why."""


def run_scene(scene, engine, out_dir: Path, progress=True, energy=False):
    """Run a validated scene on an engine; write timeseries.csv and summary.json."""
    from . import adapters, analysis
    from .progress import bar

    adapter = adapters.get(engine)
    reason = adapter.available()
    if reason is not None:
        raise EngineError(f"engine {engine} is not available: {reason}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with bar(f"{scene.name} [{engine}, {scene.contact.law}]", scene.steps, enabled=progress) as update:
        kwargs = {"energy": True} if energy and engine == "pyref" else {}
        try:
            result = adapter.run(scene, out_dir, update, **kwargs)
        except (RuntimeError, ValueError, OSError) as e:  # the engine's own words, on one line
            raise EngineError(f"{engine}: {e}") from None
    result.timeseries.to_csv(out_dir / "timeseries.csv", index=False)
    summary = {
        "scene": scene.name, "engine": engine, "law": scene.contact.law, "reset": scene.contact.reset,
        "dt_s": scene.dt, "steps": int(result.steps), "wall_time_s": float(result.wall_time_s),
        "dimension": scene.dimension, "effects": scene.effects,
    }
    summary.update(analysis.summarise(scene, result.timeseries))
    notes = list(result.notes) + analysis.warnings(scene, summary)
    summary["notes"] = notes
    (out_dir / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    for note in notes:
        sys.stderr.write(f"stickslip: warning: {note}\n")
    return summary, result.timeseries


def cmd_run(args):
    overrides = {k: getattr(args, k) for k in ("dt", "duration", "law", "reset") if getattr(args, k) is not None}
    sc = scene_mod.load(args.scene, **overrides)
    out = args.out or Path("runs") / sc.name / args.engine
    summary, _ = run_scene(sc, args.engine, out, progress=not args.quiet)
    shown = {k: v for k, v in summary.items() if k not in ("effects", "notes")}
    print(json.dumps(shown, indent=2))
    print(f"wrote {out / 'timeseries.csv'} and {out / 'summary.json'}")
    return 0


def cmd_precision(args):
    from .precision import run_precision

    sc = scene_mod.load(args.scene)  # validate first: a bad scene is a one-line error
    out = args.out or Path("precision") / sc.name
    out.mkdir(parents=True, exist_ok=True)
    csv_path, orders = run_precision(args.scene, args.engines, out, args.factors and tuple(args.factors),
                                     progress=not args.quiet, reference=args.reference)
    for (eng, measure), p in sorted(orders.items()):
        print(f"{eng:9s} {measure:18s} convergence order {p:.2f}")
    print(f"wrote {csv_path} and the diagrams in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
