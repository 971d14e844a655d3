#pragma once
// Small rotation-group helpers shared by the spatial elements and the integrators.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace odyn {

/// Cross-product matrix: skew(a) * b == a.cross(b).
inline Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}

/// Exponential map of so(3) to a unit quaternion, exact for any angle.
inline Eigen::Quaterniond quaternion_exp(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  const double half = 0.5 * angle;
  // sin(x)/x by its Taylor series near zero avoids 0/0 for tiny increments.
  const double sinc_half = angle < 1e-4 ? 0.5 - angle * angle / 48.0 : std::sin(half) / angle;
  return {std::cos(half), sinc_half * rotation_vector.x(), sinc_half * rotation_vector.y(),
          sinc_half * rotation_vector.z()};
}

/// Logarithm of a rotation matrix: the rotation vector (axis times angle, angle in [0, pi]).
inline Eigen::Vector3d rotation_log(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond q(rotation);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // the shorter way round
  const double sine_half = q.vec().norm();
  // angle / sin(angle / 2) by its Taylor series near zero, where the quotient is 0/0.
  const double angle = 2.0 * std::atan2(sine_half, q.w());
  const double scale = sine_half < 1e-6 ? 2.0 / q.w() : angle / sine_half;
  return scale * q.vec();
}

/// Inverse of SO(3)'s left Jacobian at the rotation vector theta: with R = exp(theta), the
/// rate theta' = J_l^{-1}(theta) omega for the angular velocity omega (R' R^T = skew(omega)).
inline Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  // 1/a^2 - (1 + cos a) / (2 a sin a) = 1/a^2 - 1 / (2 a tan(a/2)), finite up to a = pi; by
  // its series near zero, where the two terms cancel.
  const double a2 = angle * angle;
  const double coefficient = angle < 1e-2 ? 1.0 / 12.0 + a2 / 720.0 + a2 * a2 / 30240.0
                                          : 1.0 / a2 - 1.0 / (2.0 * angle * std::tan(0.5 * angle));
  const Eigen::Matrix3d s = skew(theta);
  return Eigen::Matrix3d::Identity() - 0.5 * s + coefficient * s * s;
}

/// Any unit vector perpendicular to the unit vector `axis` (deterministic choice).
inline Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& axis) {
  // Cross with the coordinate axis least aligned with `axis` for good conditioning.
  Eigen::Index smallest = 0;
  axis.cwiseAbs().minCoeff(&smallest);
  return axis.cross(Eigen::Vector3d::Unit(smallest)).normalized();
}

}  // namespace odyn
