# All dependencies come from Debian 12 packages (scripts/setup-deps.sh installs them).
# Versions and quirks: ../shared/docs/debian-toolchain.md.
find_package(embree 3.13 REQUIRED CONFIG)
find_package(OpenEXR 3.1 REQUIRED CONFIG)  # EXR files: renders, references, HDR textures
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
# stb_image and stb_image_write (libstb-dev): PNG, JPEG and other 8/16-bit textures in, PNG out.
pkg_check_modules(stb REQUIRED IMPORTED_TARGET stb)
