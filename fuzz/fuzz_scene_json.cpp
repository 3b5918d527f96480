// libFuzzer target: Ember's JSON scene loader (io/scene_loader.cpp), then the scene's build
// (Embree, lights) and a 4x4-pixel render of one sample, so that whatever the loader accepts is
// also rendered without a crash.
#include "fuzz/fuzz_input.h"
#include "io/scene_loader.h"
#include "packet/wavefront_integrator.h"
#include "renderer/render.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = ember::fuzz::inputFile(".json");
  ember::fuzz::writeInput(path, data, size);
  ember::fuzz::expectOnlyInputErrors([&] {
    ember::Scene scene = ember::loadJsonScene(path);
    scene.settings.width = scene.settings.height = 4;
    scene.settings.maxDepth = std::min(scene.settings.maxDepth < 0 ? 4 : scene.settings.maxDepth, 4);
    scene.build();
    const auto integrator = ember::makeIntegrator(scene.settings, ember::Kernel::Wavefront);
    ember::Film film(4, 4);
    ember::RenderOptions options;
    options.spp = 1;
    options.threads = 1;
    ember::render(scene, *integrator, options, film);
  });
  return 0;
}
