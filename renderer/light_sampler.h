// Chooses one light per shading point with probability proportional to its emitted power
// (luminance of Light::power), by binary search over the cumulative distribution. O(log n) per
// sample and no allocation, so a thousand emitters cost a few extra comparisons, not a slowdown.
#pragma once

#include "renderer/light.h"

#include <vector>

namespace ember {

class LightSampler {
 public:
  LightSampler() = default;
  // Assigns each light its samplerIndex. Lights whose power is zero are never chosen.
  LightSampler(const std::vector<Light*>& lights, float sceneRadius);

  bool empty() const { return lights_.empty(); }
  // Picks a light with u in [0, 1); returns nullptr when there is none.
  const Light* sample(float u, float& pmf) const;
  float pmf(const Light* light) const;
  // Point, spot and directional lights among those that can be chosen.
  size_t deltaLightCount() const { return deltaLights_; }

 private:
  size_t deltaLights_ = 0;
  std::vector<const Light*> lights_;
  std::vector<float> cdf_;  // cdf_[i] = P(index <= i); cdf_.back() == 1
  std::vector<float> pmf_;
};

}  // namespace ember
