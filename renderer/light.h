// Lights, behind one interface that next-event estimation samples and MIS queries:
//   PointLight        isotropic radiant intensity I [W/sr per channel]: irradiance I cos / d^2.
//   AreaLight         a shape with constant radiance L on the side of its normal, or on both sides.
//   TriangleLight     one triangle of an emissive mesh (glTF emissiveFactor), sampled by solid angle
//                     when close, else by area; both
//                     sides emit when the glTF material is doubleSided.
//   EnvironmentLight  constant radiance arriving from every direction (the scene "background").
#pragma once

#include "accel/shape.h"
#include "accel/triangle_mesh.h"
#include "core/distribution.h"
#include "materials/texture.h"
#include "renderer/light_lanes.h"

#include <array>
#include <memory>

namespace ember {

struct LightSample {
  Vec3 wi;              // unit direction from the reference point towards the light
  Vec3 p;               // the sampled point (unused for infinite lights)
  Vec3 n{0.0f};         // unit surface normal at p; zero for point and spot lights
  float pError = 0.0f;  // rounding-error bound of p (core/ray_spawn.h); 0 for exact positions
  float dist = kInfinity;
  Color Li{0.0f};    // radiance (or, for delta lights, intensity / d^2) arriving at the ref
  float pdf = 0.0f;  // solid-angle density of wi; 1 for delta lights
  bool delta = false;
};

// Where a light path starts (renderer/caustic_tracer.h): a point on the emitter and the density it
// was drawn with.
struct EmissionPoint {
  Vec3 p;
  Vec3 n{0.0f};          // unit surface normal; zero for point and spot lights
  float pError = 0.0f;   // rounding-error bound of p
  float pdfArea = 1.0f;  // area density of p; 1 for point and spot lights (a Dirac in position)
  Color scale{1.0f};     // a textured or cut-out emitter's factor at p
  float range = 0.0f;    // KHR_lights_punctual range (rangeWindow) of the first segment; 0: none
};

class Light {
 public:
  virtual ~Light() = default;
  // Light tracing: a point to start from, by u (uniform by area on a surface; the position of a
  // point or spot light); false for lights no light path starts from (directional, environment).
  virtual bool sampleEmission(Vec2, EmissionPoint&) const { return false; }
  // What that point emits in unit direction w: radiance times |cos| to the normal on a surface
  // (zero behind a one-sided one), intensity for a point or spot light: the flux per unit area (or
  // per point) and solid angle the light tracer carries.
  virtual Color emittedToward(const EmissionPoint&, const Vec3&) const { return Color(0.0f); }
  virtual bool sample(const Vec3& ref, Vec2 u, LightSample& out) const = 0;
  // Solid-angle density with which sample() from ref yields the point p with normal n.
  virtual float pdf(const Vec3& ref, const Vec3& p, const Vec3& n) const = 0;
  // Total emitted power, used to choose among lights; sceneRadius bounds infinite lights.
  virtual Color power(float sceneRadius) const = 0;
  virtual bool isDelta() const { return false; }
  // sample() for n reference points at once: sample(refs[i], us[i], out[i]) into ok[i], bit for
  // bit. The default goes point by point; lights with a lane kernel (accel/sampling_lanes.h)
  // override it.
  virtual void sampleLanes(const Vec3* refs, const Vec2* us, size_t n, LightSample* out, bool* ok) const;
  // The samples of a run of the wave driver's light queries, written into its rows
  // (renderer/light_lanes.h): query i is the vertex in the low 16 bits of keys[i], whose
  // reference point is in refRows and numbers in us, both indexed by vertex. A vertex without a
  // sample keeps its rows as they were. The default takes sample() query by query; area and point
  // lights fill whole blocks of consecutive vertices at once.
  virtual void sampleRun(const uint64_t* keys, size_t n, const float* const refRows[3], const Vec2* us,
                         const LightSampleRows& rows) const;

