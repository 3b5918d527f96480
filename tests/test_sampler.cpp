// The samplers: the Sobol sampler's 2D projections over a pixel's first 2^m samples must be
// (0, m, 2)-nets in base 2 (every elementary interval of area 2^-m holds exactly one point), its
// 1D projections stratified, every dimension uniform; both samplers are deterministic.
#include "renderer/sampler.h"

#include <gtest/gtest.h>

#include <vector>

namespace ember {
namespace {

constexpr int kLog2N = 8, kN = 1 << kLog2N;

// Requests `dims` values per sample (alternating 2D and 1D, as the integrator does) and returns
// the points of 2D request number `pair`.
std::vector<Vec2> points2D(uint64_t seed, uint64_t pixel, int pair, uint32_t first = 0) {
  std::vector<Vec2> out;
  for (uint32_t i = first; i < first + kN; ++i) {
    Sampler s(SamplerType::Sobol, seed, pixel, i);
    Vec2 p;
    for (int d = 0; d <= pair; ++d) {
      p = s.get2D();
      s.get1D();
    }
    out.push_back(p);
  }
  return out;
}

TEST(Sampler, SobolPairsAreZeroMTwoNets) {
  for (uint64_t pixel : {0ull, 17ull, 123456ull})
    for (int pair : {0, 1, 2, 3}) {  // requests 0..6: all within kMaxSobolDimensions
      const std::vector<Vec2> pts = points2D(42, pixel, pair);
      for (int a = 0; a <= kLog2N; ++a) {
        const int nx = 1 << a, ny = 1 << (kLog2N - a);
        std::vector<int> count(size_t(nx * ny), 0);
        for (const Vec2& p : pts) {
          ASSERT_GE(p.x, 0.0f);
          ASSERT_LT(p.x, 1.0f);
          ASSERT_GE(p.y, 0.0f);
          ASSERT_LT(p.y, 1.0f);
          ++count[size_t(int(p.y * float(ny)) * nx + int(p.x * float(nx)))];
        }
        for (int c : count)
          ASSERT_EQ(c, 1) << "pixel " << pixel << " pair " << pair << " intervals " << nx << "x" << ny;
      }
    }
}

TEST(Sampler, SobolOneDimensionalValuesAreStratified) {
  std::vector<int> count(kN, 0);
  for (uint32_t i = 0; i < kN; ++i) {
    Sampler s(SamplerType::Sobol, 7, 99, i);
    s.get2D();
    ++count[size_t(s.get1D() * float(kN))];
  }
  for (int c : count) EXPECT_EQ(c, 1);
}

TEST(Sampler, LaterBlocksOfSamplesAreNetsToo) {
  // Samples [256, 512) of a pixel: a separately rendered range is as well distributed.
  const std::vector<Vec2> pts = points2D(3, 5, 2, kN);
  std::vector<int> count(kN, 0);
  for (const Vec2& p : pts) ++count[size_t(int(p.y * 16.0f) * 16 + int(p.x * 16.0f))];
  for (int c : count) EXPECT_EQ(c, 1);
}

TEST(Sampler, DifferentPixelsAndDimensionsAreDecorrelated) {
  // Scrambling makes the sequences of different pixels differ, and dimension pairs differ.
  EXPECT_NE(points2D(1, 0, 0)[0], points2D(1, 1, 0)[0]);
  EXPECT_NE(points2D(1, 0, 0)[0], points2D(1, 0, 1)[0]);
  EXPECT_NE(points2D(1, 0, 0)[0], points2D(2, 0, 0)[0]);
  // Mean and variance of many dimensions' values match U(0,1): 1/2 and 1/12.
  double sum = 0.0, sumSq = 0.0;
  int n = 0;
  for (uint32_t i = 0; i < 64; ++i) {
    Sampler s(SamplerType::Sobol, 11, 1234, i);
    for (uint32_t d = 0; d < Sampler::kMaxSobolDimensions + 10; ++d, ++n) {  // past the Sobol ones too
      const float v = s.get1D();
      sum += v;
      sumSq += double(v) * v;
    }
  }
  EXPECT_NEAR(sum / n, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(sumSq / n - (sum / n) * (sum / n), 1.0 / 12.0, 0.01);
}

TEST(Sampler, DeterministicForSeedPixelAndIndex) {
  for (SamplerType type : {SamplerType::Independent, SamplerType::Sobol}) {
    Sampler a(type, 9, 77, 31), b(type, 9, 77, 31);
    for (int d = 0; d < 100; ++d) ASSERT_EQ(a.get1D(), b.get1D());
  }
}

}  // namespace
}  // namespace ember
