"""`stickslip report`: the paper's three cases on every available engine.

Writes PNG figures that correspond to the paper's Figs. 9, 11, 12, 14 and 15
and a report.md that shows them beside the paper's statements.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from . import adapters
from . import scene as scene_mod
from .cli import run_scene

# (case, law) runs: the tray is also run with the two laws the paper compares against.
RUNS = [("drag", None), ("tray", None), ("tray", "coulomb"), ("tray", "visco_plastic"), ("tilt", None)]
PYREF_ONLY_LAWS = ("coulomb", "visco_plastic")  # the engines ship only the stick-slip law


def _label(case, law):
    return case if law is None else f"{case}_{law}"


def build_report(out: Path, engines=None, progress=True, precision=True):
    import matplotlib

    matplotlib.use("Agg")
    out = Path(out)
    ok, missing = adapters.available()
    engines = [e for e in (engines or ok) if e in ok]
    skipped = {e: r for e, r in missing.items()}
    if "pyref" not in engines:
        engines = ["pyref"] + engines
    results = {}  # (label, engine) -> (summary, df)
    for case, law in RUNS:
        sc = scene_mod.load(case, **({"law": law} if law else {}))
        for eng in engines:
            if law in PYREF_ONLY_LAWS and eng != "pyref":
                continue
            d = out / "runs" / _label(case, law) / eng
            try:
                results[(_label(case, law), eng)] = run_scene(sc, eng, d, progress=progress)
            except Exception as e:  # an engine failing must not lose the others' results
                sys.stderr.write(f"stickslip: {eng} failed on {_label(case, law)}: {e}\n")
                skipped[eng] = f"failed on {_label(case, law)}: {e}"
    figs = _figures(out, results, engines)
    text = _markdown(results, engines, skipped, figs)
    if precision:
        text += _precision_section(out, engines, progress)
    (out / "report.md").write_text(text)
    print(f"wrote {out / 'report.md'}")
    return 0


# ---------------------------------------------------------------- figures
def _figures(out, results, engines):
    import matplotlib.pyplot as plt

    figs = {}
    styles = {"pyref": "-", "liggghts": "--", "yade": ":"}

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
        figs[name] = name

    # Fig. 9: friction force and sliding against the imposed displacement (drag).
    sc = scene_mod.load("drag")
    ks = sc.contact.ks
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for eng in engines:
        if ("drag", eng) not in results:
            continue
        s, df = results[("drag", eng)]
        disp = (df["grain_x"] - df["grain_x"].iloc[0]) * 1e6
        a.plot(disp, df["grain-floor_fs"], styles[eng], label=eng)
        b.plot(disp, disp - df["grain-floor_fs"] / ks * 1e6, styles[eng], label=eng)
        fn = s["fn_mean_N"]
    a.axhline(sc.contact.mu_s * fn, color="k", lw=0.5)
    a.axhline((2 * sc.contact.mu_k - sc.contact.mu_s) * fn, color="k", lw=0.5)
    a.axhline(sc.contact.mu_k * fn, color="gray", lw=0.5, ls="--")
    a.set_ylabel("friction force |Fs| (N/m)")
    a.legend()
    b.set_ylabel("sliding ≈ disp. − |Fs|/Ks (µm)")
    b.set_xlabel("imposed displacement (µm)")
    a.set_title("Fig. 9 — drag: saw-tooth between μs·Fn and (2μk−μs)·Fn")
    save(fig, "fig09_drag.png")

    # Fig. 11: height of grain 1 for the three laws.
    fig, ax = plt.subplots(figsize=(7, 4))
    for law in ("tray", "tray_coulomb", "tray_visco_plastic"):
        for eng in engines:
            if (law, eng) in results:
                df = results[(law, eng)][1]
                ax.plot(df["t"], df["grain1_y"] * 1e3, styles[eng],
                        label=f"{law.replace('tray_', '').replace('tray', 'stick_slip')} [{eng}]")
    ax.axhline(5.0, color="k", lw=0.5)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("grain 1 centre height (mm)")
    ax.set_title("Fig. 11 — tray: grain 1 stays up only with stick-slip")
    ax.legend(fontsize=8)
    save(fig, "fig11_tray_height.png")

    # Fig. 12: grain-grain tangential force per law.
    fig, axs = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for ax, law in zip(axs, ("tray_coulomb", "tray_visco_plastic", "tray")):
        for eng in engines:
            if (law, eng) in results:
                df = results[(law, eng)][1]
                ax.plot(df["t"], df["grain1-grain2_fty"], styles[eng], lw=0.8, label=eng)
        ax.set_ylabel("Fs,y (N/m)")
        ax.set_title(law.replace("tray_", "").replace("tray", "stick_slip"), fontsize=9)
        ax.legend(fontsize=8)
    axs[-1].set_xlabel("t (s)")
    fig.suptitle("Fig. 12 — tray: vertical friction force on grain 1 from grain 2")
    save(fig, "fig12_tray_friction.png")

    # Fig. 14: friction force and tan(beta) (a), zoom after the stop (b).
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 7))
    for eng in engines:
        if ("tilt", eng) not in results:
            continue
        s, df = results[("tilt", eng)]
        a.plot(df["t"], df["grain-plate_fs"], styles[eng], label=f"|Fs| [{eng}]")
        t_stop = df["t"][np.argmax(df["plate_angle"].to_numpy())]
        z = df["t"] >= t_stop - 0.005
        b.plot(df["t"][z], df["grain-plate_fs"][z], styles[eng], lw=0.7, label=eng)
    ax2 = a.twinx()
    ax2.plot(df["t"], np.tan(df["plate_angle"]), "r-", lw=0.8)
    ax2.set_ylabel("tan β", color="r")
    a.set_xlabel("t (s)")
    a.set_ylabel("friction force (N/m)")
    a.legend(loc="upper left")
    b.set_xlabel("t (s)")
    b.set_ylabel("friction force (N/m)")
    b.legend()
    a.set_title("Fig. 14 — tilt: (a) friction and tan β, (b) after the plate stops")
    save(fig, "fig14_tilt_friction.png")

    # Fig. 15: speed along the plate after the stop.
    fig, ax = plt.subplots(figsize=(7, 4))
    for eng in engines:
        if ("tilt", eng) not in results:
            continue
        s, df = results[("tilt", eng)]
        beta = df["plate_angle"]
        u = -(df["grain_vx"] * np.cos(beta) + df["grain_vy"] * np.sin(beta))
        z = df["t"] >= (s["t_first_slip_s"] or 0) - 0.002
        ax.plot(df["t"][z], u[z] * 1e3, styles[eng], label=eng)
        if s.get("t_steady_s"):
            ax.axvline(s["t_steady_s"], color="gray", lw=0.5)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("speed down the plate (mm/s)")
    ax.set_title("Fig. 15 — tilt: stick-slip, then steady sliding (grey line)")
    ax.legend()
    save(fig, "fig15_tilt_velocity.png")
    return figs


# ---------------------------------------------------------------- markdown
def _fmt(v):
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.5g}"
    return str(v)


CLAIMS = {
    "drag": [("fs_fn_max", "max |Fs|/Fn = μs = 0.5"), ("fs_fn_min", "min |Fs|/Fn = 2μk − μs = 0.4"),
             ("fs_fn_mean", "mean over whole periods = μk = 0.45"), ("slip_period_s", "measured slip period (s)"), ("slip_period_paper_s", "paper: 2(μs−μk)Fn/(Ks·V)"),
             ("slip_period_expected_s", "same, less the dashpot's jump ν_s·V"), ("slip_count", "slips"),
             ("wall_time_s", "wall time (s)")],
    "tray": [("y1_final_m", "grain 1 final height (stays above r = 5 mm)"),
             ("reached_bottom", "reaches the bottom (paper: no)"), ("time_to_rest_s", "time to rest (s)"),
             ("wall_time_s", "wall time (s)")],
    "tray_coulomb": [("y1_final_m", "grain 1 final height"), ("reached_bottom", "reaches the bottom (paper: yes)"),
                     ("wall_time_s", "wall time (s)")],
    "tray_visco_plastic": [("y1_final_m", "grain 1 final height"),
                           ("reached_bottom", "reaches the bottom (paper: yes)"), ("wall_time_s", "wall time (s)")],
    "tilt": [("tan_beta_first_slip", "tan β at the first slip (paper: μs = 0.5)"),
             ("accel_stick_slip_mps2", "mean acceleration, stick-slip phase"),
             ("accel_mean_friction_mu_k_mps2", "… if friction averaged μk·Fn"),
             ("accel_steady_mps2", "acceleration, steady sliding"),
             ("accel_steady_expected_mps2", "… expected with friction (2μk−μs)·Fn"),
             ("t_steady_s", "steady sliding from t (s)"), ("wall_time_s", "wall time (s)")],
}


def _nu_over_ks(case):
    c = scene_mod.load(case).contact
    return c.nu_s / c.ks


def _markdown(results, engines, skipped, figs):
    lines = ["# stickslip report", "",
             "The paper's three cases (Khellaf & Mansouri 2024, section 3) run from the scene files in "
             "`cases/` on every available engine. Each run's `timeseries.csv` and `summary.json` are under "
             "`runs/<case>/<engine>/`.", ""]
    lines.append("Engines: " + ", ".join(engines))
    for e, why in skipped.items():
        lines.append(f"- {e} not run: {why}")
    lines.append("")
    for label, claims in CLAIMS.items():
        present = [e for e in engines if (label, e) in results]
        if not present:
            continue
        lines += [f"## {label}", "", "| figure | " + " | ".join(present) + " |",
                  "|---|" + "---|" * len(present)]
        for key, text in claims:
            vals = [_fmt(results[(label, e)][0].get(key)) for e in present]
            lines.append(f"| {text.replace('|', chr(92) + '|')} | " + " | ".join(vals) + " |")
        # one line per distinct warning, naming the engines it came from
        notes = {}
        for e in present:
            for n in results[(label, e)][0].get("notes", []):
                notes.setdefault(n, []).append(e)
        lines += [""] + [f"> warning ({', '.join(es)}): {n}" for n, es in notes.items()] + [""]
        if label.split("_", 1)[-1] in PYREF_ONLY_LAWS:
            lines += ["(pyref only: the paper's comparison law; the engines ship only the stick-slip law)", ""]
    lines += ["## Figures", ""]
    for name in figs:
        lines += [f"![{name}]({name})", ""]
    lines += ["Every headline figure comes from `stickslip/analysis.py` reading the same columns from "
              "each engine. Summaries in JSON:", ""]
    for (label, eng), (s, _) in sorted(results.items()):
        lines.append(f"- [{label} / {eng}](runs/{label}/{eng}/summary.json)")
    return "\n".join(lines) + "\n"


def _precision_section(out, engines, progress):
    """What accuracy costs in time (issue 5): dt ladders, and the every-step-slips speed."""
    from .precision import run_precision
    from .thresholds import run_thresholds

    lines = ["", "## What accuracy costs in time", "",
             "Each case over a ladder of time steps on each engine; errors against the finest pyref run "
             "(the reference). See `stickslip/precision.py` for the error measures.", ""]
    for case in ("drag", "tray", "tilt"):
        d = out / "precision" / case
        d.mkdir(parents=True, exist_ok=True)
        csv_path, orders = run_precision(case, engines, d, progress=progress)
        lines += [f"### {case}", "", f"Data: [{csv_path.name}](precision/{case}/{csv_path.name}). Fitted "
                  "convergence orders: " + ", ".join(f"{e} {m} {p:.2f}" for (e, m), p in sorted(orders.items())), "",
                  f"![work-precision](precision/{case}/precision_{case}_work.png)",
                  f"![error vs dt](precision/{case}/precision_{case}_dt.png)", ""]
        if case == "tilt":
            lines += ["The tilt velocity at each time step: the stick-slip stretch ends where every step slips, "
                      "at V* = 2(μs−μk)Fn/(Ks·dt + νs). The dashpot part νs of that limit is physics; the Ks·dt "
                      "part is a time-step artefact, so the length of the stick-slip stretch and the speed at "
                      "which steady sliding starts depend on dt, while the steady acceleration (friction Fmin) "
                      "does not. The velocity history converges (first order) only once Ks·dt ≪ νs, i.e. "
                      f"dt ≪ νs/Ks = {_nu_over_ks('tilt'):.2g} s, below this ladder's finest step: how far, in "
                      "[docs/precision.md](../docs/precision.md) (a finer ladder with LIGGGHTS as the reference).",
                      "", f"![tilt velocity by dt](precision/{case}/precision_tilt_velocity.png)", ""]
    rows = run_thresholds(out / "thresholds")
    worst = max(abs(r["rel_diff"]) for r in rows)
    lines += ["### Speed above which every step slips", "",
              f"Measured (bisection, drag case) against V* = 2(μs−μk)Fn/(Ks·dt + νs) for {len(rows)} pairs of "
              f"dt and νs: largest difference {worst:.2%}. Data: [thresholds.csv](thresholds/thresholds.csv).", "",
              "![thresholds](thresholds/thresholds.png)", ""]
    return "\n".join(lines) + "\n"


def load_summary(path):
    return json.loads(Path(path).read_text())
