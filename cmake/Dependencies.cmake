# All dependencies come from Debian 12 packages (scripts/setup-deps.sh installs them).
# Versions and quirks: ../shared/docs/debian-toolchain.md.
find_package(embree 3.13 REQUIRED CONFIG)
find_package(OpenImageIO 2.4 REQUIRED CONFIG)
find_package(TinyGLTF REQUIRED CONFIG)
find_package(glm REQUIRED CONFIG)
find_package(TBB REQUIRED CONFIG)
find_package(CLI11 REQUIRED CONFIG)
find_package(nlohmann_json 3.10 REQUIRED CONFIG)
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
# OpenMPI (libopenmpi-dev) is optional: with it `mpirun -np N ember render` splits a render over
# N processes (distributed/); without it ember is a job of one process.
find_package(MPI COMPONENTS CXX QUIET)
pkg_check_modules(xxhash REQUIRED IMPORTED_TARGET libxxhash)  # content hashes of checkpointed scenes
find_package(hwy 1.0 REQUIRED CONFIG)  # Highway: SIMD with run-time dispatch (accel/shape_lanes.cpp)

# Quirk 1: OIIO's exported target names /usr/include/opencv4, which is absent without libopencv-dev.
get_target_property(_ember_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
list(FILTER _ember_oiio_inc EXCLUDE REGEX "opencv")
set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_ember_oiio_inc}")
