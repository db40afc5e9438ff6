# SPDX-License-Identifier: GPL-2.0-or-later
"""The paper's case 1 (section 3.1) in YADE: a grain dragged at constant speed on a floor.

    yade -n -x example_drag.py [--reset spring|total] [--csv out.csv] [--steps 2500]
    build/yade_law/yade-stickslip -n -x example_drag.py --backend cpp    # the compiled law

The paper is 2D (per metre of thickness). YADE is 3D, so the disk becomes an
"equivalent sphere" with the disk's mass per unit thickness, m = rho*pi*r^2, moving
in the xy-plane with rotation locked; with linear contact laws the dynamics are the
same. Expected: friction/Fn climbs to mu_s = 0.5, drops to 2 mu_k - mu_s = 0.4 and
saw-tooths with period (2(mu_s - mu_k)Fn - nu_s V)/(Ks V) = 3.30e-4 s.
The last line printed is `RESULT {json}` (used by tests/test_yade_law.py).
"""
import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.environ.get("STICKSLIP_YADE_LAW", os.path.dirname(os.path.abspath(sys.argv[0]))))

from stickslip_yade import stickslip_engines, stickslip_material  # noqa: E402
from yade import O, Vector3, utils  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--reset", default="spring")
ap.add_argument("--csv")
ap.add_argument("--steps", type=int, default=2500)  # 5e-3 s: static phase + ~10 periods
ap.add_argument("--dt", type=float, default=2e-6)
ap.add_argument("--nu_s", type=float, default=33.10)
ap.add_argument("--backend", default="python", help="python, or cpp: the compiled law (yade_law/README.md)")
args = ap.parse_args(sys.argv[1:])

r, rho, g, V = 0.002, 2600.0, 9.81, 1e-5  # Table 2 and section 3.1
kn, ks, nu_n, nu_s, mu_s, mu_k = 1.2e7, 9.6e6, 41.38, args.nu_s, 0.5, 0.45
m = rho * math.pi * r**2  # disk mass per metre of thickness

mat = O.materials.append(stickslip_material(kn, nu_n, density=rho))
floor = O.bodies.append(utils.wall(0.0, axis=1, material=mat))  # the plane y = 0
b = utils.sphere((0.0, r - m * g / kn, 0.0), r, material=mat)  # at its static overlap
b.state.mass = m
b.state.blockedDOFs = "xzXYZ"  # x imposed, stays in the xy-plane, no rotation
b.state.vel = Vector3(V, 0.0, 0.0)
grain = O.bodies.append(b)
O.engines = stickslip_engines(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k, reset=args.reset,
                              gravity=(0.0, -g, 0.0), rotation=False, backend=args.backend)
O.dt = args.dt
law = stickslip_law  # noqa: F821 -- published in builtins by stickslip_engines

rows = []
for step in range(1, args.steps + 1):
    O.step()
    c = law.contact(grain, floor)  # force on the grain
    fn, ft, slipped, _ = c if c is not None else (0.0, (0.0, 0.0, 0.0), False, 0)
    rows.append((step * O.dt, fn, ft[0], ft[1], int(slipped), O.bodies[grain].state.pos[0]))

if args.csv:
    with open(args.csv, "w") as f:
        f.write("t,fn,ftx,fty,slip,x\n")
        f.writelines(",".join(f"{v:.10g}" for v in row) + "\n" for row in rows)

slip_t = [row[0] for row in rows if row[4]]
ratio = [abs(row[2]) / row[1] for row in rows if row[1] > 0]
stick_ratio = [abs(row[2]) / row[1] for row in rows if row[1] > 0 and not row[4]]
gaps = [b - a for a, b in zip(slip_t, slip_t[1:])]
result = {
    "fn_mean": sum(row[1] for row in rows) / len(rows), "weight": m * g,
    "max_ratio": max(ratio), "max_stick_ratio": max(stick_ratio),
    "slip_ratios": sorted({round(abs(row[2]) / row[1], 12) for row in rows if row[4]})[:5],
    "first_slip": slip_t[0] if slip_t else None, "n_slips": len(slip_t),
    "period": sorted(gaps)[len(gaps) // 2] if gaps else None,
    "ftx_sign": math.copysign(1.0, sum(row[2] for row in rows)),
    "fty_max": max(abs(row[3]) for row in rows),
}
period = f"{result['period']:.4g} s" if result["period"] else "none"
print(f"grain weight {m * g:.5g} N/m; first slip at {result['first_slip']} s; "
      f"friction/Fn between {min(ratio[len(ratio) // 2:]):.4f} and {result['max_ratio']:.4f}; period {period}")
print("RESULT " + json.dumps(result))
