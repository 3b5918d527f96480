// Embree ray masks for flat shapes and convex solids' boundaries (Shape::flat, Shape::convexSide,
// Scene::build): each gets a mask bit of its own, rays leaving it where they cannot meet it again
// (SurfaceHit::rayMask) and shadow rays aimed at a flat emitter (Light::shadowMask) leave that bit
// out, and Embree skips the shape for them. The skip must never change what a ray finds: a masked
// ray hits exactly what an unmasked one hits, and a shadow ray is blocked exactly when it was
// before.
#include "accel/disc.h"
#include "accel/flipped_shape.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "core/ray_spawn.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "materials/lambertian.h"
#include "renderer/scene.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <set>

namespace ember {
namespace {

constexpr int kLayers = 40;  // more flat shapes than Embree has mask bits
constexpr float kSpacing = 0.1f;
constexpr float kLightY = kLayers * kSpacing + 0.5f;

std::unique_ptr<Quad> horizontalQuad(float y, float half) {
  const std::array<Vec3, 4> v{Vec3(-half, y, -half), Vec3(half, y, -half), Vec3(half, y, half),
                              Vec3(-half, y, half)};
  return std::make_unique<Quad>(v, std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)});
}

// A stack of horizontal quads under an emissive quad, with a sphere among them: a ray leaving one
// layer upwards meets the next, so two layers sharing a bit would lose hits.
Scene stackedQuads() {
  Scene scene;
  const Material* grey =
      scene.addMaterial("grey", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(0.5f))));
  for (int i = 0; i < kLayers; ++i)
    scene.shapes.push_back({"layer", horizontalQuad(float(i) * kSpacing, 1.0f), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"ball", std::make_unique<Sphere>(Vec3(0.3f, 1.05f, 0.2f), 0.04f), grey, Color(0.0f)});
  scene.shapes.push_back({"light", horizontalQuad(kLightY, 0.5f), grey, Color(4.0f)});
  scene.build();
  return scene;
}

const Light& areaLight(const Scene& scene) {
  for (const auto& light : scene.lights)
    if (!light->isDelta()) return *light;
  throw std::logic_error("no area light");
}

// The hit on top of layer i, straight from above.
SurfaceHit hitOnLayer(const Scene& scene, int i, float x, float z) {
  const Ray down{Vec3(x, float(i) * kSpacing + 0.05f, z), Vec3(0.0f, -1.0f, 0.0f)};
  SurfaceHit hit;
  EXPECT_TRUE(scene.intersect(down, hit)) << i;
  return hit;
}

// The ray leaving `from` towards its direction finds, with from's mask, exactly what it finds
// without: whether it hits, and where. Returns whether it hit.
bool findsTheSameMasked(const Scene& scene, const SurfaceHit& from, const Ray& leaving) {
  SurfaceHit masked, unmasked;
  const bool hit = scene.intersect(leaving, masked, from.rayMask(leaving.dir));
  EXPECT_EQ(hit, scene.intersect(leaving, unmasked));
  if (hit) {
    EXPECT_EQ(std::memcmp(&masked.t, &unmasked.t, sizeof(float)), 0);
    EXPECT_EQ(masked.p, unmasked.p);
    EXPECT_EQ(masked.material, unmasked.material);
  }
  return hit;
}

TEST(RayMasks, FlatShapesHaveBitsOfTheirOwnEmittersFirst) {
  const Scene scene = stackedQuads();
  // The light is given the first bit; the layers the next 31; the layers past them none.
  const uint32_t lightBit = ~areaLight(scene).shadowMask;
  EXPECT_EQ(lightBit, 1u);
  std::set<uint32_t> bits{lightBit};
  for (int i = 0; i < kLayers; ++i) {
    const SurfaceHit hit = hitOnLayer(scene, i, 0.0f, 0.0f);
    EXPECT_EQ(hit.maskFront, hit.maskBack) << i;  // flat: either side
    const uint32_t bit = ~hit.maskFront;
    if (i < 31) {
      EXPECT_EQ(std::popcount(bit), 1) << i;
      EXPECT_TRUE(bits.insert(bit).second) << "layer " << i << " shares a mask bit";
    } else {
      EXPECT_EQ(bit, 0u) << i;  // tested by every ray, as before masks
    }
  }
  SurfaceHit onBall;
  ASSERT_TRUE(scene.intersect(Ray{Vec3(0.3f, 1.095f, 0.2f), Vec3(0, -1, 0)}, onBall));
  // Convex, but past the 32 bits.
  EXPECT_EQ(onBall.maskFront, 0xFFFFFFFFu);
  EXPECT_EQ(onBall.maskBack, 0xFFFFFFFFu);
}

// What makes the equality below meaningful: Embree does skip a shape for a ray whose mask leaves
// out its bit (Debian's Embree is built with ray masks).
TEST(RayMasks, ARaySkipsTheShapeItsMaskLeavesOut) {
  const Scene scene = stackedQuads();
  const uint32_t layer5 = hitOnLayer(scene, 5, 0.0f, 0.0f).maskFront;
  const Ray down{Vec3(0.0f, 5.5f * kSpacing, 0.0f), Vec3(0.0f, -1.0f, 0.0f)};
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(down, hit, layer5));
  EXPECT_NEAR(hit.p.y, 4.0f * kSpacing, 1e-6f);  // through layer 5 to layer 4
  const Ray toLight{Vec3(0.0f, kLightY - 0.25f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), 1.0f};
  EXPECT_TRUE(scene.occluded(toLight));
  EXPECT_FALSE(scene.occluded(toLight, areaLight(scene).shadowMask));
}

