// EXR round trip with metadata, atomic writes, and texture decoding.
#include "cli_runner.h"
#include "io/image_io.h"
#include "io/input_error.h"
#include "materials/texture.h"
#include "test_paths.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <half.h>
#include <stb_image_write.h>

#include <cstring>
#include <fstream>

namespace ember {
namespace {

using test::TempDir;

TEST(ImageIo, ExrRoundTripIsExactAndCarriesMetadata) {
  TempDir dir;
  Image img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) img.set(x, y, Color(x * 0.37f, y * 12.5f, 1e-5f * float(x + y)));
  const std::string path = dir.file("a.exr");
  writeExr(path, img, {{"ember:spp", "17"}});
  const Image back = readImageRgb(path);
  ASSERT_EQ(back.width, 5);
  ASSERT_EQ(back.height, 3);
  EXPECT_EQ(back.rgb, img.rgb);  // float32, lossless compression: bit-exact
  EXPECT_EQ(readStringMetadata(path), (Metadata{{"ember:spp", "17"}}));
  // What other tools see: float R, G, B, and the metadata as a string attribute.
  Imf::InputFile in(path.c_str());
  const auto* spp = in.header().findTypedAttribute<Imf::StringAttribute>("ember:spp");
  ASSERT_NE(spp, nullptr);
  EXPECT_EQ(spp->value(), "17");
  int channels = 0;
  for (auto c = in.header().channels().begin(); c != in.header().channels().end(); ++c, ++channels)
    EXPECT_EQ(c.channel().type, Imf::FLOAT) << c.name();
  EXPECT_EQ(channels, 3);
  EXPECT_NE(in.header().channels().findChannel("R"), nullptr);
  EXPECT_NE(in.header().channels().findChannel("B"), nullptr);
  // Only the final file is left: the temporary was renamed.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path), {}), 1);
}

TEST(ImageIo, FailedWriteLeavesNothing) {
  TempDir dir;
  EXPECT_ANY_THROW(writeExr(dir.file("missing/sub/a.exr"), Image(2, 2)));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path));
}

TEST(ImageIo, CheckerTextureDecodesFromSrgbAsTheReferenceDoes) {
  const TextureImage t = readTexture(test::sourcePath("scenes/checker.png"), ColorEncoding::Auto);
  ASSERT_EQ(t.width, 512);
  ASSERT_EQ(t.height, 512);
  ImageTexture tex(t.width, t.height, t.texels, TextureFilter::Nearest, TextureWrap::Clamp);
  // ../shared/refs/CONVENTIONS.md item 15: light = 0.7912979, dark = (0.0103298, 0.0103298, 0.0742136).
  const Color light = tex.eval(Vec2(0.01f, 0.01f));
  const Color dark = tex.eval(Vec2(0.125f + 0.01f, 0.01f));
  EXPECT_NEAR(light.x, 0.7912979f, 1e-6f);
  EXPECT_NEAR(dark.x, 0.0103298f, 1e-6f);
  EXPECT_NEAR(dark.z, 0.0742136f, 1e-6f);
  // Row 0 is the top of the file and v is not flipped: (col 0, row 1) is dark.
  EXPECT_NEAR(tex.eval(Vec2(0.01f, 0.126f)).x, 0.0103298f, 1e-6f);
  // Clamp: outside [0, 1] repeats the edge texel.
  EXPECT_EQ(tex.eval(Vec2(-3.0f, -3.0f)), light);
}

TEST(ImageIo, BilinearAndWrapModes) {
  std::vector<Color> texels{Color(0.0f), Color(1.0f)};  // 2 x 1
  ImageTexture repeat(2, 1, texels, TextureFilter::Bilinear, TextureWrap::Repeat);
  EXPECT_NEAR(repeat.eval(Vec2(0.25f, 0.5f)).x, 0.0f, 1e-6f);  // texel centre
  EXPECT_NEAR(repeat.eval(Vec2(0.5f, 0.5f)).x, 0.5f, 1e-6f);   // halfway between centres
  EXPECT_NEAR(repeat.eval(Vec2(1.0f, 0.5f)).x, 0.5f, 1e-6f);   // wraps to texel 0
  ImageTexture clamp(2, 1, texels, TextureFilter::Bilinear, TextureWrap::Clamp);
  EXPECT_NEAR(clamp.eval(Vec2(1.0f, 0.5f)).x, 1.0f, 1e-6f);
  ImageTexture mirror(2, 1, texels, TextureFilter::Nearest, TextureWrap::Mirror);
  EXPECT_NEAR(mirror.eval(Vec2(1.25f, 0.5f)).x, 1.0f, 1e-6f);  // mirrored: texel 1
}

