/* SPDX-License-Identifier: GPL-2.0-or-later
   lmp-stickslip: the stock LAMMPS driver with the stick-slip styles (libstickslip_lammps.so,
   linked in: loading it adds the styles, register_styles.cpp). Same command line as
   /usr/bin/lmp (-in FILE, -var NAME VALUE, -log, -screen, -echo ...), also under mpirun.
   It prints the plugin's version once, after LAMMPS' own version line (screen and log file). */

#include "accelerator_kokkos.h"
#include "comm.h"
#include "input.h"
#include "lammps.h"
#include "lmppython.h"
#include "stickslip_version.h"
#include "utils.h"

#include <cstdio>
#include <mpi.h>

int main(int argc, char **argv)
{
  // line-buffered output: an error on one rank ends the run through MPI_Abort, which would
  // otherwise drop the buffered lines that say what went wrong
  setvbuf(stdout, nullptr, _IOLBF, 0);
  MPI_Init(&argc, &argv);
  LAMMPS_NS::LAMMPS *lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
  if (lmp->comm->me == 0)
    LAMMPS_NS::utils::logmesg(lmp, "stickslip " STICKSLIP_VERSION ": gran/hooke/stickslip, wall/gran/stickslip, "
                                   "wall/gran/region/stickslip (Khellaf & Mansouri 2024)\n");
  lmp->input->file();
  delete lmp;
  LAMMPS_NS::KokkosLMP::finalize();
  LAMMPS_NS::Python::finalize();
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
  return 0;
}
