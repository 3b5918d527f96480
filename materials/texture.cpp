#include "materials/texture.h"

#include "materials/hit_memo.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

namespace ember {

namespace {

// The distinct values of one channel, by bit pattern, in an open-addressing table of twice the
// palette's size: index(bits) gives the value's palette slot, or -1 once a 257th value appears.
class ChannelPalette {
 public:
  int index(float value, std::array<float, 256>& palette) {
    uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    for (uint32_t slot = (bits * 0x9e3779b1u) >> (32 - kLog2Slots);; slot = (slot + 1) & (kSlots - 1)) {
      if (used_[slot] && keys_[slot] == bits) return index_[slot];
      if (used_[slot]) continue;
      if (size_ == 256) return -1;
      used_[slot] = true;
      keys_[slot] = bits;
      index_[slot] = uint8_t(size_);
      palette[size_] = value;
      return size_++;
    }
  }

 private:
  static constexpr int kLog2Slots = 9;
  static constexpr uint32_t kSlots = 1u << kLog2Slots;
  std::array<uint32_t, kSlots> keys_{};
  std::array<uint8_t, kSlots> index_{};
  std::array<bool, kSlots> used_{};
  int size_ = 0;
};

// The distinct colours of an image, by bit pattern, in an open-addressing table of twice the
// palette's size: index(c) gives the colour's palette slot, or -1 once a 257th colour appears.
class ColorPalette {
 public:
  int index(const Color& c, std::vector<Color>& palette) {
    static_assert(sizeof(Color) == sizeof(std::array<uint32_t, 3>));
    std::array<uint32_t, 3> bits;
    std::memcpy(bits.data(), &c, sizeof bits);
    const uint32_t hash = (bits[0] * 0x9e3779b1u) ^ (bits[1] * 0x85ebca6bu) ^ (bits[2] * 0xc2b2ae35u);
    for (uint32_t slot = hash >> (32 - kLog2Slots);; slot = (slot + 1) & (kSlots - 1)) {
      if (used_[slot] && keys_[slot] == bits) return index_[slot];
      if (used_[slot]) continue;
      if (palette.size() == 256) return -1;
      used_[slot] = true;
      keys_[slot] = bits;
      index_[slot] = uint8_t(palette.size());
      palette.push_back(c);
      return int(palette.size()) - 1;
    }
  }

 private:
  static constexpr int kLog2Slots = 9;
  static constexpr uint32_t kSlots = 1u << kLog2Slots;
  std::array<std::array<uint32_t, 3>, kSlots> keys_{};
  std::array<uint8_t, kSlots> index_{};
  std::array<bool, kSlots> used_{};
};

}  // namespace

float decodeSrgb(float c) {
  // srgbToLinear of the 65,536 values a 16-bit channel decodes to, b / 65535, as the image reader
  // computes them (io/image_io.cpp). An 8-bit channel's b / 255 is the same rational number as
  // 257 b / 65535, and both round to the same float, so the one table serves both depths.
  static const std::vector<float> linear = [] {
    std::vector<float> table(65536);
    for (size_t b = 0; b < table.size(); ++b) table[b] = srgbToLinear(float(b) / 65535.0f);
    return table;
  }();
  const float scaled = c * 65535.0f + 0.5f;
  if (scaled >= 0.0f && scaled < 65536.0f) {  // false for NaN
    const size_t b = size_t(scaled);
    // Compared as bits: -0 must take the formula, which keeps its sign.
    if (std::bit_cast<uint32_t>(float(b) / 65535.0f) == std::bit_cast<uint32_t>(c)) return linear[b];
  }
  return srgbToLinear(c);
}

ImageTexture::ImageTexture(int width, int height, std::vector<Color> texels, TextureFilter filter,
                           TextureWrap wrapS, TextureWrap wrapT, const Color& scale)
    : width_(width),
      height_(height),
      texels_(std::move(texels)),
      filter_(filter),
      wrapS_(wrapS),
      wrapT_(wrapT),
      scale_(scale),
      id_(newHitMemoOwner()) {
  TexelStatistics stats;
  for (const Color& c : texels_) stats.add(c * scale_);
  keepStatistics(stats);

  // First the palettes, which an HDR image overflows within its first few hundred texels; the
  // indices only once they fit. A colour palette first: one byte per texel.
  {
    ColorPalette colors;
    std::vector<Color> palette;
    bool fits = true;
    for (const Color& t : texels_)
      if (colors.index(t, palette) < 0) {
        fits = false;
        break;
      }
    if (fits) {
      indices_.resize(texels_.size());
      for (size_t i = 0; i < texels_.size(); ++i) indices_[i] = uint8_t(colors.index(texels_[i], palette));
      colorPalette_ = std::move(palette);
      paletted_ = true;
      std::vector<Color>().swap(texels_);
      return;
    }
  }
  ChannelPalette channels[3];
  for (const Color& t : texels_)
    for (int c = 0; c < 3; ++c)
      if (channels[c].index(t[c], palette_[size_t(c)]) < 0) return;  // more than 256 values: floats stay
  indices_.resize(3 * texels_.size());
  for (size_t i = 0; i < texels_.size(); ++i)
    for (int c = 0; c < 3; ++c)
      indices_[3 * i + size_t(c)] = uint8_t(channels[c].index(texels_[i][c], palette_[size_t(c)]));
  paletted_ = true;
  std::vector<Color>().swap(texels_);
}

ImageTexture::ImageTexture(int width, int height, const ByteChannels& in, TextureFilter filter,
                           TextureWrap wrapS, TextureWrap wrapT, const Color& scale)
    : width_(width),
      height_(height),
      filter_(filter),
      wrapS_(wrapS),
      wrapT_(wrapT),
      scale_(scale),
      id_(newHitMemoOwner()) {
  const size_t n = size_t(width) * size_t(height);
  // Each channel's palette is its table; a texel's index is its byte (0 for a constant channel).
  for (size_t c = 0; c < 3; ++c) palette_[c] = in.tables[c];
  indices_.resize(3 * n);
  TexelStatistics stats;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* texel = in.bytes + i * size_t(in.stride);
    Color value;
    for (size_t c = 0; c < 3; ++c) {
      const uint8_t b = in.source[c] < 0 ? 0 : texel[in.source[c]];
      indices_[3 * i + c] = b;
      value[int(c)] = palette_[c][b];
    }
    stats.add(value * scale_);
  }
  keepStatistics(stats);
  paletted_ = true;
  // As the float constructor does: one byte per texel where at most 256 colours occur.
  ColorPalette colors;
  std::vector<Color> palette;
  for (size_t i = 0; i < n; ++i)
    if (colors.index(texel(int(i % size_t(width)), int(i / size_t(width))), palette) < 0) return;
  std::vector<uint8_t> single(n);
  for (size_t i = 0; i < n; ++i)
    single[i] = uint8_t(colors.index(texel(int(i % size_t(width)), int(i / size_t(width))), palette));
  indices_ = std::move(single);
  colorPalette_ = std::move(palette);
}

