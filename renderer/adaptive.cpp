#include "renderer/adaptive.h"

#include <algorithm>
#include <cmath>

namespace ember {

std::vector<double> relativeSampleVariance(const Film& film) {
  std::vector<double> v(film.pixelCount(), 0.0);
  for (size_t i = 0; i < v.size(); ++i) {
    const double n = film.counts()[i];
    if (n < 2) continue;
    const glm::dvec3 m = film.sums()[i] / n;
    const glm::dvec3 rel = film.sampleVariance(i) / (m * m + 0.01);
    v[i] = (rel.x + rel.y + rel.z) / 3.0;
  }
  return v;
}

std::vector<uint32_t> adaptiveBudgets(const Film& film, double target, uint32_t pilot, uint32_t cap) {
  const int w = film.width(), h = film.height();
  const std::vector<double> v = relativeSampleVariance(film);
  std::vector<double> sigma(v.size());
  for (size_t i = 0; i < v.size(); ++i) sigma[i] = std::sqrt(v[i]);
  // Sums of sigma before and after each pixel, so that the image mean for pixel i is formed
  // without it (a total minus sigma_i would carry sigma_i's rounding into i's budget).
  std::vector<double> before(v.size() + 1, 0.0), after(v.size() + 1, 0.0);
  for (size_t i = 0; i < v.size(); ++i) before[i + 1] = before[i] + sigma[i];
  for (size_t i = v.size(); i-- > 0;) after[i] = after[i + 1] + sigma[i];
  std::vector<uint32_t> budget(v.size(), std::max(pilot, cap));
  if (v.size() < 2) return budget;
  const double inverseTarget2 = 1.0 / (target * target);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      double local = 0.0;
      int neighbours = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          local += sigma[size_t(ny) * size_t(w) + size_t(nx)];
          ++neighbours;
        }
      local /= neighbours;
      const double mean = (before[i] + after[i + 1]) / double(v.size() - 1);  // over the other pixels
      const double product = local * mean;
      // A noiseless neighbourhood needs nothing past the pilot (also where 1 / target^2 overflows).
      const double needed = product > 0.0 ? std::ceil(product * inverseTarget2) : 0.0;
      budget[i] = uint32_t(std::clamp(needed, double(pilot), double(std::max(pilot, cap))));
    }
  return budget;
}

}  // namespace ember
