// Per-pixel accumulation of radiance samples with a box filter one pixel wide: a pixel's value is
// the mean of its own samples. Sums are kept in double, with the sum of squares, so the variance of
// each pixel mean is available too.
#pragma once

#include "core/math.h"
#include "renderer/aov.h"

#include <cstdint>
#include <string>
#include <vector>

namespace ember {

// A linear float RGB image, row 0 at the top.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // width * height * 3

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0.0f) {}
  Color at(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
  void set(int x, int y, const Color& c) {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    rgb[i] = c.x;
    rgb[i + 1] = c.y;
    rgb[i + 2] = c.z;
  }
};

// Named channels of one image, interleaved pixel by pixel: a layer of a multilayer EXR
// ("albedo" with channels albedo.R, albedo.G, albedo.B; or Z alone).
struct ImageLayer {
  std::vector<std::string> channels;
  std::vector<float> pixels;  // width * height * channels.size()
};

class Film {
 public:
  // With AOVs (renderer/aov.h), their per-sample values are summed beside the colour's.
  Film(int width, int height, AovSet aovs = {});

  // Not thread-safe per pixel; the renderer gives every pixel to exactly one task.
  void addSample(int x, int y, const Color& L) {
    const size_t i = size_t(y) * size_t(width_) + size_t(x);
    const glm::dvec3 d(L);
    sum_[i] += d;
    sumSq_[i] += d * d;
    ++count_[i];
  }
  // The same with the sample's AOVs, for a film that has them.
  void addSample(int x, int y, const Color& L, const AovSample& aov) {
    addSample(x, y, L);
    if (layout_.channels) addAovs(size_t(y) * size_t(width_) + size_t(x), aov);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  Image mean() const;
  // Variance of each pixel's mean: sample variance / n (unbiased, n - 1 in the denominator).
  Image varianceOfMean() const;
  // Pixel i's sample variance per channel (n - 1 in the denominator); 0 below 2 samples.
  glm::dvec3 sampleVariance(size_t i) const {
    const double n = count_[i];
    if (n < 2) return glm::dvec3(0.0);
    const glm::dvec3 m = sum_[i] / n;
    return glm::max(glm::dvec3(0.0), (sumSq_[i] - n * m * m) / (n - 1.0));
  }
  // The image's estimated relative error: sqrt of the mean over pixels and channels of
  // Var(mean) / (mean^2 + 0.01), i.e. the root of the relMSE (Rousselle et al. 2011's regularised
  // form, as `ember compare` reports it) the image is expected to have against its converged
  // self, from the film's own variance. Infinite while some pixel holds fewer than 2 samples.
  double relativeError() const;

  AovSet aovs() const { return aovs_; }
  const AovLayout& aovLayout() const { return layout_; }
  // The AOV layers of the set, in renderer/aov.h's order, with their EXR channel names
  // (docs/aovs.md): per-sample AOVs are means over the pixel's samples (depth, position and uv over
  // those whose camera ray hit a surface; +inf depth where none did), variance the variance of the
  // colour's mean, spp the pixel's sample count.
  std::vector<ImageLayer> aovLayers() const;

  // The accumulation state itself, pixel by pixel (checkpoint files store and restore it exactly).
  size_t pixelCount() const { return count_.size(); }
  std::vector<glm::dvec3>& sums() { return sum_; }
  std::vector<glm::dvec3>& sumsOfSquares() { return sumSq_; }
  std::vector<uint32_t>& counts() { return count_; }
  const std::vector<glm::dvec3>& sums() const { return sum_; }
  const std::vector<glm::dvec3>& sumsOfSquares() const { return sumSq_; }
  const std::vector<uint32_t>& counts() const { return count_; }
  // Adaptive sampling's per-pixel sample budgets (renderer/adaptive.h), counted from the render's
  // first sample; empty when the render samples every pixel alike.
  std::vector<uint32_t>& budgets() { return budget_; }
  const std::vector<uint32_t>& budgets() const { return budget_; }
  // The AOVs' sums: aovLayout().channels doubles per pixel.
  std::vector<double>& aovSums() { return aovSum_; }
  const std::vector<double>& aovSums() const { return aovSum_; }

  // The state of the pixels [x0, x1) x [y0, y1), saved before a tile adds a pass so that an
  // interrupted pass can be taken back exactly (renderer/render.cpp).
  struct TileBackup {
    std::vector<glm::dvec3> sum, sumSq;
    std::vector<uint32_t> count;
    std::vector<double> aov;
  };
  void save(int x0, int y0, int x1, int y1, TileBackup& backup) const;
  void restore(int x0, int y0, int x1, int y1, const TileBackup& backup);

 private:
  void addAovs(size_t pixel, const AovSample& aov);
  int width_, height_;
  std::vector<glm::dvec3> sum_, sumSq_;
  std::vector<uint32_t> count_;
  AovSet aovs_;
  AovLayout layout_;
  std::vector<double> aovSum_;
  std::vector<uint32_t> budget_;
};

}  // namespace ember
