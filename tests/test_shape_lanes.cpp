// The SIMD lane filters of accel/shape_lanes.h may reject a packet lane only if the shape's scalar
// intersect() misses it, and Shape::intersectLanes (the route of every ray, packets and single
// rays alike) must find the hit intersect() finds, to rounding, and the same bits for a lane
// alone as in its block. Checked on the rays where float rounding is most likely to mislead a
// kernel: rays leaving a surface from its offset origin (at grazing angles too), shadow rays that
// stop just short of the shape, rays aimed at points of the surface and at its edges, intervals
// starting just before or past the hit, partial blocks, for shapes tiny and huge, near the origin
// and far from it. The filters must also reject most rays that miss, and the flat shapes' kernel
// settle most hits, or they would save nothing.
#include "accel/box.h"
#include "accel/cone.h"
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/flipped_shape.h"
#include "accel/packet_commit.h"
#include "accel/packet_tfar.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "core/ray_spawn.h"
#include "core/rng.h"
#include "core/sampling.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include "simd_targets.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace ember {
namespace {

Vec2 next2(Rng& rng) {
  const float x = rng.uniform();
  return {x, rng.uniform()};
}

Vec3 randomDirection(Rng& rng) {
  return sampleUniformSphere(next2(rng));
}

// 16 rays in Embree's structure-of-arrays layout, some lanes dead.
struct Block {
  alignas(64) float org[3][RayLanes::kMaxLanes];
  alignas(64) float dir[3][RayLanes::kMaxLanes];
  alignas(64) float tnear[RayLanes::kMaxLanes];
  alignas(64) float tfar[RayLanes::kMaxLanes];
  alignas(64) int valid[RayLanes::kMaxLanes];

  void set(unsigned i, const Ray& r, bool live) {
    for (int k = 0; k < 3; ++k) {
      org[k][i] = r.origin[k];
      dir[k][i] = r.dir[k];
    }
    tnear[i] = 0.0f;
    tfar[i] = r.tMax;
    valid[i] = live ? -1 : 0;
  }
  RayLanes lanes(unsigned n = RayLanes::kMaxLanes) const {
    return RayLanes{{org[0], org[1], org[2]}, {dir[0], dir[1], dir[2]}, tnear, tfar, valid, n};
  }
};

struct Tally {
  int hits = 0;      // lanes the scalar routine hits
  int missed = 0;    // ... of them rejected by the filter: must stay 0
  int misses = 0;    // live lanes the scalar routine misses
  int rejected = 0;  // ... of them rejected by the filter
  int deadKept = 0;  // dead lanes reported as candidates: must stay 0
  std::string example;
  // Shape::intersectLanes, the route every ray takes, against intersect() lane by lane.
  int laneDisagrees = 0;  // hit in one, miss in the other: must stay 0
  int laneInexact = 0;    // both hit, but t, normal or uv differ beyond rounding: must stay 0
  int deadHit = 0;        // dead lanes (or lanes past the block's n) reported as hits: must stay 0
  int aloneDiffers = 0;   // a lane traced alone gets another hit than in its block: must stay 0
  int uvSkipDiffers = 0;  // skipping the UV changes a hit's mask, t or normal: must stay 0
  int notIdentical = 0;   // shapes whose kernel mirrors intersect(): hits not equal bit for bit
  std::string laneExample;
};

std::string describe(const Ray& r) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "o (%.9g %.9g %.9g) d (%.9g %.9g %.9g) tMax %.9g", r.origin.x, r.origin.y,
                r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.tMax);
  return buf;
}

// Both are the exact hit rounded to float, computed by different double-precision formulas (the
// plane's crossing and plane coordinates against Moller-Trumbore), so t and the barycentrics may
// differ by an ulp, and the texture coordinates by the rounding of their interpolation, whose
// terms are as large as the vertex UVs (uvScale).
bool sameHit(const LocalHit& a, const LocalHit& b, float uvScale) {
  const bool t = std::abs(a.t - b.t) <= 2.5e-7f * std::abs(b.t);
  const float uvRounding = 1e-6f * std::max({uvScale, std::abs(b.uv.x), std::abs(b.uv.y)});
  const Vec2 du = glm::abs(a.uv - b.uv);
  const bool uv = std::max(du.x, du.y) <= uvRounding;
  return t && uv && a.ng == b.ng;
}

// Bit for bit: +0 and -0 differ, and so do NaNs of different payloads.
bool identical(const LocalHit& a, const LocalHit& b) {
  return std::memcmp(&a.t, &b.t, sizeof a.t) == 0 && std::memcmp(&a.ng, &b.ng, sizeof a.ng) == 0 &&
         std::memcmp(&a.uv, &b.uv, sizeof a.uv) == 0;
}

using RayMaker = std::function<Ray(Rng&)>;

