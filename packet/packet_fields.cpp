// Compiled once per SIMD target by Highway's foreach_target.h; see packet/packet_fields.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "packet/packet_fields.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "packet/packet_fields.h"

#include <stdexcept>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Vectors of at most `width` floats (D's cap), so that none reaches into the next field.
template <class D>
HWY_INLINE void fillIn(D d, float* packets, size_t stride, unsigned width, size_t count,
                       const PacketFieldSource* fields, size_t fieldCount) {
  const size_t packetCount = (count + width - 1) / width;
  for (size_t k = 0; k < packetCount; ++k) {
    float* packet = packets + k * stride;
    for (size_t f = 0; f < fieldCount; ++f) {
      const PacketFieldSource& source = fields[f];
      float* to = packet + source.field;
      if (source.row) {
        const float* from = source.row + k * width;
        for (unsigned i = 0; i < width; i += unsigned(hn::Lanes(d)))
          hn::StoreU(hn::LoadU(d, from + i), d, to + i);
      } else {
        const auto value = hn::Set(d, source.value);
        for (unsigned i = 0; i < width; i += unsigned(hn::Lanes(d))) hn::StoreU(value, d, to + i);
      }
    }
  }
}

void FillPacketFieldsKernel(float* packets, size_t stride, unsigned width, size_t count,
                            const PacketFieldSource* fields, size_t fieldCount) {
  if (width == 16)
    fillIn(hn::CappedTag<float, 16>(), packets, stride, width, count, fields, fieldCount);
  else
    fillIn(hn::CappedTag<float, 8>(), packets, stride, width, count, fields, fieldCount);
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(FillPacketFieldsKernel);

void fillPacketFields(float* packets, size_t stride, unsigned width, size_t count,
                      const PacketFieldSource* fields, size_t fieldCount) {
  if (width != 8 && width != 16) throw std::invalid_argument("fillPacketFields: packets of 8 or 16 rays");
  HWY_DYNAMIC_DISPATCH(FillPacketFieldsKernel)(packets, stride, width, count, fields, fieldCount);
}

}  // namespace ember
#endif
