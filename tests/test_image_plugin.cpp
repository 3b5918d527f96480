// The OpenImageIO image plugin (io/image_plugin.h): it loads in the build tree, reads every format
// the built-in readers read to the same texels (stb_image, called here directly, is the oracle),
// reads what they cannot (TIFF at 8, 16 and 32 bits, TX), and turns corrupt files into errors
// that name the file.
#include "cli_runner.h"
#include "io/image_io.h"
#include "io/image_plugin.h"
#include "io/input_error.h"
#include "materials/texture.h"

#include <gtest/gtest.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace ember {
namespace {

using test::TempDir;

const ImagePlugin* pluginOrSkip() {
#ifndef EMBER_HAVE_OIIO
  return nullptr;
#else
  const ImagePlugin* plugin = imagePlugin();
  EXPECT_NE(plugin, nullptr) << imagePluginError();
  return plugin;
#endif
}

#define REQUIRE_PLUGIN(p)                                                                \
  const ImagePlugin* p = pluginOrSkip();                                                 \
  if (!p) {                                                                              \
    if (!HasFailure()) GTEST_SKIP() << "built without OpenImageIO (libopenimageio-dev)"; \
    return;                                                                              \
  }

// A 7 x 5 test card with every 8-bit value somewhere in its channels.
std::vector<uint8_t> card8(int channels) {
  std::vector<uint8_t> px(size_t(7 * 5 * channels));
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t((i * 37 + 11) % 256);
  return px;
}

TEST(ImagePlugin, LoadsAndSaysWhatItIs) {
  REQUIRE_PLUGIN(plugin);
  const std::string what = plugin->describe();
  EXPECT_NE(what.find("OpenImageIO"), std::string::npos) << what;
  EXPECT_NE(what.find("tiff"), std::string::npos) << what;
}

// PNG, TGA and BMP at 8 bits, written by stb_image_write and read by both: the same bytes.
TEST(ImagePlugin, ReadsTheSameBytesAsStbImage) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  for (int channels : {1, 2, 3, 4}) {
    const std::vector<uint8_t> px = card8(channels);
    const std::string stem = "card" + std::to_string(channels);
    ASSERT_TRUE(stbi_write_png(dir.file(stem + ".png").c_str(), 7, 5, channels, px.data(), 7 * channels));
    ASSERT_TRUE(stbi_write_tga(dir.file(stem + ".tga").c_str(), 7, 5, channels, px.data()));
    if (channels >= 3) {
      ASSERT_TRUE(stbi_write_bmp(dir.file(stem + ".bmp").c_str(), 7, 5, channels, px.data()));
    }
    for (const char* ext : {".png", ".tga", ".bmp"}) {
      const std::string path = dir.file(stem + ext);
      if (!std::filesystem::exists(path)) continue;
      int w, h, n;
      std::unique_ptr<uint8_t, decltype(&stbi_image_free)> ref(stbi_load(path.c_str(), &w, &h, &n, 0),
                                                               &stbi_image_free);
      ASSERT_TRUE(ref) << path;
      PluginPixels got;
      ASSERT_EQ(plugin->read(path, 1 << 20, got), "") << path;
      ASSERT_EQ(got.type, PluginPixels::Type::U8) << path;
      ASSERT_EQ(got.width, w);
      ASSERT_EQ(got.height, h);
      // stb expands BMP to 3 or 4 channels as stored; compare the channels both have.
      const int common = std::min(got.channels, n);
      for (size_t p = 0; p < size_t(w * h); ++p)
        for (int c = 0; c < common; ++c)
          ASSERT_EQ(got.u8[p * size_t(got.channels) + size_t(c)], ref.get()[p * size_t(n) + size_t(c)])
              << path << " pixel " << p << " channel " << c;
    }
  }
}

// Radiance HDR: the same floats (both decode RGBE exactly).
TEST(ImagePlugin, ReadsTheSameHdrFloatsAsStbImage) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  std::vector<float> px(7 * 5 * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = 0.01f * float(i * i % 97) + 1e-3f;
  const std::string path = dir.file("card.hdr");
  ASSERT_TRUE(stbi_write_hdr(path.c_str(), 7, 5, 3, px.data()));
  int w, h, n;
  std::unique_ptr<float, decltype(&stbi_image_free)> ref(stbi_loadf(path.c_str(), &w, &h, &n, 0),
                                                         &stbi_image_free);
  ASSERT_TRUE(ref);
  PluginPixels got;
  ASSERT_EQ(plugin->read(path, 1 << 20, got), "");
  ASSERT_EQ(got.type, PluginPixels::Type::F32);
  ASSERT_EQ(got.channels, n);
  for (size_t i = 0; i < got.f32.size(); ++i) ASSERT_FLOAT_EQ(got.f32[i], ref.get()[i]) << i;
}

