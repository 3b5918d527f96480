// The wave driver (8- and 16-wide Embree packets, SIMD lane filters, the bounce in arrays) must
// produce the scalar reference's image bit for bit, for every shape, material, emitter and light
// type, every strategy and sampler, any thread count and tile size, and images whose size is not
// a multiple of the tile or the wave.
#include "core/rng.h"
#include "core/sampling.h"
#include "io/scene_loader.h"
#include "materials/phong.h"
#include "materials/texture.h"
#include "packet/geometry_groups.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include "simd_targets.h"
#include "test_paths.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace ember {
namespace {

struct RenderCase {
  int threads = 2;
  int tileSize = 16;
  int spp = 3;
  uint64_t firstSample = 0;
};

Film renderWith(const Scene& scene, Kernel kernel, const RenderCase& c, PathStats* paths = nullptr) {
  const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, kernel);
  Film film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = c.spp;
  options.seed = scene.settings.seed;
  options.sampler = scene.settings.sampler;
  options.threads = c.threads;
  options.tileSize = c.tileSize;
  options.firstSample = c.firstSample;
  const RenderStats stats = render(scene, *integrator, options, film);
  if (paths) *paths = stats.paths;
  return film;
}

// Equal bit for bit, pixel by pixel, in the mean and in the variance.
void expectIdentical(const Film& a, const Film& b, const std::string& what) {
  const Image ma = a.mean(), mb = b.mean(), va = a.varianceOfMean(), vb = b.varianceOfMean();
  ASSERT_EQ(ma.rgb.size(), mb.rgb.size());
  size_t differing = 0, first = 0;
  for (size_t i = 0; i < ma.rgb.size(); ++i) {
    const bool same = std::memcmp(&ma.rgb[i], &mb.rgb[i], sizeof(float)) == 0 &&
                      std::memcmp(&va.rgb[i], &vb.rgb[i], sizeof(float)) == 0;
    if (!same && differing++ == 0) first = i / 3;
  }
  EXPECT_EQ(differing, 0u) << what << ": " << differing << " channels differ, first in pixel " << first;
}

Scene loadBuilt(const std::string& path) {
  Scene scene = loadScene(path);
  scene.build();
  return scene;
}

Scene loadSmall(const std::string& path, int width, int height) {
  Scene scene = loadScene(path);
  scene.settings.width = width;
  scene.settings.height = height;
  scene.build();
  return scene;
}

// The wave driver at both packet widths (8: AVX2's native width, 16: AVX-512's), whatever this
// machine's native width is, against the scalar reference.
void expectKernelsAgree(Scene& scene, const std::string& name, const RenderCase& c = {}) {
  const Film reference = renderWith(scene, Kernel::Scalar, c);
  const unsigned native = scene.accel().packetWidth();
  for (const unsigned width : {16u, 8u}) {
    scene.setPacketWidth(width);
    const std::string packets = " (packets of " + std::to_string(width) + ")";
    expectIdentical(reference, renderWith(scene, Kernel::Wave, c), name + ": wave vs scalar" + packets);
  }
  scene.setPacketWidth(native);
}

TEST(Wavefront, SameImageAsScalarOnTheShippedScenes) {
  for (const char* name : {"cornell-area", "cornell-point", "shapes", "textured", "demo", "gltf-mixed",
                           "courtyard", "terrace"}) {
    Scene scene = loadSmall(test::sourcePath(std::string("scenes/") + name + ".json"), 40, 36);
    expectKernelsAgree(scene, name);
  }
}

TEST(Wavefront, SameImageAsScalarForEveryStrategyAndSampler) {
  Scene scene = loadSmall(test::sourcePath("scenes/demo.json"), 33, 29);
  for (Strategy strategy : {Strategy::Mis, Strategy::Bsdf, Strategy::Light})
    for (SamplerType sampler : {SamplerType::Sobol, SamplerType::Independent}) {
      scene.settings.strategy = strategy;
      scene.settings.sampler = sampler;
      expectKernelsAgree(scene, std::string(strategyName(strategy)) +
                                    (sampler == SamplerType::Sobol ? " sobol" : " independent"));
    }
}