void check(const Shape& shape, const RayMaker& make, int blocks, uint64_t seed, float uvScale,
           bool exactLanes, Tally& t) {
  Rng rng(seed, 3);
  for (int b = 0; b < blocks; ++b) {
    Block block;
    Ray rays[RayLanes::kMaxLanes];
    for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
      rays[i] = make(rng);
      block.set(i, rays[i], rng.uniform() < 0.85f);
      // Some rays start at an interval just before or just past their first hit.
      LocalHit first;
      if (rng.uniform() < 0.2f && shape.intersect(rays[i], 0.0f, rays[i].tMax, first))
        block.tnear[i] = first.t * (rng.uniform() < 0.5f ? 0.999f : 1.001f);
    }
    // A third of the blocks are partial (Embree's single rays come as a padded block of one); the
    // lanes past n are live but must not be reported.
    const unsigned n = b % 3 == 0 ? 1 + unsigned(rng.uniform() * 15.0f) : RayLanes::kMaxLanes;
    const uint32_t bits = shape.candidateLanes(block.lanes(n));
    LaneHits laneHits;
    shape.intersectLanes(block.lanes(n), laneHits);
    // Without texture coordinates (shadow rays, untextured materials) the same hits, t and normals.
    RayLanes withoutUv = block.lanes(n);
    withoutUv.needsUv = false;
    LaneHits noUvHits;
    shape.intersectLanes(withoutUv, noUvHits);
    t.uvSkipDiffers += noUvHits.mask != laneHits.mask;
    for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
      const bool kept = (bits >> i) & 1u;
      const bool laneHit = (laneHits.mask >> i) & 1u;
      if (block.valid[i] != -1 || i >= n) {
        t.deadKept += kept;
        t.deadHit += laneHit;
        continue;
      }
      // The same ray as the only live lane of a block gets the same hit, bit for bit.
      Block alone = block;
      for (unsigned k = 0; k < RayLanes::kMaxLanes; ++k) alone.valid[k] = k == i ? -1 : 0;
      LaneHits aloneHits;
      shape.intersectLanes(alone.lanes(), aloneHits);
      if (laneHit && (noUvHits.at(i).t != laneHits.at(i).t || noUvHits.at(i).ng != laneHits.at(i).ng))
        ++t.uvSkipDiffers;
      if (aloneHits.mask != (laneHit ? 1u << i : 0u) ||
          (laneHit && !identical(aloneHits.at(i), laneHits.at(i))))
        ++t.aloneDiffers;
      LocalHit h;
      const bool hit = shape.intersect(rays[i], block.tnear[i], rays[i].tMax, h);
      if (exactLanes && hit && laneHit && !identical(laneHits.at(i), h)) ++t.notIdentical;
      if (laneHit != hit || (hit && !sameHit(laneHits.at(i), h, uvScale))) {
        ++(laneHit != hit ? t.laneDisagrees : t.laneInexact);
        if (t.laneExample.empty()) {
          char buf[160];
          std::snprintf(buf, sizeof buf,
                        ": lanes %s t %.9g uv (%.7g %.7g), intersect() %s t %.9g uv (%.7g %.7g)",
                        laneHit ? "hit" : "miss", laneHits.at(i).t, laneHits.at(i).uv.x, laneHits.at(i).uv.y,
                        hit ? "hit" : "miss", h.t, h.uv.x, h.uv.y);
          t.laneExample = describe(rays[i]) + buf;
        }
      }
      if (hit) {
        ++t.hits;
        if (!kept && t.missed++ == 0) {
          char buf[256];
          std::snprintf(buf, sizeof buf, "o (%.9g %.9g %.9g) d (%.9g %.9g %.9g) tMax %.9g: scalar t %.9g",
                        rays[i].origin.x, rays[i].origin.y, rays[i].origin.z, rays[i].dir.x, rays[i].dir.y,
                        rays[i].dir.z, rays[i].tMax, h.t);
          t.example = buf;
        }
      } else {
        ++t.misses;
        t.rejected += !kept;
      }
    }
  }
}

struct ShapeCase {
  std::string name;
  std::unique_ptr<Shape> shape;
  float size;
  Vec3 center;
  bool hasFilter;  // shapes without one keep every live lane
  // The lanes' hits equal intersect()'s bit for bit (the double-precision kernels of the sphere, disc,
  // cylinder, cone, box and axis-aligned rectangle), not only to rounding (the other flat shapes'
  // settled hits come from another formula).
  bool exactLanes = false;
};

