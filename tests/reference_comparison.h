// What the whole-image tests share: a scene file rendered at a seed with its per-pixel variance of
// the mean, the average of two such renders, the Mitsuba 3 reference of a shared scene
// (tests/data/<scene>/, 8192 spp, with per-pixel standard errors), and a z-test's verdict in words.
#pragma once

#include "io/image_compare.h"
#include "io/image_io.h"
#include "io/image_metrics.h"
#include "io/scene_loader.h"
#include "test_fixtures.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace ember::test {

struct Rendered {
  Image mean, variance;
};

// The JSON scene at `path`, changed by `mutate` if given, rendered with the default kernel; a
// render must have no non-finite samples. Mitsuba's path tracer, which made the references, cannot
// find the caustics of a point or spot light (no path reaches a point through a mirror or glass):
// scenes with one render in Ember's path-traced mode, whose image is the reference's
// (docs/performance.md).
inline Rendered renderFile(const std::string& path, uint64_t seed, int spp,
                           const std::function<void(Scene&)>& mutate = {},
                           SamplerType sampler = SamplerType::Independent) {
  Scene scene = loadJsonScene(path);
  for (const auto& light : scene.lights)
    if (light->isDelta()) scene.settings.traceCaustics = false;
  if (mutate) mutate(scene);
  scene.build();
  RenderStats stats;
  const Film film = renderFilm(scene, spp, seed, &stats, sampler);
  EXPECT_EQ(stats.nonFinite, 0u) << path;
  return {film.mean(), film.varianceOfMean()};
}

struct Reference {
  Image mean, variance;
};

inline Reference loadReference(const std::string& name) {
  const std::string dir = sourcePath("tests/data/" + name + "/");
  return {readImageRgb(dir + "reference.exr"), squared(readImageRgb(dir + "stderr.exr"))};
}

// The average of two independent renders, with the variance of that average.
inline Rendered average(const Rendered& a, const Rendered& b) {
  Rendered m = a;
  for (size_t i = 0; i < m.mean.rgb.size(); ++i) {
    m.mean.rgb[i] = 0.5f * (a.mean.rgb[i] + b.mean.rgb[i]);
    m.variance.rgb[i] = 0.25f * (a.variance.rgb[i] + b.variance.rgb[i]);
  }
  return m;
}

inline std::string describe(const BlockZTestResult& r) {
  return std::to_string(r.failures) + "/" + std::to_string(r.tests) + " blocks beyond |z| > " +
         std::to_string(r.threshold) + ", max |z| " + std::to_string(r.maxAbsZ) + ", image-mean z (" +
         std::to_string(r.meanZ[0]) + ", " + std::to_string(r.meanZ[1]) + ", " + std::to_string(r.meanZ[2]) +
         ")";
}

// A scene name as part of a GoogleTest parameter name, which allows no '-'.
inline std::string testName(std::string s) {
  for (char& c : s)
    if (c == '-') c = '_';
  return s;
}

}  // namespace ember::test
