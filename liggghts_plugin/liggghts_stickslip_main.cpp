/* liggghts-stickslip: the stock LIGGGHTS driver with the stick_slip plugin linked in.
   Same command line as /usr/bin/liggghts (-in FILE, -var NAME VALUE, -log, -screen ...),
   so `mpirun -np 2 liggghts-stickslip -in in.script` needs no LD_PRELOAD. */

#include <mpi.h>
#include "lammps.h"
#include "input.h"
#include <cstdio>

int main(int argc, char ** argv)
{
  // line-buffered output: an error->one() aborts through MPI_Abort, which would
  // otherwise drop the buffered message that says what went wrong
  setvbuf(stdout, NULL, _IOLBF, 0);
  MPI_Init(&argc, &argv);
  LAMMPS_NS::LAMMPS * lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
  lmp->input->file();
  delete lmp;
  MPI_Finalize();
  return 0;
}
