// The alias table's exact behaviour on small tables, where each outcome's share of [0, 1) can be
// counted on a grid of u (its statistics over many outcomes: test_chi2.cpp, AliasTable_manyOutcomes).
#include "core/alias_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace ember {
namespace {

// How many of the u = k / 2^bits, k < 2^bits, choose each outcome.
std::vector<long> countsOnGrid(const AliasTable& table, int bits) {
  std::vector<long> counts(table.size(), 0);
  for (long k = 0; k < (1l << bits); ++k) ++counts.at(table.sample(std::ldexp(float(k), -bits)));
  return counts;
}

TEST(AliasTable, DyadicWeightsGetExactlyTheirShareOfU) {
  // Weights 1 : 3 : 0 : 4: shares 1/8, 3/8, 0, 4/8, all exact on a grid of 2^12 values of u.
  const AliasTable table({1.0, 3.0, 0.0, 4.0});
  const std::vector<long> counts = countsOnGrid(table, 12);
  EXPECT_EQ(counts, (std::vector<long>{512, 1536, 0, 2048}));
}

TEST(AliasTable, OneOutcomeAndTheEndsOfTheUnitInterval) {
  const AliasTable one({2.5});
  EXPECT_EQ(one.sample(0.0f), 0u);
  EXPECT_EQ(one.sample(std::nextafter(1.0f, 0.0f)), 0u);
  const AliasTable table({0.0, 1.0, 1e-30, 7.0});
  for (float u : {0.0f, 1e-30f, 0.5f, std::nextafter(1.0f, 0.0f)}) EXPECT_LT(table.sample(u), 4u) << u;
  EXPECT_NE(table.sample(0.0f), 0u) << "bin 0 has weight 0: it must give its alias";
}

// Weights whose scaled shares are not exact in binary: the construction's rounding leftovers
// must not move more than a grid step of u between outcomes.
TEST(AliasTable, NonDyadicWeightsGetTheirShareToTheGridStep) {
  for (const std::vector<double>& weights : {std::vector<double>(3, 1.0), std::vector<double>(10, 0.1),
                                             std::vector<double>{0.1, 0.7, 0.2, 1e-9, 0.3}}) {
    const AliasTable table(weights);
    const int bits = 16;
    const std::vector<long> counts = countsOnGrid(table, bits);
    double total = 0.0;
    for (double w : weights) total += w;
    for (size_t i = 0; i < weights.size(); ++i)
      EXPECT_NEAR(double(counts[i]), weights[i] / total * double(1l << bits), double(weights.size()))
          << "outcome " << i << " of " << weights.size();
  }
}

TEST(AliasTable, UOutsideTheUnitIntervalStillGivesAnOutcome) {
  const AliasTable table({1.0, 2.0, 3.0});
  for (float u : {-1.0f, 1.0f, 2.0f, std::nanf(""), -std::numeric_limits<float>::infinity(),
                  std::numeric_limits<float>::infinity(), std::numeric_limits<float>::max()})
    EXPECT_LT(table.sample(u), 3u) << u;
  // At 1 and above, all alike: the last bin, past its threshold.
  for (float u : {2.0f, std::numeric_limits<float>::max(), std::numeric_limits<float>::infinity()})
    EXPECT_EQ(table.sample(u), table.sample(1.0f)) << u;
}

TEST(AliasTable, RejectsNegativeNonFiniteOrAllZeroWeights) {
  EXPECT_THROW(AliasTable(std::vector<double>{}), std::invalid_argument);
  EXPECT_THROW(AliasTable(std::vector<double>{0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(AliasTable(std::vector<double>{1.0, -0.5}), std::invalid_argument);
  EXPECT_THROW(AliasTable(std::vector<double>{1.0, std::nan("")}), std::invalid_argument);
  EXPECT_THROW(AliasTable(std::vector<double>{1.0, std::numeric_limits<double>::infinity()}),
               std::invalid_argument);
}

}  // namespace
}  // namespace ember
