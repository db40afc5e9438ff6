/* SPDX-License-Identifier: GPL-2.0-or-later
   The pair and wall styles of `tangential stick_slip`: LIGGGHTS' own granular pair style
   and wall templates, with the contact-model settings checked (and two keywords of this
   model translated) before LIGGGHTS parses them. */

#ifndef STICK_SLIP_STYLES_H_
#define STICK_SLIP_STYLES_H_

#include <mpi.h>
#include "fix_insert_stream.h"  // must precede pair_gran_base.h (a stub header otherwise fails)
#include "contact_models.h"
#include "granular_pair_style.h"
#include "granular_wall.h"
#include "pair_gran_base.h"
#include "fix_wall_gran_base.h"
#include "error.h"
#include "tangential_model_stick_slip.h"
#include <cstring>
#include <string>
#include <vector>

namespace LIGGGHTS {
namespace StickSlip {

using namespace LAMMPS_NS;

/* The settings after the model names, as LIGGGHTS' Settings::parseArguments will read them
   (keyword value pairs), checked first so that a bad line is one clear error:
   - a keyword at the end of the line without its value (LIGGGHTS would read past the end
     of its argument list: an abort, or a garbled message);
   - this model's on/off keywords with another value (LIGGGHTS does not list the allowed
     values);
   - `history_rotation keep_length|project` and `history_on_separation drop|keep` become the
     model's internal on/off settings. */
class CheckedArgs {
  std::vector<std::string> words;
  std::vector<char *> ptrs;

  static void fail(LAMMPS * lmp, const std::string & command, const std::string & what)
  {
    const std::string msg = command + ": " + what;
    lmp->error->all(FLERR, msg.c_str());
  }

public:
  CheckedArgs(LAMMPS * lmp, const std::string & command, int nargs, char ** args)
  {
    static const char * const ON_OFF[] = { "slip_reset_total", "stick_slip_record", "exact_slip_timing",
                                           "heating_tangential_history", "heating_tracking",
                                           "computeElasticPotential", "computeDissipatedEnergy" };
    for (int k = 0; k < nargs; k += 2) {
      const std::string key = args[k];
      if (k + 1 >= nargs)
        fail(lmp, command, "setting '" + key + "' at the end of the line has no value "
                           "(contact-model settings take one value each, e.g. '" + key + " on')");
      const std::string value = args[k + 1];
      std::string internal = key, translated = value;
      if (key == "history_rotation") {
        if (value != "keep_length" && value != "project")
          fail(lmp, command, "history_rotation " + value + ": allowed values are keep_length (default) and project");
        internal = ContactModels::StickSlip::ROTATION_PROJECT;
        translated = value == "project" ? "on" : "off";
      } else if (key == "history_on_separation") {
        if (value != "drop" && value != "keep")
          fail(lmp, command, "history_on_separation " + value + ": allowed values are drop (default) and keep");
        internal = ContactModels::StickSlip::SEPARATION_KEEP;
        translated = value == "keep" ? "on" : "off";
      } else {
        for (size_t j = 0; j < sizeof ON_OFF / sizeof *ON_OFF; j++)
          if (key == ON_OFF[j] && value != "on" && value != "off")
            fail(lmp, command, key + " " + value + ": allowed values are on and off");
      }
      words.push_back(internal);
      words.push_back(translated);
    }
    for (size_t k = 0; k < words.size(); k++) ptrs.push_back(&words[k][0]);
    ptrs.push_back(NULL);
  }

  int nargs() const { return static_cast<int>(words.size()); }
  char ** args() { return &ptrs[0]; }
};

template<typename Model>
class PairStyle : public PairStyles::Granular<Model> {
  LAMMPS * lmp_;
public:
  PairStyle(LAMMPS * lmp, PairGran * parent, int64_t hash) : PairStyles::Granular<Model>(lmp, parent, hash), lmp_(lmp) {}

  virtual void settings(int nargs, char ** args, IContactHistorySetup * hsetup)
  {
    CheckedArgs checked(lmp_, "pair_style gran", nargs, args);
    PairStyles::Granular<Model>::settings(checked.nargs(), checked.args(), hsetup);
  }
};

template<typename Model>
class WallStyle : public Walls::Granular<Model> {
  LAMMPS * lmp_;
  FixWallGran * parent_;
public:
  WallStyle(LAMMPS * lmp, FixWallGran * parent, int64_t hash) :
    Walls::Granular<Model>(lmp, parent, hash), lmp_(lmp), parent_(parent) {}

  virtual void settings(int nargs, char ** args, IContactHistorySetup * hsetup)
  {
    CheckedArgs checked(lmp_, std::string("fix ") + parent_->id + " " + parent_->style, nargs, args);
    Walls::Granular<Model>::settings(checked.nargs(), checked.args(), hsetup);
  }
};

template<int M, int C, int R, int S>
struct Combination {
  typedef ContactModels::GranStyle<M, ContactModels::TANGENTIAL_STICK_SLIP, C, R, S> Style;
  typedef ContactModels::ContactModel<Style> Model;

  static PairStyles::IGranularPairStyle * pair(LAMMPS * lmp, PairGran * parent, int64_t hash)
  { return new PairStyle<Model>(lmp, parent, hash); }

  static Walls::IGranularWall * wall(LAMMPS * lmp, FixWallGran * parent, int64_t hash)
  { return new WallStyle<Model>(lmp, parent, hash); }

  static void add(bool with_pair, bool with_wall)
  {
    const int64_t hash = Style::HASHCODE;  // a copy: the static member has no definition to bind to
    if (with_pair) PairStyles::Factory::instance().addStyle("gran", hash, &pair);
    if (with_wall) Walls::Factory::instance().addStyle("gran", hash, &wall);
  }
};

}
}

#endif
