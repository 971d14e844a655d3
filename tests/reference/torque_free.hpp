#pragma once
// The closed-form angular velocity of a torque-free rigid body (Landau & Lifshitz, Mechanics,
// sec. 37), for integrators' tests. Principal moments J1 < J2 < J3, started at
// omega0 = (0, W, w3) in body axes with L^2 > 2 E J2 (it turns about the J3 axis, omega_3 never
// changes sign):
//   omega_1 = A1 cn(tau), omega_2 = A2 sn(tau), omega_3 = A3 dn(tau),  tau = s t + K(m),
//   A1^2 = (2E J3 - L^2) / (J1 (J3 - J1)),  A2^2 = (2E J3 - L^2) / (J2 (J3 - J2)),
//   A3^2 = (L^2 - 2E J1) / (J3 (J3 - J1)),  s^2 = (J3 - J2)(L^2 - 2E J1) / (J1 J2 J3),
//   m = (J2 - J1)(2E J3 - L^2) / ((J3 - J2)(L^2 - 2E J1)),
// (cn falls through 0 at tau = K as omega_1 must: J1 omega_1' = (J2 - J3) omega_2 omega_3 < 0). Its
// period in tau is 4K. The small differences are formed without cancellation (2E J3 - L^2 = J2 (J3
// - J2) W^2, L^2 - 2E J2 = J3 (J3 - J2) w3^2, 1 - m = (J3 - J1)(L^2 - 2E J2) /
// ((J3 - J2)(L^2 - 2E J1))), so the solution holds to rounding near the separatrix too. Uses no
// odyn code.

#include <array>
#include <cmath>

#include "reference/elliptic.hpp"

namespace torque_free {

/// Jacobi's sn, cn and dn of u for parameter m (m1 = 1 - m given separately, to keep its
/// digits), by the descending Landen transformation (Abramowitz & Stegun 16.4).
inline std::array<double, 3> jacobi(double u, double m, double m1) {
  std::array<double, 16> a{}, c{}, phi{};
  a[0] = 1.0;
  c[0] = std::sqrt(m);
  double b = std::sqrt(m1);
  int n = 0;
  while (std::abs(c[n]) > 1e-17 && n < 15) {
    a[n + 1] = 0.5 * (a[n] + b);
    c[n + 1] = 0.5 * (a[n] - b);
    b = std::sqrt(a[n] * b);
    ++n;
  }
  phi[n] = std::ldexp(a[n] * u, n);
  for (int i = n; i > 0; --i)
    phi[i - 1] = 0.5 * (phi[i] + std::asin(c[i] / a[i] * std::sin(phi[i])));
  const double sn = std::sin(phi[0]), cn = std::cos(phi[0]);
  return {sn, cn, std::sqrt(cn * cn + m1 * sn * sn)};  // dn^2 = 1 - m sn^2 without cancellation
}

struct Body {
  double j1 = 1.0, j2 = 2.0, j3 = 3.0;  // kg m^2
  double spin = 10.0, w3 = 5.0;         // omega0 = (0, spin, w3), rad/s, both positive

  double two_e() const { return j2 * spin * spin + j3 * w3 * w3; }
  double l2() const { return j2 * j2 * spin * spin + j3 * j3 * w3 * w3; }
  double m() const { return (j2 - j1) * j2 * spin * spin / (l2() - two_e() * j1); }
  double m1() const { return (j3 - j1) * j3 * w3 * w3 / (l2() - two_e() * j1); }
  double rate() const { return std::sqrt((j3 - j2) * (l2() - two_e() * j1) / (j1 * j2 * j3)); }
  /// The period of omega.
  double period() const { return 4.0 * reference::elliptic_k_complement(m1()) / rate(); }

  /// omega(t) in body axes.
  std::array<double, 3> omega(double t) const {
    const double cross = j2 * (j3 - j2) * spin * spin;  // 2E J3 - L^2
    const double a1 = std::sqrt(cross / (j1 * (j3 - j1)));
    const double a2 = std::sqrt(cross / (j2 * (j3 - j2)));
    const double a3 = std::sqrt((l2() - two_e() * j1) / (j3 * (j3 - j1)));
    const auto [sn, cn, dn] =
        jacobi(rate() * t + reference::elliptic_k_complement(m1()), m(), m1());
    return {a1 * cn, a2 * sn, a3 * dn};
  }
};

}  // namespace torque_free