TEST(ImageIo, MissingAndCorruptTexturesAreInputErrors) {
  TempDir dir;
  EXPECT_THROW(readTexture(dir.file("none.png"), ColorEncoding::Auto), InputError);
  const std::string bad = dir.write("bad.png", "this is not a png");
  EXPECT_THROW(readTexture(bad, ColorEncoding::Auto), InputError);
}

// An EXR of half-float channels `names` (values[c] for channel c, row by row) over a data window
// that does not start at the origin, as other tools write them.
void writeHalfExr(const std::string& path, const std::vector<std::string>& names,
                  const std::vector<std::vector<float>>& values, int width, int height) {
  const Imath::Box2i window({10, 20}, {10 + width - 1, 20 + height - 1});
  Imf::Header header(window, window);
  for (const auto& name : names) header.channels().insert(name, Imf::Channel(Imf::HALF));
  std::vector<std::vector<half>> planes;
  for (const auto& v : values) planes.emplace_back(v.begin(), v.end());
  Imf::FrameBuffer frame;
  for (size_t c = 0; c < names.size(); ++c)
    frame.insert(names[c], Imf::Slice::Make(Imf::HALF, planes[c].data(), window));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(height);
}

TEST(ImageIo, ExrFromOtherToolsHalfGreyAndOffsetWindows) {
  TempDir dir;
  // Half floats over a window at (10, 20): values exact in half, read linear (no sRGB decoding).
  const std::string rgb = dir.file("rgb.exr");
  writeHalfExr(rgb, {"R", "G", "B", "A"},
               {{0.5f, 2.0f, 0.25f}, {1.0f, 0.0f, 3.0f}, {0.125f, 8.0f, 1.5f}, {1, 1, 1}}, 3, 1);
  const TextureImage t = readTexture(rgb, ColorEncoding::Auto);
  ASSERT_EQ(t.width, 3);
  ASSERT_EQ(t.height, 1);
  EXPECT_EQ(t.texels[0], Color(0.5f, 1.0f, 0.125f));
  EXPECT_EQ(t.texels[1], Color(2.0f, 0.0f, 8.0f));
  EXPECT_EQ(t.texels[2], Color(0.25f, 3.0f, 1.5f));
  // Luminance alone is grey; a file without G reads it as 0.
  const std::string grey = dir.file("y.exr");
  writeHalfExr(grey, {"Y"}, {{0.75f, 4.0f}}, 1, 2);
  const Image g = readImageRgb(grey);
  ASSERT_EQ(g.height, 2);
  EXPECT_EQ(g.at(0, 1), Color(4.0f));
  const std::string rb = dir.file("rb.exr");
  writeHalfExr(rb, {"R", "B"}, {{1.0f}, {2.0f}}, 1, 1);
  EXPECT_EQ(readImageRgb(rb).at(0, 0), Color(1.0f, 0.0f, 2.0f));
  EXPECT_TRUE(readStringMetadata(rb).empty() || readStringMetadata(rb)[0].first != "ember:spp");
}

