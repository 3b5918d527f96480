// Double-precision building blocks of the lane kernels that mirror a shape's scalar routine bit
// for bit (accel/shape_lanes.cpp, accel/quadric_lanes.cpp): the same operations in the same order
// as glm and accel/solve.h perform them. Included once per Highway target, in the "-inl.h" way:
// the include guard toggles with HWY_TARGET_TOGGLE so foreach_target.h can include it again.
#if defined(EMBER_ACCEL_DOUBLE_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef EMBER_ACCEL_DOUBLE_LANES_INL_H_
#undef EMBER_ACCEL_DOUBLE_LANES_INL_H_
#else
#define EMBER_ACCEL_DOUBLE_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include "accel/shape_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Half as many doubles as RayLanes' float blocks: one double vector per half block.
using D64 = hn::CappedTag<double, RayLanes::kMaxLanes / 2>;
using V64 = hn::Vec<D64>;
using M64 = hn::Mask<D64>;

struct Vec3V64 {
  V64 x, y, z;
};

HWY_INLINE Vec3V64 splat64(D64 d, double x, double y, double z) {
  return {hn::Set(d, x), hn::Set(d, y), hn::Set(d, z)};
}

// glm::dot of dvec3s: (x + y) + z.
HWY_INLINE V64 dot64(const V64& ax, const V64& ay, const V64& az, const V64& bx, const V64& by,
                     const V64& bz) {
  return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}
HWY_INLINE V64 dot64(const Vec3V64& a, const Vec3V64& b) {
  return dot64(a.x, a.y, a.z, b.x, b.y, b.z);
}

// Lanes i .. i + Lanes(d) - 1 of a float array, widened.
HWY_INLINE V64 loadPromoted(D64 d, const float* p, unsigned i) {
  const hn::Rebind<float, D64> df;
  return hn::PromoteTo(d, hn::LoadU(df, p + i));
}

// The live lanes of the block starting at lane i (valid == -1, below rays.n: liveLanes' rule in
// accel/shape_lanes.cpp, which the quad's route used before), as a mask. Reads
// Lanes(d) entries of rays.valid: a block's arrays hold whole double vectors (accel/user_geometry.cpp
// copies a block into padded arrays unless its length is a multiple of the float vectors').
HWY_INLINE M64 validMask(D64 d, const RayLanes& rays, unsigned i) {
  const hn::RebindToSigned<D64> di;
  const hn::Rebind<int32_t, D64> di32;
  const auto valid = hn::PromoteTo(di, hn::LoadU(di32, rays.valid + i));
  return hn::RebindMask(d, hn::And(hn::Eq(valid, hn::Set(di, -1)), hn::FirstN(di, rays.n - i)));
}

// The bits of `lanes` for the block starting at lane i, as a mask.
HWY_INLINE M64 blockMask(D64 d, uint32_t lanes, unsigned i) {
  const uint8_t bits = uint8_t((lanes >> i) & ((1u << hn::Lanes(d)) - 1u));
  return hn::LoadMaskBits(d, &bits);
}

HWY_INLINE uint32_t blockBits(D64 d, M64 m, unsigned i) {
  uint8_t bits[8] = {};
  hn::StoreMaskBits(d, m, bits);
  return uint32_t(bits[0]) << i;
}

// solveQuadratic (accel/solve.h) for every lane: `real` where it returns true, with its ordered
// roots t0 <= t1. a == 0 takes the linear branch, as the scalar routine does.
struct QuadraticRoots {
  V64 t0, t1;
  M64 real;
};
HWY_INLINE QuadraticRoots solveQuadraticLanes(D64 d, const V64& a, const V64& b, const V64& c) {
  const V64 zero = hn::Zero(d);
  const M64 flat = hn::Eq(a, zero);
  const V64 discrim = hn::Sub(hn::Mul(b, b), hn::Mul(hn::Mul(hn::Set(d, 4.0), a), c));
  const V64 root = hn::Sqrt(discrim);
  const V64 q =
      hn::Mul(hn::Set(d, -0.5), hn::IfThenElse(hn::Lt(b, zero), hn::Sub(b, root), hn::Add(b, root)));
  const V64 t0 = hn::Div(q, a);
  // q != 0.0 as C++ has it (true for NaN): not Ne, which is an ordered compare on AVX2/AVX-512.
  const V64 t1 = hn::IfThenElse(hn::Not(hn::Eq(q, zero)), hn::Div(c, q), t0);
  const M64 swap = hn::Gt(t0, t1);
  // The linear branch: -c / b, where b != 0.
  const V64 linear = hn::Div(hn::Neg(c), b);
  QuadraticRoots r;
  r.t0 = hn::IfThenElse(flat, linear, hn::IfThenElse(swap, t1, t0));
  r.t1 = hn::IfThenElse(flat, linear, hn::IfThenElse(swap, t0, t1));
  r.real = hn::Or(hn::And(flat, hn::Not(hn::Eq(b, zero))), hn::AndNot(flat, hn::Not(hn::Lt(discrim, zero))));
  return r;
}

// The scalar routines' `t <= tMin || t >= tMax`: false for a NaN t, there as here.
HWY_INLINE M64 outsideInterval(const V64& t, const V64& tMin, const V64& tMax) {
  return hn::Or(hn::Le(t, tMin), hn::Ge(t, tMax));
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif
