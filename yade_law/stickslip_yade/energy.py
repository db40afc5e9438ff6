# SPDX-License-Identifier: GPL-2.0-or-later
"""The energy books in YADE's O.energy (with O.trackEnergy; YADE's keys `kinetic` and
`gravWork` come from NewtonIntegrator): the tangential law's dissipation split into slips
and dashpot (docs/law.md, Energy) and its spring energy Ks|D|^2/2, and, because
Law2_ScGeom_ViscElPhys_Basic books nothing, the normal law's elastic energy Kn*delta^2/2
and what its dashpot took, (Fn - Kn*delta)*v_n*dt (Fn clipped at 0 included). Cumulative
entries are read back from O.energy each step, so they live in the scene and follow its
checkpoints."""
from .kernel import dot


def book_step(O, tan, ks, kn, delta, fn, v_n, dt):
    """Book one step of the contacts (`tan`: the kernel's TangentialStep); returns the least
    energy one contact took out in it (docs/law.md, "Energy")."""
    D = tan.spring
    book(O, tan.dissipated_slip.sum(), tan.dissipated_dashpot.sum(), ((fn - kn * delta) * v_n).sum() * dt,
         0.5 * ks * dot(D, D).sum(), 0.5 * (kn * delta * delta).sum())
    return float((tan.dissipated_dashpot + tan.dissipated_slip).min())


def book(O, slip, dashpot, normal_damping, spring, normal_elastic):
    E = O.energy
    have = set(E.keys())
    for name, inc in (("stickslip_slip", slip), ("stickslip_dashpot", dashpot),
                      ("stickslip_normal_damping", normal_damping)):
        E[name] = (E[name] if name in have else 0.0) + float(inc)
    E["stickslip_spring"] = float(spring)
    E["stickslip_normal_elastic"] = float(normal_elastic)
