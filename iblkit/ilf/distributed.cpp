// ilf::run_mpi_job: the MPI driver of ilf/mpi/ (the "mpi" plugin for the iblkit command) when this
// build has MPI, a clear error otherwise.
#include "iblkit/ilf/distributed.h"

#include <cstdlib>

namespace ibl::ilf {

namespace detail {
constinit plugin::Provided<MpiDriver> mpi_driver{"mpi", "distributed ILF build"};
}  // namespace detail

bool launched_by_mpi() {
  // Open MPI's mpirun, PMIx launchers (Open MPI 5, Slurm's srun --mpi=pmix), PMI-1/2 (MPICH's hydra, srun).
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

#ifdef IBLKIT_HAVE_MPI
bool have_mpi() { return true; }
#else
bool have_mpi() { return false; }
#endif

void run_mpi_job(const MpiJobDesc& job, const std::function<void(MpiJob&)>& body) {
  if (!have_mpi())
    fail(ErrorKind::Unsupported,
         "this build has no MPI (install libopenmpi-dev and configure with IBLKIT_WITH_MPI=ON "
         "to build on a cluster; without mpirun the serial build runs)");
  detail::mpi_driver.get().run(job, body);
}

}  // namespace ibl::ilf