// Balls in a closed box of spheres and flipped spheres: rays leave the balls outwards (masked)
// and, through the flipped ones' insides, inwards (not masked), and the outer sphere from inside.
TEST(RayMasks, RaysLeavingConvexSolidsFindWhatUnmaskedRaysFind) {
  Scene scene;
  const Material* grey =
      scene.addMaterial("grey", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(0.5f))));
  scene.shapes.push_back({"room", std::make_unique<FlippedShape>(std::make_unique<Sphere>(Vec3(0.0f), 10.0f)),
                          grey, Color(0.0f)});
  Rng place(5, 1);
  for (int i = 0; i < 12; ++i) {
    const Vec3 c(place.uniform() * 12.0f - 6.0f, place.uniform() * 12.0f - 6.0f,
                 place.uniform() * 12.0f - 6.0f);
    std::unique_ptr<Shape> ball = std::make_unique<Sphere>(c, 0.3f + place.uniform());
    if (i % 3 == 0) ball = std::make_unique<FlippedShape>(std::move(ball));
    scene.shapes.push_back({"ball", std::move(ball), grey, Color(0.0f)});
  }
  scene.build();
  Rng rng(9, 2);
  int compared = 0, masked = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vec3 o(rng.uniform() * 4.0f - 2.0f, rng.uniform() * 4.0f - 2.0f, rng.uniform() * 4.0f - 2.0f);
    const Vec3 d = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    SurfaceHit from;
    if (!scene.intersect(Ray{o, d}, from)) continue;
    const Vec3 dir = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));  // either side
    SCOPED_TRACE(k);
    findsTheSameMasked(scene, from, Ray{from.offsetOrigin(dir), dir});
    ++compared;
    masked += from.rayMask(dir) != 0xFFFFFFFFu;
  }
  EXPECT_GT(compared, 3000);
  EXPECT_GT(masked, 1000);
  // Outward rays are masked, inward ones not; a flipped sphere's normal points into its ball.
  SurfaceHit onBall;
  ASSERT_TRUE(scene.intersect(Ray{Vec3(0.0f, 0.0f, 9.9f), Vec3(0.0f, 0.0f, 1.0f)}, onBall));
  EXPECT_EQ(onBall.maskBack, ~1u);  // the room: rays back into it leave its inside
  EXPECT_EQ(onBall.maskFront, 0xFFFFFFFFu);
}

TEST(RayMasks, OnlyShapesInOnePlaneAreFlatAndSolidsBoundariesConvex) {
  EXPECT_TRUE(horizontalQuad(0.0f, 1.0f)->flat());
  EXPECT_TRUE(
      Triangle({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)}).flat());
  EXPECT_TRUE(Disc(Vec3(0.0f), Vec3(0, 0, 1), 1.0f).flat());
  EXPECT_TRUE(FlippedShape(horizontalQuad(0.0f, 1.0f)).flat());
  EXPECT_FALSE(Sphere(Vec3(0.0f), 1.0f).flat());
  EXPECT_EQ(Sphere(Vec3(0.0f), 1.0f).convexSide(), 1);
  EXPECT_EQ(FlippedShape(std::make_unique<Sphere>(Vec3(0.0f), 1.0f)).convexSide(), -1);
  EXPECT_EQ(horizontalQuad(0.0f, 1.0f)->convexSide(), 0);
  // A quad folded along its diagonal, within the loader's coplanarity tolerance: a grazing ray
  // leaving one half could meet the other.
  const std::array<Vec3, 4> folded{Vec3(-1, 0, -1), Vec3(1, 0, -1), Vec3(1, 1e-5f, 1), Vec3(-1, 0, 1)};
  EXPECT_FALSE(Quad(folded, {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)}).flat());
}

TEST(RayMasks, MaskedRaysFindWhatUnmaskedRaysFind) {
  const Scene scene = stackedQuads();
  const Light& light = areaLight(scene);
  Rng rng(7, 3);
  int hitsCompared = 0, shadowsCompared = 0, blocked = 0;
  for (int k = 0; k < 4000; ++k) {
    const int layer = int(rng.uniform() * kLayers);
    const SurfaceHit from =
        hitOnLayer(scene, layer, rng.uniform() * 1.8f - 0.9f, rng.uniform() * 1.8f - 0.9f);
    // Upwards, grazing ones included: a cosine-weighted direction about the normal it faces.
    const Vec3 up = from.ng.y > 0.0f ? from.ng : -from.ng;
    const Vec3 dir = Frame(up).toWorld(sampleCosineHemisphere(Vec2(rng.uniform(), rng.uniform())));
    SCOPED_TRACE(k);
    hitsCompared += findsTheSameMasked(scene, from, Ray{from.offsetOrigin(dir), dir});
    // A shadow ray to a point of the light.
    const Vec3 target(rng.uniform() - 0.5f, kLightY, rng.uniform() - 0.5f);
    const Ray shadow = spawnRayTo(from.p, from.ng, from.pError, target, Vec3(0, -1, 0),
                                  roundingErrorBound(maxAbsComponent(target)));
    const bool occluded = scene.occluded(shadow, from.rayMask(target - from.p) & light.shadowMask);
    EXPECT_EQ(occluded, scene.occluded(shadow)) << k;
    blocked += occluded;
    ++shadowsCompared;
  }
  EXPECT_GT(hitsCompared, 3500);
  EXPECT_GT(blocked, 3000);  // most shadow rays meet the next layer
  EXPECT_EQ(shadowsCompared, 4000);
}

}  // namespace
}  // namespace ember
