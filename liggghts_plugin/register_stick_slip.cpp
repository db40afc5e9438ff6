/* Registers `tangential stick_slip` with the installed LIGGGHTS library when this
   shared object is loaded (static initializer): the model name, and one pair style
   and one wall style per supported combination of normal and rolling model.
   Every other combination with stick_slip is registered too, as a creator that stops
   with an error listing the supported ones (the library would otherwise say only
   "Unknown tangential model"). */

#include <mpi.h>
#include "fix_insert_stream.h"  // must precede pair_gran_base.h (a stub header otherwise fails)
#include "contact_models.h"
#include "granular_pair_style.h"
#include "granular_wall.h"
#include "pair_gran_base.h"
#include "fix_wall_gran_base.h"
#include "error.h"
#include <set>
#include "tangential_model_stick_slip.h"

using namespace LIGGGHTS;
using namespace LIGGGHTS::ContactModels;

namespace {

const char SUPPORTED[] =
    "tangential stick_slip supports: model hooke, hooke/stiffness, hertz or hertz/stiffness; "
    "rolling_friction off, cdt, epsd, epsd2 or epsd3; no cohesion model; the default surface model";

template<int M, int R>
struct Combination {
  typedef GranStyle<M, TANGENTIAL_STICK_SLIP, COHESION_OFF, R, SURFACE_DEFAULT> Style;
  typedef ContactModel<Style> Model;

  static PairStyles::IGranularPairStyle * pair(LAMMPS * lmp, PairGran * parent, int64_t hash)
  { return new PairStyles::Granular<Model>(lmp, parent, hash); }

  static Walls::IGranularWall * wall(LAMMPS * lmp, FixWallGran * parent, int64_t hash)
  { return new Walls::Granular<Model>(lmp, parent, hash); }

  static void add(std::set<int64_t> & done)
  {
    const int64_t hash = Style::HASHCODE;  // a copy: the static member has no definition to bind to
    PairStyles::Factory::instance().addStyle("gran", hash, &pair);
    Walls::Factory::instance().addStyle("gran", hash, &wall);
    done.insert(hash);
  }
};

PairStyles::IGranularPairStyle * unsupported_pair(LAMMPS * lmp, PairGran *, int64_t)
{
  lmp->error->all(FLERR, SUPPORTED);
  return NULL;
}

Walls::IGranularWall * unsupported_wall(LAMMPS * lmp, FixWallGran *, int64_t)
{
  lmp->error->all(FLERR, SUPPORTED);
  return NULL;
}

template<int R>
void add_normal_models(std::set<int64_t> & done)
{
  Combination<HOOKE, R>::add(done);
  Combination<HOOKE_STIFFNESS, R>::add(done);
  Combination<HERTZ, R>::add(done);
  Combination<HERTZ_STIFFNESS, R>::add(done);
}

struct RegisterStickSlip {
  RegisterStickSlip()
  {
    Factory::instance().addTangentialModel("stick_slip", TANGENTIAL_STICK_SLIP);

    std::set<int64_t> supported;
    add_normal_models<ROLLING_OFF>(supported);
    add_normal_models<ROLLING_CDT>(supported);
    add_normal_models<ROLLING_EPSD>(supported);
    add_normal_models<ROLLING_EPSD2>(supported);
    add_normal_models<ROLLING_EPSD3>(supported);

    // every other combination with stick_slip stops with the list above
    const int normal[] = { NORMAL_OFF,
#define NORMAL_MODEL(ID, NAME, CONST) ID,
#include "style_normal_model.h"
#undef NORMAL_MODEL
    };
    const int cohesion[] = { COHESION_OFF,
#define COHESION_MODEL(ID, NAME, CONST) ID,
#include "style_cohesion_model.h"
#undef COHESION_MODEL
    };
    const int rolling[] = { ROLLING_OFF,
#define ROLLING_MODEL(ID, NAME, CONST) ID,
#include "style_rolling_model.h"
#undef ROLLING_MODEL
    };
    const int surface[] = {
#define SURFACE_MODEL(ID, NAME, CONST) ID,
#include "style_surface_model.h"
#undef SURFACE_MODEL
    };
    for (size_t m = 0; m < sizeof normal / sizeof *normal; m++)
      for (size_t c = 0; c < sizeof cohesion / sizeof *cohesion; c++)
        for (size_t r = 0; r < sizeof rolling / sizeof *rolling; r++)
          for (size_t s = 0; s < sizeof surface / sizeof *surface; s++) {
            const int64_t hash = Utils::generate_gran_hashcode(normal[m], TANGENTIAL_STICK_SLIP, cohesion[c], rolling[r], surface[s]);
            if (supported.count(hash)) continue;
            PairStyles::Factory::instance().addStyle("gran", hash, &unsupported_pair);
            Walls::Factory::instance().addStyle("gran", hash, &unsupported_wall);
          }
  }
};

RegisterStickSlip register_stick_slip;

}
