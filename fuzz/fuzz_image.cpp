// libFuzzer target: the image readers (io/image_io.cpp) — OpenEXR, stb_image and our PFM parser,
// told apart by the input's first bytes — as textures and reference images reach them. Any file
// must be read whole or rejected with an InputError.
#include "fuzz/fuzz_input.h"
#include "io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = ember::fuzz::inputFile(".img");
  ember::fuzz::writeInput(path, data, size);
  ember::fuzz::expectOnlyInputErrors([&] { ember::readTexture(path, ember::ColorEncoding::Auto); });
  ember::fuzz::expectOnlyInputErrors([&] { ember::readImageRgb(path); });
  ember::fuzz::expectOnlyInputErrors([&] { ember::readStringMetadata(path); });
  return 0;
}
