// Colour textures looked up by surface UV. Image lookup follows ../shared/refs/CONVENTIONS.md:
// texel column = floor(u * width), row = floor(v * height), row 0 = the first (top) row of the file,
// no v flip (glTF uses the same convention). Texel values are stored linear.
#pragma once

#include "core/math.h"
#include "core/surface_hit.h"

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace ember {

class Texture {
 public:
  virtual ~Texture() = default;
  virtual Color eval(Vec2 uv) const = 0;
  // eval(hit.uv) for a material shading `hit`, which asks more than once per vertex: textures
  // whose lookup costs more than a memo's check remember it per hit (materials/hit_memo.h).
  virtual Color evalAt(const SurfaceHit& hit) const { return eval(hit.uv); }
  // evalAt without the per-hit memo, for a caller that remembers the whole vertex's inputs itself
  // (GltfPbrMaterial::fetchFor): a second memo under it would only cost its check and store.
  // Filtered over the hit's footprint where the texture filters (SurfaceHit::uvFootprint).
  virtual Color evalFresh(const SurfaceHit& hit) const {
    return evalFootprint(hit.texCoord(texCoordSet()), hit.uvFootprint);
  }
  // The texture over a footprint `width` wide in UV units; textures that do not filter ignore it.
  virtual Color evalFootprint(Vec2 uv, float /*width*/) const { return eval(uv); }
  // Largest value the texture can return per channel (used for sampling decisions).
  virtual Color maxValue() const = 0;
  // Smallest value it can return per channel (whether a roughness map reaches 0 somewhere).
  virtual Color minValue() const = 0;
  // Mean over the texture's area.
  virtual Color average() const = 0;
  // The same value at every uv.
  virtual bool isConstant() const { return false; }
  // Whether eval can return black (every channel zero) at some uv; false only where it cannot.
  virtual bool mayBeBlack() const { return true; }
  // The set of texture coordinates eval expects (glTF textureInfo.texCoord): callers without a
  // hit (a light sample, Embree's alpha filter) interpolate that set themselves.
  virtual int texCoordSet() const { return 0; }
};

class ConstantTexture final : public Texture {
 public:
  explicit ConstantTexture(const Color& c) : value_(c) {}
  Color eval(Vec2) const override { return value_; }
  Color evalAt(const SurfaceHit&) const override { return value_; }
  Color evalFresh(const SurfaceHit&) const override { return value_; }
  Color maxValue() const override { return value_; }
  Color minValue() const override { return value_; }
  Color average() const override { return value_; }
  bool isConstant() const override { return true; }
  bool mayBeBlack() const override { return isBlack(value_); }

 private:
  Color value_;
};

// What an image texture reports of its scaled texels (maxValue, minValue, average, mayBeBlack),
// gathered texel by texel in the image's order (inline: it runs per texel at load). Every lookup
// (nearest, bilinear, a MIP level's box filter) is a convex blend of texels, so their bounds hold.
struct TexelStatistics {
  Color max{0.0f}, min{std::numeric_limits<float>::infinity()}, sum{0.0f};
  size_t count = 0;
  // Some scaled texel is black or has a negative channel (whose blend with another texel could
  // then be black): a blend of texels with neither always has a positive channel.
  bool mayBeBlack = false;
  void add(const Color& scaled) {
    max = glm::max(max, scaled);
    min = glm::min(min, scaled);
    sum += scaled;
    ++count;
    const bool positive = scaled.x > 0.0f || scaled.y > 0.0f || scaled.z > 0.0f;
    const bool negative = scaled.x < 0.0f || scaled.y < 0.0f || scaled.z < 0.0f;
    mayBeBlack = mayBeBlack || !positive || negative;
  }
  Color average() const { return count ? sum / float(count) : Color(0.0f); }
  Color minimum() const { return count ? min : Color(0.0f); }
};

enum class TextureFilter { Nearest, Bilinear };
enum class TextureWrap { Clamp, Repeat, Mirror };

class ImageTexture final : public Texture {
 public:
  ImageTexture(int width, int height, std::vector<Color> texels, TextureFilter filter, TextureWrap wrap,
               const Color& scale = Color(1.0f))
      : ImageTexture(width, height, std::move(texels), filter, wrap, wrap, scale) {}
  // wrapS applies along u (columns), wrapT along v (rows), as glTF samplers define them.
  ImageTexture(int width, int height, std::vector<Color> texels, TextureFilter filter, TextureWrap wrapS,
               TextureWrap wrapT, const Color& scale = Color(1.0f));
  // An 8-bit image read through a table per channel, without a float copy of it: channel c of
  // texel i is tables[c][bytes[i * stride + source[c]]], or tables[c][0] where source[c] < 0. The
  // texture then equals the one built from those floats, value for value, in a quarter of the
  // memory traffic (most of a textured glTF file's load time went to the float copies).
  struct ByteChannels {
    const uint8_t* bytes = nullptr;
    int stride = 0;
    std::array<int, 3> source{};
    std::array<std::array<float, 256>, 3> tables{};
  };
  ImageTexture(int width, int height, const ByteChannels& in, TextureFilter filter, TextureWrap wrapS,
               TextureWrap wrapT, const Color& scale = Color(1.0f));
  // Not copied or moved: evalAt's memo keys the texture's values by its id (materials/hit_memo.h).
  ImageTexture(const ImageTexture&) = delete;
  ImageTexture& operator=(const ImageTexture&) = delete;
  Color eval(Vec2 uv) const override;
  Color evalAt(const SurfaceHit& hit) const override;
  // Its coordinates are always set 0 (TexCoordSetTexture wraps it for the others), and it does
  // not filter: the lookup at hit.uv, without evalFootprint's call.
  Color evalFresh(const SurfaceHit& hit) const override { return eval(hit.uv); }
  Color maxValue() const override { return max_; }
  Color minValue() const override { return min_; }
  Color average() const override { return average_; }
  bool mayBeBlack() const override { return mayBeBlack_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // Whether the texels are kept as palette indices (see below).
  bool paletted() const { return paletted_; }
  // Memory per texel: 1 byte (a colour palette), 3 (per-channel palettes) or 12 (floats).
  int bytesPerTexel() const { return !paletted_ ? 12 : colorPalette_.empty() ? 3 : 1; }

 private:
  Color texel(int x, int y) const;    // (x, y) wrapped into the image first
  Color texelAt(int x, int y) const;  // (x, y) inside the image
  void keepStatistics(const TexelStatistics& stats) {
    max_ = stats.max;
    min_ = stats.minimum();
    average_ = stats.average();
    mayBeBlack_ = stats.mayBeBlack;
  }

  int width_, height_;
  // Texels of at most 256 distinct values per channel (every 8-bit image, whatever its encoding)
  // are kept as one byte per channel into a per-channel palette of their exact floats: a quarter of
  // the memory and of the cache misses of incoherent lookups, and the same values bit for bit.
  // Images of at most 256 distinct colours (indexed images, masks, checkerboards) keep one byte
  // per texel into a palette of whole colours, a third of that again. Other images (HDR, 16-bit)
  // keep their floats in texels_.
  std::vector<Color> texels_;
  std::vector<uint8_t> indices_;  // 3 per texel (per-channel palettes) or 1 (a colour palette)
  std::array<std::array<float, 256>, 3> palette_{};
  std::vector<Color> colorPalette_;  // the colour palette's colours, when it is used
  bool paletted_ = false;
  TextureFilter filter_;
  TextureWrap wrapS_, wrapT_;
  Color scale_;
  Color max_{0.0f}, min_{0.0f}, average_{0.0f};
  // Some scaled texel is black or has a negative channel (whose bilinear blend with another texel
  // could then be black): a blend of texels with neither always has a positive channel.
  bool mayBeBlack_ = false;
  uint64_t id_;  // evalAt's memo key: newHitMemoOwner()
};

// KHR_texture_transform: looks `inner` up at uv' = T R S uv (the extension's matrix: offset, then a
// rotation by `rotation` radians counter-clockwise in UV space, then scale).
class UvTransformTexture final : public Texture {
 public:
  UvTransformTexture(std::shared_ptr<const Texture> inner, Vec2 offset, float rotation, Vec2 scale)
      : inner_(std::move(inner)),
        offset_(offset),
        row0_(std::cos(rotation) * scale.x, std::sin(rotation) * scale.y),
        row1_(-std::sin(rotation) * scale.x, std::cos(rotation) * scale.y),
        widthScale_(std::sqrt(std::abs(scale.x * scale.y))) {}
  Color eval(Vec2 uv) const override { return inner_->eval(map(uv)); }
  // A footprint scales with the map's mean stretch, sqrt|det|.
  Color evalFootprint(Vec2 uv, float width) const override {
    return inner_->evalFootprint(map(uv), width * widthScale_);
  }
  Color maxValue() const override { return inner_->maxValue(); }
  Color minValue() const override { return inner_->minValue(); }
  Color average() const override { return inner_->average(); }
  bool mayBeBlack() const override { return inner_->mayBeBlack(); }

 private:
  Vec2 map(Vec2 uv) const { return Vec2(glm::dot(row0_, uv), glm::dot(row1_, uv)) + offset_; }

  std::shared_ptr<const Texture> inner_;
  Vec2 offset_, row0_, row1_;
  float widthScale_;
};

// A texture read with texture coordinate set `set` (glTF's TEXCOORD_n, n > 0): evalAt looks the
// hit's coordinates of that set up; eval takes coordinates of that set already.
class TexCoordSetTexture final : public Texture {
 public:
  TexCoordSetTexture(std::shared_ptr<const Texture> inner, int set) : inner_(std::move(inner)), set_(set) {}
  Color eval(Vec2 uv) const override { return inner_->eval(uv); }
  Color evalAt(const SurfaceHit& hit) const override { return inner_->eval(hit.texCoord(set_)); }
  // The footprint is set 0's (Scene::surfaceHit): an approximation for the other sets.
  Color evalFootprint(Vec2 uv, float width) const override { return inner_->evalFootprint(uv, width); }
  Color maxValue() const override { return inner_->maxValue(); }
  Color minValue() const override { return inner_->minValue(); }
  Color average() const override { return inner_->average(); }
  bool isConstant() const override { return inner_->isConstant(); }
  bool mayBeBlack() const override { return inner_->mayBeBlack(); }
  int texCoordSet() const override { return set_; }

 private:
  std::shared_ptr<const Texture> inner_;
  int set_;
};

// A colour texture times the hit's vertex colour (glTF COLOR_0 on the base colour, section
// 3.9.2). Vertex colours lie in [0, 1], so the inner texture's bounds hold for the product.
class VertexColorTexture final : public Texture {
 public:
  explicit VertexColorTexture(std::shared_ptr<const Texture> inner) : inner_(std::move(inner)) {}
  Color eval(Vec2 uv) const override { return inner_->eval(uv); }
  Color evalFresh(const SurfaceHit& hit) const override {
    return inner_->evalFresh(hit) * Color(hit.vertexColor());
  }
  Color evalAt(const SurfaceHit& hit) const override {
    return inner_->evalAt(hit) * Color(hit.vertexColor());
  }
  Color evalFootprint(Vec2 uv, float width) const override { return inner_->evalFootprint(uv, width); }
  Color maxValue() const override { return inner_->maxValue(); }
  Color minValue() const override { return glm::min(inner_->minValue(), Color(0.0f)); }
  Color average() const override { return inner_->average(); }
  bool mayBeBlack() const override { return true; }
  int texCoordSet() const override { return inner_->texCoordSet(); }

 private:
  std::shared_ptr<const Texture> inner_;
};

// The exact piecewise sRGB EOTF (IEC 61966-2-1) for one channel value in [0, 1].
inline float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
// srgbToLinear, bit for bit, with a table for the values an 8- or 16-bit channel decodes to
// (b / 255, b / 65535): decoding such a texture then costs a lookup per channel instead of a pow
// (most of the time a scene with image textures spent loading them).
float decodeSrgb(float c);
inline float linearToSrgb(float c) {
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

}  // namespace ember
