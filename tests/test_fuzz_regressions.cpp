// Inputs the fuzz targets (fuzz/) found crashing Ember, each kept with the fix it led to.
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "materials/texture.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_paths.h"

namespace ember {
namespace {

// fuzz_gltf: a glTF whose texture coordinates reach 7e27: `int(floor(u * width))` overflowed in
// ImageTexture::eval (undefined behaviour, which clang's UBSan stops at). Lookups are now held
// within 2^30 texels of the image, where a float has no fraction left to matter. The file is also
// a seed of fuzz/run.sh, so the sanitized fuzz build meets it on every run.
TEST(FuzzRegressions, HugeTextureCoordinatesLookUpATexel) {
  Scene scene = loadScene(test::sourcePath("tests/data/fuzz/huge-texture-uv.gltf"));
  scene.settings.width = scene.settings.height = 8;
  scene.build();
  for (Kernel kernel : {Kernel::Scalar, Kernel::Wave}) {
    const auto integrator = makeIntegrator(scene.settings, kernel);
    Film film(8, 8);
    RenderOptions options;
    options.spp = 2;
    render(scene, *integrator, options, film);
    const Image img = film.mean();
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) EXPECT_TRUE(std::isfinite(img.at(x, y).x));
  }
  const std::vector<Color> texels = {Color(0.25f), Color(0.5f), Color(0.75f), Color(1.0f)};
  for (const TextureFilter filter : {TextureFilter::Nearest, TextureFilter::Bilinear})
    for (const TextureWrap wrap : {TextureWrap::Clamp, TextureWrap::Repeat, TextureWrap::Mirror}) {
      const ImageTexture texture(2, 2, texels, filter, wrap);
      for (const Vec2 uv : {Vec2(7e27f, -3e30f), Vec2(-1e38f, 1e38f), Vec2(3e9f, 0.5f)}) {
        const float v = texture.eval(uv).x;
        EXPECT_TRUE(v >= 0.25f && v <= 1.0f) << "uv (" << uv.x << ", " << uv.y << "): " << v;
      }
    }
}

// fuzz_gltf: a GLB whose geometry puts the framing camera (and so every camera ray) beyond
// Embree's coordinate range. Debian's Embree asserts RayK::valid() and aborted, in the scalar
// loop (rtcIntersect1) as in packets (rtcIntersect16); untraceable rays now miss
// (accel/embree_accel.h, traceable).
TEST(FuzzRegressions, UntraceableCameraRaysMissInsteadOfAbortingEmbree) {
  Scene scene = loadScene(test::sourcePath("tests/data/fuzz/untraceable-camera-rays.glb"));
  scene.settings.width = scene.settings.height = 8;
  scene.build();
  for (Kernel kernel : {Kernel::Scalar, Kernel::Wave}) {
    const auto integrator = makeIntegrator(scene.settings, kernel);
    Film film(8, 8);
    RenderOptions options;
    options.spp = 2;
    EXPECT_NO_FATAL_FAILURE(render(scene, *integrator, options, film));
  }
  EXPECT_FALSE(traceable(Ray{Vec3(2e18f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 1.0f)}));
  EXPECT_FALSE(traceable(Ray{Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f), std::nanf("")}));
  EXPECT_TRUE(traceable(Ray{Vec3(1e6f), Vec3(0.0f, 0.0f, 1.0f)}));
  // A NaN in any component, not only the first (std::max would drop it in the others).
  const float nan = std::nanf("");
  for (int c = 0; c < 3; ++c) {
    Vec3 bad(0.0f);
    bad[c] = nan;
    EXPECT_FALSE(traceable(Ray{bad, Vec3(0.0f, 0.0f, 1.0f)})) << "NaN in origin component " << c;
    EXPECT_FALSE(traceable(Ray{Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f) + bad}))
        << "NaN in direction component " << c;
  }
}

// fuzz_scene_json: a number too large for a double made nlohmann throw out_of_range, which
// escaped as an unnamed error; now it is invalid JSON naming the file.
TEST(FuzzRegressions, NumberOverflowIsInvalidJsonNamingTheFile) {
  const std::string path = test::sourcePath("tests/data/fuzz/number-overflow.json");
  try {
    loadJsonScene(path);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": invalid JSON"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ember
