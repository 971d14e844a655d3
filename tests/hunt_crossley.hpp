#pragma once
// The closed-form reference of the contact and stop tests: with no other force, a mass that
// enters a Hunt-Crossley contact k delta^n (1 + d delta') at the rate v_in leaves it at the rate
// v_out that solves the law's first integral
//   d v_in - ln(1 + d v_in) = -d v_out - ln(1 - d v_out),
// whatever k and n.

#include <cmath>

namespace hunt_crossley {

/// v_out in (0, 1/d), by bisection (d > 0).
inline double exit_rate(double d, double v_in) {
  const double target = d * v_in - std::log1p(d * v_in);
  double lo = 0.0, hi = (1.0 - 1e-15) / d;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (-d * mid - std::log1p(-d * mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace hunt_crossley
