#pragma once
// Constraint equations between two body points that read only a body's frame (its points,
// their velocities and their Jacobians), so every body space shares them:
//   coincident  dim rows  P_a - P_b = 0
//   distance    1 row     (|P_b - P_a|^2 - L^2) / (2 L) = 0
// Each writes rows of an element's blocks; the *_gamma functions give the matching rows of
// gamma, the part of Phi-ddot that does not involve accelerations, with its sign changed, and
// the *_stiffness functions add the rows' geometric stiffness for their multipliers (see
// GeometricStiffness in odyn/core/element.hpp).

namespace odyn::primitive {

template <class Frame, class Blocks>
void coincident(const Frame& a, const typename Frame::Vector& s_a, const Frame& b,
                const typename Frame::Vector& s_b, Blocks& out, int row) {
  constexpr int dim = Frame::Vector::RowsAtCompileTime;
  out.phi.template segment<dim>(row) = a.point(s_a) - b.point(s_b);
  out.jacobian[0].template middleRows<dim>(row) = a.point_jacobian(s_a);
  out.jacobian[1].template middleRows<dim>(row) = -b.point_jacobian(s_b);
}

template <class Frame>
typename Frame::Vector coincident_gamma(const Frame& a, const typename Frame::Vector& s_a,
                                        const Frame& b, const typename Frame::Vector& s_b) {
  return b.centripetal(s_b) - a.centripetal(s_a);
}

/// lambda: the rows' multipliers (dim).
template <class Frame, class Lambda, class Out>
void coincident_stiffness(const Frame& a, const typename Frame::Vector& s_a, const Frame& b,
                          const typename Frame::Vector& s_b, const Lambda& lambda, Out& out) {
  out[0] += a.point_jacobian_derivative(s_a, lambda);
  out[1] -= b.point_jacobian_derivative(s_b, lambda);
}

template <class Frame, class Blocks>
void distance(const Frame& a, const typename Frame::Vector& s_a, const Frame& b,
              const typename Frame::Vector& s_b, double length, Blocks& out, int row) {
  const typename Frame::Vector d = b.point(s_b) - a.point(s_a);
  out.phi[row] = (d.squaredNorm() - length * length) / (2.0 * length);
  out.jacobian[0].row(row) = -d.transpose() * a.point_jacobian(s_a) / length;
  out.jacobian[1].row(row) = d.transpose() * b.point_jacobian(s_b) / length;
}

template <class Frame>
double distance_gamma(const Frame& a, const typename Frame::Vector& s_a, const Frame& b,
                      const typename Frame::Vector& s_b, double length) {
  const typename Frame::Vector d = b.point(s_b) - a.point(s_a);
  const typename Frame::Vector d_rate = b.point_velocity(s_b) - a.point_velocity(s_a);
  return -(d_rate.squaredNorm() + d.dot(b.centripetal(s_b) - a.centripetal(s_a))) / length;
}

/// The distance row's body-a share of Phi_q^T lambda is -(lambda / L) J_a^T d, and d moves
/// with both points.
template <class Frame, class Out>
void distance_stiffness(const Frame& a, const typename Frame::Vector& s_a, const Frame& b,
                        const typename Frame::Vector& s_b, double length, double lambda, Out& out) {
  const typename Frame::Vector d = b.point(s_b) - a.point(s_a);
  const auto jacobian_a = a.point_jacobian(s_a);
  const auto jacobian_b = b.point_jacobian(s_b);
  const double factor = lambda / length;
  out[0] += factor * (jacobian_a.transpose() * jacobian_a - a.point_jacobian_derivative(s_a, d));
  out[1] += factor * (jacobian_b.transpose() * jacobian_b + b.point_jacobian_derivative(s_b, d));
}

}  // namespace odyn::primitive