// JPEG decoders may differ in their inverse DCT's rounding (the standard allows it): libjpeg's
// and stb's pixels agree within a few levels.
TEST(ImagePlugin, ReadsJpegWithinTheDecodersRounding) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  std::vector<uint8_t> px(64 * 48 * 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) px[size_t((y * 64 + x) * 3 + c)] = uint8_t((x * 4 + y * 2 + c * 60) % 256);
  const std::string path = dir.file("card.jpg");
  ASSERT_TRUE(stbi_write_jpg(path.c_str(), 64, 48, 3, px.data(), 95));
  int w, h, n;
  std::unique_ptr<uint8_t, decltype(&stbi_image_free)> ref(stbi_load(path.c_str(), &w, &h, &n, 3),
                                                           &stbi_image_free);
  ASSERT_TRUE(ref);
  PluginPixels got;
  ASSERT_EQ(plugin->read(path, 1 << 20, got), "");
  ASSERT_EQ(got.channels, 3);
  int worst = 0;
  for (size_t i = 0; i < got.u8.size(); ++i)
    worst = std::max(worst, std::abs(int(got.u8[i]) - int(ref.get()[i])));
  EXPECT_LE(worst, 3);
}

// What only OpenImageIO reads: TIFF at 8, 16 and 32 bits and a MIP-mapped TX, through
// readTexture, decoded as the built-in readers decode (sRGB for integers, floats kept).
TEST(ImagePlugin, ReadsTiffAndTxAtEveryDepth) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  PluginPixels u8{7, 5, 3, PluginPixels::Type::U8, card8(3), {}, {}, {}, {}};
  PluginPixels u16{7, 5, 3, PluginPixels::Type::U16, {}, {}, {}, {}, {}};
  PluginPixels f32{7, 5, 3, PluginPixels::Type::F32, {}, {}, {}, {}, {}};
  for (size_t i = 0; i < 7 * 5 * 3; ++i) {
    u16.u16.push_back(uint16_t((i * 2749 + 5) % 65536));
    f32.f32.push_back(0.37f * float(i) - 1.5f);
  }
  struct Case {
    std::string name;
    const PluginPixels* px;
  };
  for (const Case& c : {Case{"u8.tif", &u8}, Case{"u16.tif", &u16}, Case{"f32.tif", &f32}, Case{"u8.tx", &u8},
                        Case{"f32.tx", &f32}}) {
    const std::string path = dir.file(c.name);
    ASSERT_EQ(plugin->write(path, *c.px), "") << path;
    const TextureImage tex = readTexture(path, ColorEncoding::Auto);
    ASSERT_EQ(tex.width, 7) << path;
    ASSERT_EQ(tex.height, 5) << path;
    for (size_t p = 0; p < 35; ++p)
      for (int ch = 0; ch < 3; ++ch) {
        const size_t i = p * 3 + size_t(ch);
        const float want = c.px->type == PluginPixels::Type::U8 ? decodeSrgb(float(c.px->u8[i]) / 255.0f)
                           : c.px->type == PluginPixels::Type::U16
                               ? decodeSrgb(float(c.px->u16[i]) / 65535.0f)
                               : std::max(c.px->f32[i], 0.0f);
        ASSERT_EQ(tex.texels[p][ch], want) << path << " texel " << p << " channel " << ch;
      }
  }
}

TEST(ImagePlugin, CorruptAndTruncatedFilesAreErrorsNamingTheFile) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  const std::vector<uint8_t> px = card8(3);
  const std::string good = dir.file("good.png");
  ASSERT_TRUE(stbi_write_png(good.c_str(), 7, 5, 3, px.data(), 21));
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string truncated = dir.write("truncated.png", bytes.substr(0, bytes.size() / 2));
  const std::string garbage = dir.write("garbage.tif", "II*\0this is not a tiff file at all");
  for (const std::string& path : {truncated, garbage}) {
    try {
      readTexture(path, ColorEncoding::Auto);
      ADD_FAILURE() << path << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(ImagePlugin, RefusesImagesLargerThanTheLimitBeforeReadingThem) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  const std::vector<uint8_t> px = card8(3);
  const std::string path = dir.file("card.png");
  ASSERT_TRUE(stbi_write_png(path.c_str(), 7, 5, 3, px.data(), 21));
  PluginPixels got;
  EXPECT_NE(plugin->read(path, 34, got).find("larger than"), std::string::npos);
  EXPECT_TRUE(got.u8.empty());
}

}  // namespace
}  // namespace ember
