// Google Benchmark micro-benchmarks of the per-sample building blocks: each analytic shape's
// intersect and occluded query through Embree, each material's sample and eval, the samplers and
// the light sampler. Results are relative: compare runs made in the same session.
#include "accel/box.h"
#include "accel/cone.h"
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "core/sampling.h"
#include "materials/gltf_pbr.h"
#include "materials/lambertian.h"
#include "materials/mixed.h"
#include "materials/phong.h"
#include "materials/specular.h"
#include "renderer/sampler.h"
#include "renderer/scene.h"

#include <benchmark/benchmark.h>

#include <functional>

namespace ember {
namespace {

std::unique_ptr<Shape> makeShape(int kind) {
  switch (kind) {
    case 0:
      return std::make_unique<Sphere>(Vec3(0.0f), 0.5f);
    case 1:
      return std::make_unique<Disc>(Vec3(0.0f), Vec3(0.2f, 0.3f, 1.0f), 0.5f);
    case 2:
      return std::make_unique<Cylinder>(Vec3(0.0f, -0.4f, 0.0f), Vec3(0.0f, 0.4f, 0.1f), 0.4f, true);
    case 3:
      return std::make_unique<Cone>(Vec3(0.0f, -0.4f, 0.0f), Vec3(0.0f, 0.4f, 0.0f), 0.4f, true);
    case 4:
      return std::make_unique<Box>(Vec3(0.0f), Vec3(0.7f), glm::mat3(1.0f));
    case 5:
      return std::make_unique<Triangle>(
          std::array<Vec3, 3>{Vec3(-0.5f, -0.5f, 0), Vec3(0.5f, -0.5f, 0), Vec3(0, 0.5f, 0)},
          std::array<Vec2, 3>{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)});
    default:
      return std::make_unique<Quad>(std::array<Vec3, 4>{Vec3(-0.5f, -0.5f, 0), Vec3(0.5f, -0.5f, 0),
                                                        Vec3(0.5f, 0.5f, 0), Vec3(-0.5f, 0.5f, 0)},
                                    std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)});
  }
}
const char* kShapeNames[] = {"sphere", "disc", "cylinder", "cone", "box", "triangle", "quad"};

// Rays from a sphere of radius 2 towards random points near the shape: about half hit.
std::vector<Ray> randomRays(size_t n) {
  Rng rng(7, 1);
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    r.origin = 2.0f * sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    const Vec3 target = 0.6f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f) * 2.0f;
    r.dir = glm::normalize(target - r.origin);
  }
  return rays;
}

void shapeQuery(benchmark::State& state, bool occlusion) {
  Scene scene;
  const Material* m =
      scene.addMaterial("grey", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(0.5f))));
  scene.shapes.push_back({"shape", makeShape(int(state.range(0))), m, Color(0.0f)});
  scene.build();
  const std::vector<Ray> rays = randomRays(4096);
  size_t i = 0, hits = 0;
  for (auto _ : state) {
    const Ray& r = rays[i++ & 4095];
    if (occlusion) {
      hits += scene.occluded(Ray{r.origin, r.dir, kInfinity});
    } else {
      SurfaceHit hit;
      hits += scene.intersect(r, hit);
    }
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(int64_t(state.iterations()));
  state.SetLabel(kShapeNames[state.range(0)]);
}
void BM_ShapeIntersect(benchmark::State& state) {
  shapeQuery(state, false);
}
void BM_ShapeOccluded(benchmark::State& state) {
  shapeQuery(state, true);
}
BENCHMARK(BM_ShapeIntersect)->DenseRange(0, 6);
BENCHMARK(BM_ShapeOccluded)->DenseRange(0, 6);

// The glTF metallic-roughness material: 0 dielectric (roughness 0.5), 1 metal (roughness 0.3),
// 2 half metallic, 3 thin-walled transmission, 4 volumetric transmission (refraction).
std::unique_ptr<Material> makeGltfPbr(int kind) {
  GltfPbrInputs in;
  in.baseColor = std::make_shared<ConstantTexture>(Color(0.8f, 0.6f, 0.3f));
  const float roughness = kind == 1 ? 0.3f : 0.5f, metallic = kind == 1 ? 1.0f : (kind == 2 ? 0.5f : 0.0f);
  in.metallicRoughness = std::make_shared<ConstantTexture>(Color(0.0f, roughness, metallic));
  if (kind >= 3) in.transmission = std::make_shared<ConstantTexture>(Color(1.0f, 0.0f, 0.0f));
  in.thinWalled = kind != 4;
  return std::make_unique<GltfPbrMaterial>(std::move(in));
}

