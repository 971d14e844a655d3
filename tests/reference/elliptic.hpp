#pragma once
// The complete elliptic integral of the first kind, for the exact periods of large-amplitude
// pendulums that several tests check integrators against.

#include <cmath>
#include <numbers>

namespace reference {

/// K from the complementary parameter m1 = 1 - k^2, by the arithmetic-geometric mean; given
/// directly, m1 keeps its digits when k is close to 1.
inline double elliptic_k_complement(double m1) {
  double a = 1.0, b = std::sqrt(m1);
  for (int i = 0; i < 30; ++i) {
    const double mean = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = mean;
  }
  return std::numbers::pi / (2.0 * a);
}

/// K(k) = int_0^{pi/2} dx / sqrt(1 - k^2 sin^2 x).
inline double elliptic_k(double k) {
  return elliptic_k_complement(1.0 - k * k);
}

}  // namespace reference
