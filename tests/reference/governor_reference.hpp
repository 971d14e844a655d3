#pragma once
// Independent reference solution of the stiff centrifugal governor of
// examples/governor_model.hpp, in its one minimal coordinate phi (each arm's angle from the
// downward vertical). It uses no odyn code on purpose: tests check the library's solution
// against it.
//
// Kinematics in the spindle frame, which turns about z at Omega(t) (s = sin phi, c = cos phi):
//   arm centre (i (a + l_c s), 0, -l_c c); arm angular velocity Omega z - i phi' y;
//   sleeve z_s = -b c - w, w = sqrt(L^2 - h^2), h = a + b s - e (the link's horizontal span).
// The phi' and Omega parts of each velocity are orthogonal: the centre's Omega part is along the
// spindle's y, its phi' part in the x-z plane, and the inertia tensor (J across d, I_a along d)
// couples z and y by (I_a - J) (z.d)(d.y) = 0 since d.y = 0. So T has no phi' Omega term and
// Omega' does not enter the phi equation. With l_c = arm_centre and z_s' = dz_s/dphi:
//   T = Omega^2 [m (a + l_c s)^2 + I_a c^2 + J s^2] + M(phi) phi'^2 / 2 + (terms without phi),
//   M = 2 (m l_c^2 + J) + m_s z_s'^2,
//   V = -2 m g l_c c + m_s g z_s + k (z_s - z0 - l0)^2 / 2,   Q = -c z_s'^2 phi',
// and Lagrange's equation is
//   M phi'' + M' phi'^2 / 2 = Omega^2 [2 m (a + l_c s) l_c c + 2 (J - I_a) s c]
//                            - 2 m g l_c s - m_s g z_s' - k (z_s - z0 - l0) z_s' - c z_s'^2 phi',
// with M' = 2 m_s z_s' z_s''. It is integrated by classical RK4 on fixed steps, the sums
// compensated. The fast eigenvalue is -1.4e4 .. -2e4 1/s, so RK4 (stable for h |lambda| < 2.78)
// needs h below ~1.4e-4 s just to be stable, and far less to follow the fast transient.
// Measured self-convergence, max difference over the 1001 outputs on [0, 1] s between runs at
// h and h / 2: h = 2e-5: phi 1.4e-13 rad, phi' 8.5e-10 rad/s; 1e-5: 7.8e-15, 4.8e-11;
// 5e-6: 4.4e-16, 2.9e-12; 2.5e-6: 1.1e-16, 1.7e-13; 1.25e-6: 1.1e-16, 1.1e-14 (phi' at fourth
// order, phi at rounding from h = 5e-6 on). The default h = 1e-6 (1e6 steps, ~0.15 s) leaves phi
// within rounding (~1e-16 rad) and phi' within ~1e-14 rad/s.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "reference/compensated_sum.hpp"

