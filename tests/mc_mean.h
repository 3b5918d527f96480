// Monte Carlo helpers shared by the statistical tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace ember::test {

// How many standard errors a Monte Carlo estimate may stray from its exact value.
inline constexpr double kSigmas = 5.0;

// Mean of i.i.d. samples with its standard error.
class McMean {
 public:
  void add(double x) {
    ++n_;
    sum_ += x;
    sumSq_ += x * x;
  }
  long count() const { return n_; }
  double mean() const { return n_ ? sum_ / double(n_) : 0.0; }
  double standardError() const {
    if (n_ < 2) return 0.0;
    const double m = mean();
    const double var = std::max(0.0, sumSq_ / double(n_) - m * m) * double(n_) / double(n_ - 1);
    return std::sqrt(var / double(n_));
  }
  // Tolerance for comparing the mean with an exact value: kSigmas standard errors plus `exactTol`
  // for what the variance cannot see (float rounding of a deterministic quantity).
  double tolerance(double exactTol = 0.0) const { return kSigmas * standardError() + exactTol; }
  void expectNear(double expected, double exactTol, const std::string& what) const {
    EXPECT_NEAR(mean(), expected, tolerance(exactTol))
        << what << " (n = " << n_ << ", stderr = " << standardError() << ")";
  }

 private:
  long n_ = 0;
  double sum_ = 0.0, sumSq_ = 0.0;
};

}  // namespace ember::test
