#include "renderer/film.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ember {

Film::Film(int width, int height)
    : width_(width),
      height_(height),
      sum_(size_t(width) * size_t(height), glm::dvec3(0.0)),
      sumSq_(size_t(width) * size_t(height), glm::dvec3(0.0)),
      count_(size_t(width) * size_t(height), 0) {}

Image Film::mean() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const size_t i = size_t(y) * size_t(width_) + size_t(x);
      img.set(x, y, count_[i] ? Color(sum_[i] / double(count_[i])) : Color(0.0f));
    }
  return img;
}

Image Film::varianceOfMean() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const size_t i = size_t(y) * size_t(width_) + size_t(x);
      const double n = count_[i];
      if (n < 2) continue;
      const glm::dvec3 m = sum_[i] / n;
      const glm::dvec3 var = glm::max(glm::dvec3(0.0), (sumSq_[i] - n * m * m) / (n - 1.0));
      img.set(x, y, Color(var / n));
    }
  return img;
}

double Film::relativeError() const {
  double sum = 0.0;
  for (size_t i = 0; i < count_.size(); ++i) {
    const double n = count_[i];
    if (n < 2) return std::numeric_limits<double>::infinity();
    const glm::dvec3 m = sum_[i] / n;
    const glm::dvec3 varOfMean = glm::max(glm::dvec3(0.0), (sumSq_[i] - n * m * m) / (n - 1.0)) / n;
    const glm::dvec3 rel = varOfMean / (m * m + 0.01);
    sum += rel.x + rel.y + rel.z;
  }
  return count_.empty() ? 0.0 : std::sqrt(sum / double(3 * count_.size()));
}

void Film::save(int x0, int y0, int x1, int y1, TileBackup& backup) const {
  const size_t w = size_t(x1 - x0), n = w * size_t(y1 - y0);
  backup.sum.resize(n);
  backup.sumSq.resize(n);
  backup.count.resize(n);
  for (int y = y0; y < y1; ++y) {
    const size_t from = size_t(y) * size_t(width_) + size_t(x0), to = size_t(y - y0) * w;
    std::copy_n(sum_.begin() + from, w, backup.sum.begin() + to);
    std::copy_n(sumSq_.begin() + from, w, backup.sumSq.begin() + to);
    std::copy_n(count_.begin() + from, w, backup.count.begin() + to);
  }
}

void Film::restore(int x0, int y0, int x1, int y1, const TileBackup& backup) {
  const size_t w = size_t(x1 - x0);
  for (int y = y0; y < y1; ++y) {
    const size_t to = size_t(y) * size_t(width_) + size_t(x0), from = size_t(y - y0) * w;
    std::copy_n(backup.sum.begin() + from, w, sum_.begin() + to);
    std::copy_n(backup.sumSq.begin() + from, w, sumSq_.begin() + to);
    std::copy_n(backup.count.begin() + from, w, count_.begin() + to);
  }
}

}  // namespace ember