// 0-4: Ember's own materials; 5-9: the glTF material in the configurations of makeGltfPbr.
std::unique_ptr<Material> makeMaterial(int kind) {
  if (kind >= 5) return makeGltfPbr(kind - 5);
  auto kd = std::make_shared<ConstantTexture>(Color(0.5f));
  switch (kind) {
    case 0:
      return std::make_unique<Lambertian>(kd);
    case 1:
      return std::make_unique<Phong>(kd, Color(0.4f), 50.0f);
    case 2:
      return std::make_unique<Mirror>(Color(1.0f));
    case 3:
      return std::make_unique<Dielectric>(1.5f, 1.0f);
    default: {
      MixedCoefficients c;
      c.kd = kd;
      c.ks = Color(0.2f);
      c.kr = Color(0.1f);
      c.kt = Color(0.1f);
      return std::make_unique<Mixed>(std::move(c));
    }
  }
}
const char* kMaterialNames[] = {"lambertian",
                                "phong",
                                "mirror",
                                "dielectric",
                                "mixed",
                                "gltf dielectric r0.5",
                                "gltf metal r0.3",
                                "gltf metallic 0.5",
                                "gltf thin transmission",
                                "gltf volume transmission"};

SurfaceHit flatHit() {
  SurfaceHit hit;
  hit.p = Vec3(0.0f);
  hit.ng = hit.ns = Vec3(0.0f, 0.0f, 1.0f);
  hit.uv = Vec2(0.5f);
  return hit;
}

void BM_MaterialSample(benchmark::State& state) {
  const auto material = makeMaterial(int(state.range(0)));
  const SurfaceHit hit = flatHit();
  const Vec3 wo = glm::normalize(Vec3(0.3f, 0.1f, 0.9f));
  Rng rng(3, 3);
  BsdfSample bs;
  for (auto _ : state) {
    const Vec2 u(rng.uniform(), rng.uniform());
    benchmark::DoNotOptimize(material->sample(hit, wo, u, rng.uniform(), bs));
    benchmark::DoNotOptimize(bs);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
  state.SetLabel(kMaterialNames[state.range(0)]);
}
void BM_MaterialEval(benchmark::State& state) {
  const auto material = makeMaterial(int(state.range(0)));
  const SurfaceHit hit = flatHit();
  const Vec3 wo = glm::normalize(Vec3(0.3f, 0.1f, 0.9f));
  Rng rng(3, 3);
  for (auto _ : state) {
    const Vec3 wi = sampleCosineHemisphere(Vec2(rng.uniform(), rng.uniform()));
    benchmark::DoNotOptimize(material->eval(hit, wo, wi));
    benchmark::DoNotOptimize(material->pdf(hit, wo, wi));
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
  state.SetLabel(kMaterialNames[state.range(0)]);
}
BENCHMARK(BM_MaterialSample)->DenseRange(0, 9);
BENCHMARK(BM_MaterialEval)->DenseRange(0, 9);

void BM_Rng(benchmark::State& state) {
  Rng rng(1, 2);
  for (auto _ : state) benchmark::DoNotOptimize(rng.uniform());
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_Rng);

void BM_Sampler2D(benchmark::State& state) {
  const SamplerType type = state.range(0) ? SamplerType::Sobol : SamplerType::Independent;
  uint64_t index = 0;
  for (auto _ : state) {
    Sampler s(type, 1, 12345, index++ & 255);
    for (int d = 0; d < 8; ++d) benchmark::DoNotOptimize(s.get2D());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * 8);
  state.SetLabel(state.range(0) ? "sobol" : "independent");
}
BENCHMARK(BM_Sampler2D)->Arg(0)->Arg(1);

void BM_LightSampler(benchmark::State& state) {
  // n quad lights of varied power, chosen by power, then sampled from a point below them.
  const int n = int(state.range(0));
  std::vector<std::unique_ptr<Shape>> shapes;
  std::vector<std::unique_ptr<Light>> lights;
  std::vector<Light*> raw;
  for (int i = 0; i < n; ++i) {
    const float x = float(i % 32) * 0.1f, z = float(i / 32) * 0.1f;
    shapes.push_back(
        std::make_unique<Quad>(std::array<Vec3, 4>{Vec3(x, 2, z), Vec3(x + 0.05f, 2, z),
                                                   Vec3(x + 0.05f, 2, z + 0.05f), Vec3(x, 2, z + 0.05f)},
                               std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)}));
    lights.push_back(std::make_unique<AreaLight>(shapes.back().get(), Color(1.0f + float(i % 7))));
    raw.push_back(lights.back().get());
  }
  const LightSampler sampler(raw, 10.0f);
  Rng rng(5, 5);
  for (auto _ : state) {
    float pmf;
    const Light* light = sampler.sample(rng.uniform(), pmf);
    LightSample ls;
    benchmark::DoNotOptimize(light->sample(Vec3(0.5f, 0.0f, 0.5f), Vec2(rng.uniform(), rng.uniform()), ls));
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_LightSampler)->Arg(1)->Arg(10)->Arg(1000);

}  // namespace
}  // namespace ember
