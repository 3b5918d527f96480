// Chooses one light per shading point with probability proportional to its emitted power
// (luminance of Light::power), from an alias table (core/alias_table.h): O(1) per sample and no
// allocation, so ten thousand emitters cost what one does.
#pragma once

#include "core/alias_table.h"
#include "renderer/light.h"

#include <vector>

namespace ember {

class LightSampler {
 public:
  LightSampler() = default;
  // Assigns each light its samplerIndex. Lights whose power is zero are never chosen.
  LightSampler(const std::vector<Light*>& lights, float sceneRadius);

  bool empty() const { return lights_.empty(); }
  size_t size() const { return lights_.size(); }
  // Picks a light with u in [0, 1); returns nullptr when there is none.
  const Light* sample(float u, float& pmf) const;
  float pmf(const Light* light) const;
  // Point, spot and directional lights among those that can be chosen.
  size_t deltaLightCount() const { return deltaLights_; }

 private:
  size_t deltaLights_ = 0;
  std::vector<const Light*> lights_;
  AliasTable choice_;
  std::vector<float> pmf_;
};

}  // namespace ember
