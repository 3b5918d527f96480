// EXR round trip with metadata, atomic writes, and texture decoding.
#include "cli_runner.h"
#include "io/image_io.h"
#include "io/input_error.h"
#include "materials/texture.h"
#include "test_paths.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

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
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("ember:spp"), "17");
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(in->spec().nchannels, 3);
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

}  // namespace
}  // namespace ember
