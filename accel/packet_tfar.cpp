// Compiled once per SIMD target by Highway's foreach_target.h; see accel/packet_tfar.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/packet_tfar.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "accel/packet_tfar.h"

#include <limits>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, kPacketTfarLanes>;

void WidenedTfar(const float* tfar, const int* valid, float* widened, unsigned n) {
  const D d;
  const hn::RebindToSigned<D> di;
  const auto infinity = hn::Set(d, std::numeric_limits<float>::infinity());
  const unsigned step = unsigned(hn::Lanes(d));
  unsigned i = 0;
  for (; i + step <= n; i += step) {
    const auto t = hn::LoadU(d, tfar + i);
    const auto live = hn::RebindMask(d, hn::Eq(hn::LoadU(di, valid + i), hn::Set(di, -1)));
    // The next float up of a positive float is its bit pattern plus one.
    const auto up = hn::BitCast(d, hn::Add(hn::BitCast(di, t), hn::Set(di, 1)));
    hn::StoreU(hn::IfThenElse(hn::And(live, hn::Lt(t, infinity)), up, t), d, widened + i);
  }
  for (; i < n; ++i) widened[i] = valid[i] == -1 ? nextFloatUp(tfar[i]) : tfar[i];
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(WidenedTfar);

void widenedTfar(const float* tfar, const int* valid, float* widened, unsigned n) {
  HWY_DYNAMIC_DISPATCH(WidenedTfar)(tfar, valid, widened, n);
}

}  // namespace ember
#endif