// Emitters of every analytic shape, one- and two-sided, facing out and in (the sphere whose normals
// point inwards encloses the scene), on a floor of material "white": the shapes the emitter tests
// below start from, each adding its own.
constexpr const char* kEmittersOnAFloor = R"(
      {"type": "quad", "material": "white", "vertices": [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]]},
      {"type": "sphere", "center": [-1.2, 0.4, 0], "radius": 0.4, "emission": [2, 1, 0.5]},
      {"type": "sphere", "center": [0, 1.0, -1], "radius": 2.5, "material": "white", "flip_normals": true},
      {"type": "disc", "center": [0.6, 1.6, 0], "normal": [0, -1, 0], "radius": 0.3, "emission": [3, 3, 3]},
      {"type": "quad", "vertices": [[-0.4, 1.8, -0.5], [0.4, 1.8, -0.5], [0.4, 1.9, 0.3], [-0.4, 1.9, 0.3]],
       "emission": [2, 2, 2], "two_sided": true},
      {"type": "triangle", "vertices": [[1.2, 0.01, 0.5], [1.6, 0.01, 0.5], [1.4, 0.5, 0.4]], "emission": [1, 3, 1]},
      {"type": "cone", "base_center": [-0.3, 0, 0.8], "apex": [-0.3, 0.6, 0.8], "radius": 0.25, "emission": [0.5, 0.5, 2]},)";

// Emitters of every kind the scene format has, inward-facing and two-sided ones included, with
// point, spot and directional lights and an environment, and a max depth that cuts paths.
TEST(Wavefront, SameImageAsScalarForEveryEmitterAndLight) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "ember_wavefront_emitters.json").string();
  std::ofstream(path) << R"({
    "image": {"width": 31, "height": 27},
    "camera": {"origin": [0, 1, 4], "target": [0, 0.6, 0], "up": [0, 1, 0], "fov_y_deg": 50},
    "render": {"max_depth": 6, "rr_depth": 2, "background": [0.05, 0.07, 0.1]},
    "materials": {
      "white": {"type": "diffuse", "reflectance": [0.7, 0.7, 0.7]},
      "gloss": {"type": "phong", "kd": [0.3, 0.3, 0.3], "ks": [0.4, 0.4, 0.4], "exponent": 40},
      "glass": {"type": "dielectric", "ior_inside": 1.5, "ior_outside": 1.0},
      "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]}
    },
    "shapes": [
)" + std::string(kEmittersOnAFloor) +
                             R"(
      {"type": "cylinder", "p0": [1.0, 0, -0.8], "p1": [1.0, 0.9, -0.8], "radius": 0.2, "material": "gloss"},
      {"type": "box", "center": [0.2, 0.25, 0.3], "size": [0.5, 0.5, 0.5], "material": "glass"},
      {"type": "sphere", "center": [-0.5, 0.3, -0.6], "radius": 0.3, "material": "mirror"}
    ],
    "lights": [
      {"type": "point", "position": [0.5, 1.5, 1.0], "intensity": [1, 1, 1]},
      {"type": "spot", "position": [0, 1.9, 0], "direction": [0, -1, 0], "intensity": 5, "inner_deg": 15, "outer_deg": 30},
      {"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": [0.5, 0.5, 0.4]}
    ]
  })";
  Scene scene = loadBuilt(path);  // a load error fails the test with its message
  for (Strategy strategy : {Strategy::Mis, Strategy::Bsdf, Strategy::Light}) {
    scene.settings.strategy = strategy;
    expectKernelsAgree(scene, std::string("emitters, ") + std::string(strategyName(strategy)));
  }
  std::filesystem::remove(path);
}

// The lane kernel's Highway kernels (next-event estimation, the continuation's compress-and-store,
// the camera rays, the Sobol lanes) on every SIMD target this CPU has, not only the one dynamic
// dispatch picks: each target's compression and vector widths are different code.
TEST(LaneKernel, SameImageAsScalarOnEverySimdTarget) {
  for (const char* name : {"terrace", "cornell-area"}) {
    Scene scene = loadSmall(test::sourcePath(std::string("scenes/") + name + ".json"), 21, 17);
    forEachSimdTarget([&] {
      expectIdentical(renderWith(scene, Kernel::Scalar, {2, 8, 2}),
                      renderWith(scene, Kernel::Wave, {2, 8, 2}), std::string(name) + ": lanes vs scalar");
    });
  }
}

