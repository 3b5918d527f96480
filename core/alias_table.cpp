#include "core/alias_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ember {

AliasTable::AliasTable(const std::vector<double>& weights) : bins_(weights.size()) {
  double total = 0.0;
  for (double w : weights) {
    if (!(w >= 0.0) || !std::isfinite(w))
      throw std::invalid_argument("AliasTable weights must be finite and >= 0");
    total += w;
  }
  if (weights.empty() || !(total > 0.0) || !std::isfinite(total))
    throw std::invalid_argument("AliasTable needs a positive, finite total weight");
  // Each bin holds 1/n of the probability: outcomes below that ("small") are topped up by one
  // above it ("large"), whose excess then becomes small or stays large.
  const double n = double(weights.size());
  std::vector<double> scaled(weights.size());
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < weights.size(); ++i) {
    scaled[i] = weights[i] / total * n;
    (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const uint32_t s = small.back(), l = large.back();
    small.pop_back();
    bins_[s] = {float(scaled[s]), l};
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What is left is 1 up to rounding: those bins keep their own outcome whole.
  for (uint32_t i : small) bins_[i] = {1.0f, i};
  for (uint32_t i : large) bins_[i] = {1.0f, i};
}

}  // namespace ember
