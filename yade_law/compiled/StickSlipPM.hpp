// SPDX-License-Identifier: GPL-2.0-or-later
/* The stick-slip friction law of Khellaf & Mansouri (2024) as a compiled YADE law: the same law
   as the Python one (yade_law/stickslip_yade/, docs/law.md), built as a YADE plugin against
   YADE's own headers and loaded into Debian's YADE through a private prefix
   (yade_law/README.md, "The compiled law").

   - StickSlipPhys: a ViscElPhys (kn, cn from the materials in series, as YADE's ViscEl law)
     whose tangential part is the law's: ks = Ks, cs = nu_s, tangensOfFrictionAngle = mu_s,
     mu_k, the spring D, the slip state and the record.
   - Ip2_ViscElMat_ViscElMat_StickSlipPhys: makes it, with the law's parameters.
   - Law2_ScGeom_StickSlipPhys_StickSlip: the normal force as Law2_ScGeom_ViscElPhys_Basic
     computes it (eq. 3), the tangential force by the law's core (law_core/stick_slip_core.h).
   - StickSlipGuard: an engine after the InteractionLoop that stops the run with the law's one
     line when a contact went non-finite (an exception thrown inside the parallel loop would
     abort YADE). */
#pragma once

#include <core/Dispatching.hpp>
#include <core/GlobalEngine.hpp>
#include <pkg/dem/ScGeom.hpp>
#include <pkg/dem/ViscoelasticPM.hpp>

#include <atomic>
#include <mutex>
#include <string>

