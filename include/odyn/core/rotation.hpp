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

/// Any unit vector perpendicular to the unit vector `axis` (deterministic choice).
inline Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& axis) {
  // Cross with the coordinate axis least aligned with `axis` for good conditioning.
  Eigen::Index smallest = 0;
  axis.cwiseAbs().minCoeff(&smallest);
  return axis.cross(Eigen::Vector3d::Unit(smallest)).normalized();
}

}  // namespace odyn
