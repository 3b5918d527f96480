// Walker's alias method with Vose's linear-time construction (Vose 1991, "A Linear Algorithm for
// Generating Random Numbers with a Given Distribution", IEEE TSE 17(9); PBRT4 section A.1): a
// discrete distribution over n outcomes sampled in O(1) with one uniform number, where inverting
// the cumulative sum costs a binary search, log2(n) dependent cache misses for a scene of
// thousands of emitters.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace ember {

class AliasTable {
 public:
  AliasTable() = default;
  // Outcome i gets probability weights[i] / sum(weights). Throws std::invalid_argument unless
  // the weights are finite and >= 0 with a positive, finite sum.
  explicit AliasTable(const std::vector<double>& weights);

  size_t size() const { return bins_.size(); }
  // The outcome for u in [0, 1): bin floor(u n) keeps its own outcome when the rest of u n is
  // below the bin's threshold, and otherwise gives its alias.
  // (In double, where u n is exact for any u with 24 significant bits and n < 2^29: in float the
  // rest would lose a bit for every bit of n.)
  // A u outside [0, 1), or NaN, still gives an outcome: below 0 it counts as 0, at 1 and above
  // as the last bin.
  size_t sample(float u) const {
    const size_t n = bins_.size();
    if (n == 1) return 0;  // one outcome: nothing to draw
    const double scaled = (u > 0.0f ? double(u) : 0.0) * double(n);
    // Compared before the conversion, which is undefined for a u of +infinity.
    const size_t bin = scaled < double(n) ? size_t(scaled) : n - 1;
    const Bin& b = bins_[bin];
    return scaled - double(bin) < double(b.threshold) ? bin : b.alias;
  }

 private:
  struct Bin {
    float threshold = 1.0f;  // the share of the bin that is its own outcome
    uint32_t alias = 0;
  };
  std::vector<Bin> bins_;
};

}  // namespace ember
