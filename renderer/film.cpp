#include "renderer/film.h"

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

}  // namespace ember