  int samplerIndex = -1;  // position in the LightSampler's table
  // The Embree ray mask of shadow rays aimed at this light: all bits but its own geometry's where
  // that is a flat shape (Shape::flat), whose test they can skip; all bits otherwise.
  uint32_t shadowMask = kAllRayMask;
  // Its caustics come from the light tracer (renderer/caustic_tracer.h), which the path tracer
  // then leaves them to.
  bool causticTraced = false;
};

// KHR_lights_punctual's range window of a point or spot light, the recommended implementation of
// its "Range Property": max(min(1 - (d / range)^4, 1), 0) multiplies the inverse-square falloff,
// so that the light reaches exactly nothing past `range`. A range of 0 means infinite (no window).
inline float rangeWindow(float distance, float range) {
  if (!(range > 0.0f)) return 1.0f;
  const float r = distance / range, r2 = r * r;
  return std::clamp(1.0f - r2 * r2, 0.0f, 1.0f);
}

class PointLight final : public Light {
 public:
  PointLight(const Vec3& position, const Color& intensity, float range = 0.0f)
      : position_(position), intensity_(intensity), range_(range) {}
  bool sample(const Vec3& ref, Vec2 u, LightSample& out) const override;
  float pdf(const Vec3&, const Vec3&, const Vec3&) const override { return 0.0f; }
  Color power(float) const override { return 4.0f * kPi * intensity_; }
  bool isDelta() const override { return true; }
  bool sampleEmission(Vec2 u, EmissionPoint& out) const override;
  Color emittedToward(const EmissionPoint& e, const Vec3& w) const override;
  const Vec3& position() const { return position_; }
  const Color& intensity() const { return intensity_; }
  // A finite range (rangeWindow): the next-event kernel's whole-vector rows assume none.
  bool ranged() const { return range_ > 0.0f; }
  // Position and intensity into the rows, for the next-event kernel to take the sample
  // (LightSampleRows::pointLight); a ranged light samples query by query.
  void sampleRun(const uint64_t* keys, size_t n, const float* const refRows[3], const Vec2* us,
                 const LightSampleRows& rows) const override;

 private:
  Vec3 position_;
  Color intensity_;
  float range_;  // 0: infinite
};

// A spot light (glTF KHR_lights_punctual): intensity I [W/sr] along `direction`, fading between
// the inner and outer cone angles with the glTF specification's smooth falloff:
// a = clamp((cos - cosOuter) / (cosInner - cosOuter), 0, 1)^2.
class SpotLight final : public Light {
 public:
  SpotLight(const Vec3& position, const Vec3& direction, const Color& intensity, float innerRad,
            float outerRad, float range = 0.0f);
  bool sample(const Vec3& ref, Vec2 u, LightSample& out) const override;
  bool sampleEmission(Vec2 u, EmissionPoint& out) const override;
  Color emittedToward(const EmissionPoint& e, const Vec3& w) const override;
  float pdf(const Vec3&, const Vec3&, const Vec3&) const override { return 0.0f; }
  // Bounded by the power inside the outer cone.
  Color power(float) const override { return 2.0f * kPi * (1.0f - cosOuter_) * intensity_; }
  bool isDelta() const override { return true; }
  float falloff(float cosAngle) const;

 private:
  Vec3 position_, direction_;
  Color intensity_;
  float cosInner_, cosOuter_;
  float range_;  // 0: infinite (rangeWindow)
};

// A directional light (the sun): irradiance E [W/m^2] on a surface facing it, arriving from the
// fixed direction `towardsLight`; a delta light reached by next-event estimation only.
class DirectionalLight final : public Light {
 public:
  DirectionalLight(const Vec3& towardsLight, const Color& irradiance)
      : towardsLight_(glm::normalize(towardsLight)), irradiance_(irradiance) {}
  bool sample(const Vec3&, Vec2, LightSample& out) const override {
    out.wi = towardsLight_;
    out.dist = kInfinity;
    out.Li = irradiance_;
    out.pdf = 1.0f;
    out.delta = true;
    return true;
  }
  float pdf(const Vec3&, const Vec3&, const Vec3&) const override { return 0.0f; }
  // Power through a disc of the scene's radius (PBRT4 section 12.4).
  Color power(float sceneRadius) const override { return kPi * sceneRadius * sceneRadius * irradiance_; }
  bool isDelta() const override { return true; }

 private:
  Vec3 towardsLight_;
  Color irradiance_;
};

// Whether `ref` lies behind the plane through `point` with unit normal `n` by more than `margin`
// plus 1e-5 of ref's coordinates: then a one-sided emitter in that plane shows it only its back,
// and the facing test of each of its samples (dot(-wi, n) > 0, whose rounding is a few ulps of 1)
// says so, as long as `margin` covers how far the samples may lie off the plane. Such a reference
// gets no light sample: every one would carry Li = 0, which next-event estimation drops anyway.
inline bool clearlyBehind(const Vec3& ref, const Vec3& point, const Vec3& n, float margin) {
  return glm::dot(ref - point, n) < -(margin + kClearlyBehindPerMagnitude * maxAbsComponent(ref));
}

class AreaLight final : public Light {
 public:
  AreaLight(const Shape* shape, const Color& radiance, bool twoSided = false);
  bool sample(const Vec3& ref, Vec2 u, LightSample& out) const override;
  bool sampleEmission(Vec2 u, EmissionPoint& out) const override;
  Color emittedToward(const EmissionPoint& e, const Vec3& w) const override;

