#pragma once
// The complete elliptic integral of the first kind, for the exact periods of large-amplitude
// pendulums that several tests check integrators against.

#include <cmath>
#include <numbers>

namespace reference {

/// K(k) = int_0^{pi/2} dx / sqrt(1 - k^2 sin^2 x), by the arithmetic-geometric mean.
inline double elliptic_k(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 30; ++i) {
    const double mean = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = mean;
  }
  return std::numbers::pi / (2.0 * a);
}

}  // namespace reference
