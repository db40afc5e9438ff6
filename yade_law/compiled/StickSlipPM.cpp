// SPDX-License-Identifier: GPL-2.0-or-later
/* The stick-slip law as a compiled YADE law (StickSlipPM.hpp says what each class is). One
   contact, one step, following docs/law.md step by step, as the Python law
   (yade_law/stickslip_yade/) does it; the law's arithmetic is the one C++ core's. */
#include "StickSlipPM.hpp"
#include "stick_slip_core.h"

#include <core/Scene.hpp>
#include <core/State.hpp>
#include <pkg/common/Sphere.hpp>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

namespace yade {

YADE_PLUGIN((StickSlipPhys)(Ip2_ViscElMat_ViscElMat_StickSlipPhys)(Law2_ScGeom_StickSlipPhys_StickSlip)(StickSlipGuard));

using Core = stickslip::StickSlipCore;

StickSlipPhys::~StickSlipPhys() { }

namespace {
	// Bad input: one line naming the parameter and its allowed range (ValueError in Python)
	[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument(what); }

	std::string number(Real v)
	{
		std::ostringstream s;
		s << v;
		return s.str();
	}

	void checkFinite(const char* name, Real v)
	{
		if (!std::isfinite(static_cast<double>(v))) refuse(std::string(name) + " = " + number(v) + ": must be a finite number");
	}

	bool isSphere(const Body& b) { return b.shape && b.shape->getClassIndex() == Sphere::getClassIndexStatic(); }

	// the three components of an Eigen vector as the core's plain doubles
	struct Vec {
		double v[3];
		explicit Vec(const Vector3r& a)
		        : v { a[0], a[1], a[2] }
		{
		}
	};
}

/* Ip2: the law's parameter rules (docs/law.md), checked whenever one is set from Python or a
   scene is loaded */
void Ip2_ViscElMat_ViscElMat_StickSlipPhys::postLoad(Ip2_ViscElMat_ViscElMat_StickSlipPhys&)
{
	checkFinite("ks", ks);
	checkFinite("nu_s", nu_s);
	checkFinite("mu_s", mu_s);
	checkFinite("mu_k", mu_k);
	if (!(ks > 0)) refuse("ks = " + number(ks) + ": must be > 0");
	if (!(nu_s >= 0)) refuse("nu_s = " + number(nu_s) + ": must be >= 0");
	if (!(mu_s > 0)) refuse("mu_s = " + number(mu_s) + ": must be > 0");
	if (!(mu_s / 2 <= mu_k && mu_k <= mu_s))
		refuse("mu_k = " + number(mu_k) + ": must be in [mu_s/2, mu_s] = [" + number(mu_s / 2) + ", " + number(mu_s)
		       + "] so that 0 <= Fmin = (2 mu_k - mu_s) Fn <= mu_k Fn");
}

void Ip2_ViscElMat_ViscElMat_StickSlipPhys::go(
        const shared_ptr<Material>& b1, const shared_ptr<Material>& b2, const shared_ptr<Interaction>& interaction)
{
	if (interaction->phys) return; // (a contact keeps its phys, and its spring, until it ends)
	shared_ptr<StickSlipPhys> phys(new StickSlipPhys());
	Calculate_ViscElMat_ViscElMat_ViscElPhys(b1, b2, interaction, phys);
	// the tangential part is the law's, whatever the materials say of ks, cs and friction
	phys->ks                     = ks;
	phys->cs                     = nu_s;
	phys->tangensOfFrictionAngle = mu_s;
	phys->mu_k                   = mu_k;
	// (scene: the dispatcher's, or none for an interaction made outside a step: YADE's current)
	phys->spheres = (isSphere(*Body::byId(interaction->getId1(), scene)) ? 1 : 0)
	        | (isSphere(*Body::byId(interaction->getId2(), scene)) ? 2 : 0);
	interaction->phys            = phys;
}

void Law2_ScGeom_StickSlipPhys_StickSlip::postLoad(Law2_ScGeom_StickSlipPhys_StickSlip&)
{
	if (reset == "spring") resetMode = SPRING;
	else if (reset == "total")
		resetMode = TOTAL;
	else
		refuse("reset = '" + reset + "': must be one of spring, total");
	if (slip_timing == "step") timingMode = STEP;
	else if (slip_timing == "exact")
		timingMode = EXACT;
	else
		refuse("slip_timing = '" + slip_timing + "': must be one of step, exact");
}

void Law2_ScGeom_StickSlipPhys_StickSlip::fail(const std::string& message)
{
	std::lock_guard<std::mutex> lock(errorLock);
	if (!failed) {
		error  = message;
		failed = true;
	}
}

std::string Law2_ScGeom_StickSlipPhys_StickSlip::takeError()
{
	std::lock_guard<std::mutex> lock(errorLock);
	failed = false;
	return error;
}

namespace {
	bool finite(const Vector3r& v) { return std::isfinite(static_cast<double>(v[0] + v[1] + v[2])); }