std::vector<ShapeCase> cases(const Vec3& at, float s) {
  std::vector<ShapeCase> out;
  auto add = [&](std::string name, std::unique_ptr<Shape> shape, bool filter) {
    out.push_back({std::move(name), std::move(shape), s, at, filter});
  };
  add("sphere", std::make_unique<Sphere>(at, s), true);
  add("flipped sphere", std::make_unique<FlippedShape>(std::make_unique<Sphere>(at, 0.7f * s)), true);
  out[0].exactLanes = out[1].exactLanes = true;
  const std::array<Vec2, 4> quadUv{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  // Axis-aligned rectangle: an exact parallelogram, filtered in one test.
  add("axis quad",
      std::make_unique<Quad>(std::array<Vec3, 4>{at + s * Vec3(-1, 0, -1), at + s * Vec3(1, 0, -1),
                                                 at + s * Vec3(1, 0, 1), at + s * Vec3(-1, 0, 1)},
                             quadUv),
      true);
  // The same facing -x, its edges given along z first (the axis-rectangle filter's other order).
  add("axis quad facing -x",
      std::make_unique<Quad>(std::array<Vec3, 4>{at + s * Vec3(0, -1, -1), at + s * Vec3(0, -1, 1),
                                                 at + s * Vec3(0, 1, 1), at + s * Vec3(0, 1, -1)},
                             quadUv),
      true);
  add("flipped axis quad",
      std::make_unique<FlippedShape>(
          std::make_unique<Quad>(std::array<Vec3, 4>{at + s * Vec3(-1, -0.5f, 0), at + s * Vec3(1, -0.5f, 0),
                                                     at + s * Vec3(1, 0.5f, 0), at + s * Vec3(-1, 0.5f, 0)},
                                 quadUv)),
      true);
  // A rotated rectangle (its fourth vertex rounds off the parallelogram), a skewed planar quad
  // and one whose fourth vertex lifts it 1e-4 out of plane: two filters each.
  const Vec3 u = glm::normalize(Vec3(0.8f, 0.3f, -0.2f)),
             w = glm::normalize(glm::cross(u, Vec3(0.1f, 1.0f, 0.3f)));
  add("rotated quad",
      std::make_unique<Quad>(
          std::array<Vec3, 4>{at - s * u - s * w, at + s * u - s * w, at + s * u + s * w, at - s * u + s * w},
          quadUv),
      true);
  add("skewed quad",
      std::make_unique<Quad>(
          std::array<Vec3, 4>{at, at + s * u, at + s * (1.6f * u + 0.9f * w), at + s * (0.2f * u + w)},
          quadUv),
      true);
  add("non-planar quad",
      std::make_unique<Quad>(
          std::array<Vec3, 4>{at, at + s * u, at + s * (u + w) + 1e-4f * s * glm::cross(u, w), at + s * w},
          quadUv),
      true);
  add("flipped rotated quad",
      std::make_unique<FlippedShape>(std::make_unique<Quad>(
          std::array<Vec3, 4>{at - s * u - s * w, at + s * u - s * w, at + s * u + s * w, at - s * u + s * w},
          quadUv)),
      true);
  // A quad given as a triangle (v3 = v0): its second half has no area.
  add("quad with an empty half",
      std::make_unique<Quad>(std::array<Vec3, 4>{at, at + s * u, at + s * (u + w), at}, quadUv), true);
  // Texture coordinates tiled 100 times, and negative: an error in the barycentrics is magnified.
  add("axis quad tiled uv",
      std::make_unique<Quad>(std::array<Vec3, 4>{at + s * Vec3(-1, 0, -1), at + s * Vec3(1, 0, -1),
                                                 at + s * Vec3(1, 0, 1), at + s * Vec3(-1, 0, 1)},
                             std::array<Vec2, 4>{Vec2(-50, -50), Vec2(50, -50), Vec2(50, 50), Vec2(-50, 50)}),
      true);
  const std::array<Vec2, 3> triUv{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  add("triangle tiled uv",
      std::make_unique<Triangle>(
          std::array<Vec3, 3>{at + s * Vec3(-1, -0.3f, 0.2f), at + s * Vec3(0.9f, 0.1f, -0.4f),
                              at + s * Vec3(0.1f, 1.1f, 0.3f)},
          std::array<Vec2, 3>{Vec2(0, 0), Vec2(100, 3), Vec2(-7, 80)}),
      true);
  add("triangle",
      std::make_unique<Triangle>(
          std::array<Vec3, 3>{at + s * Vec3(-1, -0.3f, 0.2f), at + s * Vec3(0.9f, 0.1f, -0.4f),
                              at + s * Vec3(0.1f, 1.1f, 0.3f)},
          triUv),
      true);
  add("sliver triangle",
      std::make_unique<Triangle>(
          std::array<Vec3, 3>{at, at + s * Vec3(1, 0, 0), at + s * Vec3(0.5f, 1e-3f, 0)}, triUv),
      true);
  // The shapes whose double-precision kernels mirror intersect() (accel/quadric_lanes.h): no
  // filter, every hit bit for bit.
  const size_t firstExact = out.size();
  add("capped cylinder", std::make_unique<Cylinder>(at - s * u, at + s * u, 0.5f * s, true), false);
  add("open cylinder", std::make_unique<Cylinder>(at - s * w, at + 0.3f * s * w, 0.8f * s, false), false);
  add("capped cone", std::make_unique<Cone>(at - s * u, at + s * u, 0.7f * s, true), false);
  add("open cone", std::make_unique<Cone>(at + s * w, at - s * w, 0.4f * s, false), false);
  add("flat cone", std::make_unique<Cone>(at, at + 0.05f * s * u, s, true), false);
  add("flipped cone",
      std::make_unique<FlippedShape>(std::make_unique<Cone>(at - s * u, at + s * u, 0.7f * s, true)), false);
  add("disc", std::make_unique<Disc>(at, w, s), false);
  add("axis box", std::make_unique<Box>(at, Vec3(s), glm::mat3(1.0f)), false);
  add("rotated box", std::make_unique<Box>(at, s * Vec3(1.0f, 0.3f, 2.0f), glm::mat3(u, w, glm::cross(u, w))),
      false);
  for (size_t k = firstExact; k < out.size(); ++k) out[k].exactLanes = true;
  // Axis-aligned rectangles take their exact double-precision kernel too.
  for (ShapeCase& c : out)
    if (c.name.find("axis quad") != std::string::npos) c.exactLanes = true;
  return out;
}

// Ray families; every one starts from a point related to the shape.
std::vector<std::pair<std::string, RayMaker>> families(const Shape& shape, float size, const Vec3& center) {
  std::vector<std::pair<std::string, RayMaker>> out;
  out.push_back({"random", [=](Rng& rng) {
                   const Vec3 o = center + 3.0f * size *
                                               (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f) *
                                               2.0f;
                   return Ray{o, randomDirection(rng)};
                 }});
  out.push_back({"aimed at the surface", [&shape, size](Rng& rng) {
                   const ShapeSample s = shape.sampleArea(next2(rng));
                   const Vec3 o =
                       s.p + size * std::pow(10.0f, -3.0f + 4.0f * rng.uniform()) * randomDirection(rng);
                   return Ray{o, glm::normalize(s.p - o)};
                 }});
  // Leaving the surface from the offset origin of a sampled point, in any direction: the
  // reflected, transmitted and grazing rays of a path.
  out.push_back({"leaving the surface", [&shape](Rng& rng) {
                   const ShapeSample s = shape.sampleArea(next2(rng));
                   Vec3 d = randomDirection(rng);
                   if (rng.uniform() < 0.3f)
                     d = glm::normalize(d - glm::dot(d, s.n) * s.n * (1.0f - 1e-3f * rng.uniform()));
                   const float err = roundingErrorBound(maxAbsComponent(s.p));
                   return Ray{offsetAlongNormal(s.p, s.n, err, d), d};
                 }});
  // Shadow rays to the shape's own surface, which must stop just short of it.
  out.push_back({"shadow rays to it", [&shape, size](Rng& rng) {
                   const ShapeSample s = shape.sampleArea(next2(rng));
                   Vec3 w = randomDirection(rng);
                   if (glm::dot(w, s.n) < 0.0f) w = -w;
                   const Vec3 ref = s.p + size * std::pow(10.0f, -3.0f + 3.5f * rng.uniform()) * w;
                   const float err = roundingErrorBound(maxAbsComponent(ref) + size);
                   const Vec3 nFrom = glm::normalize(-w + 0.5f * randomDirection(rng));
                   return spawnRayTo(ref, nFrom, err, s.p, s.n, roundingErrorBound(maxAbsComponent(s.p)));
                 }});
  // Just past the rim: points sampled on the surface, pushed outwards in the tangent plane.
  out.push_back({"at the edges", [&shape, size, center](Rng& rng) {
                   const ShapeSample s = shape.sampleArea(next2(rng));
                   const Vec3 out = s.p - center;
                   const Vec3 tangent = out - glm::dot(out, s.n) * s.n;
                   const Vec3 target = s.p + (1e-6f * rng.uniform()) * tangent;
                   const Vec3 o = target + size * (0.1f + rng.uniform()) * randomDirection(rng);
                   return Ray{o, glm::normalize(target - o), rng.uniform() < 0.5f ? kInfinity : 2.0f * size};
                 }});
  // Across the rim, found by bisection: from a fixed origin, rays aimed along a line in the tangent
  // plane of a surface point are hit at the point and missed far along the line; between the two,
  // 40 halvings find where the scalar routine's verdict flips (an edge, a cap's rim or a curved
  // shape's silhouette), and the ray is aimed within 1e-9 to 1e-4 of the shape's size of it, on
  // either side. There a filter's rounding decides, so a bound too tight shows.
  out.push_back({"across the rim", [&shape, size](Rng& rng) {
                   const ShapeSample s = shape.sampleArea(next2(rng));
                   const Vec3 o = s.p + size * (0.05f + 3.0f * rng.uniform()) * randomDirection(rng);
                   Vec3 along = randomDirection(rng);
                   along -= glm::dot(along, s.n) * s.n;
                   const Ray atPoint{o, glm::normalize(s.p - o)};
                   if (!(glm::length(along) > 1e-3f)) return atPoint;
                   along = glm::normalize(along);
                   const auto aimed = [&](float lambda) {
                     return Ray{o, glm::normalize(s.p + lambda * along - o)};
                   };
                   const auto hits = [&](float lambda) {
                     LocalHit h;
                     return shape.intersect(aimed(lambda), 0.0f, kInfinity, h);
                   };
                   float in = 0.0f, beyond = 4.0f * size;
                   if (!hits(in) || hits(beyond))
                     return atPoint;  // no single crossing of the rim on this line
                   for (int k = 0; k < 40; ++k) {
                     const float mid = 0.5f * (in + beyond);
                     if (mid == in || mid == beyond) break;
                     (hits(mid) ? in : beyond) = mid;
                   }
                   // Offsets below a float step of lambda leave it the bisection's last hit or first miss.
                   const float offset = size * std::pow(10.0f, -9.0f + 5.0f * rng.uniform());
                   return aimed(rng.uniform() < 0.5f ? in - offset : beyond + offset);
                 }});
  return out;
}

void runAll(const Vec3& at, float size, uint64_t seed) {
  for (const ShapeCase& c : cases(at, size)) {
    for (const auto& [family, make] : families(*c.shape, c.size, c.center)) {
      SCOPED_TRACE(c.name + ", " + family);
      Tally t;
      check(*c.shape, make, 400, seed, c.name.find("tiled") != std::string::npos ? 100.0f : 1.0f,
            c.exactLanes, t);
      EXPECT_EQ(t.missed, 0) << "the filter rejected " << t.missed << " of " << t.hits
                             << " lanes the scalar routine hits; first: " << t.example;
      EXPECT_EQ(t.deadKept, 0);
      EXPECT_EQ(t.deadHit, 0);
      EXPECT_EQ(t.laneDisagrees, 0) << "first: " << t.laneExample;
      EXPECT_EQ(t.laneInexact, 0) << "first: " << t.laneExample;
      EXPECT_EQ(t.aloneDiffers, 0);
      EXPECT_EQ(t.uvSkipDiffers, 0);
      EXPECT_EQ(t.notIdentical, 0);
      if (family != "random") continue;
      if (c.hasFilter) {
        EXPECT_GT(t.rejected, t.misses * 9 / 10) << "rejects too few of " << t.misses << " misses";
      } else {
        EXPECT_EQ(t.rejected, 0);
      }
    }
  }
}

TEST(ShapeLanes, FiltersKeepEveryHitNearTheOrigin) {
  runAll(Vec3(0.0f), 1.0f, 1);
}

TEST(ShapeLanes, FiltersKeepEveryHitOfTinyShapes) {
  runAll(Vec3(0.3f, -0.2f, 0.1f), 1e-3f, 2);
}

TEST(ShapeLanes, FiltersKeepEveryHitOfHugeShapes) {
  runAll(Vec3(0.0f, -2e3f, 0.0f), 1e3f, 3);
}

TEST(ShapeLanes, FiltersKeepEveryHitFarFromTheOrigin) {
  runAll(Vec3(6e3f, -3.5e3f, 1.1e4f), 2.0f, 4);
}

}  // namespace
}  // namespace ember

