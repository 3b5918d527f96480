// ImageTexture keeps 8-bit images (at most 256 distinct values per channel) as palette indices
// and everything else as floats; either way a lookup must return the texel's value bit for bit.
#include "materials/texture.h"

#include "core/surface_hit.h"
#include "materials/lambertian.h"

#include "core/rng.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

namespace ember {
namespace {

uint32_t bitsOf(float x) {
  uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

// Every texel read back at its centre, nearest filter, compared bit for bit.
void expectExactTexels(const std::vector<Color>& texels, int width, int height, bool paletted) {
  const ImageTexture texture(width, height, texels, TextureFilter::Nearest, TextureWrap::Clamp);
  ASSERT_EQ(texture.paletted(), paletted);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Color got =
          texture.eval(Vec2((float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height)));
      const Color& want = texels[size_t(y) * size_t(width) + size_t(x)];
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(bitsOf(got[c]), bitsOf(want[c])) << "texel (" << x << ", " << y << ") channel " << c;
    }
  }
}

// The table-backed decoder equals the sRGB formula bit for bit: on the values an 8-bit and a
// 16-bit channel decode to, their float neighbours, and values no table holds.
TEST(Srgb, TableDecodeEqualsTheFormula) {
  auto same = [](float c) {
    const float got = decodeSrgb(c), want = srgbToLinear(c);
    return std::bit_cast<uint32_t>(got) == std::bit_cast<uint32_t>(want) ||
           (std::isnan(got) && std::isnan(want));
  };
  for (int b = 0; b < 256; ++b) {
    const float c = float(b) / 255.0f;
    EXPECT_TRUE(same(c)) << b;
    EXPECT_TRUE(same(std::nextafter(c, 2.0f))) << b;
    EXPECT_TRUE(same(std::nextafter(c, -1.0f))) << b;
  }
  for (int b = 0; b < 65536; ++b) {
    const float c = float(b) / 65535.0f;
    ASSERT_TRUE(same(c)) << b;
    ASSERT_TRUE(same(std::nextafter(c, 2.0f))) << b;
    ASSERT_TRUE(same(std::nextafter(c, -1.0f))) << b;
  }
  Rng rng(3, 1);
  for (int i = 0; i < 100000; ++i) ASSERT_TRUE(same(1.2f * rng.uniform() - 0.1f)) << i;
  for (const float c :
       {-0.0f, 1.0f / 255.0f + 1e-9f, 255.5f / 255.0f, std::numeric_limits<float>::infinity(),
        -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 1e30f, -1e30f})
    EXPECT_TRUE(same(c)) << c;
}

// mayBeBlack is false only where no lookup can be black: a constant colour that is not black, or
// an image none of whose scaled texels is black or has a negative channel (a bilinear blend of a
// positive and a negative texel can be). Lambertian::absorbsAt then holds exactly at black texels.
TEST(ImageTexture, MayBeBlackOnlyWithABlackOrNegativeTexel) {
  EXPECT_FALSE(ConstantTexture(Color(0.5f, 0.0f, 0.0f)).mayBeBlack());
  EXPECT_TRUE(ConstantTexture(Color(0.0f)).mayBeBlack());
  const auto image = [](std::vector<Color> texels, Color scale = Color(1.0f)) {
    return std::make_shared<ImageTexture>(2, 1, std::move(texels), TextureFilter::Bilinear,
                                          TextureWrap::Repeat, scale);
  };
  EXPECT_FALSE(image({Color(0.1f, 0.1f, 0.3f), Color(0.9f)})->mayBeBlack());  // the shared checker's colours
  EXPECT_FALSE(image({Color(0.0f, 0.0f, 0.2f), Color(0.3f, 0.0f, 0.0f)})->mayBeBlack());
  EXPECT_TRUE(image({Color(0.0f), Color(0.9f)})->mayBeBlack());
  EXPECT_TRUE(image({Color(0.5f, -0.5f, 0.0f), Color(-0.5f, 0.5f, 0.0f)})->mayBeBlack());
  EXPECT_TRUE(
      image({Color(0.0f, 0.5f, 0.0f), Color(0.9f)}, Color(1.0f, 0.0f, 1.0f))->mayBeBlack());  // scaled
  EXPECT_TRUE(
      UvTransformTexture(image({Color(0.0f), Color(0.9f)}), Vec2(0.0f), 0.0f, Vec2(1.0f)).mayBeBlack());

  const Lambertian checker(std::make_shared<ImageTexture>(2, 1, std::vector<Color>{Color(0.0f), Color(0.9f)},
                                                          TextureFilter::Nearest, TextureWrap::Repeat));
  SurfaceHit hit;
  hit.uv = Vec2(0.25f, 0.5f);
  EXPECT_TRUE(checker.absorbsAt(hit));
  hit.uv = Vec2(0.75f, 0.5f);
  EXPECT_FALSE(checker.absorbsAt(hit));
  EXPECT_TRUE(Lambertian(std::make_shared<ConstantTexture>(Color(0.0f))).absorbsAt(hit));
  EXPECT_FALSE(Lambertian(std::make_shared<ConstantTexture>(Color(0.2f))).absorbsAt(hit));
}

TEST(ImageTexture, EightBitImagesReadBackExactly) {
  // An sRGB-decoded 8-bit image, each channel in its own order: 256 values per channel, the
  // palette's limit, counting both zeros (-0 and +0 are different bit patterns, so different
  // palette entries).
  const int w = 64, h = 32;
  std::vector<Color> texels(size_t(w * h));
  for (size_t i = 0; i < texels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      texels[i][c] = srgbToLinear(float(1 + (i * size_t(2 * c + 1) + size_t(c)) % 254) / 255.0f);
  texels[7] = Color(-0.0f, 0.0f, -0.0f);
  texels[9] = Color(0.0f, -0.0f, 0.0f);
  expectExactTexels(texels, w, h, true);
}

TEST(ImageTexture, ImagesOfFewColoursKeepOneBytePerTexel) {
  // 256 distinct colours (a checkerboard's two and 254 more; -0 and +0 differ), each channel's
  // values shared between colours: one byte per texel, read back exactly.
  const int w = 64, h = 16;
  std::vector<Color> texels(size_t(w * h));
  for (size_t i = 0; i < texels.size(); ++i) {
    const size_t k = i % 256;
    texels[i] = Color(float(k % 7) / 6.0f, float(k / 7) / 36.0f, (k % 2) ? 0.0f : -0.0f);
  }
  expectExactTexels(texels, w, h, true);
  EXPECT_EQ(ImageTexture(w, h, texels, TextureFilter::Nearest, TextureWrap::Clamp).bytesPerTexel(), 1);
  // A 257th colour whose channels are all values seen before: per-channel palettes, still exact.
  texels[300] =
      Color(texels[1].r, texels[7].g, texels[1].b);  // (1/6, 1/36, +0): only k = 8 has the first two, with -0
  ASSERT_NE(bitsOf(texels[300].g), bitsOf(texels[1].g));
  expectExactTexels(texels, w, h, true);
  EXPECT_EQ(ImageTexture(w, h, texels, TextureFilter::Nearest, TextureWrap::Clamp).bytesPerTexel(), 3);
}

TEST(ImageTexture, HighDynamicRangeImagesReadBackExactly) {
  // 257 distinct values in one channel: beyond a palette, kept as floats.
  const int w = 257, h = 3;
  std::vector<Color> texels(size_t(w * h), Color(0.25f));
  for (int x = 0; x < w; ++x) texels[size_t(x)].g = 1.0f + float(x) * 0.37f;
  expectExactTexels(texels, w, h, false);
  // Random floats everywhere.
  Rng rng(9, 2);
  std::vector<Color> noise(size_t(40 * 40));
  for (Color& c : noise) c = Color(rng.uniform(), 100.0f * rng.uniform(), rng.uniform() - 0.5f);
  expectExactTexels(noise, 40, 40, false);
}

TEST(ImageTexture, BilinearLookupsAgreeBetweenPaletteAndFloats) {
  // The same 8-bit image once as it is (paletted) and once with one extra value far away (which
  // forces floats for the whole image): every lookup away from that texel must be equal.
  const int w = 300, h = 2;
  std::vector<Color> small(size_t(w * h));
  for (size_t i = 0; i < small.size(); ++i)
    small[i] = Color(float(i % 256) / 255.0f, float((i * 7) % 256) / 255.0f, 0.5f);
  std::vector<Color> wide = small;
  for (int k = 0; k < 2; ++k) wide[size_t(k * w + w - 1)].r = 3.0f + float(k);  // 257th value of red
  const ImageTexture a(w, h, small, TextureFilter::Bilinear, TextureWrap::Repeat);
  const ImageTexture b(w, h, wide, TextureFilter::Bilinear, TextureWrap::Repeat);
  ASSERT_TRUE(a.paletted());
  ASSERT_FALSE(b.paletted());
  Rng rng(3, 3);
  for (int i = 0; i < 2000; ++i) {
    // Clear of the last column, which a lookup near u = 0 also reads when it wraps.
    const Vec2 uv(0.05f + 0.85f * rng.uniform(), 4.0f * rng.uniform() - 2.0f);
    const Color ca = a.eval(uv), cb = b.eval(uv);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(bitsOf(ca[c]), bitsOf(cb[c])) << "uv " << uv.x << " " << uv.y;
  }
}

}  // namespace
}  // namespace ember
