# SPDX-License-Identifier: GPL-2.0-or-later
"""The compiled law (yade_law/compiled/, a YADE plugin) from a YADE script: its engines and a
view of its contacts with the Python law's queries (contact, lookup, has_slipped, ...).

The plugin is loaded when YADE starts through the launcher build/yade_law/yade-stickslip (a
private YADE_PREFIX holding Debian's YADE and the plugin), which first checks that the plugin
reads YADE's classes where this YADE keeps them (yade_law/compiled/layout_check.py). A script
started otherwise gets one line saying how to start it. A YADE built from source with the law's
files in its pkg/dem/ has the classes itself, with its own headers: no prefix, no check.
"""
import importlib.util
import os

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # yade_law/
LAW2 = "Law2_ScGeom_StickSlipPhys_StickSlip"
LAUNCHER = "build/yade_law/yade-stickslip"


def loaded():
    """True if the YADE of this process has the plugin's classes."""
    import yade.wrapper

    return hasattr(yade.wrapper, LAW2)


def require():
    """Refuse, in one line, a process whose YADE lacks the plugin or whose plugin failed the
    layout check."""
    if not loaded():
        raise RuntimeError(f"backend = 'cpp': the compiled law is not loaded in this YADE; start YADE with "
                           f"{LAUNCHER} (built by ./run.sh setup) instead of yade, or use backend = 'python'")
    import yade.wrapper

    if not getattr(yade.wrapper, LAW2).asPlugin():
        return  # compiled into a YADE built from source (yade_law/README.md): YADE's own headers
    verdict = layout_check().verdict(os.environ.get("YADE_PREFIX", ""))
    if verdict:
        raise RuntimeError(verdict)


def layout_check():
    """yade_law/compiled/layout_check.py, imported from its file (it is not in a package)."""
    path = os.path.join(HERE, "compiled", "layout_check.py")
    spec = importlib.util.spec_from_file_location("stickslip_yade_layout_check", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def functors(ks, nu_s, mu_s, mu_k, reset, slip_timing, rotation):
    """The compiled law's Ip2, Law2 and guard (ValueError naming a parameter out of range)."""
    import yade.wrapper as w

    ip2 = w.Ip2_ViscElMat_ViscElMat_StickSlipPhys(ks=ks, nu_s=nu_s, mu_s=mu_s, mu_k=mu_k)
    law = getattr(w, LAW2)(reset=reset, slip_timing=slip_timing, rotation=rotation)
    return ip2, law, w.StickSlipGuard(law=law, label="stickslip_guard")


class CompiledLaw:
    """The compiled law's contacts, read from YADE's interactions, with the Python law's
    queries (law.py: StickSlipLaw's), so that a script reads either law the same way."""

    def __init__(self, law):
        self.law = law  # the Law2 functor

    @staticmethod
    def _phys(id1, id2):
        from yade import O

        I = O.interactions[id1, id2] if O.interactions.has(id1, id2) else None
        if I is None or not I.isReal or type(I.phys).__name__ != "StickSlipPhys":
            return None, None
        return I, I.phys

    def contact(self, id1, id2):
        """(Fn, F_s on id1 as (3,) array, slipped this step, slip steps since made) or None."""
        import numpy as np

        I, p = self._phys(id1, id2)
        if p is None or I.geom.penetrationDepth < 0:
            return None
        f = -np.array(p.shearForce.__getinitargs__())  # (shearForce: the force on id2)
        if I.id1 != id1:
            f = -f
        return max(0.0, p.Fn + p.Fv), f, bool(p.slipped), int(p.slips)  # (Fn as the law computed it)

    def lookup(self, id1, id2):
        got = self.contact(id1, id2)
        return None if got is None else got[:3]

    def has_slipped(self, id1, id2):
        _, p = self._phys(id1, id2)
        return p is not None and bool(p.slipped)

    def _real(self):
        from yade import O

        return [I for I in O.interactions if type(I.phys).__name__ == "StickSlipPhys"]

    def n_contacts(self):
        return len(self._real())

    @property
    def n_slipped(self):
        """Contacts that slipped in the last step (the law counts them, its guard reports)."""
        return self.law.nSlipped

    # the Python law's per-contact arrays (keys id1 << 32 | id2, fn, F_s on id1, slipped, count)
    def _arrays(self):
        import numpy as np

        L = sorted(self._real(), key=lambda I: (I.id1, I.id2))
        keys = np.array([(I.id1 << 32) | I.id2 for I in L], np.int64)
        fn = np.array([max(0.0, I.phys.Fn + I.phys.Fv) for I in L])
        F_s = -np.array([I.phys.shearForce.__getinitargs__() for I in L]).reshape(len(L), 3)
        slipped = np.array([I.phys.slipped for I in L], bool)
        count = np.array([I.phys.slips for I in L], np.int64)
        return keys, fn, F_s, slipped, count

    keys = property(lambda self: self._arrays()[0])
    fn = property(lambda self: self._arrays()[1])
    F_s = property(lambda self: self._arrays()[2])
    slipped = property(lambda self: self._arrays()[3])
    count = property(lambda self: self._arrays()[4])

    @property
    def setup_step(self):
        from yade import O

        return self.law.setupIter == O.iter

    @setup_step.setter
    def setup_step(self, on):
        """True: the next step evaluates the forces with no time elapsed (verlet_start.py)."""
        from yade import O

        self.law.setupIter = O.iter if on else -1

    error = None  # (the compiled law's errors stop the run through its guard, with their line)