TEST(ImageIo, IntegerFormatsDecodeFromSrgbAndHdrStaysLinear) {
  TempDir dir;
  // 8-bit PNG, BMP and TGA: exact bytes, decoded from sRGB by Auto, kept by Linear.
  const uint8_t rgb[6] = {0, 128, 255, 64, 32, 16};
  for (const char* name : {"a.png", "a.bmp", "a.tga"}) {
    const std::string path = dir.file(name);
    const std::string ext = std::filesystem::path(path).extension().string();
    const int ok = ext == ".png"   ? stbi_write_png(path.c_str(), 2, 1, 3, rgb, 6)
                   : ext == ".bmp" ? stbi_write_bmp(path.c_str(), 2, 1, 3, rgb)
                                   : stbi_write_tga(path.c_str(), 2, 1, 3, rgb);
    ASSERT_TRUE(ok) << name;
    const TextureImage lin = readTexture(path, ColorEncoding::Linear);
    EXPECT_EQ(lin.texels[0], Color(0.0f, 128.0f / 255.0f, 1.0f)) << name;
    EXPECT_EQ(lin.texels[1], Color(64.0f, 32.0f, 16.0f) / 255.0f) << name;
    const TextureImage srgb = readTexture(path, ColorEncoding::Auto);
    EXPECT_NEAR(srgb.texels[0].y, srgbToLinear(128.0f / 255.0f), 1e-7f) << name;
  }
  // 16 bits per channel, grey (tests/data/images/grey16.png: rows 0, 65535 and 1000, 40000).
  const TextureImage g16 =
      readTexture(test::sourcePath("tests/data/images/grey16.png"), ColorEncoding::Linear);
  ASSERT_EQ(g16.width, 2);
  ASSERT_EQ(g16.height, 2);
  EXPECT_EQ(g16.texels[1], Color(1.0f));
  EXPECT_EQ(g16.texels[2], Color(1000.0f / 65535.0f));
  EXPECT_EQ(g16.texels[3], Color(40000.0f / 65535.0f));
  // Radiance HDR is linear under Auto; these values survive its shared exponent exactly.
  const float hdr[6] = {0.5f, 0.25f, 0.125f, 8.0f, 4.0f, 2.0f};
  const std::string path = dir.file("a.hdr");
  ASSERT_TRUE(stbi_write_hdr(path.c_str(), 2, 1, 3, hdr));
  const TextureImage h = readTexture(path, ColorEncoding::Auto);
  EXPECT_EQ(h.texels[0], Color(0.5f, 0.25f, 0.125f));
  EXPECT_EQ(h.texels[1], Color(8.0f, 4.0f, 2.0f));
  // The PNG writer's output reads back byte for byte.
  const std::string png = dir.file("out.png");
  writePng(png, 2, 1, std::vector<uint8_t>(rgb, rgb + 6));
  EXPECT_EQ(readTexture(png, ColorEncoding::Linear).texels[1], Color(64.0f, 32.0f, 16.0f) / 255.0f);
}

// A PFM file: its rows bottom-up, its floats in the byte order its scale's sign gives.
std::string pfm(const char* magic, int width, int height, bool littleEndian,
                const std::vector<float>& bottomUp) {
  std::string s = std::string(magic) + "\n" + std::to_string(width) + " " + std::to_string(height) + "\n" +
                  (littleEndian ? "-1.0" : "1.0") + "\n";
  for (const float v : bottomUp) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int k = 0; k < 4; ++k) s += char(littleEndian ? bits >> (8 * k) : bits >> (8 * (3 - k)));
  }
  return s;
}

TEST(ImageIo, PfmBothByteOrdersRowsFromTheBottom) {
  TempDir dir;
  for (const bool little : {true, false}) {
    // 1 x 2 RGB: the bottom row (written first) is (1, 2, 3), the top one (0.5, 0.25, 1e-3).
    const std::string rgb =
        dir.write("rgb.pfm", pfm("PF", 1, 2, little, {1.0f, 2.0f, 3.0f, 0.5f, 0.25f, 1e-3f}));
    const TextureImage t = readTexture(rgb, ColorEncoding::Auto);  // linear: a float format
    ASSERT_EQ(t.width, 1);
    ASSERT_EQ(t.height, 2);
    EXPECT_EQ(t.texels[0], Color(0.5f, 0.25f, 1e-3f)) << little;
    EXPECT_EQ(t.texels[1], Color(1.0f, 2.0f, 3.0f)) << little;
    const std::string grey = dir.write("grey.pfm", pfm("Pf", 2, 1, little, {7.0f, 0.125f}));
    EXPECT_EQ(readImageRgb(grey).at(1, 0), Color(0.125f)) << little;
  }
  // A file shorter than its header says, and a header without a size.
  std::string cut = pfm("PF", 4, 4, true, std::vector<float>(47, 1.0f));
  EXPECT_THROW(readTexture(dir.write("cut.pfm", cut), ColorEncoding::Auto), InputError);
  EXPECT_THROW(readTexture(dir.write("bad.pfm", "PF\nx y\n-1\n"), ColorEncoding::Auto), InputError);
  EXPECT_THROW(readTexture(dir.write("huge.pfm", "PF\n-3 2\n-1\n"), ColorEncoding::Auto), InputError);
}

