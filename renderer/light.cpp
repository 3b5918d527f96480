#include "renderer/light.h"

#include "accel/spherical_triangle.h"
#include "core/ray_spawn.h"
#include "core/sampling.h"

#include <algorithm>
#include <optional>

namespace ember {

// The delta-light sample towards `position`, with radiant intensity I arriving as I / d^2.
static bool samplePosition(const Vec3& position, const Vec3& ref, const Color& intensity, LightSample& out) {
  const Vec3 d = position - ref;
  const float dist2 = glm::dot(d, d);
  if (dist2 == 0.0f) return false;
  out.dist = std::sqrt(dist2);
  out.wi = d / out.dist;
  out.p = position;
  out.Li = intensity / dist2;
  out.pdf = 1.0f;
  out.delta = true;
  return true;
}

bool PointLight::sample(const Vec3& ref, Vec2, LightSample& out) const {
  if (!samplePosition(position_, ref, intensity_, out)) return false;
  if (range_ > 0.0f) out.Li *= rangeWindow(out.dist, range_);
  return true;
}

SpotLight::SpotLight(const Vec3& position, const Vec3& direction, const Color& intensity, float innerRad,
                     float outerRad, float range)
    : position_(position),
      direction_(glm::normalize(direction)),
      intensity_(intensity),
      cosInner_(std::cos(innerRad)),
      cosOuter_(std::cos(outerRad)),
      range_(range) {}

float SpotLight::falloff(float cosAngle) const {
  // KHR_lights_punctual's recommended implementation, including its guard against inner == outer.
  const float scale = 1.0f / std::max(0.001f, cosInner_ - cosOuter_);
  const float a = std::clamp((cosAngle - cosOuter_) * scale, 0.0f, 1.0f);
  return a * a;
}

bool SpotLight::sample(const Vec3& ref, Vec2, LightSample& out) const {
  if (!samplePosition(position_, ref, intensity_, out)) return false;
  out.Li *= falloff(glm::dot(-out.wi, direction_)) * rangeWindow(out.dist, range_);
  return true;
}

// The rounding-error bound of points computed from data inside `b` (a sampled point is a sum of
// terms no larger than the bounds' coordinates).
static float errorBoundWithin(const Bounds& b) {
  return roundingErrorBound(std::max(maxAbsComponent(b.lower), maxAbsComponent(b.upper)));
}

AreaLight::AreaLight(const Shape* shape, const Color& radiance, bool twoSided)
    : shape_(shape), radiance_(radiance), twoSided_(twoSided), pError_(errorBoundWithin(shape->bounds())) {
  if (!twoSided_ && shape_->flat()) {
    // The plane through one of its points. Its samples lie within pError_ of it; the margin
    // covers that (twice: two sampled points) and the rounding of the dot products with room.
    const ShapeSample s = shape_->sampleArea(Vec2(0.5f));
    if (std::isfinite(glm::dot(s.p, s.n)) && std::abs(glm::length(s.n) - 1.0f) < 1e-3f) {
      skipsBehind_ = true;
      back_ = BackPlane{s.p, s.n, 4.0f * pError_ + kClearlyBehindPerMagnitude * maxAbsComponent(s.p)};
    }
  }
}

void Light::sampleLanes(const Vec3* refs, const Vec2* us, size_t n, LightSample* out, bool* ok) const {
  for (size_t i = 0; i < n; ++i) ok[i] = sample(refs[i], us[i], out[i]);
}

bool AreaLight::sample(const Vec3& ref, Vec2 u, LightSample& out) const {
  if (seesOnlyBack(ref)) return false;  // as sampleLanes
  ShapeSample s;
  float pdf;
  // pdf > 0 decides, as in sampleLanes, whatever the shape returned.
  return shape_->sampleSolidAngle(ref, u, s, pdf) && pdf > 0.0f && fromShapeSample(ref, s, pdf, out);
}

void AreaLight::sampleLanes(const Vec3* refs, const Vec2* us, size_t n, LightSample* out, bool* ok) const {
  std::fill(ok, ok + n, false);
  sampleBlocks(
      n, [&](size_t q) { return refs[q]; }, [&](size_t q) { return us[q]; },
      [&](size_t q, const LightSample& s) {
        ok[q] = true;
        out[q] = s;
      });
}

void AreaLight::sampleRows(const float* const refRows[3], const Vec2* us, size_t first,
                           const LightSampleRows& rows) const {
  SolidAngleLanes lanes;
  const uint32_t live = loadSolidAngleRows(refRows, us, first, skipsBehind_ ? &back_ : nullptr, lanes);
  if (live == 0) return;
  lanes.n = SolidAngleLanes::kMaxLanes;
  shape_->sampleSolidAngleLanes(lanes);
  storeLightSampleRows(lanes, live, radiance_, twoSided_, pError_, rows, first);
}

namespace {

// A vertex's sample into the rows: what the next-event kernel reads of a LightSample.
void storeSample(const LightSampleRows& rows, size_t v, const LightSample& ls) {
  for (int c = 0; c < 3; ++c) {
    rows.p[c][v] = ls.p[c];
    rows.n[c][v] = ls.n[c];
    rows.wi[c][v] = ls.wi[c];
    rows.Li[c][v] = ls.Li[c];
  }
  rows.pError[v] = ls.pError;
  rows.pdf[v] = ls.pdf;
  rows.delta[v] = ls.delta ? -1 : 0;
  rows.infinite[v] = std::isfinite(ls.dist) ? 0 : -1;
}

// Queries are keys (a light's index << 16 | vertex), rising with the vertex within a light's run,
// and one shape's vertices are consecutive: most of a run falls into blocks of kSampleBlock
// queries on consecutive vertices, which read and write the rows as whole vectors. (Any order is
// correct; a block is found only where the keys rise one by one.)
constexpr size_t kSampleBlock = SolidAngleLanes::kMaxLanes;
bool consecutiveBlock(const uint64_t* keys, size_t q, size_t n) {
  if (q + kSampleBlock > n) return false;
  for (size_t i = 1; i < kSampleBlock; ++i)
    if (keys[q + i] != keys[q] + i) return false;
  return true;
}

size_t vertexOf(uint64_t key) {
  return size_t(key & 0xffffu);
}

}  // namespace

void Light::sampleRun(const uint64_t* keys, size_t n, const float* const refRows[3], const Vec2* us,
                      const LightSampleRows& rows) const {
  for (size_t q = 0; q < n; ++q) {
    const size_t v = vertexOf(keys[q]);
    LightSample ls;
    if (sample(Vec3(refRows[0][v], refRows[1][v], refRows[2][v]), us[v], ls)) storeSample(rows, v, ls);
  }
}

void PointLight::sampleRun(const uint64_t* keys, size_t n, const float* const refRows[3], const Vec2* us,
                           const LightSampleRows& rows) const {
  if (ranged()) {
    Light::sampleRun(keys, n, refRows, us, rows);
    return;
  }
  const auto fill = [&](size_t first, size_t count) {
    for (int c = 0; c < 3; ++c) {
      std::fill_n(rows.p[c] + first, count, position_[c]);
      std::fill_n(rows.Li[c] + first, count, intensity_[c]);
      std::fill_n(rows.n[c] + first, count, 0.0f);
    }
    std::fill_n(rows.pError + first, count, 0.0f);
    std::fill_n(rows.pointLight + first, count, -1);
  };
  for (size_t q = 0; q < n;) {
    const bool block = consecutiveBlock(keys, q, n);
    fill(vertexOf(keys[q]), block ? kSampleBlock : 1);
    q += block ? kSampleBlock : 1;
  }
}

void AreaLight::sampleRun(const uint64_t* keys, size_t n, const float* const refRows[3], const Vec2* us,
                          const LightSampleRows& rows) const {
  const auto consecutive = [&](size_t q) { return consecutiveBlock(keys, q, n); };
  for (size_t q = 0; q < n;) {
    size_t end = q;
    while (end < n && !consecutive(end)) ++end;
    if (end > q)
      sampleBlocks(
          end - q,
          [&](size_t i) {
            const size_t v = vertexOf(keys[q + i]);
            return Vec3(refRows[0][v], refRows[1][v], refRows[2][v]);
          },
          [&](size_t i) { return us[vertexOf(keys[q + i])]; },
          [&](size_t i, const LightSample& ls) { storeSample(rows, vertexOf(keys[q + i]), ls); });
    for (; consecutive(end); end += kSampleBlock) sampleRows(refRows, us, vertexOf(keys[end]), rows);
    q = end;
  }
}

bool AreaLight::fromShapeSample(const Vec3& ref, const ShapeSample& s, float pdf, LightSample& out) const {
  const Vec3 d = s.p - ref;
  const float dist = glm::length(d);
  if (dist == 0.0f) return false;
  const Vec3 wi = d / dist;
  fillSample(s, pdf, dist, wi, glm::dot(-wi, s.n) > 0.0f, out);
  return true;
}

void AreaLight::fillSample(const ShapeSample& s, float pdf, float dist, const Vec3& wi, bool facing,
                           LightSample& out) const {
  out.dist = dist;
  out.wi = wi;
  out.p = s.p;
  out.n = s.n;
  out.pError = pError_;
  out.pdf = pdf;
  out.delta = false;
  // One-sided: the light emits only towards the side its normal faces.
  out.Li = twoSided_ || facing ? radiance_ : Color(0.0f);
}

TriangleLight::TriangleLight(const TriangleMesh* mesh, uint32_t prim, const Color& radiance,
                             const Texture* texture, bool twoSided)
    : mesh_(mesh),
      prim_(prim),
      v_{mesh->positions[mesh->indices[prim].x], mesh->positions[mesh->indices[prim].y],
         mesh->positions[mesh->indices[prim].z]},
      ng_(mesh->surfaceAt(prim, 0.0f, 0.0f).ng),
      radiance_(radiance),
      texture_(texture),
      twoSided_(twoSided),
      pError_(mesh->pointError(prim)),
      area_(mesh->triangleArea(prim)),
      backMargin_(4.0f * pError_ + kClearlyBehindPerMagnitude * maxAbsComponent(v_[0])) {}

float TriangleLight::pdf(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  if (const auto st = sphericalTriangleForSampling(ref, v_[0], v_[1], v_[2], area_))
    return float(1.0 / st->solidAngle());
  return areaToSolidAnglePdf(1.0f / area_, ref, p, n);
}

bool TriangleLight::sample(const Vec3& ref, Vec2 u, LightSample& out) const {
  if (seesOnlyBack(ref)) return false;
  // Barycentrics (b1, b2) of vertices 1 and 2: where a direction uniform in the solid angle meets
  // the triangle, or a point uniform by area.
  Vec2 b;
  const std::optional<SphericalTriangle> st = sphericalTriangleForSampling(ref, v_[0], v_[1], v_[2], area_);
  if (st) {
    b = barycentricsAlong(v_[0], v_[1], v_[2], ref, st->sample(u));
  } else {
    const Vec2 a = sampleUniformTriangle(u);  // barycentrics of vertices 0 and 1
    b = Vec2(a.y, 1.0f - a.x - a.y);
  }
  const Vec3 p = pointOnTriangle(v_[0], v_[1], v_[2], b.x, b.y);
  const Vec3 d = p - ref;
  out.dist = glm::length(d);
  if (out.dist == 0.0f) return false;
  out.wi = d / out.dist;
  out.p = p;
  out.n = ng_;
  out.pError = pError_;
  out.pdf = st ? float(1.0 / st->solidAngle()) : areaToSolidAnglePdf(1.0f / area_, ref, p, ng_);
  out.delta = false;
  out.Li = twoSided_ || glm::dot(-out.wi, ng_) > 0.0f ? radiance_ : Color(0.0f);
  if (texture_ || mesh_->opacity) out.Li *= emissionFactorAt(b);
  return out.pdf > 0.0f && std::isfinite(out.pdf);
}

Color TriangleLight::emissionFactorAt(Vec2 b) const {
  Color factor(1.0f);
  if (texture_) {
    // The texture as a hit there sees it: its own coordinate set, and COLOR_0 where it reads it.
    SurfaceHit at;
    at.uv = mesh_->uvAt(prim_, b.x, b.y);
    at.attributes = mesh_;
    at.prim = prim_;
    at.bary = b;
    factor *= texture_->evalFresh(at);
  }
  // Cut-out (MASK) or partly transparent (BLEND) parts emit as much as rays that hit them find.
  if (mesh_->opacity) factor *= mesh_->opacity->coverage(*mesh_, prim_, b);
  return factor;
}

EnvironmentLight::EnvironmentLight(std::shared_ptr<const ImageTexture> map, float rotateYDeg)
    : map_(std::move(map)),
      cosRot_(std::cos(glm::radians(rotateYDeg))),
      sinRot_(std::sin(glm::radians(rotateYDeg))) {
  const int w = map_->width(), h = map_->height();
  std::vector<float> weights(size_t(w) * size_t(h));
  double sum = 0.0, sinSum = 0.0;
  Color weighted(0.0f);
  for (int y = 0; y < h; ++y) {
    const float sinTheta = std::sin(kPi * (float(y) + 0.5f) / float(h));
    for (int x = 0; x < w; ++x) {
      const Color c = map_->eval(Vec2((float(x) + 0.5f) / float(w), (float(y) + 0.5f) / float(h)));
      weights[size_t(y) * size_t(w) + size_t(x)] = luminance(c) * sinTheta;
      sum += luminance(c) * sinTheta;
      weighted += c * sinTheta;
      sinSum += sinTheta;
    }
  }
  // A floor keeps every direction samplable: bilinear lookups give dark texels next to bright
  // ones some radiance, which light sampling must be able to reach too.
  const float floor = float(1e-3 * sum / double(weights.size()));
  for (float& v : weights) v += floor;
  distribution_ = Distribution2D(weights, w, h);
  average_ = sinSum > 0.0 ? weighted / float(sinSum) : Color(0.0f);
}

Vec2 EnvironmentLight::toUv(const Vec3& d) const {
  // Turn the world direction into the map's frame (the inverse of the map's rotation about +y).
  const Vec3 l(cosRot_ * d.x - sinRot_ * d.z, d.y, sinRot_ * d.x + cosRot_ * d.z);
  float u = 0.5f + std::atan2(l.x, -l.z) / (2.0f * kPi);
  if (u >= 1.0f) u -= 1.0f;
  return {u, std::acos(std::clamp(l.y, -1.0f, 1.0f)) * kInvPi};
}

Vec3 EnvironmentLight::fromUv(Vec2 uv) const {
  const float phi = 2.0f * kPi * (uv.x - 0.5f), theta = kPi * uv.y;
  const float s = std::sin(theta);
  const Vec3 l(s * std::sin(phi), std::cos(theta), -s * std::cos(phi));
  return {cosRot_ * l.x + sinRot_ * l.z, l.y, -sinRot_ * l.x + cosRot_ * l.z};
}

Color EnvironmentLight::radiance(const Vec3& dir) const {
  return map_ ? map_->eval(toUv(dir)) : radiance_;
}

float EnvironmentLight::pdfDirection(const Vec3& dir) const {
  if (!map_) return kUniformSpherePdf;
  const Vec2 uv = toUv(dir);
  const float sinTheta = std::sin(kPi * uv.y);
  if (sinTheta <= 0.0f) return 0.0f;
  // Jacobian of the equirectangular map: d omega = 2 pi^2 sin(theta) du dv.
  return distribution_.pdf(uv) / (2.0f * kPi * kPi * sinTheta);
}

bool EnvironmentLight::sample(const Vec3&, Vec2 u, LightSample& out) const {
  out.dist = kInfinity;
  out.delta = false;
  if (!map_) {
    out.wi = sampleUniformSphere(u);
    out.pdf = kUniformSpherePdf;
    out.Li = radiance_;
    return true;
  }
  float pdfUv;
  const Vec2 uv = distribution_.sample(u, pdfUv);
  const float sinTheta = std::sin(kPi * uv.y);
  if (pdfUv <= 0.0f || sinTheta <= 0.0f) return false;
  out.wi = fromUv(uv);
  out.pdf = pdfUv / (2.0f * kPi * kPi * sinTheta);
  out.Li = map_->eval(uv);
  return true;
}
}  // namespace ember

