#include "io/filtered_texture.h"

#include "io/input_error.h"
#include "materials/hit_memo.h"

#include <atomic>
#include <mutex>

namespace ember {

namespace {

std::atomic<bool> anyFailure{false};
std::mutex failureMutex;
std::string firstFailure;

void recordFailure(const std::string& name) {
  if (anyFailure.load(std::memory_order_relaxed)) return;
  std::lock_guard<std::mutex> lock(failureMutex);
  if (!firstFailure.empty()) return;
  firstFailure = name + ": texture lookups failed during the render (the file disappeared or changed?)";
  anyFailure.store(true);
}

ImagePlugin::Wrap pluginWrap(TextureWrap wrap) {
  return wrap == TextureWrap::Clamp    ? ImagePlugin::Wrap::Clamp
         : wrap == TextureWrap::Mirror ? ImagePlugin::Wrap::Mirror
                                       : ImagePlugin::Wrap::Repeat;
}

}  // namespace

std::string filteredTextureFailure() {
  if (!anyFailure.load()) return "";
  std::lock_guard<std::mutex> lock(failureMutex);
  return firstFailure;
}

std::string takeFilteredTextureFailure() {
  std::lock_guard<std::mutex> lock(failureMutex);
  std::string failure = std::move(firstFailure);
  firstFailure.clear();
  anyFailure.store(false);
  return failure;
}

FilteredImageTexture::FilteredImageTexture(const ImagePlugin& plugin, const std::string& name,
                                           const void* handle, const ImagePlugin::TextureFile& info,
                                           TextureWrap wrap, const Color& scale)
    : plugin_(plugin),
      name_(name),
      handle_(handle),
      wrapS_(pluginWrap(wrap)),
      wrapT_(wrapS_),
      scale_(scale),
      id_(newHitMemoOwner()) {
  // The file's bounds, scaled (a negative scale swaps them); a blend of texels stays within them.
  const Color lo = Color(info.min[0], info.min[1], info.min[2]) * scale;
  const Color hi = Color(info.max[0], info.max[1], info.max[2]) * scale;
  min_ = glm::min(lo, hi);
  max_ = glm::max(lo, hi);
  average_ = Color(info.mean[0], info.mean[1], info.mean[2]) * scale;
  // Black is impossible only where some channel is positive everywhere and none is ever negative.
  const bool positive = min_.x > 0.0f || min_.y > 0.0f || min_.z > 0.0f;
  const bool negative = min_.x < 0.0f || min_.y < 0.0f || min_.z < 0.0f;
  mayBeBlack_ = !positive || negative;
}

FilteredImageTexture::FilteredImageTexture(const ImagePlugin& plugin, const std::string& name, int width,
                                           int height, const std::vector<Color>& texels, TextureWrap wrapS,
                                           TextureWrap wrapT, const Color& scale)
    : plugin_(plugin),
      name_(name),
      wrapS_(pluginWrap(wrapS)),
      wrapT_(pluginWrap(wrapT)),
      scale_(scale),
      id_(newHitMemoOwner()) {
  rgb_.reserve(texels.size() * 3);
  // A filtered value is a weighted mean of texels: black only where some texel may be.
  TexelStatistics stats;
  for (const Color& c : texels) {
    rgb_.insert(rgb_.end(), {c.x, c.y, c.z});
    stats.add(c * scale_);
  }
  max_ = stats.max;
  min_ = stats.minimum();
  average_ = stats.average();
  mayBeBlack_ = stats.mayBeBlack;
  handle_ = plugin_.addTexture(rgb_.data(), width, height);
  if (!handle_) throw InputError(name + ": OpenImageIO's texture system cannot take the image");
}

Color FilteredImageTexture::lookup(Vec2 uv, float width) const {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return Color(0.0f);
  float rgb[3] = {0.0f, 0.0f, 0.0f};
  const float w = std::isfinite(width) ? width : 0.0f;
  // A square footprint of side w in (s, t): dsdx = dtdy = w.
  if (!plugin_.lookup(handle_, wrapS_, wrapT_, uv.x, uv.y, w, 0.0f, 0.0f, w, rgb)) {
    recordFailure(name_);
    return Color(0.0f);
  }
  return scale_ * Color(rgb[0], rgb[1], rgb[2]);
}

Color FilteredImageTexture::evalAt(const SurfaceHit& hit) const {
  return HitMemo<Color, FilteredImageTexture>::at(hit, id_, [&] { return lookup(hit.uv, hit.uvFootprint); });
}

}  // namespace ember
