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
# Compressed glTF (io/gltf_compression.cpp): EXT_meshopt_compression (libmeshoptimizer-dev, CMake
# config), KHR_draco_mesh_compression (libdraco-dev, CMake config) and EXT_texture_webp
# (libwebp-dev, pkg-config only). Draco is linked statically (draco::draco_static): Debian's
# libdraco.so.7 exports a tinygltf of its own, another version, whose symbols would take the place
# of libtinygltf's (Ember crashed in TinyGLTF::LoadASCIIFromString). Only Draco's own objects come
# from the archive as long as libstb and libtinygltf precede it on the link line, as ember_io lists
# them (io/CMakeLists.txt): the archive's tiny_gltf_utils.cc.o also defines stb_image, and is
# pulled in, its tinygltf with it, by any stbi_ or tinygltf symbol still undefined when the linker
# reaches the archive. GltfCompression.TinygltfIsLibtinygltf checks the unit tests' binary.
find_package(meshoptimizer REQUIRED CONFIG)
find_package(draco REQUIRED CONFIG)
pkg_check_modules(webp REQUIRED IMPORTED_TARGET libwebp)
# OpenImageIO (libopenimageio-dev) through pkg-config: its CMake config demands openimageio-tools
# (and Qt with it) and names a missing opencv include folder (../shared/docs/debian-toolchain.md).
# Only the image plugin module links it (io/image_plugin.h says why); without it Ember builds and
# reads images with its built-in readers.
pkg_check_modules(OpenImageIO QUIET IMPORTED_TARGET OpenImageIO)
