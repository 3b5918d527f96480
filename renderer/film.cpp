#include "renderer/film.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ember {

Film::Film(int width, int height, AovSet aovs)
    : width_(width),
      height_(height),
      sum_(size_t(width) * size_t(height), glm::dvec3(0.0)),
      sumSq_(size_t(width) * size_t(height), glm::dvec3(0.0)),
      count_(size_t(width) * size_t(height), 0),
      aovs_(aovs),
      layout_(aovs),
      aovSum_(size_t(width) * size_t(height) * size_t(layout_.channels), 0.0) {}

void Film::addAovs(size_t pixel, const AovSample& aov) {
  double* sum = aovSum_.data() + pixel * size_t(layout_.channels);
  const auto add = [&](int at, const float* v, int n) {
    if (at < 0) return;
    for (int k = 0; k < n; ++k) sum[at + k] += double(v[k]);
  };
  add(layout_.albedo, &aov.albedo.x, 3);
  add(layout_.normal, &aov.normal.x, 3);
  if (!aov.hit) return;  // depth, position and uv average over the samples that hit a surface
  const float one = 1.0f;
  add(layout_.coverage, &one, 1);
  add(layout_.depth, &aov.depth, 1);
  add(layout_.position, &aov.position.x, 3);
  add(layout_.uv, &aov.uv.x, 2);
}

std::vector<ImageLayer> Film::aovLayers() const {
  std::vector<ImageLayer> layers;
  const size_t pixels = count_.size(), stride = size_t(layout_.channels);
  // A per-sample AOV's mean: its sums over the pixel's samples, or over those that hit a surface.
  const auto mean = [&](int at, std::vector<std::string> channels, bool overHits, float none) {
    ImageLayer layer;
    const size_t n = channels.size();
    layer.channels = std::move(channels);
    layer.pixels.assign(pixels * n, none);
    for (size_t i = 0; i < pixels; ++i) {
      const double* sum = aovSum_.data() + i * stride;
      const double count = overHits ? sum[layout_.coverage] : double(count_[i]);
      if (count > 0.0)
        for (size_t k = 0; k < n; ++k) layer.pixels[i * n + k] = float(sum[size_t(at) + k] / count);
    }
    layers.push_back(std::move(layer));
  };
  if (layout_.albedo >= 0) mean(layout_.albedo, {"albedo.R", "albedo.G", "albedo.B"}, false, 0.0f);
  if (layout_.normal >= 0) mean(layout_.normal, {"N.X", "N.Y", "N.Z"}, false, 0.0f);
  if (layout_.coverage >= 0) {
    ImageLayer layer;
    layer.channels = {"coverage"};
    layer.pixels.resize(pixels);
    for (size_t i = 0; i < pixels; ++i)
      layer.pixels[i] =
          count_[i] ? float(aovSum_[i * stride + size_t(layout_.coverage)] / double(count_[i])) : 0.0f;
    layers.push_back(std::move(layer));
  }
  if (layout_.depth >= 0) mean(layout_.depth, {"Z"}, true, std::numeric_limits<float>::infinity());
  if (layout_.position >= 0) mean(layout_.position, {"P.X", "P.Y", "P.Z"}, true, 0.0f);
  if (layout_.uv >= 0) mean(layout_.uv, {"uv.U", "uv.V"}, true, 0.0f);
  if (aovs_.has(Aov::Variance)) {
    const Image var = varianceOfMean();
    layers.push_back({{"variance.R", "variance.G", "variance.B"}, var.rgb});
  }
  if (aovs_.has(Aov::Spp)) {
    ImageLayer layer;
    layer.channels = {"spp"};
    layer.pixels.assign(count_.begin(), count_.end());
    layers.push_back(std::move(layer));
  }
  return layers;
}

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
      img.set(x, y, Color(sampleVariance(i) / n));
    }
  return img;
}

double Film::relativeError() const {
  double sum = 0.0;
  for (size_t i = 0; i < count_.size(); ++i) {
    const double n = count_[i];
    if (n < 2) return std::numeric_limits<double>::infinity();
    const glm::dvec3 m = sum_[i] / n;
    const glm::dvec3 varOfMean = sampleVariance(i) / n;
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
  const size_t c = size_t(layout_.channels);
  backup.aov.resize(n * c);
  for (int y = y0; y < y1; ++y) {
    const size_t from = size_t(y) * size_t(width_) + size_t(x0), to = size_t(y - y0) * w;
    std::copy_n(sum_.begin() + from, w, backup.sum.begin() + to);
    std::copy_n(sumSq_.begin() + from, w, backup.sumSq.begin() + to);
    std::copy_n(count_.begin() + from, w, backup.count.begin() + to);
    std::copy_n(aovSum_.begin() + from * c, w * c, backup.aov.begin() + to * c);
  }
}

void Film::restore(int x0, int y0, int x1, int y1, const TileBackup& backup) {
  const size_t w = size_t(x1 - x0);
  for (int y = y0; y < y1; ++y) {
    const size_t to = size_t(y) * size_t(width_) + size_t(x0), from = size_t(y - y0) * w;
    std::copy_n(backup.sum.begin() + from, w, sum_.begin() + to);
    std::copy_n(backup.sumSq.begin() + from, w, sumSq_.begin() + to);
    std::copy_n(backup.count.begin() + from, w, count_.begin() + to);
    const size_t c = size_t(layout_.channels);
    std::copy_n(backup.aov.begin() + from * c, w * c, aovSum_.begin() + to * c);
  }
}

}  // namespace ember
