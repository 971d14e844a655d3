#pragma once
// The basic constraint equations from which the spatial joints are built (Haug's catalogue,
// written for body-frame angular velocities), beside the point constraints every space
// shares (odyn/core/point_constraints.hpp). Each writes rows of an element's blocks:
//   dot1        1 row   (R_a u) . (R_b w) = 0          (two body vectors stay perpendicular)
//   dot2        1 row   (R_a u) . (P_b - P_a) = 0      (a point stays in a plane of body a)
// and the matching rows of gamma, the part of Phi-ddot that does not involve accelerations,
// with its sign changed, and of the geometric stiffness for the row's multiplier (see
// GeometricStiffness in odyn/core/element.hpp).

#include <Eigen/Core>

#include "odyn/core/point_constraints.hpp"
#include "odyn/core/spatial.hpp"

namespace odyn::spatial::primitive {

using Vec3 = Eigen::Vector3d;
using Frame = Spatial::Frame;

// Shared with every body space: coincident points and point distance.
using odyn::primitive::coincident;
using odyn::primitive::coincident_gamma;
using odyn::primitive::coincident_stiffness;
using odyn::primitive::distance;
using odyn::primitive::distance_gamma;
using odyn::primitive::distance_stiffness;

/// Gradient of (R u) . g with respect to the body-frame angular velocity: u x (R^T g).
inline Vec3 turn_gradient(const Frame& f, const Vec3& u, const Vec3& global) {
  return u.cross(f.rotation.transpose() * global);
}

template <class Blocks>
void dot1(const Frame& a, const Vec3& u, const Frame& b, const Vec3& w, Blocks& out, int row,
          double scale = 1.0) {
  const Vec3 U = a.direction(u), W = b.direction(w);
  out.phi[row] = scale * U.dot(W);
  out.jacobian[0].row(row).template head<3>().setZero();
  out.jacobian[0].row(row).template tail<3>() = scale * turn_gradient(a, u, W).transpose();
  out.jacobian[1].row(row).template head<3>().setZero();
  out.jacobian[1].row(row).template tail<3>() = scale * turn_gradient(b, w, U).transpose();
}

/// d(turn_gradient(f, u, g))/d(body-frame rotation) for a fixed global g.
inline Eigen::Matrix3d turn_hessian(const Frame& f, const Vec3& u, const Vec3& global) {
  return skew(u) * skew(f.rotation.transpose() * global);
}

template <class Out>
void dot1_stiffness(const Frame& a, const Vec3& u, const Frame& b, const Vec3& w, double lambda,
                    Out& out) {
  out[0].template bottomRightCorner<3, 3>() += lambda * turn_hessian(a, u, b.direction(w));
  out[1].template bottomRightCorner<3, 3>() += lambda * turn_hessian(b, w, a.direction(u));
}

inline double dot1_rate(const Frame& a, const Vec3& u, const Frame& b, const Vec3& w) {
  return a.direction_rate(u).dot(b.direction(w)) + a.direction(u).dot(b.direction_rate(w));
}

inline double dot1_gamma(const Frame& a, const Vec3& u, const Frame& b, const Vec3& w) {
  const Vec3 U = a.direction(u), W = b.direction(w);
  return -(W.dot(a.centripetal(u)) + U.dot(b.centripetal(w)) +
           2.0 * a.direction_rate(u).dot(b.direction_rate(w)));
}

template <class Blocks>
void dot2(const Frame& a, const Vec3& u, const Vec3& s_a, const Frame& b, const Vec3& s_b,
          Blocks& out, int row) {
  const Vec3 U = a.direction(u);
  const Vec3 d = b.point(s_b) - a.point(s_a);
  out.phi[row] = U.dot(d);
  out.jacobian[0].row(row).template head<3>() = -U.transpose();
  out.jacobian[0].row(row).template tail<3>() =
      (turn_gradient(a, u, d) - s_a.cross(a.rotation.transpose() * U)).transpose();
  out.jacobian[1].row(row).template head<3>() = U.transpose();
  out.jacobian[1].row(row).template tail<3>() = s_b.cross(b.rotation.transpose() * U).transpose();
}

inline double dot2_gamma(const Frame& a, const Vec3& u, const Vec3& s_a, const Frame& b,
                         const Vec3& s_b) {
  const Vec3 U = a.direction(u);
  const Vec3 d = b.point(s_b) - a.point(s_a);
  const Vec3 d_rate = b.point_velocity(s_b) - a.point_velocity(s_a);
  return -(d.dot(a.centripetal(u)) + 2.0 * a.direction_rate(u).dot(d_rate) +
           U.dot(b.centripetal(s_b) - a.centripetal(s_a)));
}

/// Body a's share is lambda (-U; u x R_a^T (P_b - x_a)) with x_a its centre (the term of
/// P_a's own turn, u . s_a, does not change): its rotation turns U and the lever.
template <class Out>
void dot2_stiffness(const Frame& a, const Vec3& u, const Frame& b, const Vec3& s_b, double lambda,
                    Out& out) {
  const Vec3 U = a.direction(u);
  const Eigen::Matrix3d u_cross = skew(u);
  out[0].template topRightCorner<3, 3>() += lambda * a.rotation * u_cross;
  out[0].template bottomLeftCorner<3, 3>() -= lambda * u_cross * a.rotation.transpose();
  out[0].template bottomRightCorner<3, 3>() +=
      lambda * turn_hessian(a, u, b.point(s_b) - a.position);
  out[1] += lambda * b.point_jacobian_derivative(s_b, U);
}

}  // namespace odyn::spatial::primitive
