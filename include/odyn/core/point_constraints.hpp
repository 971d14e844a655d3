#pragma once
// Constraint equations between two body points that read only a body's frame (its points,
// their velocities and their Jacobians), so every body space shares them:
//   coincident  dim rows  P_a - P_b = 0
//   distance    1 row     (|P_b - P_a|^2 - L^2) / (2 L) = 0
// Each writes rows of an element's blocks; the *_gamma functions give the matching rows of
// gamma, the part of Phi-ddot that does not involve accelerations, with its sign changed.

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

}  // namespace odyn::primitive