namespace ember {
namespace {

// A triangle of about `size` at `at`, neither axis-aligned nor right-angled.
std::array<Vec3, 3> testTriangle(const Vec3& at, float size) {
  return {at + size * Vec3(-1, -0.3f, 0.2f), at + size * Vec3(0.9f, 0.1f, -0.4f),
          at + size * Vec3(0.1f, 1.1f, 0.3f)};
}

// The speed of flat shapes comes from the kernel settling the hits away from their edges: rays
// aimed at interior points (barycentric margin >= 0.05) from a few sizes away must nearly all be
// settled, near the origin and far from it.
TEST(ShapeLanes, KernelSettlesHitsAwayFromEdges) {
  for (const auto& [at, size] : {std::pair{Vec3(0.0f), 1.0f}, std::pair{Vec3(6e3f, -3.5e3f, 1.1e4f), 2.0f}}) {
    const auto [v0, v1, v2] = testTriangle(at, size);
    const DoublePlane plane = DoublePlane::through(v0, v1, v2);
    for (const bool parallelogram : {false, true}) {
      SCOPED_TRACE(std::string(parallelogram ? "parallelogram" : "triangle") + " at " + std::to_string(at.x));
      const TriangleFilter filter = TriangleFilter::of(v0, v1, v2, plane, parallelogram);
      const Vec3 n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
      Rng rng(7, parallelogram);
      int rays = 0, settled = 0;
      for (int b = 0; b < 200; ++b) {
        Block block;
        for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
          float b1 = rng.uniform(), b2 = rng.uniform();
          if (!parallelogram && b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
          // At least 0.05 from every edge.
          b1 = 0.05f + (parallelogram ? 0.9f : 0.85f) * b1;
          b2 = 0.05f + (parallelogram ? 0.9f : 0.85f) * b2;
          const Vec3 target = v0 + b1 * (v1 - v0) + b2 * (v2 - v0);
          Vec3 w = randomDirection(rng);
          if (std::abs(glm::dot(w, n)) < 0.1f) w = glm::normalize(w + 0.2f * n);
          const Vec3 o = target + size * (1.0f + 2.0f * rng.uniform()) * w;
          block.set(i, Ray{o, glm::normalize(target - o)}, true);
        }
        TriangleLanes lanes;
        triangleLanes(block.lanes(), filter, lanes);
        rays += int(RayLanes::kMaxLanes);
        settled += __builtin_popcount(lanes.inside);
      }
      EXPECT_GE(settled, rays * 95 / 100) << settled << " of " << rays << " settled";
    }
  }
}

// The axis-aligned rectangle's kernel against its scalar routine on the inputs where a lane mask
// could diverge from a branch: a zero direction component of either sign, NaN and infinite
// components, empty and reversed intervals, origins on the plane and exactly on an edge's line.
void expectAxisRectangleKernelEqualsTheScalar() {
  const Vec3 v0(-1.0f, 0.5f, -0.5f), v1(1.0f, 0.5f, -0.5f), v2(1.0f, 0.5f, 0.5f), v3(-1.0f, 0.5f, 0.5f);
  AxisRectangle rect;
  ASSERT_TRUE(AxisRectangle::of(v0, v1, v2, v3, rect));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const Ray rays[] = {
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)},        // straight down: a hit
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.3f, 0.0f, 0.1f)},         // parallel, +0
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.3f, -0.0f, 0.1f)},        // parallel, -0
      {Vec3(0.0f, 0.5f, 0.0f), Vec3(0.3f, -0.0f, 0.1f)},        // in the plane
      {Vec3(0.0f, 0.5f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)},        // from the plane: t = 0
      {Vec3(1.0f, 2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)},        // onto an edge's line
      {Vec3(1.0f, 2.0f, 0.5f), Vec3(0.0f, -1.0f, 0.0f)},        // onto a corner
      {Vec3(nan, 2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)},         // NaN origin
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(nan, -1.0f, 0.0f)},         // NaN direction
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, nan, 0.0f)},          // NaN denominator
      {Vec3(inf, 2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)},         // infinite origin
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(inf, -1.0f, 0.0f)},         // infinite direction
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, -1e-40f, 0.0f)},      // subnormal denominator
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f), 1.5f},  // interval ending at the plane
      {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f), 1.0f},  // ... and before it
      {Vec3(0.0f, -2.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)},       // the plane behind
  };
  Block block;
  const unsigned n = unsigned(std::size(rays));
  for (unsigned i = 0; i < n; ++i) block.set(i, rays[i], true);
  const unsigned reversed = n - 2;  // the ray whose interval ends before the plane starts past its end
  block.tnear[reversed] = 3.0f;
  const uint32_t mask = axisRectangleCrossings(block.lanes(n), rect, (1u << n) - 1u);
  int hits = 0;
  for (unsigned i = 0; i < n; ++i) {
    SCOPED_TRACE(describe(rays[i]));
    RectangleCrossing crossing;
    const bool hit = rect.cross(rays[i], block.tnear[i], rays[i].tMax, crossing);
    ASSERT_EQ(((mask >> i) & 1u) != 0, hit) << "lane " << i;
    hits += hit;
  }
  EXPECT_GE(hits, 3);  // at least straight down, onto the edge and onto the corner
  // The quad's route: the same crossings for the live lanes only (every third lane dead here),
  // with each lane's t and texture coordinates those of the scalar routine.
  for (unsigned i = 0; i < n; i += 3) block.valid[i] = 0;
  const Vec2 uv[4] = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  float t[RayLanes::kMaxLanes], u[RayLanes::kMaxLanes], v[RayLanes::kMaxLanes];
  const uint32_t liveMask = axisRectangleHits(block.lanes(n), rect, t, uv, u, v);
  uint32_t expected = 0;
  for (unsigned i = 0; i < n; ++i)
    if (block.valid[i] != 0) expected |= mask & (1u << i);
  EXPECT_EQ(liveMask, expected);
  const Quad quad({v0, v1, v2, v3}, {uv[0], uv[1], uv[2], uv[3]});
  for (uint32_t bits = liveMask; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    RectangleCrossing crossing;
    ASSERT_TRUE(rect.cross(rays[i], block.tnear[i], rays[i].tMax, crossing));
    EXPECT_EQ(std::bit_cast<uint32_t>(t[i]), std::bit_cast<uint32_t>(crossing.t)) << "lane " << i;
    LocalHit h;
    ASSERT_TRUE(quad.intersect(rays[i], block.tnear[i], rays[i].tMax, h)) << "lane " << i;
    EXPECT_EQ(h.t, crossing.t) << "lane " << i;
    EXPECT_EQ(h.uv.x, u[i]) << "lane " << i;
    EXPECT_EQ(h.uv.y, v[i]) << "lane " << i;
  }
}

