#include "io/tonemap.h"

#include "materials/texture.h"

namespace ember {

Image reinhardLinear(const Image& image, const ReinhardParams& params, float* logAverageOut,
                     float* whiteOut) {
  constexpr double kDelta = 1e-6;  // keeps log() finite on black pixels (the paper's delta)
  double logSum = 0.0;
  size_t n = 0;
  float maxLum = 0.0f;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Color c = image.at(x, y);
      const float lum = luminance(c);
      // Black pixels (an empty background) stay out of the key's average: on a model against black
      // they would pull the log-average towards delta and blow the model out to white.
      if (!isFinite(c) || !(lum > 0.0f)) continue;
      logSum += std::log(kDelta + lum);
      maxLum = std::max(maxLum, lum);
      ++n;
    }
  const float logAverage = params.logAverage.value_or(n ? float(std::exp(logSum / double(n))) : 1.0f);
  const float white = params.white.value_or(maxLum);
  const float scale = logAverage > 0.0f ? params.key / logAverage : 0.0f;
  const float whiteScaled = std::max(white * scale, 1e-20f);
  const float invWhite2 = 1.0f / (whiteScaled * whiteScaled);

  Image out(image.width, image.height);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Color c = image.at(x, y);
      const float lum = luminance(c);
      if (!isFinite(c) || !(lum > 0.0f)) continue;
      const float L = scale * lum;
      const float Ld = L * (1.0f + L * invWhite2) / (1.0f + L);
      out.set(x, y, glm::clamp(c * (Ld / lum), Color(0.0f), Color(1.0f)));
    }
  if (logAverageOut) *logAverageOut = logAverage;
  if (whiteOut) *whiteOut = white;
  return out;
}

ReinhardResult tonemapReinhard(const Image& image, const ReinhardParams& params) {
  ReinhardResult result;
  const Image display = reinhardLinear(image, params, &result.logAverage, &result.white);
  result.rgb8.resize(display.rgb.size());
  for (size_t i = 0; i < display.rgb.size(); ++i)
    result.rgb8[i] = uint8_t(std::lround(255.0f * std::clamp(linearToSrgb(display.rgb[i]), 0.0f, 1.0f)));
  return result;
}

}  // namespace ember
