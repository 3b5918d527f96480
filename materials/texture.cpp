#include "materials/texture.h"

namespace ember {

ImageTexture::ImageTexture(int width, int height, std::vector<Color> texels, TextureFilter filter,
                           TextureWrap wrapS, TextureWrap wrapT, const Color& scale)
    : width_(width),
      height_(height),
      texels_(std::move(texels)),
      filter_(filter),
      wrapS_(wrapS),
      wrapT_(wrapT),
      scale_(scale) {
  Color sum(0.0f);
  for (const Color& c : texels_) {
    max_ = glm::max(max_, c * scale_);
    sum += c * scale_;
  }
  if (!texels_.empty()) average_ = sum / float(texels_.size());
}

static int wrapIndex(int i, int n, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::Clamp:
      return std::clamp(i, 0, n - 1);
    case TextureWrap::Repeat:
      return ((i % n) + n) % n;
    case TextureWrap::Mirror: {
      const int period = 2 * n;
      int m = ((i % period) + period) % period;
      return m < n ? m : period - 1 - m;
    }
  }
  return 0;
}

Color ImageTexture::texel(int x, int y) const {
  x = wrapIndex(x, width_, wrapS_);
  y = wrapIndex(y, height_, wrapT_);
  return texels_[size_t(y) * size_t(width_) + size_t(x)];
}

Color ImageTexture::eval(Vec2 uv) const {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return Color(0.0f);
  const float x = uv.x * float(width_);
  const float y = uv.y * float(height_);
  if (filter_ == TextureFilter::Nearest) {
    return scale_ * texel(int(std::floor(x)), int(std::floor(y)));
  }
  // Bilinear between the four nearest texel centres (centres sit at half-integer coordinates).
  const float fx = x - 0.5f, fy = y - 0.5f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float tx = fx - float(x0), ty = fy - float(y0);
  const Color top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), tx);
  const Color bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), tx);
  return scale_ * glm::mix(top, bottom, ty);
}

}  // namespace ember
