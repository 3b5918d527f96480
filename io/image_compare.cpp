#include "io/image_compare.h"

#include <cmath>
#include <stdexcept>

namespace ember {

double twoSidedNormalQuantile(double p) {
  // P(|Z| > z) = erfc(z / sqrt 2) is monotone in z: bisection to double precision.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double sidakLevel(double alpha, int m) {
  return -std::expm1(std::log1p(-alpha) / double(m));
}

Image squared(const Image& stderrImage) {
  Image out = stderrImage;
  for (float& v : out.rgb) v *= v;
  return out;
}

BlockZTestResult blockZTest(const Image& image, const Image& variance, const Image& reference,
                            const Image& refVariance, int blockSize, double alpha) {
  const int w = image.width, h = image.height;
  for (const Image* other : {&variance, &reference, &refVariance})
    if (other->width != w || other->height != h) throw std::invalid_argument("image sizes differ");
  const int bx = (w + blockSize - 1) / blockSize, by = (h + blockSize - 1) / blockSize;

  BlockZTestResult r;
  r.tests = bx * by * 3;
  // The whole-image means are 3 more tests in the same family.
  r.threshold = twoSidedNormalQuantile(sidakLevel(alpha, r.tests + 3));

  std::array<double, 3> diffSum{}, varSum{};
  for (int j = 0; j < by; ++j)
    for (int i = 0; i < bx; ++i) {
      std::array<double, 3> d{}, v{};
      int n = 0;
      for (int y = j * blockSize; y < std::min(h, (j + 1) * blockSize); ++y)
        for (int x = i * blockSize; x < std::min(w, (i + 1) * blockSize); ++x, ++n) {
          const Color a = image.at(x, y), b = reference.at(x, y);
          const Color va = variance.at(x, y), vb = refVariance.at(x, y);
          for (int c = 0; c < 3; ++c) {
            d[size_t(c)] += double(a[c]) - double(b[c]);
            v[size_t(c)] += double(va[c]) + double(vb[c]);
          }
        }
      for (size_t c = 0; c < 3; ++c) {
        diffSum[c] += d[c];
        varSum[c] += v[c];
        // Block mean difference d/n has variance v/n^2: z = d / sqrt(v). A block whose pixels
        // all have zero variance must match exactly.
        const double z = v[c] > 0.0 ? d[c] / std::sqrt(v[c]) : (d[c] == 0.0 ? 0.0 : INFINITY);
        r.maxAbsZ = std::max(r.maxAbsZ, std::abs(z));
        if (std::abs(z) > r.threshold) ++r.failures;
      }
    }
  for (size_t c = 0; c < 3; ++c) {
    r.meanZ[c] = varSum[c] > 0.0 ? diffSum[c] / std::sqrt(varSum[c]) : 0.0;
    if (std::abs(r.meanZ[c]) > r.threshold) r.meanPasses = false;
  }
  return r;
}

}  // namespace ember
