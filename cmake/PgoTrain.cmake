# The training run of a profile-guided build (cmake/Pgo.cmake): the instrumented EMBER renders
# the shipped scenes other than the four benchmark scenes, which together use every analytic
# shape, material and emitter type, textures and normal maps, glTF meshes, point, spot and
# directional lights (courtyard.json, gltf-mixed.json), an environment map and the caustic light
# tracer (demo.json, by default), then the demo again with the path tracer alone, and
# terrace.json (every analytic shape, diffuse, textured, mirror and glass materials, every light
# kind: the wave driver's Lambertian run kernel) with caustics light-traced and path-traced. All
# of them take the wave driver. Untrained, GCC compiled the driver's kernels as cold code
# (optimised for size, split from the hot text), which cost a fifth of their speed.
# One thread: the counters then see the same work whatever the machine.
# Run as: cmake -DEMBER=<instrumented ember> -DSOURCE=<source dir> -DOUT=<scratch dir> -P PgoTrain.cmake
foreach(var EMBER SOURCE OUT)
  if(NOT ${var})
    message(FATAL_ERROR "PgoTrain.cmake needs -D${var}=...")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT})

set(runs "scenes/demo.json"
         "scenes/demo.json --caustics path --width 128 --height 128"
         "scenes/gltf-mixed.json"
         "scenes/courtyard.json"
         "scenes/gltf/bricks.gltf"
         "scenes/gltf/sphere-grid.gltf"
         "scenes/terrace.json"
         "scenes/terrace.json --caustics path")
foreach(run IN LISTS runs)
  separate_arguments(args UNIX_COMMAND "${run}")
  list(POP_FRONT args scene)
  execute_process(COMMAND ${EMBER} render ${SOURCE}/${scene} ${args} --spp 8 --threads 1 -q -o ${OUT}/training.exr
                  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "PGO training: `ember render ${run}` failed (${result}):\n${out}")
  endif()
endforeach()
