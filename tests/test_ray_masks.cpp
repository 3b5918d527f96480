// Embree ray masks for flat shapes and convex solids' boundaries (Shape::flat, Shape::convexSide,
// Scene::build): each gets a mask bit of its own, rays leaving it where they cannot meet it again
// (SurfaceHit::maskFor, maskToward) and shadow rays aimed at a flat emitter (Light::shadowMask) leave that
// bit out, and Embree skips the shape for them. The skip must never change what a ray finds: a masked ray
// hits exactly what an unmasked one hits, and a shadow ray is blocked exactly when it was before.
#include "accel/box.h"
#include "accel/cone.h"
#include "accel/cylinder.h"
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
#include <glm/gtc/matrix_transform.hpp>

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

// The ray leaving `from` towards `dir` finds, with its mask, exactly what it finds without:
// whether it hits, and where. Returns whether it hit; `mask` is the mask it had.
bool findsTheSameMasked(const Scene& scene, const SurfaceHit& from, const Vec3& dir, uint32_t& mask) {
  const bool front = frontSide(from.ng, dir);
  const Ray leaving{from.offsetOrigin(front), dir};
  mask = from.maskFor(front);
  SurfaceHit masked, unmasked;
  const bool hit = scene.intersect(leaving, masked, mask);
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

// A segment from a surface to a point within rounding of its own plane (a light sampled on the
// surface it lights) keeps the surface's bit: its far end may lie on the other side.
TEST(RayMasks, ASegmentAlongItsOwnPlaneKeepsTheSurfacesBit) {
  const Scene scene = stackedQuads();
  const SurfaceHit from = hitOnLayer(scene, 3, 0.1f, 0.2f);
  const Vec3 onPlane(-0.5f, from.p.y, 0.4f);
  EXPECT_EQ(from.maskToward(onPlane, from.pError, frontSide(from.ng, onPlane - from.p)), 0xFFFFFFFFu);
  const Vec3 above(-0.5f, from.p.y + 0.05f, 0.4f);
  EXPECT_NE(from.maskToward(above, 0.0f, frontSide(from.ng, above - from.p)), 0xFFFFFFFFu);
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

// Balls, flipped balls, a box, open and capped cylinders and cones, a disc and a triangle inside a
// flipped sphere: rays leave them to either side (masked where they cannot come back), and so do
// segments to points in the room.
TEST(RayMasks, RaysLeavingSolidsAndPlanesFindWhatUnmaskedRaysFind) {
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
  // The other convex solids, open tubes and cones among them (seen from inside through their
  // open ends), and flat shapes in the room.
  const glm::mat3 turn = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(Vec3(1, 2, 3))));
  scene.shapes.push_back(
      {"box", std::make_unique<Box>(Vec3(3, -3, 2), Vec3(2.0f, 1.0f, 1.5f), turn), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"tube", std::make_unique<Cylinder>(Vec3(-4, 0, 0), Vec3(-1, 2, 1), 1.2f, false), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"can", std::make_unique<Cylinder>(Vec3(2, 3, -3), Vec3(3, 5, -2), 0.8f, true), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"funnel", std::make_unique<Cone>(Vec3(0, -4, 3), Vec3(1, -1, 2), 1.5f, false), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"cone", std::make_unique<Cone>(Vec3(-3, -3, -3), Vec3(-2, -1, -4), 1.0f, true), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"disc", std::make_unique<Disc>(Vec3(0, 5, 0), Vec3(0, -1, 0), 2.0f), grey, Color(0.0f)});
  scene.shapes.push_back(
      {"tri",
       std::make_unique<Triangle>(std::array<Vec3, 3>{Vec3(-5, -5, 5), Vec3(5, -5, 5), Vec3(0, 5, 5)},
                                  std::array<Vec2, 3>{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)}),
       grey, Color(0.0f)});
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
    uint32_t mask;
    findsTheSameMasked(scene, from, dir, mask);
    ++compared;
    masked += mask != 0xFFFFFFFFu;
    // And a segment to a point in the room, as a shadow ray is made.
    const Vec3 to(rng.uniform() * 16.0f - 8.0f, rng.uniform() * 16.0f - 8.0f, rng.uniform() * 16.0f - 8.0f);
    const bool front = frontSide(from.ng, to - from.p);
    const Ray segment = spawnRayTo(from.p, from.ng, from.pError, to, Vec3(0.0f), 0.0f, front);
    EXPECT_EQ(scene.occluded(segment, from.maskToward(to, 0.0f, front)), scene.occluded(segment));
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
    uint32_t mask;
    hitsCompared += findsTheSameMasked(scene, from, dir, mask);
    // A shadow ray to a point of the light.
    const Vec3 target(rng.uniform() - 0.5f, kLightY, rng.uniform() - 0.5f);
    const float targetError = roundingErrorBound(maxAbsComponent(target));
    const bool front = frontSide(from.ng, target - from.p);
    const Ray shadow = spawnRayTo(from.p, from.ng, from.pError, target, Vec3(0, -1, 0), targetError, front);
    const bool occluded =
        scene.occluded(shadow, from.maskToward(target, targetError, front) & light.shadowMask);
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
