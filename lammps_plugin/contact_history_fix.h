/* SPDX-License-Identifier: GPL-2.0-or-later
   The pair style's contact history fix: stock FixNeighHistory (same ID, same style name
   NEIGH_HISTORY, so restart files are stock's and interchangeable), except that
   write_restart outside a run saves the contact history that the end of the last run
   stored with the atoms, instead of storing it again from the neighbour list.

   Why: in this LAMMPS (29 Sep 2021) the `write_restart` command moves atoms to their
   current ranks and rebuilds the ghost atoms (comm->exchange, comm->borders) before it
   writes, and FixNeighHistory::write_restart then stores the history again from the
   neighbour list of the last run, whose atom indices no longer name the same atoms: contacts
   lose their history, and the run after `write_restart` differs from one without it
   (lammps/lammps#3022; measured with stock styles, lammps_plugin/README.md "Restarts").
   Nothing is lost by skipping that store: FixNeighHistory::post_run() has already stored
   the history with the atoms at the end of the run. Inside a run (the `restart` command's
   periodic files) the neighbour list is current, and the store happens as in stock. */

#ifndef STICKSLIP_CONTACT_HISTORY_FIX_H
#define STICKSLIP_CONTACT_HISTORY_FIX_H

#include "comm.h"
#include "fix_neigh_history.h"
#include "modify.h"
#include "update.h"

#include <cstdio>

namespace StickSlip {

class ContactHistoryFix : public LAMMPS_NS::FixNeighHistory {
 public:
  ContactHistoryFix(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg) : FixNeighHistory(lmp, narg, arg) {}

  void write_restart(FILE *fp) override
  {
    if (update->whichflag != 0) {  // inside a run or minimization: stock
      FixNeighHistory::write_restart(fp);
      return;
    }
    // outside a run: the atoms hold the history since post_run(); write what stock writes
    // after its store (no global state: a size of 0)
    if (comm->me == 0) {
      const int size = 0;
      fwrite(&size, sizeof(int), 1, fp);
    }
  }

  static LAMMPS_NS::Fix *make(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg)
  {
    return new ContactHistoryFix(lmp, narg, arg);
  }

  /* Runs `create` (which makes the pair style's history fix through LAMMPS' fix map under
     the style name NEIGH_HISTORY) with this class as that style, then restores the map. */
  template <class Create> static void creating_history_fix(LAMMPS_NS::Modify *modify, Create create)
  {
    auto &map = *modify->fix_map;
    const auto stock = map["NEIGH_HISTORY"];
    map["NEIGH_HISTORY"] = &make;
    create();
    map["NEIGH_HISTORY"] = stock;
  }
};

}  // namespace StickSlip

#endif
