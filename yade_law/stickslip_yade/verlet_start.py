# SPDX-License-Identifier: GPL-2.0-or-later
"""velocity_verlet_start: YADE's first step as the start of velocity Verlet (pyref,
LIGGGHTS), for a run that must be their twin (yade_law/README.md, "Twin runs")."""


def velocity_verlet_start(law=None):
    """Make YADE's first step the start of velocity Verlet (pyref, LIGGGHTS), for a run that
    must be their twin; call it once, instead of the first O.step().

    YADE's leapfrog takes a body's velocity as v(t - dt/2): its first step computes the
    forces from v(0), loads every spring by V_s dt and gives the whole kick
    v(dt/2) = v(0) + dt F(0)/m. Velocity Verlet evaluates the forces at the start with no
    time elapsed (the springs not loaded) and gives half a kick. This step does the same:
    the law's forces at x(0), v(0) as a setup evaluation (law.setup_step), then each
    dynamic sphere gets v(dt/2) = v(0) + dt/2 F(0)/m (the mean of YADE's v(0) and
    v(0) + dt F(0)/m), x(dt) = x(0) + dt v(dt/2), and its spin likewise. From then on
    leapfrog and velocity Verlet give the same positions and forces."""
    import builtins

    from yade import O, Quaternion, Sphere, Vector3

    law = builtins.stickslip_law if law is None else law
    if O.iter != 0:
        raise RuntimeError(f"velocity_verlet_start: the scene is at iteration {O.iter}; it starts a run (iteration 0)")
    bodies = [b for b in O.bodies if b is not None and b.dynamic]
    for b in bodies:
        if not isinstance(b.shape, Sphere) or b.isClump or b.isClumpMember:
            raise ValueError(f"velocity_verlet_start: body {b.id} is not a free sphere (clumps and other shapes "
                             f"are not supported)")
    # (copies: a State's vectors are views of YADE's own)
    start = [(Vector3(b.state.pos), Vector3(b.state.vel), Vector3(b.state.angVel), Quaternion(b.state.ori))
             for b in bodies]
    law.setup_step = True  # (law.py: the step loads no spring)
    O.step()
    dt = O.dt
    for b, (x0, v0, w0, q0) in zip(bodies, start):
        s = b.state
        v = v0 + 0.5 * (s.vel - v0)
        s.vel, s.pos = v, x0 + dt * v
        w = w0 + 0.5 * (s.angVel - w0)
        if w != s.angVel:
            s.angVel = w
            s.ori = (Quaternion(w / w.norm(), w.norm() * dt) * q0) if w.norm() > 0 else q0