// A scene edited and built again, at the same address, is a new scene: here its Lambertian
// materials become Phong ones, which the driver must evaluate through the material's own methods,
// not the kernels' Lambertian form. (When the driver decided per scene which scenes it covered,
// keyed by the scene's address, it once kept the old answer and read Phong as Lambertian.)
TEST(LaneKernel, DecidesAfreshForASceneBuiltAgain) {
  Scene scene = loadSmall(test::sourcePath("scenes/cornell-area.json"), 24, 20);
  const std::unique_ptr<Integrator> lanes = makeIntegrator(scene.settings, Kernel::Wave);
  RenderOptions options;
  options.spp = 2;
  options.seed = scene.settings.seed;
  options.sampler = scene.settings.sampler;
  options.threads = 2;
  options.tileSize = 8;
  const auto renderLanes = [&] {
    Film film(scene.settings.width, scene.settings.height);
    render(scene, *lanes, options, film);
    return film;
  };
  expectIdentical(renderWith(scene, Kernel::Scalar, {2, 8, 2}), renderLanes(), "before the edit");
  const Material* phong = scene.addMaterial(
      "phong", std::make_unique<Phong>(std::make_shared<ConstantTexture>(Color(0.5f)), Color(0.3f), 20.0f));
  for (Scene::ShapeEntry& entry : scene.shapes)
    if (entry.material) entry.material = phong;
  scene.build();
  expectIdentical(renderWith(scene, Kernel::Scalar, {2, 8, 2}), renderLanes(), "after the edit and build()");
}

// The scenes the lane kernel covers (packet/wave_integrator.h), at the edges of its set: every
// analytic shape, a textured material, mirrors and glass (caustics path-traced or left to the
// light tracer), emitters of every shape, one- and two-sided, facing in and out (a
// sphere whose normals point inwards encloses the scene), point and spot lights, a black (absorbing)
// material, paths cut by max depth or by Russian roulette alone from the second segment, both samplers, and
// waves of one sample per pixel. The scene is then changed just outside the set, where the kernel must hand
// it to the wavefront kernel. The camera is inside the inward-facing sphere.
TEST(LaneKernel, SameImageAsScalarOnTheScenesItCovers) {
  const std::string path = (std::filesystem::temp_directory_path() / "ember_lanes_covered.json").string();
  const std::string checker = test::sourcePath("scenes/checker.png");
  const std::string json = R"({
    "image": {"width": 29, "height": 23},
    "camera": {"origin": [0, 1.1, 1.3], "target": [0, 0.6, 0], "up": [0, 1, 0], "fov_y_deg": 50},
    "render": {"max_depth": 7, "rr_depth": 2},
    "materials": {
      "white": {"type": "diffuse", "reflectance": [0.7, 0.7, 0.7]},
      "red": {"type": "diffuse", "reflectance": [0.6, 0.1, 0.05]},
      "black": {"type": "diffuse", "reflectance": [0, 0, 0]},
      "checker": {"type": "diffuse", "reflectance": {"texture": ")" +
                           checker + R"(", "filter": "bilinear"}},
      "mirror": {"type": "mirror", "reflectance": [0.9, 0.8, 0.9]},
      "glass": {"type": "dielectric", "ior_inside": 1.5, "ior_outside": 1.0},
      "lens": {"type": "refraction", "ior_inside": 1.3, "ior_outside": 1.0, "transmittance": [0.9, 0.95, 1.0]}
    },
    "shapes": [
)" + std::string(kEmittersOnAFloor) +
                           R"(
      {"type": "cylinder", "p0": [1.0, 0, -0.8], "p1": [1.0, 0.9, -0.8], "radius": 0.2, "material": "red"},
      {"type": "box", "center": [0.2, 0.25, 0.3], "size": [0.5, 0.5, 0.5], "material": "checker"},
      {"type": "sphere", "center": [-0.5, 0.3, -0.6], "radius": 0.3, "material": "black"},
      {"type": "quad", "material": "red", "emission": [0.3, 0.3, 0.3],
       "vertices": [[-2, 0.2, -2], [-1.5, 0.2, -2], [-1.5, 0.9, -2.2], [-2, 0.9, -2.2]]},
      {"type": "sphere", "center": [0.4, 0.35, -0.2], "radius": 0.3, "material": "glass"},
      {"type": "sphere", "center": [-0.9, 1.2, -1.2], "radius": 0.35, "material": "mirror"},
      {"type": "disc", "center": [0.9, 1.0, 0.2], "normal": [-1, 0, 0.3], "radius": 0.2, "material": "lens"}
    ],
    "lights": [
      {"type": "point", "position": [0.5, 1.5, 1.0], "intensity": [1, 1, 1]},
      {"type": "spot", "position": [0, 1.9, 0], "direction": [0, -1, 0], "intensity": 5, "inner_deg": 15, "outer_deg": 30}
    ]
  })";
  std::ofstream(path) << json;
  Scene scene = loadBuilt(path);  // a load error fails the test with its message
  for (SamplerType sampler : {SamplerType::Sobol, SamplerType::Independent})
    for (bool caustics : {true, false}) {
      scene.settings.sampler = sampler;
      scene.settings.traceCaustics = caustics;
      const std::string name =
          std::string(sampler == SamplerType::Sobol ? "covered, sobol" : "covered, independent") +
          (caustics ? ", caustics traced" : ", caustics path-traced");
      expectKernelsAgree(scene, name);
      expectKernelsAgree(scene, name + ", one sample per pass", RenderCase{2, 16, 1, 3});
    }
  // Unbounded depth (Russian roulette alone ends the paths): the runs of hits on constant
  // Lambertian shapes then arrive in the vector kernel (packet/arrival_lanes.h), on every target.
  scene.settings.maxDepth = -1;
  for (bool caustics : {true, false}) {
    scene.settings.traceCaustics = caustics;
    // Whole waves too (a 16 x 16 tile at 4 spp: 1,024 paths), so that runs reach the rows' end.
    forEachSimdTarget([&] {
      const std::string name =
          caustics ? "unbounded depth, caustics traced" : "unbounded depth, caustics path-traced";
      expectKernelsAgree(scene, name);
      expectKernelsAgree(scene, name + ", whole waves", RenderCase{2, 16, 4});
    });
  }
  scene.settings.maxDepth = 7;
  // Open to the sky: without the enclosing sphere, under a sun (directional light), with a
  // constant background and with an environment map.
  const auto replaced = [](std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
  };
  std::string open = replaced(
      json,
      R"({"type": "sphere", "center": [0, 1.0, -1], "radius": 2.5, "material": "white", "flip_normals": true},)",
      "");
  open = replaced(
      open, R"("lights": [)",
      R"("lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": [0.5, 0.5, 0.4]},)");
  const std::string sky = test::sourcePath("scenes/gltf/sky.exr");
  for (const std::string& variant :
       {replaced(open, R"("rr_depth": 2})", R"("rr_depth": 2, "background": [0.3, 0.35, 0.4]})"),
        replaced(open, R"("materials": {)", R"("environment": {"map": ")" + sky + R"("}, "materials": {)")}) {
    std::ofstream(path) << variant;
    Scene sunlit = loadBuilt(path);
    ASSERT_NE(sunlit.environment(), nullptr);
    expectKernelsAgree(sunlit, sunlit.environmentMap ? "sun and environment map" : "sun and background");
  }
  // The other strategies, at bounded and unbounded depth (the vector arrival's runs).
  for (Strategy strategy : {Strategy::Light, Strategy::Bsdf})
    for (int maxDepth : {7, -1}) {
      scene.settings.strategy = strategy;
      scene.settings.maxDepth = maxDepth;
      expectKernelsAgree(scene, "strategy " + std::string(strategyName(strategy)) + ", max depth " +
                                    std::to_string(maxDepth));
    }
  std::filesystem::remove(path);
}

