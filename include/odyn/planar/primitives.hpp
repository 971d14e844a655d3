#pragma once
// The planar constraint equation that the point constraints (odyn/core/point_constraints.hpp)
// and the joint angle (PairJoint) leave out:
//   on_line   1 row   (R_a n) . (P_b - P_a) = 0   (b's point stays on a line of body a, whose
//                                                 normal in body a is n)
// written into rows of an element's blocks, with the matching row of gamma.

#include <Eigen/Core>

#include "odyn/core/planar.hpp"
#include "odyn/core/point_constraints.hpp"

namespace odyn::planar::primitive {

using Vec2 = Eigen::Vector2d;
using Frame = Planar::Frame;

using odyn::primitive::coincident;
using odyn::primitive::coincident_gamma;
using odyn::primitive::coincident_stiffness;
using odyn::primitive::distance;
using odyn::primitive::distance_gamma;
using odyn::primitive::distance_stiffness;

template <class Blocks>
void on_line(const Frame& a, const Vec2& normal, const Vec2& s_a, const Frame& b, const Vec2& s_b,
             Blocks& out, int row) {
  const Vec2 n = a.direction(normal);
  const Vec2 d = b.point(s_b) - a.point(s_a);
  out.phi[row] = n.dot(d);
  // d/dphi_a: the normal turns with a (perpendicular(n) . d) and so does P_a.
  out.jacobian[0].row(row) << -n.x(), -n.y(),
      Planar::perpendicular(n).dot(d) - n.dot(Planar::perpendicular(a.direction(s_a)));
  out.jacobian[1].row(row) << n.x(), n.y(), n.dot(Planar::perpendicular(b.direction(s_b)));
}

inline double on_line_gamma(const Frame& a, const Vec2& normal, const Vec2& s_a, const Frame& b,
                            const Vec2& s_b) {
  const Vec2 n = a.direction(normal);
  const Vec2 d = b.point(s_b) - a.point(s_a);
  const Vec2 d_rate = b.point_velocity(s_b) - a.point_velocity(s_a);
  return -(d.dot(a.centripetal(normal)) + 2.0 * a.direction_rate(normal).dot(d_rate) +
           n.dot(b.centripetal(s_b) - a.centripetal(s_a)));
}

/// Geometric stiffness of the on_line row for its multiplier: body a's share is
/// lambda (-n; perpendicular(n) . (P_b - x_a)) with x_a its centre, and its turn turns n.
template <class Out>
void on_line_stiffness(const Frame& a, const Vec2& normal, const Frame& b, const Vec2& s_b,
                       double lambda, Out& out) {
  const Vec2 n = a.direction(normal);
  const Vec2 turned = Planar::perpendicular(n);
  out[0].template topRightCorner<2, 1>() -= lambda * turned;
  out[0].template bottomLeftCorner<1, 2>() -= lambda * turned.transpose();
  out[0](2, 2) -= lambda * n.dot(b.point(s_b) - a.position);
  out[1] += lambda * b.point_jacobian_derivative(s_b, n);
}

}  // namespace odyn::planar::primitive