TEST(ImageIo, HeadersClaimingHugeImagesAreRejectedBeforeAllocating) {
  TempDir dir;
  // A PNG signature, an IHDR chunk of 20000 x 20000 grey (within stb_image's own limit of 2^30
  // bytes) and an empty IDAT, with the chunks' CRCs right: libpng, under OpenImageIO, checks them and
  // reads up to the first IDAT before the size reaches Ember.
  const auto chunk = [](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    uint32_t crc = 0xffffffffu;  // CRC-32 (ISO 3309), as PNG defines it
    for (unsigned char byte : body) {
      crc ^= byte;
      for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    crc ^= 0xffffffffu;
    std::string out;
    for (int shift = 24; shift >= 0; shift -= 8) out += char((data.size() >> shift) & 0xffu);
    out += body;
    for (int shift = 24; shift >= 0; shift -= 8) out += char((crc >> shift) & 0xffu);
    return out;
  };
  const std::string png = "\x89PNG\r\n\x1a\n" +
                          chunk("IHDR", std::string("\0\0\x4e\x20\0\0\x4e\x20\x08\0\0\0\0", 13)) +
                          chunk("IDAT", "");
  const std::string big = dir.write("big.png", png);
  const std::string pfmBig = dir.write("big.pfm", "PF\n100000 100000\n-1\n");
  for (const std::string& path : {big, pfmBig}) {
    try {
      readTexture(path, ColorEncoding::Auto);
      ADD_FAILURE() << path << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("larger than Ember reads"), std::string::npos) << e.what();
    }
  }
}

TEST(ImageIo, ExrAttributeLargerThanTheFileIsRejected) {
  TempDir dir;
  const std::string path = dir.file("a.exr");
  writeExr(path, Image(2, 2), {{"ember:note", "abc"}});
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  const std::string key("ember:note\0string\0", 18);
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const int32_t huge = 0x7fffffff;  // OpenEXR would allocate this before finding the file short
  std::memcpy(&bytes[at + key.size()], &huge, 4);
  const std::string bad = dir.write("bad.exr", bytes);
  try {
    readImageRgb(bad);
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'ember:note' declares 2147483647 bytes"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(readStringMetadata(bad), InputError);
}

TEST(ImageIo, CorruptAndTruncatedImagesNameTheFile) {
  TempDir dir;
  // An EXR's magic number followed by garbage, and a PNG cut in half.
  const std::string exr = dir.write("bad.exr", std::string("\x76\x2f\x31\x01", 4) + std::string(100, 'x'));
  const std::string cut = dir.file("cut.png");
  {
    const std::string whole = dir.file("whole.png");
    std::vector<uint8_t> px(64 * 64 * 3, 200);
    ASSERT_TRUE(stbi_write_png(whole.c_str(), 64, 64, 3, px.data(), 64 * 3));
    std::ifstream in(whole, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    dir.write("cut.png", bytes.substr(0, bytes.size() / 2));
  }
  for (const std::string& path : {exr, cut}) {
    try {
      readImageRgb(path);
      ADD_FAILURE() << path << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_THROW(readTexture(path, ColorEncoding::Auto), InputError) << path;
    EXPECT_THROW(readStringMetadata(path), InputError) << path;
  }
}

}  // namespace
}  // namespace ember