// More geometries than the counting sort's buckets pay for (packet/wavefront_integrator.cpp,
// groupByGeometry sorts the wave's keys instead), many of them lights: 1,200 small spheres and
// quads, every third one emitting, over a floor.
TEST(Wavefront, SameImageAsScalarWithThousandsOfGeometries) {
  const std::string path = (std::filesystem::temp_directory_path() / "ember_wavefront_many.json").string();
  {
    std::ofstream f(path);
    f << R"({"image": {"width": 24, "height": 20},
      "camera": {"origin": [0, 3, 6], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 50},
      "render": {"max_depth": 5, "rr_depth": 2},
      "materials": {"white": {"type": "diffuse", "reflectance": [0.7, 0.7, 0.7]}},
      "shapes": [{"type": "quad", "material": "white", "vertices": [[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]]})";
    for (int i = 0; i < 1200; ++i) {
      const float x = -4.0f + 8.0f * float(i % 40) / 39.0f, z = -4.0f + 8.0f * float(i / 40) / 29.0f;
      const std::string emit = i % 3 == 0 ? R"(, "emission": [1, 0.8, 0.6])" : R"(, "material": "white")";
      if (i % 2 == 0) {
        f << R"(, {"type": "sphere", "center": [)" << x << ", 0.3, " << z << R"(], "radius": 0.08)" << emit
          << "}";
      } else {
        f << R"(, {"type": "quad", "vertices": [[)" << x << ", 0.6, " << z << "], [" << x + 0.1f << ", 0.6, "
          << z << "], [" << x + 0.1f << ", 0.6, " << z + 0.1f << "], [" << x << ", 0.6, " << z + 0.1f << "]]"
          << emit << "}";
      }
    }
    f << "]}";
  }
  Scene scene = loadBuilt(path);  // a load error fails the test with its message
  ASSERT_GT(scene.geometryCount() + 1, GeometryGroups::kMaxCountingSortBuckets);
  expectKernelsAgree(scene, "1,200 geometries", RenderCase{2, 16, 2, 0});
  std::filesystem::remove(path);
}

