"""What accuracy costs in time: a scene over a ladder of time steps on each engine.

Each run's error is measured against the finest run of the ladder on the reference
engine (pyref, the oracle, by default; `--reference liggghts` reaches finer steps in
the same time, LIGGGHTS being equal to pyref at equal dt to round-off). Error measures are per case and physical:
  drag: relative error of the mean friction |Fs|/Fn and of the slip period;
  tray: error of grain 1's final height (relative to its fall room, 0.25 mm) and of
        its time to rest;
  tilt: RMS difference of the speed down the plate after the first slip, relative to
        the reference's final speed.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from . import analysis
from . import scene as scene_mod

DEFAULT_FACTORS = (8, 4, 2, 1, 0.5, 0.25)  # x the scene's dt: 6 steps over 1.5 decades
# Precision runs of the tray stop once stick-slip has brought grain 1 to rest (0.15 s).
DURATIONS = {"tray": 0.4}


def measures(sc, summary, df, ref=None):
    """Error measures of one run (relative, dimensionless) against the reference run."""
    kind = sc.analysis["kind"]
    if ref is None:
        return {}
    rs, rdf = ref
    if kind == "drag":
        return {"mean_friction": _rel(summary["fs_fn_mean"], rs["fs_fn_mean"]),
                "slip_period": _rel(summary["slip_period_s"], rs["slip_period_s"])}
    if kind == "tray":
        room = 0.25e-3  # grain 1's initial height above the bottom
        return {"final_height": abs(summary["y1_final_m"] - rs["y1_final_m"]) / room,
                "time_to_rest": _rel(summary["time_to_rest_s"], rs["time_to_rest_s"])}
    if kind == "tilt":
        return {"velocity_history": _velocity_error(sc, df, rs, rdf)}
    return {}


def _rel(a, b):
    if a is None or b is None or b == 0:
        return math.nan
    return abs(a - b) / abs(b)


def _speed_down_plate(sc, df):
    g, w = sc.analysis["grain"], sc.analysis["wall"]
    beta = df[f"{w}_angle"].to_numpy()
    return -(df[f"{g}_vx"].to_numpy() * np.cos(beta) + df[f"{g}_vy"].to_numpy() * np.sin(beta))


def _velocity_error(sc, df, rs, rdf):
    t0 = rs["t_first_slip_s"]
    tr = rdf["t"].to_numpy()
    sel = tr >= t0
    u_ref = _speed_down_plate(sc, rdf)[sel]
    u = np.interp(tr[sel], df["t"].to_numpy(), _speed_down_plate(sc, df))
    return float(np.sqrt(np.mean((u - u_ref) ** 2)) / max(abs(u_ref[-1]), 1e-30))


def ladder(sc, factors):
    """Time steps from the factors, keeping those below 0.9 of the stability limit."""
    limit = 0.9 * sc.critical_dt()
    return [sc.dt * f for f in sorted(factors, reverse=True) if sc.dt * f <= limit]


def run_precision(scene_name, engines, out: Path, factors=None, progress=True, reference="pyref"):
    """The ladder on each engine; errors against the finest run of `reference` (pyref by
    default: the oracle; a faster engine that agrees with it at equal dt can reach
    finer steps)."""
    from .cli import run_scene

    base = scene_mod.load(scene_name)
    factors = factors or DEFAULT_FACTORS
    kw = {"duration": DURATIONS[base.analysis["kind"]]} if base.analysis["kind"] in DURATIONS else {}
    dts = ladder(base, factors)
    out = Path(out)
    runs = {}
    for eng in [reference] + [e for e in engines if e != reference]:
        for dt in dts:
            sc = scene_mod.load(scene_name, dt=dt, **kw)
            d = out / "runs" / eng / f"dt_{dt:.3e}"
            try:
                runs[(eng, dt)] = (sc, *run_scene(sc, eng, d, progress=progress))
            except Exception as e:  # one engine failing leaves the others' diagram
                print(f"stickslip: precision: {eng} at dt={dt:g} failed: {e}")
    ref_key = (reference, min(dts))
    if ref_key not in runs:
        raise RuntimeError(f"precision: the reference run ({reference} at dt = {min(dts):g} s) failed")
    ref = runs[ref_key][1:]
    rows = []
    for (eng, dt), (sc, s, df) in sorted(runs.items(), key=lambda kv: (kv[0][0], -kv[0][1])):
        m = measures(sc, s, df, ref)
        is_ref = (eng, dt) == ref_key
        rows.append({"engine": eng, "dt_s": dt, "wall_time_s": s["wall_time_s"], "steps": s["steps"],
                     "reference": is_ref, **{f"err_{k}": (math.nan if is_ref else v) for k, v in m.items()}})
    csv_path = out / f"precision_{base.name}.csv"
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    orders = _plots(base.name, rows, out, reference)
    if base.analysis["kind"] == "tilt":
        _plot_tilt_velocities(runs, out, reference)
    return csv_path, orders


def _plot_tilt_velocities(runs, out, engine="pyref"):
    """Fig. 15 at each time step: which parts of the curve are physics, which are dt."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for (eng, dt), (sc, s, df) in sorted(runs.items(), key=lambda kv: kv[0][1]):
        if eng != engine or s["t_first_slip_s"] is None:
            continue
        sel = df["t"].to_numpy() >= s["t_first_slip_s"] - 0.002
        v_star = formula_v_star(sc, s)
        ax.plot(df["t"][sel], _speed_down_plate(sc, df)[sel] * 1e3,
                label=f"dt = {dt:.1e} s (every step slips above {v_star * 1e3:.2f} mm/s)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("speed down the plate (mm/s)")
    ax.set_title(f"tilt: velocity after the first slip, by time step ({engine})")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "precision_tilt_velocity.png", dpi=110)
    plt.close(fig)


