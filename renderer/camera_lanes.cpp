// Compiled once per SIMD target by Highway's foreach_target.h; see renderer/camera_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "renderer/camera_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "renderer/camera_lanes.h"

#include <algorithm>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr size_t kBlock = 16;
using D = hn::CappedTag<float, kBlock>;
using V = hn::Vec<D>;

void PerspectiveDirectionsKernel(const PerspectiveFrame& f, const int* x, const int* y, const Vec2* jitter,
                                 size_t n, float* const (&dir)[3]) {
  const D d;
  const hn::RebindToSigned<D> di;
  const size_t step = hn::Lanes(d);
  const V two = hn::Set(d, 2.0f), one = hn::Set(d, 1.0f);
  for (size_t first = 0; first < n; first += step) {
    const size_t lanes = std::min(step, n - first);
    // The block's raster positions, float(x) + jitter.x as Camera::generateRay's caller forms them.
    alignas(64) int32_t px[kBlock] = {}, py[kBlock] = {};
    alignas(64) float jx[kBlock] = {}, jy[kBlock] = {};
    for (size_t i = 0; i < lanes; ++i) {
      px[i] = x[first + i], py[i] = y[first + i];
      jx[i] = jitter[first + i].x, jy[i] = jitter[first + i].y;
    }
    const V rx = hn::Add(hn::ConvertTo(d, hn::Load(di, px)), hn::Load(d, jx));
    const V ry = hn::Add(hn::ConvertTo(d, hn::Load(di, py)), hn::Load(d, jy));
    // sx = (2 x invWidth - 1) scale aspect, sy = (1 - 2 y invHeight) scale.
    const V sx =
        hn::Mul(hn::Mul(hn::Sub(hn::Mul(hn::Mul(two, rx), hn::Set(d, f.invWidth)), one), hn::Set(d, f.scale)),
                hn::Set(d, f.aspect));
    const V sy =
        hn::Mul(hn::Sub(one, hn::Mul(hn::Mul(two, ry), hn::Set(d, f.invHeight))), hn::Set(d, f.scale));
    // normalize(forward + sx right + sy up): v * (1 / sqrt(dot(v, v))).
    V v[3];
    for (int k = 0; k < 3; ++k)
      v[k] = hn::Add(hn::Add(hn::Set(d, f.forward[k]), hn::Mul(sx, hn::Set(d, f.right[k]))),
                     hn::Mul(sy, hn::Set(d, f.up[k])));
    const V inv = hn::Div(
        one, hn::Sqrt(hn::Add(hn::Add(hn::Mul(v[0], v[0]), hn::Mul(v[1], v[1])), hn::Mul(v[2], v[2]))));
    for (int k = 0; k < 3; ++k) {
      alignas(64) float out[kBlock];
      hn::Store(hn::Mul(v[k], inv), d, out);
      std::copy_n(out, lanes, dir[k] + first);
    }
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(PerspectiveDirectionsKernel);

void perspectiveDirections(const PerspectiveFrame& frame, const int* x, const int* y, const Vec2* jitter,
                           size_t n, float* const (&dir)[3]) {
  HWY_DYNAMIC_DISPATCH(PerspectiveDirectionsKernel)(frame, x, y, jitter, n, dir);
}

}  // namespace ember
#endif
