// Reinhard et al. 2002 global operator against hand-computed values.
#include "io/tonemap.h"
#include "materials/texture.h"

#include <gtest/gtest.h>

namespace ember {
namespace {

TEST(Tonemap, ReinhardMatchesHandComputedValues) {
  // Two grey pixels of luminance 1 and 4: log-average = sqrt(1 * 4) = 2, so with key 0.18 the
  // scale is 0.09: L = 0.09 and 0.36. White defaults to the maximum (4 -> 0.36), so
  // Ld(0.36) = 0.36 (1 + 0.36 / 0.36^2) / 1.36 = 1 and Ld(0.09) = 0.09 (1 + 0.09 / 0.1296) / 1.09.
  Image img(2, 1);
  img.set(0, 0, Color(1.0f));
  img.set(1, 0, Color(4.0f));
  float logAvg = 0.0f, white = 0.0f;
  const Image out = reinhardLinear(img, ReinhardParams{}, &logAvg, &white);
  EXPECT_NEAR(logAvg, 2.0f, 1e-5f);
  EXPECT_FLOAT_EQ(white, 4.0f);
  const float expectedDark = 0.09f * (1.0f + 0.09f / 0.1296f) / 1.09f;
  EXPECT_NEAR(out.at(0, 0).x, expectedDark, 1e-5f);
  EXPECT_NEAR(out.at(1, 0).x, 1.0f, 1e-5f);

  const ReinhardResult r = tonemapReinhard(img, ReinhardParams{});
  EXPECT_EQ(r.rgb8[3], 255);
  EXPECT_EQ(r.rgb8[0], uint8_t(std::lround(255.0f * linearToSrgb(expectedDark))));
}

// A model on an empty black background: the key is the model's. Two pixels of luminance 1 and 4
// among 98 black ones give the same log-average (2) and the same display values as the two alone,
// where averaging the black pixels in (log delta = -13.8 each) would scale the model up ~10^5 times
// and blow it out to white.
TEST(Tonemap, BlackBackgroundDoesNotSetTheKey) {
  Image alone(2, 1), onBlack(10, 10);
  alone.set(0, 0, Color(1.0f));
  alone.set(1, 0, Color(4.0f));
  onBlack.set(3, 4, Color(1.0f));
  onBlack.set(6, 5, Color(4.0f));
  float a = 0.0f, b = 0.0f;
  const Image x = reinhardLinear(alone, ReinhardParams{}, &a),
              y = reinhardLinear(onBlack, ReinhardParams{}, &b);
  EXPECT_NEAR(b, 2.0f, 1e-5f);
  EXPECT_EQ(a, b);
  EXPECT_EQ(x.at(0, 0), y.at(3, 4));
  EXPECT_EQ(x.at(1, 0), y.at(6, 5));
  EXPECT_LT(y.at(3, 4).x, 0.2f) << "the dim pixel keeps a dim display value";
}

TEST(Tonemap, KeyAndWhiteAreHonoured) {
  Image img(2, 1);
  img.set(0, 0, Color(1.0f));
  img.set(1, 0, Color(4.0f));
  // key 0.36 doubles the scale; white = 8 (input units) -> 1.44 scaled.
  const Image out = reinhardLinear(img, ReinhardParams{0.36f, 8.0f, std::nullopt});
  const float L = 0.72f, w2 = 1.44f * 1.44f;
  EXPECT_NEAR(out.at(1, 0).x, L * (1.0f + L / w2) / (1.0f + L), 1e-5f);
}

TEST(Tonemap, PreservesColourRatios) {
  Image img(2, 1);
  img.set(0, 0, Color(0.2f, 0.1f, 0.05f));
  img.set(1, 0, Color(10.0f));  // the white point, so the first pixel is not clipped
  const Color c = reinhardLinear(img, ReinhardParams{}).at(0, 0);
  EXPECT_LT(c.x, 1.0f);
  EXPECT_NEAR(c.x / c.y, 2.0f, 1e-4f);
  EXPECT_NEAR(c.y / c.z, 2.0f, 1e-4f);
}

TEST(Tonemap, BlackAndNonFinitePixelsMapToBlack) {
  Image img(3, 1);
  img.set(0, 0, Color(0.5f));
  img.set(1, 0, Color(0.0f));
  img.set(2, 0, Color(NAN, 1.0f, 1.0f));
  const Image out = reinhardLinear(img, ReinhardParams{});
  EXPECT_GT(out.at(0, 0).x, 0.0f);
  EXPECT_EQ(out.at(1, 0), Color(0.0f));
  EXPECT_EQ(out.at(2, 0), Color(0.0f));
}

TEST(Tonemap, SrgbTransferFunctionsInvertEachOther) {
  for (float v : {0.0f, 0.001f, 0.0031308f, 0.04045f, 0.2f, 0.5f, 1.0f})
    EXPECT_NEAR(srgbToLinear(linearToSrgb(v)), v, 1e-6f);
  EXPECT_NEAR(srgbToLinear(230.0f / 255.0f), 0.7912979f, 1e-6f);  // ../shared/refs checker value
}

}  // namespace
}  // namespace ember
