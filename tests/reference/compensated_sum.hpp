#pragma once
// Kahan's compensated summation, for the reference solutions' fixed-step integrators: a million
// increments added to a coordinate would otherwise round by ~1e-11, more than the truncation
// error of the steps. (Do not compile with -ffast-math.)

namespace reference {

/// sum += x, with the rounding error kept in carry and fed back into the next addition.
inline void add_compensated(double& sum, double& carry, double x) {
  const double y = x - carry, s = sum + y;
  carry = (s - sum) - y;
  sum = s;
}

}  // namespace reference
