#pragma once
// A spatial rigid body: its inertia and its initial state, as the user describes it.

#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "odyn/core/errors.hpp"
#include "odyn/core/spatial.hpp"
#include "odyn/linalg/symmetric_eigenvalues.hpp"

namespace odyn::spatial {

struct Body {
  using Space = odyn::Spatial;

  std::string name = {};
  double mass = 0.0;
  /// Inertia tensor about the centre of mass, in body axes (kg m^2).
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  /// Initial pose: centre of mass and body-to-global orientation.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// Initial velocity: centre of mass (global) and angular velocity (body frame).
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  /// Which of the 6 velocity components the user prescribes for assembly (linear, angular).
  /// Unset: the non-zero ones. Assembly keeps given components when the constraints allow it.
  std::optional<std::array<bool, 6>> velocity_given = std::nullopt;

  /// Inertia from principal moments about body axes.
  static Eigen::Matrix3d principal(double ixx, double iyy, double izz) {
    return Eigen::Vector3d(ixx, iyy, izz).asDiagonal();
  }

  Space::Configuration configuration() const {
    Space::Configuration q;
    const Eigen::Quaterniond unit = orientation.normalized();
    q << position, unit.w(), unit.x(), unit.y(), unit.z();
    return q;
  }

  Space::Velocity velocity() const {
    Space::Velocity v;
    v << linear_velocity, angular_velocity;
    return v;
  }

  std::array<bool, 6> given_components() const {
    if (velocity_given) return *velocity_given;
    std::array<bool, 6> given{};
    const Space::Velocity v = velocity();
    for (int i = 0; i < 6; ++i) given[i] = v[i] != 0.0;
    return given;
  }

  Space::MassBlock mass_block() const { return Space::mass_block(mass, inertia); }

  /// Throws ModelError if the body cannot be simulated.
  void validate() const {
    if (!(mass > 0.0) || !std::isfinite(mass))
      throw ModelError(name, "mass must be positive and finite, got " + to_text(mass) + " kg");
    if (!inertia.allFinite()) throw ModelError(name, "inertia contains a non-finite value");
    if ((inertia - inertia.transpose()).norm() > 1e-12 * inertia.norm())
      throw ModelError(name, "inertia tensor must be symmetric");
    const Eigen::Vector3d moments = symmetric_eigenvalues(inertia);
    if (!(moments.minCoeff() > 0.0))
      throw ModelError(name, "inertia must be positive definite; principal moments are (" +
                                 to_text(moments.transpose()) + ") kg m^2");
    // Each principal moment is a sum of two others' mass distributions: J1 <= J2 + J3.
    const double slack = 1e-9 * moments.sum();
    if (moments[2] > moments[0] + moments[1] + slack)
      throw ModelError(name, "principal moments (" + to_text(moments.transpose()) +
                                 ") violate the triangle inequality J3 <= J1 + J2; no "
                                 "physical body has them");
    if (!position.allFinite() || !orientation.coeffs().allFinite())
      throw ModelError(name, "initial pose contains NaN or infinity");
    if (orientation.norm() < 1e-12)
      throw ModelError(name, "initial orientation quaternion has zero length");
    if (!linear_velocity.allFinite() || !angular_velocity.allFinite())
      throw ModelError(name, "initial velocity contains NaN or infinity");
  }
};

}  // namespace odyn::spatial
