// Inputs the fuzz targets (fuzz/) found crashing Ember, each kept with the fix it led to.
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "packet/wavefront_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_paths.h"

namespace ember {
namespace {

// fuzz_gltf: a GLB whose geometry puts the framing camera (and so every camera ray) beyond
// Embree's coordinate range. Debian's Embree asserts RayK::valid() and aborted, in the scalar
// loop (rtcIntersect1) as in packets (rtcIntersect16); untraceable rays now miss
// (accel/embree_accel.h, traceable).
TEST(FuzzRegressions, UntraceableCameraRaysMissInsteadOfAbortingEmbree) {
  Scene scene = loadScene(test::sourcePath("tests/data/fuzz/untraceable-camera-rays.glb"));
  scene.settings.width = scene.settings.height = 8;
  scene.build();
  for (Kernel kernel : {Kernel::Scalar, Kernel::Wavefront, Kernel::Stream}) {
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