TEST(ShapeLanes, AxisRectangleKernelEqualsTheScalarOnSpecialRaysOnEveryTarget) {
  forEachSimdTarget(expectAxisRectangleKernelEqualsTheScalar);
}

// Two rectangles that share an edge (a floor and a wall) leave no crack: a ray aimed at a point
// of the edge, from anywhere inside the corner they make, at any scale and offset, crosses at
// least one of them, in the scalar routine and in the kernel alike, with texture coordinates
// within the corners'. Without the margin (AxisRectangle::kMargin set to 0) float rounding lets
// rays through, and this test fails; without edgeCoordinates' clamp, a hit in the margin gets
// texture coordinates past an edge.
TEST(ShapeLanes, AbuttingAxisRectanglesLeaveNoCrack) {
  forEachSimdTarget([] {
    Rng rng(41, 2);
    int rays = 0;
    for (const float scale : {1e-3f, 1.0f, 7.0f, 3e4f}) {
      for (const float shift : {0.0f, 1.5f, -40.0f, 1000.0f}) {
        const float offset = shift * scale;  // far from the origin, in units of the corner's size
        const auto at = [&](float x, float y, float z) {
          return Vec3(offset + scale * x, offset + scale * y, offset + scale * z);
        };
        AxisRectangle floor, wall;  // y = 0 for x, z in [-1, 1]; x = 1 for y in [0, 2], z in [-1, 1]
        ASSERT_TRUE(AxisRectangle::of(at(-1, 0, 1), at(1, 0, 1), at(1, 0, -1), at(-1, 0, -1), floor));
        ASSERT_TRUE(AxisRectangle::of(at(1, 0, -1), at(1, 0, 1), at(1, 2, 1), at(1, 2, -1), wall));
        for (int trial = 0; trial < 64; ++trial) {
          Block block;
          Ray ray[RayLanes::kMaxLanes];
          for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
            // From inside the corner (x < 1, y > 0) to a point on the shared edge x = 1, y = 0.
            const Vec3 origin =
                at(2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform(), 2.0f * rng.uniform() - 1.0f);
            const Vec3 target(wall.c, floor.c, at(0, 0, 1.8f * rng.uniform() - 0.9f).z);
            ray[i] = Ray{origin, glm::normalize(target - origin)};
            block.set(i, ray[i], true);
          }
          // Texture coordinates too: a hit in the margin outside an edge takes the edge's, never
          // ones past the corners' (which a repeating texture would wrap to the opposite edge).
          const Vec2 uv[4] = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
          float t[RayLanes::kMaxLanes], u[RayLanes::kMaxLanes], v[RayLanes::kMaxLanes];
          uint32_t lanes = 0;
          for (const AxisRectangle* rect : {&floor, &wall}) {
            const uint32_t hits = axisRectangleHits(block.lanes(), *rect, t, uv, u, v);
            for (uint32_t bits = hits; bits != 0; bits &= bits - 1) {
              const unsigned i = unsigned(__builtin_ctz(bits));
              ASSERT_TRUE(u[i] >= 0.0f && u[i] <= 1.0f && v[i] >= 0.0f && v[i] <= 1.0f)
                  << "uv " << u[i] << " " << v[i] << ": " << describe(ray[i]);
            }
            lanes |= hits;
          }
          for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
            RectangleCrossing crossing;
            const bool scalar = floor.cross(ray[i], 0.0f, kInfinity, crossing) ||
                                wall.cross(ray[i], 0.0f, kInfinity, crossing);
            ASSERT_TRUE(scalar) << "scale " << scale << " offset " << offset << ": " << describe(ray[i]);
            ASSERT_TRUE((lanes >> i) & 1u)
                << "scale " << scale << " offset " << offset << ": " << describe(ray[i]);
            ++rays;
          }
        }
      }
    }
    EXPECT_EQ(rays, 4 * 4 * 64 * 16);
  });
}