  float pdf(const Vec3& ref, const Vec3& p, const Vec3& n) const override {
    return shape_->pdfSolidAngle(ref, p, n);
  }
  // Blocks of the shape's sampleSolidAngleLanes.
  void sampleLanes(const Vec3* refs, const Vec2* us, size_t n, LightSample* out, bool* ok) const override;
  // The same blocks for queries kept in the caller's own form: query q in [0, n) samples from
  // refOf(q) with the numbers uOf(q), and sampled(q, sample) receives each query's sample, bit for
  // bit sample()'s; a query without one (behind the light, or no sample) gets no call.
  template <class RefOf, class UOf, class Sampled>
  void sampleBlocks(size_t n, RefOf refOf, UOf uOf, Sampled sampled) const;
  // The samples of the kMaxLanes queries held at rows [first, first + kMaxLanes) of a caller that
  // keeps them as rows (reference points in refRows, numbers in us), each written into `rows` at
  // its own index: whole vectors in and out where sampleBlocks copies lane by lane. Bit for bit
  // sample()'s; a query without a sample leaves its rows untouched.
  void sampleRows(const float* const refRows[3], const Vec2* us, size_t first,
                  const LightSampleRows& rows) const;
  // Blocks of consecutive vertices through sampleRows, the queries between them through
  // sampleBlocks.
  void sampleRun(const uint64_t* keys, size_t n, const float* const refRows[3], const Vec2* us,
                 const LightSampleRows& rows) const override;
  // Lambertian emitter: Phi = pi * A * L per emitting side.
  Color power(float) const override { return (twoSided_ ? 2.0f : 1.0f) * kPi * shape_->area() * radiance_; }
  const Shape* shape() const { return shape_; }
  const Color& radiance() const { return radiance_; }
  bool twoSided() const { return twoSided_; }
  float pointError() const { return pError_; }  // of the shape's sampled points
  // Whether `ref` lies clearly behind a one-sided flat emitter: every sample of it would face away
  // (Li black), so sampleLanes skips the lane and reports no sample, as shadowFor would have
  // discarded it. "Clearly" is a margin far above the rounding of the facing test.
  bool seesOnlyBack(const Vec3& ref) const {
    return skipsBehind_ && clearlyBehind(ref, back_.point, back_.normal, back_.margin);
  }

 private:
  // The light sample from the shape's sample (s, pdf) seen from ref.
  bool fromShapeSample(const Vec3& ref, const ShapeSample& s, float pdf, LightSample& out) const;
  // The light sample of (s, pdf) at distance `dist` in direction wi, `facing` when s.n faces the
  // reference point: what fromShapeSample and sampleLanes' kernel both end with.
  void fillSample(const ShapeSample& s, float pdf, float dist, const Vec3& wi, bool facing,
                  LightSample& out) const;

  const Shape* shape_;
  Color radiance_;
  bool twoSided_;
  float pError_;              // rounding-error bound of the shape's sampled points
  bool skipsBehind_ = false;  // one-sided and flat: refs behind its plane see no light
  BackPlane back_{Vec3(0.0f), Vec3(0.0f), 0.0f};
};

class TriangleLight final : public Light {
 public:
  // `texture` (optional, borrowed) multiplies the radiance at the surface's UV (glTF emissiveTexture).
  TriangleLight(const TriangleMesh* mesh, uint32_t prim, const Color& radiance,
                const Texture* texture = nullptr, bool twoSided = false);
  bool sample(const Vec3& ref, Vec2 u, LightSample& out) const override;
  bool sampleEmission(Vec2 u, EmissionPoint& out) const override;
  Color emittedToward(const EmissionPoint& e, const Vec3& w) const override;

