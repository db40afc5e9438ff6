// SPDX-License-Identifier: GPL-2.0-or-later
/* Functions that the YADE headers this plugin is compiled with (2025.2.0, the oldest YADE source
   Debian serves) declare and the installed libraries (Debian 12's YADE 2023.02a) may lack.

   Every file that includes a YADE class's header registers that class with YADE's factory and
   so emits its inline members, among them the Python registration, which names every Python
   method of the class. Where the headers name a method the installed library does not define,
   the plugin would fail to load (YADE aborts on an undefined symbol). These definitions fill the
   gap. They are weak: where the installed library defines the function, its definition is the
   one used. And the class's inline members this plugin emits are never the ones called either:
   the library, loaded first, defines them too, and the dynamic linker takes its copies. */
#include <core/Body.hpp>
#include <core/Cell.hpp>
#include <core/State.hpp>

namespace yade {

// Cell.getFluctuationVelocity (added after 2023.02a): a body's velocity less the mean field's
__attribute__((weak)) Vector3r Cell::bodyFluctuationVelPy(const shared_ptr<Body>& b)
{
	if (b) return bodyFluctuationVel(b->state->pos, b->state->vel, prevVelGrad);
	return Vector3r::Zero();
}

} // namespace yade
