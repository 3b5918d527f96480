#include "io/filtered_texture.h"

#include "io/input_error.h"
#include "materials/hit_memo.h"

namespace ember {

FilteredImageTexture::FilteredImageTexture(const ImagePlugin& plugin, const std::string& name, int width,
                                           int height, const std::vector<Color>& texels, TextureWrap wrap,
                                           const Color& scale)
    : plugin_(plugin),
      wrap_(wrap == TextureWrap::Clamp    ? ImagePlugin::Wrap::Clamp
            : wrap == TextureWrap::Mirror ? ImagePlugin::Wrap::Mirror
                                          : ImagePlugin::Wrap::Repeat),
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
  plugin_.lookup(handle_, wrap_, wrap_, uv.x, uv.y, w, 0.0f, 0.0f, w, rgb);
  return scale_ * Color(rgb[0], rgb[1], rgb[2]);
}

Color FilteredImageTexture::evalAt(const SurfaceHit& hit) const {
  return HitMemo<Color, FilteredImageTexture>::at(hit, id_, [&] { return lookup(hit.uv, hit.uvFootprint); });
}

}  // namespace ember