	std::string vec(const Vector3r& v)
	{
		std::ostringstream s;
		s.precision(17);
		s << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
		return s.str();
	}
}

/* One contact, one step (docs/law.md, steps 1-6). */
bool Law2_ScGeom_StickSlipPhys_StickSlip::go(shared_ptr<IGeom>& ig, shared_ptr<IPhys>& ip, Interaction* I)
{
	const ScGeom&  geom  = *static_cast<ScGeom*>(ig.get());
	StickSlipPhys& phys  = *static_cast<StickSlipPhys*>(ip.get());
	const Real     delta = geom.penetrationDepth;
	if (delta < 0) return false; // the contact ends, and its spring with it (YADE drops the interaction)

	const Body::id_t     id1 = I->getId1(), id2 = I->getId2();
	const BodyContainer& bodies = *scene->bodies;
	const Body &         b1 = *bodies[id1], &b2 = *bodies[id2];
	const State &        s1 = *b1.state, &s2 = *b2.state;
	const Vector3r&      n = geom.normal; // from body 1 to body 2
	const bool           periodic = scene->isPeriodic;
	const Vector3r       shift2   = periodic ? scene->cell->intrShiftPos(I->cellDist) : Vector3r::Zero();
	const Vector3r       shiftVel = periodic ? scene->cell->intrShiftVel(I->cellDist) : Vector3r::Zero();

	// eq. 3, never tensile, with the operations of Law2_ScGeom_ViscElPhys_Basic (YADE's own
	// normal force, bit for bit: its velocity at YADE's contact point, its sign of the shift)
	const Vector3r c1x            = geom.contactPoint - s1.pos;
	const Vector3r c2x            = geom.contactPoint - s2.pos - shift2;
	const Vector3r yadeVelocity   = (s1.vel + s1.angVel.cross(c1x)) - (s2.vel + s2.angVel.cross(c2x)) + shiftVel;
	const Real     normalVelocity = n.dot(yadeVelocity);
	phys.Fn                       = phys.kn * delta;
	phys.Fv                       = phys.cn * normalVelocity;
	const Real normForceReal      = phys.Fn + phys.Fv;
	if (normForceReal < 0) phys.normalForce = Vector3r::Zero();
	else
		phys.normalForce = normForceReal * n;
	const Real fn = normForceReal < 0 ? Real(0) : normForceReal;

	// step 1: the velocity of body 1's contact point relative to body 2's. A sphere's lever
	// arm reaches midway into the overlap; a wall's (facet's, box's) side is the point of its
	// surface nearest the sphere's centre. Across a periodic boundary body 2's image moves
	// with the cell too.
	const bool sphere1 = phys.spheres & 1, sphere2 = phys.spheres & 2;
	Vector3r   a1, a2, vrel;
	if (sphere1 && sphere2) {
		// a sphere pair: YADE's contact point is the law's, midway in the overlap on the line of
		// the centres, so its lever arms and relative velocity are the law's, but for the cell's
		// shift, which YADE adds where the image's motion is to be subtracted
		a1 = c1x;
		a2 = c2x;
		vrel = rotation ? yadeVelocity : Vector3r(s1.vel - s2.vel + shiftVel);
		if (periodic) vrel -= 2 * shiftVel;
	} else {
		const Real r1 = sphere1 ? static_cast<const Sphere&>(*b1.shape).radius : Real(0);
		const Real r2 = sphere2 ? static_cast<const Sphere&>(*b2.shape).radius : Real(0);
		const Real half = 0.5 * delta;
		if (sphere1) a1 = (r1 - half) * n;
		else
			a1 = (s2.pos + shift2 - (r2 - delta) * n) - s1.pos;
		if (sphere2) a2 = -(r2 - half) * n;
		else
			a2 = (s1.pos + (r1 - delta) * n) - (s2.pos + shift2);
		vrel = s1.vel - s2.vel - shiftVel;
		if (rotation || !sphere1) vrel += s1.angVel.cross(a1);
		if (rotation || !sphere2) vrel -= s2.angVel.cross(a2);
	}
	const Real     vn = n.dot(vrel);
	const Vector3r Vs = vrel - vn * n; // eq. 6

	Vector3r& D = phys.spring;
	Vector3r  F;
	bool      slipped = false;
	double    stick   = 1.0; // share of the step spent sticking (the energy books)
	double    before2 = 0.0; // |D|^2 at the step's start
	const Real dt = scene->iter == setupIter ? Real(0) : scene->dt;
	if (!(delta > 0)) {
		// touching at zero overlap (YADE keeps such a contact with a wall or facet): no contact
		// yet for the law (docs/law.md step 3), no force, no spring
		D = F = Vector3r::Zero();
	} else {
		// step 3: the spring turned into the current tangent plane keeping its length
		const Real dn = D.dot(n);
		if (dn != 0) {
			const Real old2 = D.squaredNorm();
			D -= dn * n;
			const Real new2 = D.squaredNorm();
			if (new2 > 0) D *= std::sqrt(old2 / new2);
		}
		before2 = D.squaredNorm();
		// eq. 7, then eq. 5: the trial force on body 1
		D += Vs * dt;
		const Real nu_s = phys.cs, ks = phys.ks, mu_s = phys.tangensOfFrictionAngle;
		F                   = -ks * D - nu_s * Vs;
		const Real T        = mu_s * fn;
		const Real fmin     = Core::kinetic(mu_s, phys.mu_k) * fn;
		const Real mag2     = F.squaredNorm();
		slipped             = Core::slips(mag2, T * T); // step 5, squared: a sticking step needs no root
		Vec        f(F), d(D), v(Vs);
		if (timingMode == EXACT) {
			slipped = Core::exact_step(
			        slipped, f.v, d.v, v.v, ks, nu_s, dt, T, fmin, Core::kinetic(mu_s, phys.mu_k) / mu_s, resetMode == TOTAL, stick);
		} else if (slipped) {
			// the force drops to Fmin along the trial force, the spring is reset (eq. 8)
			const double fdamp[3] = { -nu_s * v.v[0], -nu_s * v.v[1], -nu_s * v.v[2] };
			Core::drop_to(f.v, fmin, std::sqrt(mag2), Core::stock_ratio);
			Core::reset(f.v, fdamp, ks, resetMode == TOTAL, d.v);
			stick = 0.0;
		}
		if (slipped) {
			F = Vector3r(f.v[0], f.v[1], f.v[2]);
			D = Vector3r(d.v[0], d.v[1], d.v[2]);
		}
	}
	phys.slipped = slipped;
	if (slipped) {
		phys.slips++;
		slippedNow.fetch_add(1, std::memory_order_relaxed);
	}
	phys.shearForce = -F; // the tangential force on body 2, as YADE's laws keep it

	if (!std::isfinite(static_cast<double>(fn + F[0] + F[1] + F[2]))) {
		std::ostringstream s;
		s.precision(17);
		s << "stick-slip law: ";
		for (const auto* b : { &b1, &b2 })
			for (const auto& [what, x] : { std::pair<const char*, const Vector3r*>("position", &b->state->pos),
			                               std::pair<const char*, const Vector3r*>("velocity", &b->state->vel),
			                               std::pair<const char*, const Vector3r*>("angular velocity", &b->state->angVel) })
				if (!finite(*x)) {
					s << "body " << b->getId() << " has a non-finite " << what << " " << vec(*x) << " at iteration " << scene->iter
					  << ": the run has blown up (time step above the stability limit?) or was given a non-finite value";
					fail(s.str());
					return true;
				}
		s << "non-finite force on contact (" << id1 << ", " << id2 << ") at iteration " << scene->iter << " (Fn = " << fn
		  << ", F_s = " << vec(F) << "): bodies at the same place, or a blown-up run";
		fail(s.str());
		return true;
	}

	if (scene->trackEnergy) {
		// docs/law.md, Energy: the work received less the spring's gain; the dashpot's share
		// over the time the contact stuck, the slips' the rest. The normal law's books too
		// (YADE's ViscEl law keeps none).
		const Vec  f(F), v(Vs);
		const Real after2  = D.squaredNorm();
		const Real total   = (delta > 0) ? Real(Core::dissipated(f.v, v.v, dt, phys.ks, before2, after2)) : Real(0);
		const Real dashpot = (delta > 0) ? phys.cs * Vs.squaredNorm() * dt * stick : Real(0);
		scene->energy->add(total - dashpot, "stickslip_slip", slipIx, false);
		scene->energy->add(dashpot, "stickslip_dashpot", dashpotIx, false);
		scene->energy->add((fn - phys.kn * delta) * vn * dt, "stickslip_normal_damping", normalDampingIx, false);
		scene->energy->add(0.5 * phys.ks * after2, "stickslip_spring", springIx, true);
		scene->energy->add(0.5 * phys.kn * delta * delta, "stickslip_normal_elastic", normalElasticIx, true);
	}

	if (!I->isActive) return true; // (as YADE's ViscEl law: an inactive contact applies nothing)
	// step 6: -Fn n + F_s on body 1, the opposite on body 2; the normal force's torques as
	// YADE's ViscEl law gives them, the law's about the lever arms
	addForce(id1, F - phys.normalForce, scene);
	addForce(id2, phys.normalForce - F, scene);
	if (rotation && sphere1 && sphere2) { // (the same lever arms: one cross product a body)
		addTorque(id1, c1x.cross(F - phys.normalForce), scene);
		addTorque(id2, c2x.cross(phys.normalForce - F), scene);
	} else if (rotation) {
		addTorque(id1, -c1x.cross(phys.normalForce) + a1.cross(F), scene);
		addTorque(id2, c2x.cross(phys.normalForce) - a2.cross(F), scene);
	} else {
		addTorque(id1, -c1x.cross(phys.normalForce), scene);
		addTorque(id2, c2x.cross(phys.normalForce), scene);
	}
	return true;
}

void StickSlipGuard::action()
{
	if (!law) return;
	law->nSlipped = law->slippedNow.exchange(0);
	if (scene->trackEnergy) {
		// the law's books exist from the first step on, contacts or not (as the Python law's)
		scene->energy->add(0, "stickslip_slip", law->slipIx, false);
		scene->energy->add(0, "stickslip_dashpot", law->dashpotIx, false);
		scene->energy->add(0, "stickslip_normal_damping", law->normalDampingIx, false);
		scene->energy->add(0, "stickslip_spring", law->springIx, true);
		scene->energy->add(0, "stickslip_normal_elastic", law->normalElasticIx, true);
	}
	if (law->failed) throw std::runtime_error(law->takeError());
}

/* ---- the layout check: what this plugin reads where YADE keeps it ---- */
namespace {
	unsigned long address(const void* p) { return static_cast<unsigned long>(reinterpret_cast<uintptr_t>(p)); }
}

boost::python::dict
Law2_ScGeom_StickSlipPhys_StickSlip::layoutPointers(const shared_ptr<Interaction>& I, const shared_ptr<Body>& b, const boost::python::object& scene)
{
	const Scene*        s = boost::python::extract<shared_ptr<Scene>>(scene)().get();
	boost::python::dict out;
	out["Interaction.geom"] = address(I->geom.get());
	out["Interaction.phys"] = address(I->phys.get());
	out["Body.state"]       = address(b->state.get());
	out["Body.shape"]       = address(b->shape.get());
	out["Scene.cell"]       = address(s->cell.get());
	out["Scene.energy"]     = address(s->energy.get());
	return out;
}

unsigned long Law2_ScGeom_StickSlipPhys_StickSlip::layoutAddress(const boost::python::object& object)
{
	return address(boost::python::extract<shared_ptr<Serializable>>(object)().get());
}

boost::python::dict Law2_ScGeom_StickSlipPhys_StickSlip::layoutProbe(const shared_ptr<Interaction>& I, const shared_ptr<Body>& b, const boost::python::object& scene)
{
	const Scene* s = boost::python::extract<shared_ptr<Scene>>(scene)().get();
	boost::python::dict out;
	out["Interaction.id1"]          = I->getId1();
	out["Interaction.id2"]          = I->getId2();
	out["Interaction.iterMadeReal"] = I->iterMadeReal;
	out["Interaction.cellDist"]     = I->cellDist;
	out["Interaction.isActive"]     = I->isActive;
	const ScGeom* g                 = dynamic_cast<const ScGeom*>(I->geom.get());
	if (g) {
		out["ScGeom.normal"]           = g->normal;
		out["ScGeom.contactPoint"]     = g->contactPoint;
		out["ScGeom.penetrationDepth"] = g->penetrationDepth;
	}
	const StickSlipPhys* p = dynamic_cast<const StickSlipPhys*>(I->phys.get());
	if (p) {
		out["StickSlipPhys.kn"]                     = p->kn;
		out["StickSlipPhys.cn"]                     = p->cn;
		out["StickSlipPhys.ks"]                     = p->ks;
		out["StickSlipPhys.cs"]                     = p->cs;
		out["StickSlipPhys.tangensOfFrictionAngle"] = p->tangensOfFrictionAngle;
		out["StickSlipPhys.normalForce"]            = p->normalForce;
		out["StickSlipPhys.shearForce"]             = p->shearForce;
		out["StickSlipPhys.Fn"]                     = p->Fn;
		out["StickSlipPhys.Fv"]                     = p->Fv;
		out["StickSlipPhys.mu_k"]                   = p->mu_k;
		out["StickSlipPhys.spring"]                 = p->spring;
		out["StickSlipPhys.slips"]                  = p->slips;
	}
	out["Body.id"]         = b->getId();
	out["Body.isSphere"]   = isSphere(*b);
	const Sphere* sph      = dynamic_cast<const Sphere*>(b->shape.get());
	if (sph) out["Sphere.radius"] = sph->radius;
	const State& st        = *b->state;
	out["State.pos"]       = st.pos;
	out["State.vel"]       = st.vel;
	out["State.angVel"]    = st.angVel;
	out["State.mass"]      = st.mass;
	out["Scene.dt"]        = s->dt;
	out["Scene.iter"]      = s->iter;
	out["Scene.isPeriodic"] = s->isPeriodic;
	out["Scene.trackEnergy"] = s->trackEnergy;
	out["Scene.bodies"]    = long(s->bodies->size());
	out["Cell.hSize"]      = s->cell->hSize;
	out["Cell.shiftPos"]   = s->cell->intrShiftPos(I->cellDist);
	out["Cell.shiftVel"]   = s->cell->intrShiftVel(I->cellDist);
	return out;
}

void Law2_ScGeom_StickSlipPhys_StickSlip::layoutAdd(const boost::python::object& scene, long id, const Vector3r& f, const Vector3r& t)
{
	Scene* s = boost::python::extract<shared_ptr<Scene>>(scene)().get();
	s->forces.addForce(id, f);
	s->forces.addTorque(id, t);
}

Real Law2_ScGeom_StickSlipPhys_StickSlip::layoutEnergy(const boost::python::object& scene, const std::string& name)
{
	const Scene* s = boost::python::extract<shared_ptr<Scene>>(scene)().get();
	int id = -1;
	s->energy->findId(name, id, false, false);
	return id < 0 ? Real(NAN) : s->energy->energies.get(id);
}

bool Law2_ScGeom_StickSlipPhys_StickSlip::asPlugin()
{
#ifdef STICKSLIP_YADE_PLUGIN
	return true; // yade_law/compiled/CMakeLists.txt: YADE 2025.2.0's headers, Debian's YADE's libraries
#else
	return false; // compiled into YADE from its own source: its headers are its own
#endif
}

} // namespace yade
