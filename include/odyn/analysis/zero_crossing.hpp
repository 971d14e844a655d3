#pragma once
// Locating where a function of time crosses zero within a step, for the switches of force laws
// and the events of watches (dynamics.hpp, analysis/watches.hpp): the Illinois variant of
// regula falsi, which keeps regula falsi's bracket and converges superlinearly.

#include <algorithm>

namespace odyn {

/// A bracket [lo, hi] on the time from a step's start, with g(lo) < 0 <= g(hi).
struct CrossingBracket {
  double lo, hi, g_lo, g_hi;
};

/// Narrows `b` until it is at most `tolerance` wide (or after max_iterations), `g(t)` giving
/// the function at a trial time; trials never go below `min_trial`. The crossing is then
/// within [lo, hi]; hi is the first time found on its far side.
template <class Function>
CrossingBracket narrow_crossing(CrossingBracket b, double tolerance, double min_trial, Function&& g,
                                int max_iterations = 100) {
  int stale_side = 0;
  for (int iteration = 0; iteration < max_iterations && b.hi - b.lo > tolerance; ++iteration) {
    double trial = (b.lo * b.g_hi - b.hi * b.g_lo) / (b.g_hi - b.g_lo);
    if (!(trial > b.lo && trial < b.hi)) trial = 0.5 * (b.lo + b.hi);
    trial = std::max(trial, min_trial);
    if (trial >= b.hi) break;
    const double value = g(trial);
    if (value >= 0.0) {
      b.hi = trial, b.g_hi = value;
      if (stale_side == 1) b.g_lo *= 0.5;  // Illinois: keep the other end moving
      stale_side = 1;
    } else {
      b.lo = trial, b.g_lo = value;
      if (stale_side == -1) b.g_hi *= 0.5;
      stale_side = -1;
    }
  }
  return b;
}

}  // namespace odyn
