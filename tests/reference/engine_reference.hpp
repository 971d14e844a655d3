#pragma once
// Independent reference solution of the single-cylinder engine of shared/specs/engine.md, in the
// one minimal coordinate theta (crank rotation about +X, theta = 0 at top dead centre). It uses
// no odyn code on purpose: tests check the library's absolute-coordinate solution against it.
//
// Kinematics (s = sin theta, c = cos theta, w = sqrt(L^2 - r^2 s^2)):
//   crank pin (0, -r s, r c), piston pin z_p = r c + w, rod centre (0, -r s / 2, r c + w / 2),
//   rod angle about X: sin phi = -r s / L, so phi' = -r c / w.
// Lagrange with T = J(theta) omega^2 / 2 and V = g (m_rod z_rod + m_piston z_p) gives
//   J alpha + J' omega^2 / 2 = Q = F_gas z_p' - c_load omega - g (m_rod z_rod' + m_piston z_p'),
// where ' is d/dtheta. The equation is integrated with classical RK4 on fixed steps; every
// stroke boundary theta = n pi is hit exactly, so no step straddles a jump (or kink) of the gas
// force.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "reference/compensated_sum.hpp"

namespace engine_reference {

struct Parameters {
  double r = 0.04, L = 0.14, D = 0.08, C = 9, p_atm = 101325, kappa = 1.4, p_comb = 3.0e6,
         c_load = 0.1, g = 9.81, m_crank = 1.399, m_rod = 0.253, m_piston = 0.643,
         Ixx_crank = 1.524, Ixx_rod = 0.399, theta0 = 0, omega0 = 157.08;
};

struct Sample {
  double t, theta, omega, alpha, z_piston, z_piston_dot, R_z;
};

// Positions and their first and second derivatives with respect to theta.
struct Kinematics {
  double z_piston, z_rod;                          // heights of piston and rod centre
  double dz_piston, dz_rod, dy_rod, dphi_rod;      // d/dtheta
  double ddz_piston, ddz_rod, ddy_rod, ddphi_rod;  // d^2/dtheta^2
};

inline Kinematics kinematics(double theta, const Parameters& p = {}) {
  const double s = std::sin(theta), c = std::cos(theta), r = p.r;
  const double w = std::sqrt(p.L * p.L - r * r * s * s);
  const double dw = -r * r * s * c / w;  // from w^2 = L^2 - r^2 s^2
  const double ddw = -(r * r * (c * c - s * s) + dw * dw) / w;
  Kinematics k;
  k.z_piston = r * c + w;
  k.z_rod = r * c + 0.5 * w;
  k.dz_piston = -r * s + dw;
  k.dz_rod = -r * s + 0.5 * dw;
  k.dy_rod = -0.5 * r * c;
  k.dphi_rod = -r * c / w;
  k.ddz_piston = -r * c + ddw;
  k.ddz_rod = -r * c + 0.5 * ddw;
  k.ddy_rod = 0.5 * r * s;
  k.ddphi_rod = r * s / w + r * c * dw / (w * w);
  return k;
}

inline double piston_z(double theta, const Parameters& p = {}) {
  return kinematics(theta, p).z_piston;
}

// Stroke n mod 4 of the cycle for theta in [n pi, (n + 1) pi): 0 intake, 1 compression,
// 2 power, 3 exhaust. Same as the spec's phi = theta mod 4 pi.
inline int stroke_of(double theta) {
  const long long n = static_cast<long long>(std::floor(theta / std::numbers::pi));
  return static_cast<int>(((n % 4) + 4) % 4);
}

// Gas force on the piston along +Z in a given stroke. The integrator passes the stroke
// explicitly: at a boundary theta = n pi, rounding of theta must not pick the wrong formula.
inline double gas_force_in_stroke(int stroke, double z_piston, const Parameters& p = {}) {
  const double area = std::numbers::pi * p.D * p.D / 4;
  const double v_c = area * 2 * p.r / (p.C - 1);
  const double v_1 = v_c + 2 * p.r * area;
  const double v = v_c + area * ((p.r + p.L) - z_piston);
  double pressure = p.p_atm;
  if (stroke == 1) pressure = p.p_atm * std::pow(v_1 / v, p.kappa);
  if (stroke == 2)
    pressure = (p.p_atm * std::pow(p.C, p.kappa) + p.p_comb) * std::pow(v_c / v, p.kappa);
  return -(pressure - p.p_atm) * area;
}

// theta is the cumulative crank angle; exactly at theta = n pi the later stroke applies.
inline double gas_force(double theta_cumulative, double z_piston, const Parameters& p = {}) {
  return gas_force_in_stroke(stroke_of(theta_cumulative), z_piston, p);
}

// Generalized inertia J(theta) = 2 T / omega^2.
inline double inertia(double theta, const Parameters& p = {}) {
  const Kinematics k = kinematics(theta, p);
  return p.Ixx_crank + p.m_rod * (k.dy_rod * k.dy_rod + k.dz_rod * k.dz_rod) +
         p.Ixx_rod * k.dphi_rod * k.dphi_rod + p.m_piston * k.dz_piston * k.dz_piston;
}

inline double inertia_derivative(double theta, const Parameters& p = {}) {
  const Kinematics k = kinematics(theta, p);
  return 2 * (p.m_rod * (k.dy_rod * k.ddy_rod + k.dz_rod * k.ddz_rod) +
              p.Ixx_rod * k.dphi_rod * k.ddphi_rod + p.m_piston * k.dz_piston * k.ddz_piston);
}

// Generalized force conjugate to theta: gas, load torque and gravity (-dV/dtheta).
inline double generalized_force_in_stroke(int stroke, double theta, double omega,
                                          const Parameters& p = {}) {
  const Kinematics k = kinematics(theta, p);
  return gas_force_in_stroke(stroke, k.z_piston, p) * k.dz_piston - p.c_load * omega -
         p.g * (p.m_rod * k.dz_rod + p.m_piston * k.dz_piston);
}

inline double generalized_force(double theta, double omega, const Parameters& p = {}) {
  return generalized_force_in_stroke(stroke_of(theta), theta, omega, p);
}

inline double angular_acceleration_in_stroke(int stroke, double theta, double omega,
                                             const Parameters& p = {}) {
  return (generalized_force_in_stroke(stroke, theta, omega, p) -
          0.5 * inertia_derivative(theta, p) * omega * omega) /
         inertia(theta, p);
}

inline double angular_acceleration(double theta, double omega, const Parameters& p = {}) {
  return angular_acceleration_in_stroke(stroke_of(theta), theta, omega, p);
}

// Z force of the block on the crank at the bearing. Vertical momentum balance of crank + rod +
// piston: the prismatic joint carries no Z force and the load is a pure torque, so
// R_z + F_gas - g sum(m) = sum(m a_z); the crank's centre of mass stays on the axis.
inline double reaction_z_in_stroke(int stroke, double theta, double omega, double alpha,
                                   const Parameters& p = {}) {
  const Kinematics k = kinematics(theta, p);
  const double a_rod = k.dz_rod * alpha + k.ddz_rod * omega * omega;
  const double a_piston = k.dz_piston * alpha + k.ddz_piston * omega * omega;
  return p.m_crank * p.g + p.m_rod * (a_rod + p.g) + p.m_piston * (a_piston + p.g) -
         gas_force_in_stroke(stroke, k.z_piston, p);
}

inline double reaction_z(double theta, double omega, double alpha, const Parameters& p = {}) {
  return reaction_z_in_stroke(stroke_of(theta), theta, omega, alpha, p);
}

namespace detail {

struct State {
  double theta, omega;
};

// One RK4 step, returned as an increment so that the caller can add it with compensation or
// shorten the step to land on a stroke boundary.
inline State rk4_increment(const State& y, double h, int stroke, const Parameters& p) {
  auto f = [&](double dtheta, double domega) {
    const double theta = y.theta + dtheta, omega = y.omega + domega;
    return State{omega, angular_acceleration_in_stroke(stroke, theta, omega, p)};
  };
  const State k1 = f(0, 0), k2 = f(h / 2 * k1.theta, h / 2 * k1.omega),
              k3 = f(h / 2 * k2.theta, h / 2 * k2.omega), k4 = f(h * k3.theta, h * k3.omega);
  return State{h / 6 * (k1.theta + 2 * k2.theta + 2 * k3.theta + k4.theta),
               h / 6 * (k1.omega + 2 * k2.omega + 2 * k3.omega + k4.omega)};
}


}  // namespace detail

// Integrates from t = 0 to t_end with RK4 steps of at most h and returns samples at
// t = k dt_out. h = 1e-5 keeps the truncation error near 1e-12 rad at t = 1 s. Assumes the
// crank keeps turning forward (omega > 0); throws otherwise.
inline std::vector<Sample> solve(double t_end, double dt_out, const Parameters& p = {},
                                 double h = 1e-5) {
  using detail::State;
  const double pi = std::numbers::pi;
  State y{p.theta0, p.omega0}, carry{0, 0};
  long long n = static_cast<long long>(std::floor(y.theta / pi));  // current stroke interval
  auto stroke = [&n] { return static_cast<int>(((n % 4) + 4) % 4); };
  auto advance = [&](const State& d) {
    reference::add_compensated(y.theta, carry.theta, d.theta);
    reference::add_compensated(y.omega, carry.omega, d.omega);
  };

  std::vector<Sample> out;
  auto record = [&](double time) {
    const Kinematics k = kinematics(y.theta, p);
    const double alpha = angular_acceleration_in_stroke(stroke(), y.theta, y.omega, p);
    out.push_back({time, y.theta, y.omega, alpha, k.z_piston, k.dz_piston * y.omega,
                   reaction_z_in_stroke(stroke(), y.theta, y.omega, alpha, p)});
  };

  const long long n_out = std::llround(t_end / dt_out);
  out.reserve(n_out + 1);
  record(0);
  double t = 0;
  for (long long i = 1; i <= n_out; ++i) {
    const double t_target = i * dt_out;
    while (t < t_target) {
      // Equal steps up to the output time; t is recomputed, never accumulated.
      const double t0 = t;
      const auto steps =
          static_cast<long long>(std::max(1.0, std::ceil((t_target - t0) / h - 1e-9)));
      const double dt = (t_target - t0) / steps;
      for (long long j = 1; j <= steps; ++j) {
        if (!(y.omega > 0)) throw std::runtime_error("engine_reference: crank stopped turning");
        const double theta_event = static_cast<double>(n + 1) * pi;
        // Distance still to go to the boundary, formed before theta is rounded.
        auto overshoot = [&](const State& d) {
          return (y.theta - theta_event) + (d.theta - carry.theta);
        };
        const State d = detail::rk4_increment(y, dt, stroke(), p);
        if (overshoot(d) < 0) {
          advance(d);
          t = j == steps ? t_target : t0 + j * dt;
          continue;
        }
        // Shorten the step so it ends on the boundary: the step's theta is smooth and increasing
        // in its length, so safeguarded Newton (d theta / d tau ~ omega) converges in a few
        // iterations.
        double lo = 0, hi = dt, tau = dt * (1 - overshoot(d) / d.theta);
        for (int it = 0; it < 100; ++it) {
          const State s = detail::rk4_increment(y, tau, stroke(), p);
          const double g = overshoot(s);
          (g < 0 ? lo : hi) = tau;
          if (std::abs(g) <= 1e-15 * (1 + std::abs(theta_event)) || hi - lo <= 1e-18) break;
          const double next = tau - g / (y.omega + s.omega);
          tau = (next > lo && next < hi) ? next : 0.5 * (lo + hi);
        }
        advance(detail::rk4_increment(y, tau, stroke(), p));
        y.theta = theta_event;
        carry.theta = 0;
        ++n;
        t = t0 + (j - 1) * dt + tau;
        break;  // re-plan equal steps over the rest of the output interval
      }
    }
    record(t_target);
  }
  return out;
}

}  // namespace engine_reference