// Triangle meshes (Embree's own packet kernels, alpha-tested, normal-mapped) beside shapes.
TEST(Wavefront, SameImageAsScalarOnGltfMeshes) {
  for (const char* name : {"scenes/gltf/bricks.gltf", "scenes/gltf/sphere-grid.gltf"}) {
    Scene scene = loadSmall(test::sourcePath(name), 37, 21);
    expectKernelsAgree(scene, name);
  }
  const std::string duckPath = test::sharedGltfDir() + "/Duck/glTF/Duck.gltf";
  if (std::filesystem::exists(duckPath)) {
    Scene duck = loadSmall(duckPath, 32, 32);
    expectKernelsAgree(duck, "Duck");
  }
}

// Meshes larger than the caches get their hits' triangles and vertices prefetched
// (packet/hit_prefetch.h, above Scene::kPrefetchMeshBytes): a hint that must not change the image,
// and whose reads of the index buffer the sanitizer build checks. The grid's meshes are padded
// with unused copies of a vertex until they pass the threshold; no triangle uses them.
TEST(Wavefront, SameImageAsScalarWhereMeshHitsArePrefetched) {
  Scene scene = loadScene(test::sourcePath("scenes/gltf/sphere-grid.gltf"));
  scene.settings.width = 29;
  scene.settings.height = 23;
  scene.build();
  ASSERT_FALSE(scene.prefetchesMeshHits());
  ASSERT_FALSE(scene.meshes.empty());
  TriangleMesh& mesh = *scene.meshes.front().mesh;
  const size_t padding = Scene::kPrefetchMeshBytes / sizeof(Vec3) + 1;
  mesh.positions.resize(mesh.positions.size() + padding, mesh.positions.front());
  if (!mesh.normals.empty()) mesh.normals.resize(mesh.positions.size(), mesh.normals.front());
  if (!mesh.uvs.empty()) mesh.uvs.resize(mesh.positions.size(), mesh.uvs.front());
  if (!mesh.tangents.empty()) mesh.tangents.resize(mesh.positions.size(), mesh.tangents.front());
  scene.build();
  ASSERT_TRUE(scene.prefetchesMeshHits());
  expectKernelsAgree(scene, "sphere grid, prefetched");
}

// Thread counts, tile sizes that do not divide the image, tiles larger and smaller than a wave
// (tile 40: 40 x 30 = 1,200 pixels, more than a wave's 1,024 paths, so one sample index spans two
// waves), and a sample range that does not start at 0: always the same film.
TEST(Wavefront, SameImageForAnyThreadsTilesAndSampleRange) {
  const Scene scene = loadSmall(test::sourcePath("scenes/shapes.json"), 45, 30);
  static_assert(40 * 30 > WaveIntegrator::kWaveSize);
  const Film reference = renderWith(scene, Kernel::Scalar, RenderCase{1, 16, 5, 7});
  for (const RenderCase c : {RenderCase{1, 16, 5, 7}, RenderCase{2, 16, 5, 7}, RenderCase{2, 7, 5, 7},
                             RenderCase{2, 40, 5, 7}, RenderCase{1, 3, 5, 7}}) {
    const std::string what = "threads " + std::to_string(c.threads) + ", tile " + std::to_string(c.tileSize);
    expectIdentical(reference, renderWith(scene, Kernel::Wave, c), what);
    expectIdentical(reference, renderWith(scene, Kernel::Wave, c), what + ", lanes");
  }
}