namespace governor_reference {

// Must equal governor::Parameters (examples/governor_model.hpp) field by field: the test
// "bdf held to 0.03 of its tolerance" in tests/test_bdf.cpp compares those that move phi. The
// spindle's and sleeve's inertias do not affect phi; they are here to keep the two structs alike.
struct Parameters {
  double a = 0.05, b = 0.15, e = 0.03, L = 0.20;  // m
  double arm_mass = 1.0, arm_centre = 0.25, arm_transverse = 0.01, arm_axial = 1e-4;
  double sleeve_mass = 0.5, sleeve_axial = 5e-4, sleeve_transverse = 5e-4;
  double spindle_mass = 2.0, spindle_axial = 2e-3, spindle_transverse = 2e-2;
  double stiffness = 5e5, damping = 1e5, z0 = -0.45;
  double design_angle = 30.0 * std::numbers::pi / 180.0;
  double initial_angle = 27.0 * std::numbers::pi / 180.0;
  double omega0 = 100.0, omega1 = 200.0, ramp_time = 1.0, g = 9.81;
};

struct Sample {
  double t, phi, phi_dot, spring_force;  // spring tension, N
};

// Omega(t): omega0, then (1 - cos) up to omega1 over ramp_time, then omega1.
inline double spindle_speed(double t, const Parameters& p) {
  if (t <= 0) return p.omega0;
  if (t >= p.ramp_time) return p.omega1;
  return p.omega0 + (p.omega1 - p.omega0) * (1 - std::cos(std::numbers::pi * t / p.ramp_time)) / 2;
}

// z_s and its first two derivatives with respect to phi.
struct Sleeve {
  double z, dz, ddz;
};

inline Sleeve sleeve(double phi, const Parameters& p) {
  const double s = std::sin(phi), c = std::cos(phi);
  const double h = p.a + p.b * s - p.e, dh = p.b * c, ddh = -p.b * s;
  const double w = std::sqrt(p.L * p.L - h * h);
  const double dw = -h * dh / w;                          // from w^2 = L^2 - h^2
  const double ddw = -(dh * dh + h * ddh + dw * dw) / w;  // its derivative again
  return {-p.b * c - w, p.b * s - dw, p.b * c - ddw};
}

// d/dphi of the Omega^2 part of T, per Omega^2, and its derivative.
inline double centrifugal(double phi, const Parameters& p) {
  const double s = std::sin(phi), c = std::cos(phi), m = p.arm_mass, lc = p.arm_centre;
  return 2 * m * (p.a + lc * s) * lc * c + 2 * (p.arm_transverse - p.arm_axial) * s * c;
}
inline double centrifugal_slope(double phi, const Parameters& p) {
  const double s = std::sin(phi), c = std::cos(phi), m = p.arm_mass, lc = p.arm_centre;
  return 2 * m * lc * (lc * c * c - (p.a + lc * s) * s) +
         2 * (p.arm_transverse - p.arm_axial) * (c * c - s * s);
}

// dV/dphi of gravity alone.
inline double gravity_moment(double phi, const Parameters& p) {
  return 2 * p.arm_mass * p.g * p.arm_centre * std::sin(phi) +
         p.sleeve_mass * p.g * sleeve(phi, p).dz;
}

// The spring's free length l0 that puts the equilibrium at design_angle for omega0.
inline double free_length(const Parameters& p) {
  const double phi = p.design_angle;
  const Sleeve zs = sleeve(phi, p);
  const double stretch =
      (p.omega0 * p.omega0 * centrifugal(phi, p) - gravity_moment(phi, p)) / (p.stiffness * zs.dz);
  return zs.z - p.z0 - stretch;
}

inline double mass(double phi, const Parameters& p) {
  const double dz = sleeve(phi, p).dz;
  return 2 * (p.arm_mass * p.arm_centre * p.arm_centre + p.arm_transverse) +
         p.sleeve_mass * dz * dz;
}

inline double spring_force(double phi, double phi_dot, const Parameters& p, double l0) {
  const Sleeve zs = sleeve(phi, p);
  return p.stiffness * (zs.z - p.z0 - l0) + p.damping * zs.dz * phi_dot;
}

inline double acceleration(double t, double phi, double phi_dot, const Parameters& p, double l0) {
  const Sleeve zs = sleeve(phi, p);
  const double omega = spindle_speed(t, p);
  const double m = mass(phi, p), dm = 2 * p.sleeve_mass * zs.dz * zs.ddz;
  const double force = omega * omega * centrifugal(phi, p) - gravity_moment(phi, p) -
                       spring_force(phi, phi_dot, p, l0) * zs.dz;
  return (force - 0.5 * dm * phi_dot * phi_dot) / m;
}

// The linearization at the equilibrium for a constant speed: its angle and the two real
// eigenvalues (overdamped) of M x'' + C x' + K x = 0.
struct Modes {
  double phi, fast, slow, M, C, K;
};

inline Modes modes(double omega, const Parameters& p) {
  const double l0 = free_length(p);
  auto stiffness = [&](double phi) {
    const Sleeve zs = sleeve(phi, p);
    return 2 * p.arm_mass * p.g * p.arm_centre * std::cos(phi) + p.sleeve_mass * p.g * zs.ddz +
           p.stiffness * (zs.dz * zs.dz + (zs.z - p.z0 - l0) * zs.ddz) -
           omega * omega * centrifugal_slope(phi, p);
  };
  double phi = p.design_angle;  // Newton on the static balance
  for (int it = 0; it < 50; ++it) {
    const double residual = spring_force(phi, 0, p, l0) * sleeve(phi, p).dz +
                            gravity_moment(phi, p) - omega * omega * centrifugal(phi, p);
    const double step = residual / stiffness(phi);
    phi -= step;
    if (std::abs(step) < 1e-15) break;
  }
  const double dz = sleeve(phi, p).dz;
  const double M = mass(phi, p), C = p.damping * dz * dz, K = stiffness(phi);
  const double root = std::sqrt(C * C - 4 * M * K);  // real: overdamped
  return {phi, (-C - root) / (2 * M), 2 * K / (-C - root), M, C, K};
}

namespace detail {

struct State {
  double phi, phi_dot;
};

inline State rk4_increment(double t, const State& y, double h, const Parameters& p, double l0) {
  auto f = [&](double dt, double dphi, double drate) {
    const double rate = y.phi_dot + drate;
    return State{rate, acceleration(t + dt, y.phi + dphi, rate, p, l0)};
  };
  const State k1 = f(0, 0, 0), k2 = f(h / 2, h / 2 * k1.phi, h / 2 * k1.phi_dot),
              k3 = f(h / 2, h / 2 * k2.phi, h / 2 * k2.phi_dot),
              k4 = f(h, h * k3.phi, h * k3.phi_dot);
  return State{h / 6 * (k1.phi + 2 * k2.phi + 2 * k3.phi + k4.phi),
               h / 6 * (k1.phi_dot + 2 * k2.phi_dot + 2 * k3.phi_dot + k4.phi_dot)};
}

}  // namespace detail

// Integrates from t = 0 (phi = initial_angle, phi' = 0) to t_end with equal RK4 steps of at most
// h and returns samples at t = k dt_out.
inline std::vector<Sample> solve(double t_end, double dt_out, const Parameters& p = {},
                                 double h = 1e-6) {
  const double l0 = free_length(p);
  detail::State y{p.initial_angle, 0}, carry{0, 0};
  std::vector<Sample> out;
  const long long n_out = std::llround(t_end / dt_out);
  out.reserve(n_out + 1);
  out.push_back({0, y.phi, y.phi_dot, spring_force(y.phi, y.phi_dot, p, l0)});
  for (long long i = 1; i <= n_out; ++i) {
    const double t0 = (i - 1) * dt_out, t1 = i * dt_out;
    const auto steps = static_cast<long long>(std::max(1.0, std::ceil((t1 - t0) / h - 1e-9)));
    const double dt = (t1 - t0) / steps;
    for (long long j = 0; j < steps; ++j) {
      const detail::State d = detail::rk4_increment(t0 + j * dt, y, dt, p, l0);
      reference::add_compensated(y.phi, carry.phi, d.phi);
      reference::add_compensated(y.phi_dot, carry.phi_dot, d.phi_dot);
    }
    out.push_back({t1, y.phi, y.phi_dot, spring_force(y.phi, y.phi_dot, p, l0)});
  }
  return out;
}

}  // namespace governor_reference
