// ImageTexture keeps 8-bit images (at most 256 distinct values per channel) as palette indices
// and everything else as floats; either way a lookup must return the texel's value bit for bit.
#include "materials/texture.h"

#include "core/surface_hit.h"
#include "materials/lambertian.h"

#include "core/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
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

// Wrapping as the glTF sampler modes define it, written out plainly: the reference for
// ImageTexture's cheaper forms (one division per axis for repeat).
int referenceWrap(int i, int n, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::Clamp:
      return std::min(std::max(i, 0), n - 1);
    case TextureWrap::Repeat:
      return ((i % n) + n) % n;
    case TextureWrap::Mirror:
      break;
  }
  const int m = ((i % (2 * n)) + 2 * n) % (2 * n);
  return m < n ? m : 2 * n - 1 - m;
}

// Bilinear and nearest lookups equal the formula with every texel coordinate wrapped on its own,
// bit for bit: every wrap mode (each axis its own), images one texel wide and odd sizes, UVs far
// outside the image on either side and on the seams.
TEST(ImageTexture, WrappedLookupsEqualTheReferenceFormula) {
  Rng rng(17, 4);
  const TextureWrap modes[] = {TextureWrap::Clamp, TextureWrap::Repeat, TextureWrap::Mirror};
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{1, 3}, std::pair{2, 5}, std::pair{7, 3}})
    for (const TextureWrap ws : modes)
      for (const TextureWrap wt : modes) {
        std::vector<Color> texels(size_t(w * h));
        for (Color& t : texels) t = Color(rng.uniform(), rng.uniform() * 4.0f, 1000.0f * rng.uniform());
        const ImageTexture bilinear(w, h, texels, TextureFilter::Bilinear, ws, wt, Color(1.0f));
        const ImageTexture nearest(w, h, texels, TextureFilter::Nearest, ws, wt, Color(1.0f));
        const int width = w, height = h;  // clang 14 cannot capture structured bindings
        const auto at = [&](int x, int y) {
          return texels[size_t(referenceWrap(y, height, wt)) * size_t(width) +
                        size_t(referenceWrap(x, width, ws))];
        };
        for (int i = 0; i < 400; ++i) {
          const float range = i % 4 == 0 ? 1e6f : i % 4 == 1 ? 3.0f : 1.0f;
          Vec2 uv(range * (2.0f * rng.uniform() - 1.0f), range * (2.0f * rng.uniform() - 1.0f));
          if (i % 7 == 0) uv = Vec2(float(i % 5 - 2) / float(w), float(i % 3 - 1) / float(h));  // seams
          const float fx = uv.x * float(w) - 0.5f, fy = uv.y * float(h) - 0.5f;
          const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
          const float tx = fx - float(x0), ty = fy - float(y0);
          const Color want = glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), tx),
                                      glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), tx), ty);
          const Color got = bilinear.eval(uv);
          const Color wantNearest = at(int(std::floor(uv.x * float(w))), int(std::floor(uv.y * float(h))));
          const Color gotNearest = nearest.eval(uv);
          for (int c = 0; c < 3; ++c) {
            ASSERT_EQ(bitsOf(got[c]), bitsOf(want[c])) << w << "x" << h << " uv " << uv.x << " " << uv.y;
            ASSERT_EQ(bitsOf(gotNearest[c]), bitsOf(wantNearest[c])) << w << "x" << h;
          }
        }
      }
}

// ImageTexture::evalAt remembers a lookup per hit (materials/hit_memo.h). Whatever a hit's slot
// held before (nothing, the same texture and UV, another UV, another texture, a NaN UV, a texture
// rebuilt at the same address), it must return eval(hit.uv) bit for bit.
TEST(ImageTexture, RememberedLookupsEqualFreshOnes) {
  Rng rng(21, 4);
  const auto randomTexels = [&](int n) {
    std::vector<Color> texels;
    for (int i = 0; i < n; ++i) texels.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
    return texels;
  };
  const ImageTexture first(16, 16, randomTexels(256), TextureFilter::Bilinear, TextureWrap::Repeat);
  const ImageTexture second(16, 16, randomTexels(256), TextureFilter::Nearest, TextureWrap::Mirror);
  const ImageTexture* textures[] = {&first, &second};
  std::vector<SurfaceHit> wave(2048);  // hits side by side, as in a wave
  for (int round = 0; round < 4000; ++round) {
    SurfaceHit& hit = wave[size_t(rng.uniform() * 2047.0f)];
    if (round % 97 == 0)
      hit.uv = Vec2(std::numeric_limits<float>::quiet_NaN(), 0.5f);
    else if (round % 5 != 0)  // else the slot's own UV again
      hit.uv = Vec2(3.0f * rng.uniform() - 1.0f, 3.0f * rng.uniform() - 1.0f);
    const ImageTexture& t = *textures[round % 3 == 0 ? 1 : 0];
    const Color want = t.eval(hit.uv), got = t.evalAt(hit), again = t.evalAt(hit);
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(bitsOf(got[c]), bitsOf(want[c])) << "round " << round;
      ASSERT_EQ(bitsOf(again[c]), bitsOf(want[c])) << "round " << round;
    }
  }
  // Textures built where a freed one lay get their own values, not their predecessor's: the
  // values to expect come from textures that all stay alive.
  SurfaceHit hit;
  hit.uv = Vec2(0.3f, 0.6f);
  std::vector<std::vector<Color>> images;
  std::vector<std::unique_ptr<ImageTexture>> alive;
  for (int k = 0; k < 4; ++k) {
    images.push_back(randomTexels(4));
    alive.push_back(
        std::make_unique<ImageTexture>(2, 2, images.back(), TextureFilter::Nearest, TextureWrap::Clamp));
  }
  std::optional<ImageTexture> reused;
  for (size_t k = 0; k < 4; ++k) {
    reused.emplace(2, 2, images[k], TextureFilter::Nearest, TextureWrap::Clamp);
    const Color want = alive[k]->eval(hit.uv), got = reused->evalAt(hit);
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(bitsOf(got[c]), bitsOf(want[c])) << "texture " << k << " at the address of texture " << k - 1;
  }
}

}  // namespace
}  // namespace ember
