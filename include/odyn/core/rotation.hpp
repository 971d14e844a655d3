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
  double cos_half, sin_half_over_angle;
  if (half < 0.1) {
    // The increments of a time step: Taylor series of cos(x) and sin(x)/x to x^8, whose
    // remainders (x^10/10!, x^10/11!) stay below half an ulp of 1 here, with no library call
    // and no 0/0 at zero.
    const double x2 = half * half;
    cos_half = 1.0 + x2 * (-1.0 / 2 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320))));
    const double sinc_half =
        1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880))));
    sin_half_over_angle = 0.5 * sinc_half;
  } else {
    cos_half = std::cos(half);
    sin_half_over_angle = std::sin(half) / angle;
  }
  return {cos_half, sin_half_over_angle * rotation_vector.x(),
          sin_half_over_angle * rotation_vector.y(), sin_half_over_angle * rotation_vector.z()};
}

/// Any unit vector perpendicular to the unit vector `axis` (deterministic choice).
inline Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& axis) {
  // Cross with the coordinate axis least aligned with `axis` for good conditioning.
  Eigen::Index smallest = 0;
  axis.cwiseAbs().minCoeff(&smallest);
  return axis.cross(Eigen::Vector3d::Unit(smallest)).normalized();
}

}  // namespace odyn