static int wrapIndex(int i, int n, TextureWrap wrap) {
  // Most lookups fall inside the image: no integer division for them (two per coordinate were a
  // third of a bilinear lookup's time).
  if (unsigned(i) < unsigned(n)) return i;
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
  return texelAt(wrapIndex(x, width_, wrapS_), wrapIndex(y, height_, wrapT_));
}

Color ImageTexture::texelAt(int x, int y) const {
  const size_t i = size_t(y) * size_t(width_) + size_t(x);
  if (!paletted_) return texels_[i];
  if (!colorPalette_.empty()) return colorPalette_[indices_[i]];
  const uint8_t* k = &indices_[3 * i];
  return {palette_[0][k[0]], palette_[1][k[1]], palette_[2][k[2]]};
}

Color ImageTexture::eval(Vec2 uv) const {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return Color(0.0f);
  // Finite UVs far outside [0, 1] (a file may hold them, or a texture transform's scale make them)
  // are held within 2^30 texels: a float that large has no fraction left, so any texel is as right
  // as another, and the conversion to int below would overflow (undefined; found by fuzz_gltf).
  constexpr float kMaxTexels = 0x1p30f;
  const float x = std::clamp(uv.x * float(width_), -kMaxTexels, kMaxTexels);
  const float y = std::clamp(uv.y * float(height_), -kMaxTexels, kMaxTexels);
  if (filter_ == TextureFilter::Nearest) {
    return scale_ * texel(int(std::floor(x)), int(std::floor(y)));
  }
  // Bilinear between the four nearest texel centres (centres sit at half-integer coordinates).
  const float fx = x - 0.5f, fy = y - 0.5f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float tx = fx - float(x0), ty = fy - float(y0);
  const int xa = wrapIndex(x0, width_, wrapS_), xb = wrapIndex(x0 + 1, width_, wrapS_);
  const int ya = wrapIndex(y0, height_, wrapT_), yb = wrapIndex(y0 + 1, height_, wrapT_);
  const Color top = glm::mix(texelAt(xa, ya), texelAt(xb, ya), tx);
  const Color bottom = glm::mix(texelAt(xa, yb), texelAt(xb, yb), tx);
  return scale_ * glm::mix(top, bottom, ty);
}

// A bilinear lookup reads four texels through their palettes (ImageTexture::eval 3% of the textured
// scene's render), and Lambertian asks twice per vertex, Phong and the mixed material three times.
Color ImageTexture::evalAt(const SurfaceHit& hit) const {
  return HitMemo<Color, ImageTexture>::at(hit, id_, [&] { return eval(hit.uv); });
}

}  // namespace ember