// The ray counters (bench's rays/s) count the same rays in every kernel.
TEST(Wavefront, CountsTheSameRaysAsScalar) {
  const Scene scene = loadSmall(test::sourcePath("scenes/cornell-area.json"), 24, 24);
  PathStats scalar, wave;
  renderWith(scene, Kernel::Scalar, {}, &scalar);
  renderWith(scene, Kernel::Wave, {}, &wave);
  EXPECT_EQ(scalar.rays, wave.rays);
  EXPECT_EQ(scalar.shadowRays, wave.shadowRays);
  EXPECT_EQ(scalar.vertices, wave.vertices);
  const Scene shapes = loadSmall(test::sourcePath("scenes/shapes.json"), 24, 24);
  PathStats scalarShapes, lanes;
  renderWith(shapes, Kernel::Scalar, {}, &scalarShapes);
  renderWith(shapes, Kernel::Wave, {}, &lanes);
  EXPECT_EQ(scalarShapes.rays, lanes.rays);
  EXPECT_EQ(scalarShapes.shadowRays, lanes.shadowRays);
  EXPECT_EQ(scalarShapes.vertices, lanes.vertices);
}

// packet/geometry_groups.h: a permutation of the batch, grouped by geometry with misses first,
// and stable within a group; the counting sort and the key sort (many geometries) agree. Batch
// sizes that leave the counting sort's ranges (kWays of them) unequal or empty, and a full one.
TEST(GeometryGroups, GroupsABatchByGeometryMissesFirst) {
  const Scene scene = loadBuilt(test::sourcePath("scenes/cornell-point.json"));
  for (const size_t n :
       {size_t(1), size_t(2), size_t(3), size_t(5), size_t(17), size_t(1000), GeometryGroups::kMaxLanes}) {
    ClosestHitBatch batch(GeometryGroups::kMaxLanes);
    Rng rng(5, 9 + n);
    for (size_t i = 0; i < n; ++i)  // from in front of the open box: some rays leave the scene
      batch.push(Ray{Vec3(0.0f, 1.0f, 3.0f), sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()))});
    batch.trace(scene.accel());
    const auto key = [&](size_t a) { return uint32_t(batch.geometryOf(a) + 1u); };  // a miss (~0u) is 0
    std::vector<size_t> expected(n);
    for (size_t a = 0; a < n; ++a) expected[a] = a;
    std::stable_sort(expected.begin(), expected.end(), [&](size_t x, size_t y) { return key(x) < key(y); });
    if (n >= 1000) {
      ASSERT_EQ(key(expected.front()), 0u) << "no ray missed: the test needs misses";
      ASSERT_GT(key(expected.back()), 1u);
    }
    GeometryGroups counting, sorting;
    counting.group(batch, n, scene.geometryCount());
    sorting.group(batch, n, GeometryGroups::kMaxCountingSortBuckets + 1);
    for (size_t o = 0; o < n; ++o) {
      ASSERT_EQ(counting.order()[o], expected[o]) << "batch of " << n << ", position " << o;
      ASSERT_EQ(sorting.order()[o], expected[o]) << "batch of " << n << ", position " << o;
    }
    // The runs: consecutive, non-empty, each of one geometry and none two of the same.
    for (const GeometryGroups* groups : {&counting, &sorting}) {
      size_t covered = 0;
      std::set<uint32_t> seen;
      for (size_t r = 0; r < groups->runCount(); ++r) {
        const GeometryGroups::Run run = groups->runs()[r];
        ASSERT_EQ(run.begin, covered) << "batch of " << n << ", run " << r;
        ASSERT_LT(run.begin, run.end) << "batch of " << n << ", run " << r;
        ASSERT_TRUE(seen.insert(run.geometry).second) << "batch of " << n << ", run " << r;
        for (size_t o = run.begin; o < run.end; ++o)
          ASSERT_EQ(batch.geometryOf(expected[o]), run.geometry) << "batch of " << n << ", position " << o;
        covered = run.end;
      }
      ASSERT_EQ(covered, n) << "batch of " << n;
    }
  }
}

TEST(Wavefront, KernelNames) {
  EXPECT_EQ(parseKernel("wave"), Kernel::Wave);
  EXPECT_EQ(parseKernel("wavefront"), Kernel::Wave);
  EXPECT_EQ(parseKernel("lanes"), Kernel::Wave);
  EXPECT_EQ(parseKernel("scalar"), Kernel::Scalar);
  EXPECT_FALSE(parseKernel("stream").has_value());  // retired with the copies it ran
  EXPECT_FALSE(parseKernel("packet").has_value());
}

}  // namespace
}  // namespace ember
