#include "core/distribution.h"

#include <algorithm>

namespace ember {

Distribution1D::Distribution1D(std::vector<float> f) : func_(std::move(f)), cdf_(func_.size() + 1, 0.0f) {
  const size_t n = func_.size();
  double running = 0.0;
  for (size_t i = 0; i < n; ++i) {
    func_[i] = std::max(0.0f, func_[i]);
    running += double(func_[i]) / double(n);
    cdf_[i + 1] = float(running);
  }
  integral_ = float(running);
  if (running > 0.0) {
    for (size_t i = 1; i <= n; ++i) cdf_[i] = float(double(cdf_[i]) / running);
  } else {
    for (size_t i = 1; i <= n; ++i) cdf_[i] = float(i) / float(n);  // all zero: sample uniformly
  }
  cdf_[n] = 1.0f;
}

float Distribution1D::sample(float u, float& pdf, size_t& index) const {
  // The last bin whose cdf start is <= u.
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
  index = size_t(std::clamp<std::ptrdiff_t>(it - cdf_.begin() - 1, 0, std::ptrdiff_t(func_.size()) - 1));
  const float width = cdf_[index + 1] - cdf_[index];
  const float du = width > 0.0f ? (u - cdf_[index]) / width : 0.5f;
  pdf = integral_ > 0.0f ? func_[index] / integral_ : 1.0f;
  return std::min((float(index) + std::clamp(du, 0.0f, 1.0f)) / float(func_.size()), 0.99999994f);
}

float Distribution1D::pdf(float x) const {
  if (func_.empty()) return 0.0f;
  const size_t i = std::min(size_t(std::max(0.0f, x) * float(func_.size())), func_.size() - 1);
  return integral_ > 0.0f ? func_[i] / integral_ : 1.0f;
}

Distribution2D::Distribution2D(const std::vector<float>& f, int width, int height) {
  std::vector<float> rowIntegrals(static_cast<size_t>(height));
  rows_.reserve(size_t(height));
  for (int y = 0; y < height; ++y) {
    rows_.emplace_back(
        std::vector<float>(f.begin() + ptrdiff_t(y) * width, f.begin() + ptrdiff_t(y + 1) * width));
    rowIntegrals[size_t(y)] = rows_.back().integral();
  }
  marginal_ = Distribution1D(std::move(rowIntegrals));
}

Vec2 Distribution2D::sample(Vec2 u, float& pdf) const {
  float pdfRow, pdfColumn;
  size_t row, column;
  const float v = marginal_.sample(u.y, pdfRow, row);
  const float x = rows_[row].sample(u.x, pdfColumn, column);
  pdf = pdfRow * pdfColumn;
  return {x, v};
}

float Distribution2D::pdf(Vec2 p) const {
  const size_t row = std::min(size_t(std::max(0.0f, p.y) * float(rows_.size())), rows_.size() - 1);
  return marginal_.pdf(p.y) * rows_[row].pdf(p.x);
}

}  // namespace ember