// Only quads that are exactly axis-aligned rectangles take the axis-aligned rectangle's route.
TEST(ShapeLanes, AxisRectangleOnlyForAxisRectangles) {
  const Vec3 v0(1.0f, 2.0f, 3.0f), v1(1.0f, 2.0f, 5.0f), v3(1.0f, -1.0f, 3.0f), v2(1.0f, -1.0f, 5.0f);
  AxisRectangle f;
  ASSERT_TRUE(AxisRectangle::of(v0, v1, v2, v3, f));
  EXPECT_EQ(f.axis, 0);
  EXPECT_EQ(f.across[0], 2);  // v1 - v0 runs along z
  EXPECT_EQ(f.across[1], 1);
  EXPECT_EQ(f.c, 1.0f);
  EXPECT_EQ(f.lo[0], 3.0f);
  EXPECT_EQ(f.hi[0], 5.0f);
  EXPECT_EQ(f.lo[1], -1.0f);
  EXPECT_EQ(f.hi[1], 2.0f);
  EXPECT_EQ(f.corner[0], 3.0f);
  EXPECT_EQ(f.corner[1], 2.0f);
  EXPECT_EQ(f.edge[0], 2.0f);
  EXPECT_EQ(f.edge[1], -3.0f);
  // One corner off the plane, or off the parallelogram, by an ulp; an edge along no axis; an
  // edge of zero length; a NaN or infinite corner.
  const float up = std::nextafter(1.0f, 2.0f);
  EXPECT_FALSE(AxisRectangle::of(v0, v1, Vec3(up, -1.0f, 5.0f), v3, f));
  EXPECT_FALSE(AxisRectangle::of(v0, v1, Vec3(1.0f, -1.0f, std::nextafter(5.0f, 6.0f)), v3, f));
  EXPECT_FALSE(AxisRectangle::of(v0, Vec3(1.0f, 3.0f, 5.0f), Vec3(1.0f, 0.0f, 5.0f), v3, f));
  EXPECT_FALSE(AxisRectangle::of(v0, v0, v3, v3, f));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(AxisRectangle::of(v0, Vec3(1.0f, 2.0f, nan), Vec3(1.0f, -1.0f, nan), v3, f));
  EXPECT_FALSE(AxisRectangle::of(v0, Vec3(1.0f, 2.0f, inf), Vec3(1.0f, -1.0f, inf), v3, f));
}

}  // namespace
}  // namespace ember

namespace ember {
namespace {

// The settled hits' double-precision kernel must be DoublePlane::crossedWithin (measured from the
// anchor v0) and PlaneCoordinates::at bit for bit, on every lane it is given, hit or not:
// rays near and far from the origin, intervals that start past the plane or end before it,
// and rays parallel to the plane.
TEST(ShapeLanes, PlaneCrossingsKernelEqualsTheScalarCrossing) {
  for (const auto& [at, size] : {std::pair{Vec3(0.0f), 1.0f}, std::pair{Vec3(6e3f, -3.5e3f, 1.1e4f), 2.0f}}) {
    const auto [v0, v1, v2] = testTriangle(at, size);
    const DoublePlane plane = DoublePlane::through(v0, v1, v2);
    const PlaneCoordinates coords = PlaneCoordinates::of(v0, v1, v2);
    const Vec3 n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    Rng rng(11, 4);
    int hits = 0, lanes = 0;
    for (int b = 0; b < 300; ++b) {
      Block block;
      for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
        const Vec3 target = v0 + rng.uniform() * (v1 - v0) + rng.uniform() * (v2 - v0);
        const Vec3 o = target + size * (0.01f + 3.0f * rng.uniform()) * randomDirection(rng);
        Vec3 d = glm::normalize(target - o);
        if (i == 3) d = glm::normalize(glm::cross(n, d));  // parallel to the plane
        block.set(i, Ray{o, d, rng.uniform() < 0.2f ? 0.5f * glm::length(target - o) : kInfinity}, true);
        if (rng.uniform() < 0.2f) block.tnear[i] = 2.0f * glm::length(target - o);  // starts past it
      }
      const unsigned n16 = b % 4 == 0 ? 1 + unsigned(rng.uniform() * 15.0f) : RayLanes::kMaxLanes;
      const uint32_t want = (n16 >= 32 ? ~0u : (1u << n16) - 1u) & 0xb7ffu;  // some lanes not asked
      PlaneCrossings out;
      const uint32_t mask = planeCrossings(block.lanes(n16), plane, coords, want, true, out);
      for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
        const bool asked = (want >> i) & 1u;
        const bool laneHit = (mask >> i) & 1u;
        if (!asked) {
          EXPECT_FALSE(laneHit) << "lane " << i << " was not asked for";
          continue;
        }
        ++lanes;
        const RayLanes r = block.lanes(n16);
        const Ray ray = r.ray(i);
        double t;
        const bool hit = plane.crossedWithin(ray, r.tnear[i], ray.tMax, coords.v0, t);
        ASSERT_EQ(laneHit, hit) << "lane " << i << ": " << describe(ray);
        if (!hit) continue;
        ++hits;
        const float tf = float(t);
        const Vec2 bc = coords.at(glm::dvec3(ray.origin) + t * glm::dvec3(ray.dir));
        EXPECT_EQ(std::memcmp(&tf, &out.t[i], sizeof tf), 0) << describe(ray);
        EXPECT_EQ(std::memcmp(&bc.x, &out.b[0][i], sizeof(float)), 0) << describe(ray);
        EXPECT_EQ(std::memcmp(&bc.y, &out.b[1][i], sizeof(float)), 0) << describe(ray);
      }
    }
    EXPECT_GT(hits, lanes / 2);  // most rays are aimed at the triangle
  }
}