namespace ember {

// Light tracing's starting points (renderer/caustic_tracer.h). A point or spot light starts every
// path at its position, with the intensity of the direction taken; a surface at a point uniform by
// area, with its radiance times the cosine.

bool PointLight::sampleEmission(Vec2, EmissionPoint& out) const {
  out = EmissionPoint{position_, Vec3(0.0f), 0.0f, 1.0f, Color(1.0f), range_};
  return true;
}

Color PointLight::emittedToward(const EmissionPoint& e, const Vec3&) const {
  return intensity_ * e.scale;
}

bool SpotLight::sampleEmission(Vec2, EmissionPoint& out) const {
  out = EmissionPoint{position_, Vec3(0.0f), 0.0f, 1.0f, Color(1.0f), range_};
  return true;
}

Color SpotLight::emittedToward(const EmissionPoint& e, const Vec3& w) const {
  return intensity_ * e.scale * falloff(glm::dot(w, direction_));
}

bool AreaLight::sampleEmission(Vec2 u, EmissionPoint& out) const {
  const ShapeSample s = shape_->sampleArea(u);
  const float area = shape_->area();
  if (!(area > 0.0f) || !std::isfinite(area)) return false;
  out = EmissionPoint{s.p, s.n, pError_, 1.0f / area, Color(1.0f), 0.0f};
  return true;
}

Color AreaLight::emittedToward(const EmissionPoint& e, const Vec3& w) const {
  const float c = glm::dot(w, e.n);
  return twoSided_ || c > 0.0f ? radiance_ * (std::abs(c) * e.scale) : Color(0.0f);
}

bool TriangleLight::sampleEmission(Vec2 u, EmissionPoint& out) const {
  if (!(area_ > 0.0f)) return false;
  const Vec2 a = sampleUniformTriangle(u);  // barycentrics of vertices 0 and 1
  const Vec2 b(a.y, 1.0f - a.x - a.y);
  out = EmissionPoint{
      pointOnTriangle(v_[0], v_[1], v_[2], b.x, b.y), ng_, pError_, 1.0f / area_, Color(1.0f), 0.0f};
  // The emissive texture and the cut-out, as sample() reads them at its points.
  if (texture_ || mesh_->opacity) out.scale = emissionFactorAt(b);
  return true;
}

Color TriangleLight::emittedToward(const EmissionPoint& e, const Vec3& w) const {
  const float c = glm::dot(w, e.n);
  return twoSided_ || c > 0.0f ? radiance_ * (std::abs(c) * e.scale) : Color(0.0f);
}

}  // namespace ember
