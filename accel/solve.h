// Real roots of a x^2 + b x + c = 0 in double precision, ordered t0 <= t1. Uses the form that
// avoids cancellation between -b and the square root (Press et al., Numerical Recipes, 5.6).
#pragma once

#include <cmath>
#include <utility>

namespace ember {

inline bool solveQuadratic(double a, double b, double c, double& t0, double& t1) {
  if (a == 0.0) {
    if (b == 0.0) return false;
    t0 = t1 = -c / b;
    return true;
  }
  const double discrim = b * b - 4.0 * a * c;
  if (discrim < 0.0) return false;
  const double root = std::sqrt(discrim);
  const double q = b < 0.0 ? -0.5 * (b - root) : -0.5 * (b + root);
  t0 = q / a;
  t1 = q != 0.0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

}  // namespace ember
