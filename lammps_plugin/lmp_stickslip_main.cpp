/* lmp-stickslip: the stock LAMMPS driver with the stick-slip styles (libstickslip_lammps.so,
   linked in: loading it adds the styles, register_styles.cpp). Same command line as
   /usr/bin/lmp (-in FILE, -var NAME VALUE, -log, -screen, -echo ...), also under mpirun. */

#include "accelerator_kokkos.h"
#include "input.h"
#include "lammps.h"
#include "lmppython.h"

#include <cstdio>
#include <mpi.h>

int main(int argc, char **argv)
{
  // line-buffered output: an error on one rank ends the run through MPI_Abort, which would
  // otherwise drop the buffered lines that say what went wrong
  setvbuf(stdout, nullptr, _IOLBF, 0);
  MPI_Init(&argc, &argv);
  LAMMPS_NS::LAMMPS *lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
  lmp->input->file();
  delete lmp;
  LAMMPS_NS::KokkosLMP::finalize();
  LAMMPS_NS::Python::finalize();
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
  return 0;
}
