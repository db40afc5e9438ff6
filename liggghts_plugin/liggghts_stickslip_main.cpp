/* SPDX-License-Identifier: GPL-2.0-or-later
   liggghts-stickslip: the stock LIGGGHTS driver with the stick_slip plugin linked in.
   Same command line as /usr/bin/liggghts (-in FILE, -var NAME VALUE, -log, -screen ...),
   so `mpirun -np 2 liggghts-stickslip -in in.script` needs no LD_PRELOAD. It prints the
   plugin's version once, after LIGGGHTS' own version line (screen and log file). */

#include <mpi.h>
#include "comm.h"
#include "lammps.h"
#include "input.h"
#include "stickslip_version.h"
#include <cstdio>

int main(int argc, char ** argv)
{
  // line-buffered output: an error->one() aborts through MPI_Abort, which would
  // otherwise drop the buffered message that says what went wrong
  setvbuf(stdout, NULL, _IOLBF, 0);
  MPI_Init(&argc, &argv);
  LAMMPS_NS::LAMMPS * lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
  if (lmp->comm->me == 0) {
    const char * banner = "stickslip " STICKSLIP_VERSION ": tangential stick_slip (Khellaf & Mansouri 2024)\n";
    if (lmp->screen) fputs(banner, lmp->screen);
    if (lmp->logfile) fputs(banner, lmp->logfile);
  }
  lmp->input->file();
  delete lmp;
  MPI_Finalize();
  return 0;
}
