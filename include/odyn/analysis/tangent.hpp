#pragma once
// The derivatives of the equations of motion at a state, in the coordinates an analysis runs in
// (absolute or joint ones: any class with AbsoluteCoordinates' interface). With the residual
//     r(q, v, v', lambda) = M v' - Q(q, v, t) + Phi_q^T lambda
// they are, in the coordinates' velocity space (a change of position taken as the increment
// that integrate() applies):
//     mass       dr/dv'   exact, since r is linear in v';
//     damping    dr/dv    central differences of fourth order;
//     stiffness  dr/dq    with v, v' and lambda held, the same differences. It holds the forces'
//                         stiffness and the constraints' geometric stiffness d(Phi_q^T lambda)/dq,
//                         whole, where the integrators' Newton matrices keep parts of them;
//     jacobian   Phi_q    exact, since Phi_q v + Phi_t is linear in v (constraint_jacobian).
// Differences of the residual as a whole need nothing from the elements beyond what a dynamic
// run asks of them, and serve every element alike, Python's included. Their steps are 1e-3 rad
// and 1e-3 of the model's size, where the stencil's error (h^4) and the rounding (eps / h) are
// both about 1e-12 of the forces. Each column costs four residuals of O(N): O(N^2), dense.

#include <Eigen/Core>
#include <algorithm>

namespace odyn {

/// The equations of motion's derivatives at a state (see the file's comment). n velocity
/// coordinates, m constraint equations.
struct Tangent {
  /// Which derivatives to form: statics needs neither mass nor damping.
  struct Parts {
    bool mass = true, damping = true;
  };
  Eigen::MatrixXd mass;       // (n x n) dr/dv'
  Eigen::MatrixXd damping;    // (n x n) dr/dv
  Eigen::MatrixXd stiffness;  // (n x n) dr/dq
  Eigen::MatrixXd jacobian;   // (m x n) Phi_q
};

namespace detail {
/// The residual r at the coordinates' positions, velocities, accelerations and multipliers,
/// with the frames, constraints and forces evaluated there.
template <class Coordinates>
void residual_here(Coordinates& c, Eigen::Ref<Eigen::VectorXd> out) {
  c.update_frames();
  c.evaluate_constraints();
  c.evaluate_forces();
  c.dynamics_residual(out);
}

/// The fourth-order central difference (8 (f(h) - f(-h)) - (f(2h) - f(-2h))) / 12h, f(s) given
/// into `value` by set(s).
template <class Set>
void fourth_order_difference(double h, Eigen::Ref<Eigen::VectorXd> out, Eigen::VectorXd& value,
                             Set&& set) {
  constexpr double weights[4] = {1.0, -8.0, 8.0, -1.0};
  constexpr double steps[4] = {-2.0, -1.0, 1.0, 2.0};
  out.setZero();
  for (int k = 0; k < 4; ++k) {
    set(steps[k] * h);
    out += (weights[k] / (12.0 * h)) * value;
  }
}
}  // namespace detail

/// Phi_q in the coordinates' velocity space at their held positions, column by column from
/// Phi_q v + Phi_t (exact: linear in v). Velocities and evaluations as found on return.
template <class Coordinates>
Eigen::MatrixXd constraint_jacobian(Coordinates& c) {
  const Eigen::Index n = c.num_velocities(), m = c.num_equations();
  Eigen::MatrixXd out(m, n);
  c.update_frames();
  c.evaluate_constraints();
  const Eigen::VectorXd rates0 = c.velocity_constraint_values();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double held = c.velocities()[j];
    c.velocities()[j] = held + 1.0;
    c.update_frames();
    c.evaluate_constraints();
    out.col(j) = c.velocity_constraint_values() - rates0;
    c.velocities()[j] = held;
  }
  c.update_frames();
  c.evaluate_constraints();
  return out;
}

/// The derivatives at the coordinates' state (positions, velocities, accelerations and
/// multipliers as held). `length` sets the steps in travel (about the model's size); steps in
/// turn are 1e-3 rad. The state and its evaluations are as found on return.
template <class Coordinates>
Tangent tangent(Coordinates& c, double length, Tangent::Parts parts = {}) {
  const Eigen::Index n = c.num_velocities();
  Tangent out{Eigen::MatrixXd::Zero(parts.mass ? n : 0, parts.mass ? n : 0),
              Eigen::MatrixXd::Zero(parts.damping ? n : 0, parts.damping ? n : 0),
              Eigen::MatrixXd(n, n), constraint_jacobian(c)};
  const Eigen::VectorXd q = c.positions(), v = c.velocities(), a = c.accelerations();
  const auto coordinates = c.velocity_coordinates();
  Eigen::VectorXd r0(n), r(n), increment = Eigen::VectorXd::Zero(n);
  detail::residual_here(c, r0);
  const double speed_step = 1e-3 * std::max(1.0, v.cwiseAbs().maxCoeff());
  for (Eigen::Index j = 0; j < n; ++j) {
    // r is linear in v': a unit step is exact.
    if (parts.mass) {
      c.accelerations()[j] += 1.0;
      detail::residual_here(c, r);
      out.mass.col(j) = r - r0;
      c.accelerations()[j] = a[j];
    }
    if (parts.damping)
      detail::fourth_order_difference(speed_step, out.damping.col(j), r, [&](double s) {
        c.velocities()[j] = v[j] + s;
        detail::residual_here(c, r);
      });
    c.velocities()[j] = v[j];
    const double turn_step = 1e-3, travel_step = 1e-3 * length;
    const bool angular = coordinates[static_cast<std::size_t>(j)].angular;
    detail::fourth_order_difference(angular ? turn_step : travel_step, out.stiffness.col(j), r,
                                    [&](double s) {
                                      increment[j] = s;
                                      c.integrate(q, increment, c.positions());
                                      detail::residual_here(c, r);
                                    });
    increment[j] = 0.0;
    c.positions() = q;
  }
  detail::residual_here(c, r);
  return out;
}

}  // namespace odyn
