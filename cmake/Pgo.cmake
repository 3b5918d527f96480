# Profile-guided optimisation (GCC), as Firefox, Chrome, CPython and Clang ship their release
# builds. With -DEMBER_PGO=ON a Release build first builds an instrumented `ember` of the same
# sources in <build>/pgo/instrumented, renders the training scenes with it (cmake/PgoTrain.cmake:
# the shipped scenes other than the four benchmark scenes, so that docs/performance.md measures
# the gain on scenes the profile never saw), and compiles everything with the profile it wrote.
# The compiler then lays out the hot path by the branches it took and inlines by the calls it
# made; floating-point semantics are unchanged, so images stay bit-identical (docs/performance.md,
# optimisation log: 0.90-0.98x the render time).
#
# Functions the training never ran are optimised as without a profile (-fprofile-partial-training),
# so a scene unlike the training set is not slowed by it. The profile is remade whenever the
# instrumented binary changes; objects that did not change keep the profile they were compiled
# with, which is only ever less tuned, never wrong.
option(EMBER_PGO "Profile-guided optimisation of Release builds (GCC; two builds and a 10 s training run)" OFF)
# Set by the PGO build on its instrumented sub-build: where the instrumented binary writes its profile.
set(EMBER_PGO_INSTRUMENT "" CACHE PATH "Internal: build instrumented, writing the profile to this directory")
mark_as_advanced(EMBER_PGO_INSTRUMENT)

if(EMBER_PGO_INSTRUMENT)
  # Profile files are named after the object's path below the build directory, so that the
  # optimised build (another directory) finds them.
  add_compile_options(-fprofile-generate=${EMBER_PGO_INSTRUMENT} -fprofile-update=prefer-atomic
                      -fprofile-prefix-path=${CMAKE_BINARY_DIR})
  add_link_options(-fprofile-generate=${EMBER_PGO_INSTRUMENT})
endif()

set(ember_pgo_enabled OFF)
if(EMBER_PGO)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    message(FATAL_ERROR "EMBER_PGO needs GCC (its -fprofile-use); this build uses ${CMAKE_CXX_COMPILER_ID}")
  endif()
  if(EMBER_SANITIZE OR EMBER_FUZZ OR EMBER_PGO_INSTRUMENT)
    message(FATAL_ERROR "EMBER_PGO is for optimised builds, not with EMBER_SANITIZE, EMBER_FUZZ or an instrumented build")
  endif()
  set(ember_pgo_enabled ON)
  set(ember_pgo_dir ${CMAKE_BINARY_DIR}/pgo)
  set(ember_pgo_profile ${ember_pgo_dir}/profile)
  set(ember_pgo_binary ${ember_pgo_dir}/instrumented/app/ember)

  include(ExternalProject)
  ExternalProject_Add(ember_pgo_instrumented
    SOURCE_DIR ${PROJECT_SOURCE_DIR}
    BINARY_DIR ${ember_pgo_dir}/instrumented
    CMAKE_ARGS -DCMAKE_BUILD_TYPE=${CMAKE_BUILD_TYPE}
               -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER}
               -DCMAKE_CXX_FLAGS=${CMAKE_CXX_FLAGS}
               -DEMBER_LTO=${EMBER_LTO}
               -DEMBER_PGO=OFF
               -DEMBER_PGO_INSTRUMENT=${ember_pgo_profile}
               -DEMBER_BUILD_TESTS=OFF
               -DEMBER_BUILD_BENCHMARKS=OFF
    BUILD_COMMAND ${CMAKE_COMMAND} --build <BINARY_DIR> --target ember
    BUILD_ALWAYS ON  # its own build tool decides what the source changes need
    BUILD_BYPRODUCTS ${ember_pgo_binary}
    INSTALL_COMMAND "")

  add_custom_command(
    OUTPUT ${ember_pgo_dir}/profile.stamp
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${ember_pgo_profile}
    COMMAND ${CMAKE_COMMAND} -DEMBER=${ember_pgo_binary} -DSOURCE=${PROJECT_SOURCE_DIR}
            -DOUT=${ember_pgo_dir}/training -P ${PROJECT_SOURCE_DIR}/cmake/PgoTrain.cmake
    COMMAND ${CMAKE_COMMAND} -E touch ${ember_pgo_dir}/profile.stamp
    DEPENDS ${ember_pgo_binary} ${PROJECT_SOURCE_DIR}/cmake/PgoTrain.cmake
    COMMENT "Ember PGO: rendering the training scenes with the instrumented build"
    VERBATIM)
  add_custom_target(ember_pgo_profile DEPENDS ${ember_pgo_dir}/profile.stamp)
  add_dependencies(ember_pgo_profile ember_pgo_instrumented)

  add_compile_options(-fprofile-use=${ember_pgo_profile} -fprofile-partial-training
                      -fprofile-prefix-path=${CMAKE_BINARY_DIR} -Wno-missing-profile)
  # With the profile, link-time optimisation inlines std::string copies differently, and GCC 12
  # then reports accesses on paths no call reaches, in <bits/char_traits.h>: a write of SIZE_MAX
  # bytes (-Wstringop-overflow, CLI11) and a 27-byte read of a string literal's 16-byte small-string
  # buffer (-Wstringop-overread, a test's vector<string>::push_back). Only those diagnostics, and
  # only at the link, where LTO compiles.
  add_link_options(-fprofile-use=${ember_pgo_profile} -fprofile-partial-training -Wno-stringop-overflow
                   -Wno-stringop-overread)
endif()

# Every target of the given directories compiles after the profile exists (call it after the
# add_subdirectory calls).
function(ember_pgo_wait_for_profile)
  if(NOT ember_pgo_enabled)
    return()
  endif()
  foreach(dir IN LISTS ARGN)
    get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
    foreach(target IN LISTS targets)
      add_dependencies(${target} ember_pgo_profile)
    endforeach()
  endforeach()
endfunction()
