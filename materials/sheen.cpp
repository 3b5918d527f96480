#include "materials/sheen.h"

#include <array>

namespace ember {

double sheenAlbedoQuadrature(float cosTheta, float sheenRoughness, int n) {
  const CharlieSheen sheen(sheenRoughness);
  const float c = std::clamp(cosTheta, 1e-4f, 1.0f);
  const Vec3 o(std::sqrt(std::max(0.0f, 1.0f - c * c)), 0.0f, c);
  // Midpoints in (s, phi) with cos theta_i = s^2: the solid-angle measure d(cos) d(phi) becomes
  // 2 s ds d(phi), which puts the points where the lobe peaks, towards the horizon. The lobe is
  // symmetric about the plane of o and the normal, so phi covers [0, pi] twice over.
  double sum = 0.0;
  for (int a = 0; a < n; ++a) {
    const double sv = (a + 0.5) / double(n);
    const float ci = float(sv * sv);
    const float si = std::sqrt(std::max(0.0f, 1.0f - ci * ci));
    double row = 0.0;
    for (int b = 0; b < 2 * n; ++b) {
      const float phi = kPi * (float(b) + 0.5f) / float(2 * n);
      const Vec3 i(si * std::cos(phi), si * std::sin(phi), ci);
      row += sheen.evalCos(o, i);
    }
    sum += 2.0 * sv * row;
  }
  return sum * 2.0 * double(kPi) / (double(n) * double(2 * n));
}

namespace {

// The table is uniform in sqrt(cos theta), dense at grazing angles where E changes fastest.
constexpr int kCosSteps = 32, kRoughnessSteps = 16, kQuadrature = 48;

struct AlbedoTable {
  std::array<float, kCosSteps * kRoughnessSteps> values;
  AlbedoTable() {
    for (int r = 0; r < kRoughnessSteps; ++r) {
      const float roughness = CharlieSheen::kMinRoughness +
                              (1.0f - CharlieSheen::kMinRoughness) * float(r) / float(kRoughnessSteps - 1);
      for (int c = 0; c < kCosSteps; ++c)
        values[size_t(r * kCosSteps + c)] = float(sheenAlbedoQuadrature(
            float(c * c) / float((kCosSteps - 1) * (kCosSteps - 1)), roughness, kQuadrature));
    }
  }
};

}  // namespace

float sheenAlbedo(float cosTheta, float sheenRoughness) {
  static const AlbedoTable table;  // thread-safe initialisation; built by the first sheen material
  const float x = std::sqrt(std::clamp(std::abs(cosTheta), 0.0f, 1.0f)) * float(kCosSteps - 1);
  const float r = std::clamp(sheenRoughness, CharlieSheen::kMinRoughness, 1.0f);
  const float y =
      (r - CharlieSheen::kMinRoughness) / (1.0f - CharlieSheen::kMinRoughness) * float(kRoughnessSteps - 1);
  const int x0 = std::min(int(x), kCosSteps - 2), y0 = std::min(int(y), kRoughnessSteps - 2);
  const float fx = x - float(x0), fy = y - float(y0);
  const auto at = [&](int xi, int yi) { return table.values[size_t(yi * kCosSteps + xi)]; };
  return (1.0f - fy) * ((1.0f - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1.0f - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

}  // namespace ember