// A live lane with a zero direction (which traceable() lets through) takes the sphere's scalar
// routine, and its neighbours keep their kernel hits.
TEST(ShapeLanes, SphereLaneWithAZeroDirectionGetsTheScalarResult) {
  const Sphere sphere(Vec3(0.0f), 1.0f);
  Block block;
  Rng rng(2, 9);
  for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
    const Vec3 o = 3.0f * randomDirection(rng);
    block.set(i, Ray{o, glm::normalize(0.2f * randomDirection(rng) - o)}, true);
  }
  for (int k = 0; k < 3; ++k) block.dir[k][5] = 0.0f;
  for (int k = 0; k < 3; ++k) block.org[k][9] = 0.0f;  // inside, at the centre
  for (int k = 0; k < 3; ++k) block.dir[k][9] = 0.0f;
  LaneHits hits;
  sphere.intersectLanes(block.lanes(), hits);
  for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
    LocalHit h;
    const bool hit = sphere.intersect(block.lanes().ray(i), block.tnear[i], block.tfar[i], h);
    ASSERT_EQ(((hits.mask >> i) & 1u) != 0, hit) << "lane " << i;
    if (hit) {
      EXPECT_TRUE(identical(hits.at(i), h)) << "lane " << i;
    }
  }
  EXPECT_FALSE((hits.mask >> 5) & 1u);
  EXPECT_EQ(__builtin_popcount(hits.mask), 14);
}

}  // namespace
}  // namespace ember

namespace ember {
namespace {

// accel/packet_tfar.h against the scalar loops it replaced in the intersect callback: every lane,
// live or not, with finite, infinite, zero and negative tfar, for every packet width Embree calls
// with (16, 8, 4, 1) and widths that leave a tail after the last whole vector.
// The branches of the exact routines that only degenerate directions reach, lane by lane against
// intersect(): a cone's rays parallel to a generator (the quadratic's linear branch), a cylinder's
// along its axis, rays parallel to a disc, and a box's rays with zero components (the slab
// test's parallel case), inside and outside the slabs.
TEST(ShapeLanes, DegenerateDirectionsGetTheScalarResult) {
  const Vec3 base(0.2f, -0.1f, 0.3f), apex(0.2f, 1.9f, 0.3f);
  const Cone cone(base, apex, 1.0f, true);
  const Cylinder cylinder(base, apex, 0.5f, true);
  const Disc disc(base, Vec3(0.0f, 1.0f, 0.0f), 1.0f);
  const Box box(base, Vec3(1.0f, 2.0f, 0.5f), glm::mat3(1.0f));
  const Quad rectangle({base + Vec3(-1.0f, 0.0f, -0.5f), base + Vec3(1.0f, 0.0f, -0.5f),
                        base + Vec3(1.0f, 0.0f, 0.5f), base + Vec3(-1.0f, 0.0f, 0.5f)},
                       {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)});
  Rng rng(4, 11);
  for (const Shape* shape : {static_cast<const Shape*>(&cone), static_cast<const Shape*>(&cylinder),
                             static_cast<const Shape*>(&disc), static_cast<const Shape*>(&box),
                             static_cast<const Shape*>(&rectangle)}) {
    SCOPED_TRACE(std::string(shape->typeName()));
    int hitCount = 0;
    for (int b = 0; b < 50; ++b) {
      Block block;
      for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
        const Vec3 o = base + 2.5f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f);
        const float phi = 2.0f * kPi * rng.uniform();
        Vec3 d;
        switch (i % 4) {
          case 0:  // along a generator of the cone (slope: radius 1 over height 2), up or down
            d = glm::normalize(Vec3(std::cos(phi), (rng.uniform() < 0.5f ? -2.0f : 2.0f), std::sin(phi)));
            break;
          case 1:  // along the axis
            d = Vec3(0.0f, rng.uniform() < 0.5f ? -1.0f : 1.0f, 0.0f);
            break;
          case 2:  // parallel to the disc and the box's y faces
            d = Vec3(std::cos(phi), 0.0f, std::sin(phi));
            break;
          default:  // along a box axis
            d = Vec3(0.0f);
            d[int(rng.uniform() * 2.99f)] = rng.uniform() < 0.5f ? -1.0f : 1.0f;
        }
        block.set(i, Ray{o, d}, rng.uniform() < 0.9f);
      }
      LaneHits hits;
      shape->intersectLanes(block.lanes(), hits);
      for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
        LocalHit h;
        const bool hit =
            block.valid[i] == -1 && shape->intersect(block.lanes().ray(i), block.tnear[i], block.tfar[i], h);
        ASSERT_EQ(((hits.mask >> i) & 1u) != 0, hit)
            << "lane " << i << ": " << describe(block.lanes().ray(i));
        if (hit) {
          ++hitCount;
          EXPECT_TRUE(identical(hits.at(i), h)) << "lane " << i << ": " << describe(block.lanes().ray(i));
        }
      }
    }
    EXPECT_GT(hitCount, 50);
  }
}

TEST(PacketTfar, VectorPassEqualsTheScalarLoopOnEveryTarget) {
  forEachSimdTarget([] {
    Rng rng(7, 1);
    const float special[] = {kInfinity,
                             0.0f,
                             -1.0f,
                             1e-30f,
                             std::numeric_limits<float>::max(),
                             3.5f,
                             std::numeric_limits<float>::quiet_NaN(),
                             -kInfinity,
                             -0.0f,
                             std::numeric_limits<float>::denorm_min()};
    for (const unsigned n : {16u, 8u, 4u, 1u, 13u, 7u}) {
      for (int trial = 0; trial < 200; ++trial) {
        // The pass reads tfar only, and writes no widened lane past n.
        alignas(64) float tfar[kPacketTfarLanes], expected[kPacketTfarLanes];
        alignas(64) int valid[kPacketTfarLanes];
        for (unsigned i = 0; i < kPacketTfarLanes; ++i) {
          tfar[i] = i >= n                 ? -7.0f
                    : rng.uniform() < 0.3f ? special[rng.nextU32() % 10]
                                           : 100.0f * rng.uniform();
          // Embree writes -1 (live) and 0; any other value counts as dead, as in the lane kernels.
          const float pick = rng.uniform();
          valid[i] = pick < 0.5f ? -1 : pick < 0.8f ? 0 : pick < 0.9f ? 1 : std::numeric_limits<int>::max();
        }
        float widened[kPacketTfarLanes], widenedExpected[kPacketTfarLanes];
        std::fill(widened, widened + kPacketTfarLanes, -9.0f);
        std::fill(widenedExpected, widenedExpected + kPacketTfarLanes, -9.0f);
        std::memcpy(expected, tfar, sizeof(tfar));
        for (unsigned i = 0; i < n; ++i) widenedExpected[i] = valid[i] == -1 ? nextFloatUp(tfar[i]) : tfar[i];
        widenedTfar(tfar, valid, widened, n);
        ASSERT_EQ(0, std::memcmp(widened, widenedExpected, sizeof(widened)))
            << "n " << n << " trial " << trial;
        ASSERT_EQ(0, std::memcmp(tfar, expected, sizeof(tfar))) << "n " << n << " trial " << trial;
      }
    }
  });
}