def formula_v_star(sc, summary):
    """Speed above which every step slips on the held plate (thresholds.formula)."""
    from .thresholds import formula

    g = next(q for q in sc.grains if q.name == sc.analysis["grain"])
    fn = sc.grain_mass(g) * float(np.linalg.norm(sc.gravity)) / math.sqrt(1 + summary["tan_beta_stop"] ** 2)
    return formula(sc, sc.dt, sc.contact.nu_s if sc.effects["tangential_damping"] else 0.0, fn)


def convergence_order(dts, errs):
    """Slope of log(error) against log(dt) over the finite, non-zero errors."""
    pts = [(math.log(d), math.log(e)) for d, e in zip(dts, errs) if e and math.isfinite(e) and e > 0]
    if len(pts) < 3:
        return math.nan
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def _plots(name, rows, out, reference="pyref"):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [k for k in rows[0] if k.startswith("err_")]
    engines = sorted({r["engine"] for r in rows})
    orders = {}
    # Runs at the reference's own dt measure how far an engine is from pyref, not a
    # discretisation error (pyref's is zero there, LIGGGHTS' round-off): plotted, not fitted.
    dt_ref = min((r["dt_s"] for r in rows if r["reference"]), default=0.0)
    fig1, ax1 = plt.subplots(figsize=(6.5, 4.5))
    fig2, ax2 = plt.subplots(figsize=(6.5, 4.5))
    for eng in engines:
        rr = [r for r in rows if r["engine"] == eng and not r["reference"]]
        for k, mark in zip(keys, "os^"):
            dts = [r["dt_s"] for r in rr]
            # An error of exactly 0 (e.g. a period equal to the reference's to the step) has
            # no place on a log axis: left out of the plot, kept in the CSV.
            errs = [r[k] if r[k] and r[k] > 0 else math.nan for r in rr]
            p = convergence_order([d for d in dts if d > dt_ref * (1 + 1e-9)],
                                  [e for d, e in zip(dts, errs) if d > dt_ref * (1 + 1e-9)])
            orders[(eng, k[4:])] = p
            ax1.loglog([r["wall_time_s"] for r in rr], errs, mark + "-", label=f"{eng}: {k[4:]}")
            ax2.loglog(dts, errs, mark + "-", label=f"{eng}: {k[4:]} (order {p:.2f})")
    ax1.set_xlabel("wall time (s)")
    ax1.set_ylabel(f"relative error vs finest {reference} run")
    ax1.set_title(f"{name}: work-precision")
    ax1.legend(fontsize=8)
    ax2.set_xlabel("time step dt (s)")
    ax2.set_ylabel(f"relative error vs finest {reference} run")
    ax2.set_title(f"{name}: error vs dt (order fitted above the reference dt)")
    ax2.legend(fontsize=8)
    for fig, fname in ((fig1, f"precision_{name}_work.png"), (fig2, f"precision_{name}_dt.png")):
        fig.tight_layout()
        fig.savefig(out / fname, dpi=110)
        plt.close(fig)
    return orders
