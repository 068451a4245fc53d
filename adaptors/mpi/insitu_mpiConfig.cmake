# find_package(insitu_mpi): the MPI adaptor (insitu::insitu_mpi and, when it was built, the
# Fortran module's insitu::insitu_mpi_fortran), on top of find_package(insitu).
include(CMakeFindDependencyMacro)
find_dependency(insitu)
set(MPI_CXX_SKIP_MPICXX ON)
find_dependency(MPI COMPONENTS C CXX)
include("${CMAKE_CURRENT_LIST_DIR}/insitu_mpiTargets.cmake")
