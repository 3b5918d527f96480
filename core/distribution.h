// Piecewise-constant distributions for importance sampling tabulated functions (PBRT4 section
// A.4.2 and A.5.3): 1D by inverting the cumulative sum, 2D as a marginal over rows times the
// conditional within the chosen row. Densities are with respect to [0, 1) and [0, 1)^2.
#pragma once

#include "core/math.h"

#include <vector>

namespace ember {

class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::vector<float> f);

  size_t size() const { return func_.size(); }
  float integral() const { return integral_; }
  // Continuous sample in [0, 1) with its density; `index` is the chosen bin.
  float sample(float u, float& pdf, size_t& index) const;
  float pdf(float x) const;

 private:
  std::vector<float> func_;
  std::vector<float> cdf_;  // size + 1 entries, cdf_[0] = 0, cdf_.back() = 1
  float integral_ = 0.0f;
};

class Distribution2D {
 public:
  Distribution2D() = default;
  // f has width * height entries, row-major; rows are the second coordinate.
  Distribution2D(const std::vector<float>& f, int width, int height);

  Vec2 sample(Vec2 u, float& pdf) const;
  float pdf(Vec2 p) const;

 private:
  std::vector<Distribution1D> rows_;
  Distribution1D marginal_;
};

}  // namespace ember
