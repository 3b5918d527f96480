// libFuzzer target: Ember's JSON scene loader (io/scene_loader.cpp), then the scene's build
// (Embree, lights) and a 4x4-pixel render of one sample, so that whatever the loader accepts is
// also rendered without a crash.
#include "fuzz/fuzz_input.h"
#include "io/scene_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = ember::fuzz::inputFile(".json");
  ember::fuzz::writeInput(path, data, size);
  ember::fuzz::expectOnlyInputErrors([&] {
    ember::Scene scene = ember::loadJsonScene(path);
    ember::fuzz::buildAndRenderTiny(scene, 4);
  });
  return 0;
}