  // Seen from close by, uniform in the solid angle the triangle subtends (accel/spherical_triangle.h),
  // else uniform by area.
  float pdf(const Vec3& ref, const Vec3& p, const Vec3& n) const override;
  // With a texture, its mean over the whole image stands in for the mean over this triangle: power
  // only steers which light is sampled, so an estimate costs variance, never bias.
  Color power(float) const override {
    return (twoSided_ ? 2.0f : 1.0f) * kPi * area_ * radiance_ *
           (texture_ ? texture_->average() : Color(1.0f));
  }
  // Whether `ref` lies clearly behind a one-sided triangle (clearlyBehind): sample() then returns
  // no sample, where every one would carry Li = 0.
  bool seesOnlyBack(const Vec3& ref) const {
    return !twoSided_ && clearlyBehind(ref, v_[0], ng_, backMargin_);
  }

 private:
  // The emissive texture times the cut-out's coverage at barycentrics b (1 without either).
  Color emissionFactorAt(Vec2 b) const;

  const TriangleMesh* mesh_;
  uint32_t prim_;
  // The triangle's vertices and unit geometric normal (as TriangleMesh::surfaceAt computes it),
  // copied from the mesh: a light sample then reads its own object, where following the mesh's
  // index and vertex arrays cost a cache miss each (18% of a render with 10,000 emitters).
  std::array<Vec3, 3> v_;
  Vec3 ng_;
  Color radiance_;
  const Texture* texture_;
  bool twoSided_;
  float pError_;  // rounding-error bound of the triangle's sampled points
  float area_;
  float backMargin_;  // seesOnlyBack's: the sampled points' error, twice, and the vertex's rounding
};

// Radiance arriving from infinitely far away: a constant colour, or an equirectangular map
// (latitude-longitude: u = 0.5 + atan2(d.x, -d.z) / (2 pi), so u = 0.5 looks along -z; v =
// acos(d.y) / pi, v = 0 straight up), optionally turned about +y. A map is importance-sampled with a
// piecewise-constant 2D distribution of texel luminance x sin(theta) (PBRT4 section 12.5.2); the
// constant one uniformly over the sphere.
class EnvironmentLight final : public Light {
 public:
  explicit EnvironmentLight(const Color& radiance) : radiance_(radiance), average_(radiance) {}
  EnvironmentLight(std::shared_ptr<const ImageTexture> map, float rotateYDeg);

  bool sample(const Vec3& ref, Vec2 u, LightSample& out) const override;
  float pdf(const Vec3&, const Vec3& dir, const Vec3&) const override { return pdfDirection(dir); }
  // Power through a disc of the scene's radius from every direction (PBRT4 section 12.5.1).
  Color power(float sceneRadius) const override {
    return 4.0f * kPi * kPi * sceneRadius * sceneRadius * average_;
  }
  Color radiance(const Vec3& dir) const;
  float pdfDirection(const Vec3& dir) const;

 private:
  Vec2 toUv(const Vec3& dir) const;
  Vec3 fromUv(Vec2 uv) const;

  Color radiance_{0.0f};
  Color average_{0.0f};
  std::shared_ptr<const ImageTexture> map_;
  Distribution2D distribution_;
  float cosRot_ = 1.0f, sinRot_ = 0.0f;
};

template <class RefOf, class UOf, class Sampled>
void AreaLight::sampleBlocks(size_t n, RefOf refOf, UOf uOf, Sampled sampled) const {
  SolidAngleLanes lanes{};  // shapes without a lane kernel fill only the live lanes
  size_t query[SolidAngleLanes::kMaxLanes];
  for (size_t next = 0; next < n;) {
    // The next block of queries that can see the light's emitting side. The lanes are
    // independent: a query's sample does not depend on which others share its block.
    lanes.n = 0;
    for (; next < n && lanes.n < SolidAngleLanes::kMaxLanes; ++next) {
      const Vec3 ref = refOf(next);
      if (seesOnlyBack(ref)) continue;
      query[lanes.n] = next;
      lanes.set(lanes.n++, ref, uOf(next));
    }
    if (lanes.n == 0) break;
    lanes.padFrom(lanes.n);
    shape_->sampleSolidAngleLanes(lanes);
    // fromShapeSample for the block: its directions in one kernel, equal to the scalar's.
    LightDirectionLanes dirs;
    lightDirectionLanes(lanes, dirs);
    for (unsigned i = 0; i < lanes.n; ++i) {
      if (!(lanes.pdf[i] > 0.0f && dirs.dist[i] != 0.0f)) continue;
      LightSample s;
      fillSample({lanes.point(i), lanes.normalAt(i)}, lanes.pdf[i], dirs.dist[i],
                 Vec3(dirs.wi[0][i], dirs.wi[1][i], dirs.wi[2][i]), (dirs.facing >> i) & 1u, s);
      sampled(query[i], s);
    }
  }
}

}  // namespace ember
