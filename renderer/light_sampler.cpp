#include "renderer/light_sampler.h"

#include <algorithm>

namespace ember {

LightSampler::LightSampler(const std::vector<Light*>& lights, float sceneRadius) {
  double total = 0.0;
  std::vector<double> weights;
  for (Light* light : lights) {
    const double w = std::max(0.0f, luminance(light->power(sceneRadius)));
    if (!(w > 0.0) || !std::isfinite(w)) continue;
    light->samplerIndex = int(lights_.size());
    lights_.push_back(light);
    deltaLights_ += light->isDelta();
    weights.push_back(w);
    total += w;
  }
  for (double w : weights) pmf_.push_back(float(w / total));
  if (!weights.empty()) choice_ = AliasTable(weights);
}

const Light* LightSampler::sample(float u, float& pmf) const {
  if (lights_.empty()) return nullptr;
  const size_t i = choice_.sample(u);
  pmf = pmf_[i];
  return lights_[i];
}

float LightSampler::pmf(const Light* light) const {
  if (!light || light->samplerIndex < 0 || size_t(light->samplerIndex) >= pmf_.size()) return 0.0f;
  return pmf_[size_t(light->samplerIndex)];
}

}  // namespace ember