// The live lanes of a block (liveLanes: valid == -1 and below n; the rectangle's validMask inside
// its kernel, the same rule) on every target, for blocks of every length with live and dead lanes (-1 and 0,
// as Embree marks them) on both sides of n.
TEST(ShapeLanes, LiveLanesOnEveryTarget) {
  forEachSimdTarget([] {
    Rng rng(5, 9);
    const Vec3 v0(-1.0f, 0.5f, -0.5f), v1(1.0f, 0.5f, -0.5f), v2(1.0f, 0.5f, 0.5f), v3(-1.0f, 0.5f, 0.5f);
    AxisRectangle rect;
    ASSERT_TRUE(AxisRectangle::of(v0, v1, v2, v3, rect));
    for (unsigned n = 1; n <= RayLanes::kMaxLanes; ++n)
      for (int trial = 0; trial < 50; ++trial) {
        Block block;
        uint32_t expected = 0;
        for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) {
          // Straight down onto the rectangle: every live lane hits it.
          const Ray ray{Vec3(rng.uniform() - 0.5f, 2.0f, rng.uniform() - 0.5f), Vec3(0.0f, -1.0f, 0.0f)};
          block.set(i, ray, rng.uniform() < 0.6f);
          if (i < n && block.valid[i] != 0) expected |= 1u << i;
        }
        ASSERT_EQ(liveLanes(block.lanes(n)), expected) << "n " << n;
        float t[RayLanes::kMaxLanes];
        ASSERT_EQ(axisRectangleHits(block.lanes(n), rect, t), expected) << "n " << n;
      }
  });
}

// The callback's vector commit against the scalar rule it replaced, lane by lane: ties at tfar
// (kept only over a larger geometry ID, never over none), NaN, infinite, signed-zero and equal t,
// blocks of every width at any offset in packets of 1, 4, 8 and 16 rays (hit arrays of exactly
// that size on the heap, so that a stray lane is a sanitizer error), mask bits past the block
// ignored, and the packet's other lanes untouched. On every SIMD target the CPU and the build have
// (AVX-512, AVX2, SSE4, ...: 8, 8 and 4 lanes a step), not only the one dispatch picks.
TEST(PacketCommit, VectorCommitEqualsTheScalarRule) {
  forEachSimdTarget([] {
    Rng rng(11, 3);
    constexpr unsigned kLanes = RayLanes::kMaxLanes;
    const float special[] = {kInfinity, 0.0f, -0.0f, 2.0f, std::numeric_limits<float>::quiet_NaN(), 1e-30f};
    const uint32_t geometries[] = {RTC_INVALID_GEOMETRY_ID, 0u, 4u, 5u, 6u, 0x7fffffffu, 0x80000000u};
    const uint32_t ours = 5u;
    // RTCHitN's fields, each an array of `width`: Ng x, y, z, u, v, primID, geomID, instID[levels].
    constexpr unsigned kFields = 7 + RTC_MAX_INSTANCE_LEVEL_COUNT;
    enum Field : unsigned { NgX, NgY, NgZ, U, V, Prim, Geom, Inst };
    int kept = 0, ties = 0;
    for (const unsigned width : {16u, 8u, 4u, 1u}) {
      for (const unsigned n : {16u, 13u, 8u, 7u, 4u, 1u}) {
        if (n > width) continue;
        for (int trial = 0; trial < 200; ++trial) {
          const unsigned first = rng.nextU32() % (width - n + 1);
          LaneHits hits;
          alignas(64) float tfar[kLanes];
          for (unsigned i = 0; i < kLanes; ++i) {
            tfar[i] = rng.uniform() < 0.3f ? special[rng.nextU32() % 6] : 10.0f * rng.uniform();
            const bool tie = rng.uniform() < 0.3f;
            hits.t[i] = tie                    ? tfar[i]
                        : rng.uniform() < 0.2f ? special[rng.nextU32() % 6]
                                               : 10.0f * rng.uniform();
            for (int c = 0; c < 3; ++c) hits.ng[c][i] = rng.uniform() - 0.5f;
            hits.uv[0][i] = rng.uniform(), hits.uv[1][i] = rng.uniform();
            if (rng.uniform() < 0.7f) hits.mask |= 1u << i;  // bits past n too: they must be ignored
          }
          std::vector<uint32_t> got(kFields * width);
          for (unsigned f = 0; f < kFields; ++f)
            for (unsigned i = 0; i < width; ++i)
              got[f * width + i] =
                  f == Geom ? geometries[rng.nextU32() % 7] : std::bit_cast<uint32_t>(-3.0f - float(f)) + i;
          std::vector<uint32_t> want = got;
          alignas(64) float wantTfar[kLanes];
          std::memcpy(wantTfar, tfar, sizeof(tfar));
          for (unsigned i = 0; i < n; ++i) {
            const unsigned lane = first + i;
            if (!((hits.mask >> i) & 1u)) continue;
            const float t = hits.t[i];
            if (!(t <= wantTfar[i])) continue;
            if (t == wantTfar[i]) {
              ++ties;
              const uint32_t current = want[Geom * width + lane];
              if (current == RTC_INVALID_GEOMETRY_ID || current <= ours) continue;
            }
            ++kept;
            wantTfar[i] = t;
            for (unsigned c = 0; c < 3; ++c)
              want[(NgX + c) * width + lane] = std::bit_cast<uint32_t>(hits.ng[c][i]);
            want[U * width + lane] = std::bit_cast<uint32_t>(hits.uv[0][i]);
            want[V * width + lane] = std::bit_cast<uint32_t>(hits.uv[1][i]);
            want[Prim * width + lane] = 17u, want[Geom * width + lane] = ours,
                                want[Inst * width + lane] = 23u;
          }
          commitLaneHits(hits, n, tfar, reinterpret_cast<RTCHitN*>(got.data()), width, first, 17u, ours, 23u);
          const std::string where = "width " + std::to_string(width) + " n " + std::to_string(n) + " trial " +
                                    std::to_string(trial);
          ASSERT_EQ(0, std::memcmp(tfar, wantTfar, sizeof(tfar))) << where;
          ASSERT_EQ(got, want) << where;
        }
      }
    }
    EXPECT_GT(kept, 2000);
    EXPECT_GT(ties, 600);
  });
}
}  // namespace
}  // namespace ember
