// libFuzzer target: the glTF/GLB loader — tinygltf's parser, then our own accessor, index,
// material and texture checks (io/gltf_loader.cpp, io/gltf_materials.cpp) — and the scene's build
// and a 4x4-pixel render. The first input byte picks the file type, so one corpus holds both.
#include "fuzz/fuzz_input.h"
#include "io/scene_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string gltf = ember::fuzz::inputFile(".gltf"), glb = ember::fuzz::inputFile(".glb");
  // Binary glTF starts with the magic "glTF"; everything else is tried as JSON glTF.
  const bool binary = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
  const std::string& path = binary ? glb : gltf;
  ember::fuzz::writeInput(path, data, size);
  ember::fuzz::expectOnlyInputErrors([&] {
    ember::Scene scene = ember::loadScene(path);
    ember::fuzz::buildAndRenderTiny(scene, 3);
  });
  return 0;
}