namespace yade {

class StickSlipPhys : public ViscElPhys {
public:
	virtual ~StickSlipPhys();
	// clang-format off
	YADE_CLASS_BASE_DOC_ATTRS_CTOR(StickSlipPhys,ViscElPhys,"IPhys of the stick-slip law (Khellaf & Mansouri 2024), made by :yref:`Ip2_ViscElMat_ViscElMat_StickSlipPhys` for :yref:`Law2_ScGeom_StickSlipPhys_StickSlip`. kn and cn are YADE's ViscEl values; ks is Ks, cs is nu_s, tangensOfFrictionAngle is mu_s. normalForce + shearForce is the force on body 2 (as YADE's own laws).",
		((Real,mu_k,NaN,,"Kinetic friction coefficient: after a slip the force is Fmin = (2 mu_k - mu_s) Fn (eq. 8)."))
		((Vector3r,spring,Vector3r::Zero(),,"The tangential spring D (eq. 7): the elongation whose force -Ks D acts on body 1."))
		((bool,slipped,false,,"The contact slipped in the last step."))
		((long,slips,0,,"Steps in which the contact slipped since it was made."))
		((int,spheres,0,Attr::readonly,"Which bodies are spheres: 1 body 1, 2 body 2, 3 both (set when the contact is made).")),
		createIndex();
	);
	// clang-format on
	REGISTER_CLASS_INDEX(StickSlipPhys, ViscElPhys);
};
REGISTER_SERIALIZABLE(StickSlipPhys);

class Ip2_ViscElMat_ViscElMat_StickSlipPhys : public Ip2_ViscElMat_ViscElMat_ViscElPhys {
public:
	void go(const shared_ptr<Material>& b1, const shared_ptr<Material>& b2, const shared_ptr<Interaction>& interaction) override;
	void postLoad(Ip2_ViscElMat_ViscElMat_StickSlipPhys&);
	// clang-format off
	YADE_CLASS_BASE_DOC_ATTRS(Ip2_ViscElMat_ViscElMat_StickSlipPhys,Ip2_ViscElMat_ViscElMat_ViscElPhys,"Makes :yref:`StickSlipPhys` from two :yref:`ViscElMat`: kn and cn as :yref:`Ip2_ViscElMat_ViscElMat_ViscElPhys` (the materials in series), the tangential parameters the stick-slip law's, from this functor. Values outside the law's ranges raise ValueError naming the parameter.",
		((Real,ks,NaN,Attr::triggerPostLoad,"Tangential stiffness Ks (eq. 5) [N/m], > 0."))
		((Real,nu_s,0,Attr::triggerPostLoad,"Tangential dashpot nu_s (eq. 5) [N s/m], >= 0."))
		((Real,mu_s,NaN,Attr::triggerPostLoad,"Static friction coefficient mu_s, > 0."))
		((Real,mu_k,NaN,Attr::triggerPostLoad,"Kinetic friction coefficient mu_k, in [mu_s/2, mu_s]."))
	);
	// clang-format on
	FUNCTOR2D(ViscElMat, ViscElMat);
};
REGISTER_SERIALIZABLE(Ip2_ViscElMat_ViscElMat_StickSlipPhys);

class Law2_ScGeom_StickSlipPhys_StickSlip : public LawFunctor {
public:
	enum Reset { SPRING = 0, TOTAL = 1 };
	enum Timing { STEP = 0, EXACT = 1 };
	bool go(shared_ptr<IGeom>&, shared_ptr<IPhys>&, Interaction*) override;
	void postLoad(Law2_ScGeom_StickSlipPhys_StickSlip&);
	// the first error of the run (a non-finite contact), for StickSlipGuard
	std::atomic<bool> failed { false };
	std::atomic<long> slippedNow { 0 }; // contacts that slipped in this step (the guard moves it to nSlipped)
	std::string       error;
	std::mutex        errorLock;
	void              fail(const std::string& message);
	std::string       takeError();
	// YADE's layout as this plugin reads it, for the layout check (yade_law/compiled/layout_probe.py):
	// first the addresses the objects' pointer members hold (nothing dereferenced), then values
	static boost::python::dict layoutPointers(const shared_ptr<Interaction>& I, const shared_ptr<Body>& b, const boost::python::object& scene);
	static unsigned long       layoutAddress(const boost::python::object& object);
	static boost::python::dict layoutProbe(const shared_ptr<Interaction>& I, const shared_ptr<Body>& b, const boost::python::object& scene);
	static void                layoutAdd(const boost::python::object& scene, long id, const Vector3r& f, const Vector3r& t);
	static Real                layoutEnergy(const boost::python::object& scene, const std::string& name);
	static bool                asPlugin(); // built as a plugin for another YADE (the layout check applies)
	// clang-format off
	YADE_CLASS_BASE_DOC_ATTRS_CTOR_PY(Law2_ScGeom_StickSlipPhys_StickSlip,LawFunctor,"The stick-slip friction law of Khellaf & Mansouri (2024) (docs/law.md): YADE's ViscEl normal force (eq. 3), a tangential spring and dashpot (eq. 5) in series with a slider that slips at mu_s Fn and drops to Fmin = (2 mu_k - mu_s) Fn (eq. 8).",
		((std::string,reset,"spring",Attr::triggerPostLoad,"At a slip the spring alone carries Fmin ('spring', eq. 8) or spring and dashpot together ('total')."))
		((std::string,slip_timing,"step",Attr::triggerPostLoad,"The slip tested at the end of the step ('step', the paper) or each slip at its time inside it ('exact')."))
		((bool,rotation,true,,"Spheres' spins enter the contact velocity and the law's torques are applied (walls', facets' and boxes' turns always enter)."))
		((long,nSlipped,0,(Attr::readonly|Attr::noSave),"Contacts that slipped in the last step (counted by StickSlipGuard)."))
		((long,setupIter,-1,,"The iteration at which the law evaluates the forces with no time elapsed (springs not loaded): velocity Verlet's start (stickslip_yade.velocity_verlet_start)."))
		((int,resetMode,SPRING,(Attr::hidden|Attr::noSave),"reset as a number"))
		((int,timingMode,STEP,(Attr::hidden|Attr::noSave),"slip_timing as a number"))
		((int,slipIx,-1,(Attr::hidden|Attr::noSave),"O.energy index: stickslip_slip"))
		((int,dashpotIx,-1,(Attr::hidden|Attr::noSave),"O.energy index: stickslip_dashpot"))
		((int,normalDampingIx,-1,(Attr::hidden|Attr::noSave),"O.energy index: stickslip_normal_damping"))
		((int,springIx,-1,(Attr::hidden|Attr::noSave),"O.energy index: stickslip_spring"))
		((int,normalElasticIx,-1,(Attr::hidden|Attr::noSave),"O.energy index: stickslip_normal_elastic"))
		,
		/*ctor*/,
		/*py*/
		.def("layoutPointers",&Law2_ScGeom_StickSlipPhys_StickSlip::layoutPointers,"(for the layout check) the addresses the pointer members of an interaction, a body and the scene hold, as this plugin reads them").staticmethod("layoutPointers")
		.def("layoutAddress",&Law2_ScGeom_StickSlipPhys_StickSlip::layoutAddress,"(for the layout check) the address of the YADE object Python holds").staticmethod("layoutAddress")
		.def("layoutProbe",&Law2_ScGeom_StickSlipPhys_StickSlip::layoutProbe,"(for the layout check) the members of an interaction, a body and the scene as this plugin reads them").staticmethod("layoutProbe")
		.def("layoutAdd",&Law2_ScGeom_StickSlipPhys_StickSlip::layoutAdd,"(for the layout check) a force and a torque added to a body through this plugin").staticmethod("layoutAdd")
		.def("layoutEnergy",&Law2_ScGeom_StickSlipPhys_StickSlip::layoutEnergy,"(for the layout check) an O.energy entry as this plugin reads it").staticmethod("layoutEnergy")
		.def("asPlugin",&Law2_ScGeom_StickSlipPhys_StickSlip::asPlugin,"True if built as a plugin against another YADE's headers (yade_law/compiled/CMakeLists.txt), False if compiled into YADE with its own sources").staticmethod("asPlugin")
	);
	// clang-format on
	FUNCTOR2D(ScGeom, StickSlipPhys);
};
REGISTER_SERIALIZABLE(Law2_ScGeom_StickSlipPhys_StickSlip);

class StickSlipGuard : public GlobalEngine {
public:
	void action() override;
	// clang-format off
	YADE_CLASS_BASE_DOC_ATTRS(StickSlipGuard,GlobalEngine,"Stops the run with the stick-slip law's one line (RuntimeError) when a contact of :yref:`law<StickSlipGuard.law>` went non-finite in this step, and counts the contacts that slipped in it (:yref:`Law2_ScGeom_StickSlipPhys_StickSlip.nSlipped`). Place it right after the InteractionLoop (stickslip_yade.stickslip_engines does).",
		((shared_ptr<Law2_ScGeom_StickSlipPhys_StickSlip>,law,,,"The law whose contacts it watches."))
	);
	// clang-format on
};
REGISTER_SERIALIZABLE(StickSlipGuard);

} // namespace yade
