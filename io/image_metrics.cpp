#include "io/image_metrics.h"

#include "io/image_compare.h"

#include <cmath>
#include <stdexcept>

namespace ember {

ImageMetrics computeMetrics(const Image& image, const Image& reference) {
  if (image.width != reference.width || image.height != reference.height)
    throw std::invalid_argument("image sizes differ");
  ImageMetrics m;
  std::array<double, 3> sumI{}, sumR{}, ae{}, se{}, rel{};
  size_t n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Color a = image.at(x, y), r = reference.at(x, y);
      if (!isFinite(a) || !isFinite(r)) {
        ++m.nonFinite;
        continue;
      }
      ++n;
      for (size_t c = 0; c < 3; ++c) {
        const double d = double(a[int(c)]) - double(r[int(c)]);
        sumI[c] += a[int(c)];
        sumR[c] += r[int(c)];
        ae[c] += std::abs(d);
        se[c] += d * d;
        rel[c] += d * d / (double(r[int(c)]) * r[int(c)] + 0.01);
      }
    }
  if (n == 0) return m;
  for (size_t c = 0; c < 3; ++c) {
    m.meanImage[c] = sumI[c] / double(n);
    m.meanReference[c] = sumR[c] / double(n);
    m.mae[c] = ae[c] / double(n);
    m.rmse[c] = std::sqrt(se[c] / double(n));
    m.relmse[c] = rel[c] / double(n);
  }
  m.maeAll = (ae[0] + ae[1] + ae[2]) / double(3 * n);
  m.rmseAll = std::sqrt((se[0] + se[1] + se[2]) / double(3 * n));
  m.relmseAll = (rel[0] + rel[1] + rel[2]) / double(3 * n);
  return m;
}

Image poolVariance(const Image& variance, int radius) {
  if (radius <= 0) return variance;
  Image out(variance.width, variance.height);
  for (int y = 0; y < variance.height; ++y)
    for (int x = 0; x < variance.width; ++x) {
      glm::dvec3 sum(0.0);
      int n = 0;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx, ++n)
          sum += glm::dvec3(variance.at(std::clamp(x + dx, 0, variance.width - 1),
                                        std::clamp(y + dy, 0, variance.height - 1)));
      out.set(x, y, glm::max(variance.at(x, y), Color(sum / double(n))));
    }
  return out;
}

PixelZTest pixelZTest(const Image& image, const Image& imageVarianceIn, const Image& reference,
                      const Image& referenceStderr, double alpha, int poolRadius) {
  for (const Image* other : {&imageVarianceIn, &reference, &referenceStderr})
    if (other->width != image.width || other->height != image.height)
      throw std::invalid_argument("image sizes differ");
  const Image imageVariance = poolVariance(imageVarianceIn, poolRadius);
  Image refVariance = referenceStderr;
  for (float& v : refVariance.rgb) v *= v;
  refVariance = poolVariance(refVariance, poolRadius);
  PixelZTest t;
  t.alpha = alpha;
  t.tests = size_t(image.width) * size_t(image.height) * 3;
  t.threshold = twoSidedNormalQuantile(sidakLevel(alpha, int(t.tests)));
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    const double d = double(image.rgb[i]) - double(reference.rgb[i]);
    const double var = double(imageVariance.rgb[i]) + double(refVariance.rgb[i]);
    double z;
    if (!std::isfinite(d) || !std::isfinite(var)) {
      z = INFINITY;
    } else if (var > 0.0) {
      z = d / std::sqrt(var);
    } else {
      z = std::abs(d) <= 1e-6 * (1.0 + std::abs(double(reference.rgb[i]))) ? 0.0 : INFINITY;
    }
    t.maxAbsZ = std::max(t.maxAbsZ, std::abs(z));
    if (std::abs(z) > t.threshold) ++t.rejected;
  }
  return t;
}

}  // namespace ember
