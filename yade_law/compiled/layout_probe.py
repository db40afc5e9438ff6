# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in YADE with the compiled law loaded (layout_check.py does): every member the law reads
or writes, set through YADE's Python attributes (YADE's own compiled code, which knows where
its classes keep them) to a value no default has (or, where Python cannot set it, the value
YADE's own code computed), then read through the plugin
(Law2_ScGeom_StickSlipPhys_StickSlip.layoutProbe and its siblings). First the pointer members
(the state and shape a body holds, an interaction's geometry and phys, the scene's cell and
energy books): the addresses the plugin reads in them against those of the objects Python
holds, nothing dereferenced, so that a plugin whose classes do not match YADE's is named here
rather than crashing on a wrong pointer; then the values. Prints one line,
`RESULT {"mismatches": [{"member", "yade", "plugin"}, ...]}`.

The scene: two spheres in a periodic, sheared cell (so that the cell's shift and its velocity
are not zero), made to touch by YADE's own dispatchers, and energy tracking on.
"""
import json
import sys

from yade import (O, Ig2_Sphere_Sphere_ScGeom, Ip2_ViscElMat_ViscElMat_StickSlipPhys,
                  Law2_ScGeom_StickSlipPhys_StickSlip, InteractionLoop, Matrix3, ForceResetter, Vector3, Vector3i,
                  ViscElMat, utils)

law = Law2_ScGeom_StickSlipPhys_StickSlip
O.periodic = True
O.cell.hSize = Matrix3(1.25, 0.125, 0.0625, 0.03125, 1.5, 0.25, 0.0, 0.375, 1.75)
O.cell.velGrad = Matrix3(0.5, 0.25, 0.0, 0.0, -0.125, 0.75, 0.0625, 0.0, 0.0)
O.dt = 1.234375e-5
O.trackEnergy = True
mat = O.materials.append(ViscElMat(kn=2.0e5, cn=3.0, ks=0.0, cs=0.0, frictionAngle=0.0, density=2000.0))
for k, x in enumerate(((0.3, 0.4, 0.5), (0.6, 0.7, 0.8), (0.3 + 0.19, 0.4, 0.5))):
    O.bodies.append(utils.sphere(x, 0.1 + 0.0009765625 * k, material=mat))
O.engines = [ForceResetter(), InteractionLoop([Ig2_Sphere_Sphere_ScGeom()],
                                              [Ip2_ViscElMat_ViscElMat_StickSlipPhys(ks=7.5e4, nu_s=1.5, mu_s=0.5,
                                                                                     mu_k=0.4375)],
                                              [law()])]
O.step()  # (the cell's velocity gradient times its previous size, as YADE keeps it, is set in a step)
I = utils.createInteraction(0, 2)
I.cellDist = Vector3i(1, -2, 3)
g, p = I.geom, I.phys
g.normal, g.contactPoint = Vector3(0.6, 0.0, 0.8), Vector3(0.25, 0.5, 0.75)  # (penetrationDepth: YADE's own)
p.kn, p.cn, p.ks, p.cs, p.tangensOfFrictionAngle = 1.5e5, 2.5, 6.5e4, 1.25, 0.625
p.normalForce, p.shearForce, p.Fn, p.Fv = Vector3(1.0, 2.0, 3.0), Vector3(-4.0, 5.0, -6.0), 7.25, 0.375
p.mu_k, p.spring, p.slips = 0.5625, Vector3(1e-4, -2e-4, 3e-4), 17
b = O.bodies[2]
s = b.state
s.pos, s.vel, s.angVel, s.mass = Vector3(0.49, 0.41, 0.52), Vector3(1.5, -2.5, 3.5), Vector3(-0.5, 0.75, -1.25), 3.125

def plain(v):
    """A YADE vector or matrix as nested lists, numbers as they are."""
    if hasattr(v, "__getinitargs__"):
        return [plain(x) for x in v.__getinitargs__()]
    return v


def report(yade, got):
    mismatches = [{"member": k, "yade": plain(v), "plugin": plain(got.get(k))}
                  for k, v in yade.items() if plain(got.get(k)) != plain(v)]
    mismatches += [{"member": k, "yade": None, "plugin": plain(v)} for k, v in got.items() if k not in yade]
    print("RESULT " + json.dumps({"mismatches": mismatches}))
    return mismatches


where = law.layoutAddress
pointers = {"Interaction.geom": where(I.geom), "Interaction.phys": where(I.phys), "Body.state": where(b.state),
            "Body.shape": where(b.shape), "Scene.cell": where(O.cell), "Scene.energy": where(O.energy)}
if report(pointers, law.layoutPointers(I, b, O._sceneObj)):
    sys.exit(0)  # (the values would be read through wrong pointers)
got = law.layoutProbe(I, b, O._sceneObj)
c = O.cell
shift = Vector3(*I.cellDist)
yade = {
    "Interaction.id1": I.id1, "Interaction.id2": I.id2, "Interaction.iterMadeReal": I.iterMadeReal,
    "Interaction.cellDist": I.cellDist, "Interaction.isActive": I.isActive,
    "ScGeom.normal": g.normal, "ScGeom.contactPoint": g.contactPoint, "ScGeom.penetrationDepth": g.penetrationDepth,
    "StickSlipPhys.kn": p.kn, "StickSlipPhys.cn": p.cn, "StickSlipPhys.ks": p.ks, "StickSlipPhys.cs": p.cs,
    "StickSlipPhys.tangensOfFrictionAngle": p.tangensOfFrictionAngle, "StickSlipPhys.normalForce": p.normalForce,
    "StickSlipPhys.shearForce": p.shearForce, "StickSlipPhys.Fn": p.Fn, "StickSlipPhys.Fv": p.Fv,
    "StickSlipPhys.mu_k": p.mu_k, "StickSlipPhys.spring": p.spring, "StickSlipPhys.slips": p.slips,
    "Body.id": b.id, "Body.isSphere": True, "Sphere.radius": b.shape.radius,
    "State.pos": s.pos, "State.vel": s.vel, "State.angVel": s.angVel, "State.mass": s.mass,
    "Scene.dt": O.dt, "Scene.iter": O.iter, "Scene.isPeriodic": O.periodic, "Scene.trackEnergy": O.trackEnergy,
    "Scene.bodies": len(O.bodies), "Cell.hSize": c.hSize, "Cell.shiftPos": c.hSize * shift,
    "Cell.shiftVel": c.velGrad * c.prevHSize * shift,
}
# The force container's adders and an energy entry: written through the plugin, read by YADE
f, t = Vector3(0.125, -0.25, 0.5), Vector3(-1.0, 2.0, -4.0)
f0, t0 = O.forces.f(1), O.forces.t(1)
law.layoutAdd(O._sceneObj, 1, f, t)
yade["ForceContainer.addForce"], got["ForceContainer.addForce"] = O.forces.f(1) - f0, f
yade["ForceContainer.addTorque"], got["ForceContainer.addTorque"] = O.forces.t(1) - t0, t
O.energy["stickslip_layout_probe"] = 2.71875
yade["EnergyTracker.get"], got["EnergyTracker.get"] = 2.71875, law.layoutEnergy(O._sceneObj, "stickslip_layout_probe")

report(yade, got)
