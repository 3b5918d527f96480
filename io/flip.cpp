#include "io/flip.h"

#include <array>
#include <cmath>
#include <stdexcept>

namespace ember {

namespace {

// CIE XYZ of linear sRGB primaries, D65 white (IEC 61966-2-1).
constexpr float kWhiteX = 0.950428545f, kWhiteY = 1.0f, kWhiteZ = 1.088900371f;

Vec3 rgbToXyz(const Vec3& c) {
  return {0.4124564f * c.x + 0.3575761f * c.y + 0.1804375f * c.z,
          0.2126729f * c.x + 0.7151522f * c.y + 0.0721750f * c.z,
          0.0193339f * c.x + 0.1191920f * c.y + 0.9503041f * c.z};
}
Vec3 xyzToRgb(const Vec3& c) {
  return {3.2404542f * c.x - 1.5371385f * c.y - 0.4985314f * c.z,
          -0.9692660f * c.x + 1.8760108f * c.y + 0.0415560f * c.z,
          0.0556434f * c.x - 0.2040259f * c.y + 1.0572252f * c.z};
}

// The linearised CIELab ("YyCxCz") opponent space in which FLIP filters (paper section 4.1).
Vec3 xyzToYcxcz(const Vec3& c) {
  const float y = c.y / kWhiteY;
  return {116.0f * y - 16.0f, 500.0f * (c.x / kWhiteX - y), 200.0f * (y - c.z / kWhiteZ)};
}
Vec3 ycxczToXyz(const Vec3& c) {
  const float y = (c.x + 16.0f) / 116.0f;
  return {(c.y / 500.0f + y) * kWhiteX, y * kWhiteY, (y - c.z / 200.0f) * kWhiteZ};
}

Vec3 xyzToLab(const Vec3& c) {
  auto f = [](float t) {
    constexpr float d = 6.0f / 29.0f;
    return t > d * d * d ? std::cbrt(t) : t / (3.0f * d * d) + 4.0f / 29.0f;
  };
  const float fx = f(c.x / kWhiteX), fy = f(c.y / kWhiteY), fz = f(c.z / kWhiteZ);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

// Hunt effect: chroma scales with lightness (paper eq. 2).
Vec3 hunt(const Vec3& lab) {
  return {lab.x, 0.01f * lab.x * lab.y, 0.01f * lab.x * lab.z};
}

// HyAB distance (Abasi et al. 2020): city-block in lightness, Euclidean in chroma.
float hyab(const Vec3& a, const Vec3& b) {
  return std::abs(a.x - b.x) + std::sqrt((a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

struct Kernel {
  int radius;
  std::vector<float> w;  // (2r+1)^2, row-major
  float at(int dx, int dy) const { return w[size_t((dy + radius) * (2 * radius + 1) + dx + radius)]; }
};

// Contrast sensitivity functions as sums of Gaussians in the spatial domain (paper eq. 1 and
// table 1): S(x) = sum_i a_i sqrt(pi / b_i) exp(-pi^2 x^2 / b_i), x in degrees of visual angle.
std::array<Kernel, 3> csfKernels(float ppd) {
  struct Params {
    float a1, b1, a2, b2;
  };
  const Params channels[3] = {{1.0f, 0.0047f, 0.0f, 1e-5f},    // achromatic
                              {1.0f, 0.0053f, 0.0f, 1e-5f},    // red-green
                              {34.1f, 0.04f, 13.5f, 0.025f}};  // blue-yellow
  const float maxB = 0.04f;
  const int radius = int(std::ceil(3.0f * std::sqrt(maxB / (2.0f * kPi * kPi)) * ppd));
  std::array<Kernel, 3> kernels;
  for (int c = 0; c < 3; ++c) {
    Kernel& k = kernels[size_t(c)];
    k.radius = radius;
    k.w.resize(size_t((2 * radius + 1) * (2 * radius + 1)));
    double sum = 0.0;
    const Params& p = channels[c];
    for (int y = -radius; y <= radius; ++y)
      for (int x = -radius; x <= radius; ++x) {
        const float d2 = float(x * x + y * y) / (ppd * ppd);
        const float v = p.a1 * std::sqrt(kPi / p.b1) * std::exp(-kPi * kPi * d2 / p.b1) +
                        p.a2 * std::sqrt(kPi / p.b2) * std::exp(-kPi * kPi * d2 / p.b2);
        k.w[size_t((y + radius) * (2 * radius + 1) + x + radius)] = v;
        sum += v;
      }
    for (float& v : k.w) v = float(v / sum);
  }
  return kernels;
}

// Edge (first derivative) and point (second derivative) detectors of a Gaussian with
// sigma = 0.5 * 0.082 degrees (paper section 4.2), each normalised so that its positive weights
// sum to 1 and its negative weights to -1. Returned for the x direction; y is the transpose.
void featureKernels(float ppd, Kernel& edge, Kernel& point) {
  const float sigma = 0.5f * 0.082f * ppd;
  const int radius = int(std::ceil(3.0f * sigma));
  for (Kernel* k : {&edge, &point}) {
    k->radius = radius;
    k->w.assign(size_t((2 * radius + 1) * (2 * radius + 1)), 0.0f);
  }
  for (int y = -radius; y <= radius; ++y)
    for (int x = -radius; x <= radius; ++x) {
      const float g = std::exp(-float(x * x + y * y) / (2.0f * sigma * sigma));
      const size_t i = size_t((y + radius) * (2 * radius + 1) + x + radius);
      edge.w[i] = -float(x) * g;
      point.w[i] = (float(x * x) / (sigma * sigma) - 1.0f) * g;
    }
  for (Kernel* k : {&edge, &point}) {
    double pos = 0.0, neg = 0.0;
    for (float v : k->w) (v > 0.0f ? pos : neg) += v;
    for (float& v : k->w) v = v > 0.0f ? float(v / pos) : float(v / -neg);
  }
}

// Convolution with clamp-to-edge borders.
template <typename Sample, typename Value>
Value convolve(const Kernel& k, int w, int h, int x, int y, bool transpose, Sample sample, Value zero) {
  Value sum = zero;
  for (int dy = -k.radius; dy <= k.radius; ++dy)
    for (int dx = -k.radius; dx <= k.radius; ++dx) {
      const int sx = std::clamp(x + dx, 0, w - 1), sy = std::clamp(y + dy, 0, h - 1);
      sum += (transpose ? k.at(dy, dx) : k.at(dx, dy)) * sample(sx, sy);
    }
  return sum;
}

}  // namespace

FlipResult computeFlip(const Image& reference, const Image& test, float ppd) {
  if (reference.width != test.width || reference.height != test.height)
    throw std::invalid_argument("FLIP: image sizes differ");
  const int w = reference.width, h = reference.height;
  const size_t n = size_t(w) * size_t(h);
  const auto csf = csfKernels(ppd);
  Kernel edge, point;
  featureKernels(ppd, edge, point);

  // Colour pipeline inputs (YyCxCz) and feature inputs (normalised achromatic Y = Y / Yn).
  std::vector<Vec3> ycc[2];
  std::vector<float> lum[2];
  const Image* images[2] = {&reference, &test};
  for (int i = 0; i < 2; ++i) {
    ycc[i].resize(n);
    lum[i].resize(n);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Vec3 xyz = rgbToXyz(glm::clamp(images[i]->at(x, y), Vec3(0.0f), Vec3(1.0f)));
        ycc[i][size_t(y) * size_t(w) + size_t(x)] = xyzToYcxcz(xyz);
        lum[i][size_t(y) * size_t(w) + size_t(x)] = xyz.y / kWhiteY;
      }
  }

  // The largest colour difference FLIP can see: between pure green and pure blue (paper sec. 4.1).
  constexpr float qc = 0.7f, pc = 0.4f, pt = 0.95f, qf = 0.5f;
  const float cmax =
      std::pow(hyab(hunt(xyzToLab(rgbToXyz(Vec3(0, 1, 0)))), hunt(xyzToLab(rgbToXyz(Vec3(0, 0, 1))))), qc);

  FlipResult result;
  result.errorMap.resize(n);
  double total = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 lab[2];
      float edgeMag[2], pointMag[2];
      for (int i = 0; i < 2; ++i) {
        const auto& src = ycc[i];
        Vec3 filtered;
        for (int c = 0; c < 3; ++c)
          filtered[c] = convolve(
              csf[size_t(c)], w, h, x, y, false,
              [&](int sx, int sy) { return src[size_t(sy) * size_t(w) + size_t(sx)][c]; }, 0.0f);
        const Vec3 rgb = glm::clamp(xyzToRgb(ycxczToXyz(filtered)), Vec3(0.0f), Vec3(1.0f));
        lab[i] = hunt(xyzToLab(rgbToXyz(rgb)));
        const auto& l = lum[i];
        auto sample = [&](int sx, int sy) { return l[size_t(sy) * size_t(w) + size_t(sx)]; };
        const float ex = convolve(edge, w, h, x, y, false, sample, 0.0f);
        const float ey = convolve(edge, w, h, x, y, true, sample, 0.0f);
        const float px = convolve(point, w, h, x, y, false, sample, 0.0f);
        const float py = convolve(point, w, h, x, y, true, sample, 0.0f);
        edgeMag[i] = std::sqrt(ex * ex + ey * ey);
        pointMag[i] = std::sqrt(px * px + py * py);
      }
      // Colour error, compressed so that differences beyond pc * cmax saturate slowly (eq. 4).
      const float dc = std::pow(hyab(lab[0], lab[1]), qc);
      const float ec =
          dc < pc * cmax ? (pt / (pc * cmax)) * dc : pt + (dc - pc * cmax) / (cmax - pc * cmax) * (1.0f - pt);
      // Feature error (eq. 5) and the final combination (eq. 6).
      const float df = std::max(std::abs(edgeMag[0] - edgeMag[1]), std::abs(pointMag[0] - pointMag[1]));
      const float ef = std::pow(std::min(1.0f, df / std::sqrt(2.0f)), qf);
      const float e = std::pow(std::clamp(ec, 0.0f, 1.0f), 1.0f - ef);
      result.errorMap[size_t(y) * size_t(w) + size_t(x)] = e;
      total += e;
    }
  result.mean = n ? total / double(n) : 0.0;
  return result;
}

}  // namespace ember
