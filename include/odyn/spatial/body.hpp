#pragma once
// A spatial rigid body: its inertia and its initial state, as the user describes it. A body may
// lack inertia in some directions: a point mass in every one, a slender rod about its axis. The
// model then stands a moment in for the missing one (MasslessDirections), which is exact as long
// as nothing turns the body that way; analysis/massless_motion.hpp checks that nothing does.

#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "odyn/core/errors.hpp"
#include "odyn/core/spatial.hpp"
#include "odyn/linalg/symmetric_eigenvalues.hpp"

namespace odyn::spatial {

/// The directions in which a body has no inertia, and the moment the equations of motion use
/// about them instead. Any positive moment gives the same motion when no joint or force turns
/// the body that way: its spin there stays zero, and the stand-in carries no energy.
struct MasslessDirections {
  int count = 0;  // 0: a rigid body; 1: a slender rod (its axis); 3: a point mass (all)
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // a rod's axis, in body coordinates
  double stand_in = 0.0;                           // kg m^2

  const char* what() const { return count == 3 ? "point mass" : "slender rod"; }
  /// The inertia with the stand-in moment about the massless directions.
  Eigen::Matrix3d filled(const Eigen::Matrix3d& inertia) const {
    if (count == 3) return stand_in * Eigen::Matrix3d::Identity();
    if (count == 1) return inertia + stand_in * axis * axis.transpose();
    return inertia;
  }
  /// The part of an angular velocity (body axes) along the massless directions.
  Eigen::Vector3d along(const Eigen::Vector3d& angular_velocity) const {
    if (count == 3) return angular_velocity;
    if (count == 1) return axis * axis.dot(angular_velocity);
    return Eigen::Vector3d::Zero();
  }
};

struct Body {
  using Space = odyn::Spatial;

  std::string name = {};
  double mass = 0.0;
  /// Inertia tensor about the centre of mass, in body axes (kg m^2). Zero for a point mass; a
  /// slender rod's is zero about its axis, its two other moments equal (slender_rod).
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
  /// A slender rod's inertia: m L^2 / 12 about every axis across it, none about `axis` (body
  /// coordinates, along the rod).
  static Eigen::Matrix3d slender_rod(double mass, double length,
                                     const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ()) {
    const Eigen::Vector3d u = axis.normalized();
    return mass * length * length / 12.0 * (Eigen::Matrix3d::Identity() - u * u.transpose());
  }

  /// Where the body has no inertia: a point mass (all moments zero), a slender rod (one zero
  /// moment, about its axis), or nowhere. Moments below 1e-12 of the largest count as zero.
  MasslessDirections massless() const {
    MasslessDirections out;
    const Eigen::Vector3d moments = symmetric_eigenvalues(inertia);  // ascending
    if (moments[2] == 0.0) {
      out.count = 3;
      out.stand_in = mass * 1.0;  // m times 1 m^2: any positive moment would do
    } else if (moments[0] <= 1e-12 * moments[2]) {
      // A rod's inertia is I (1 - u u^T): the axis u is along the largest column of I - J.
      const Eigen::Matrix3d rest = moments[2] * Eigen::Matrix3d::Identity() - inertia;
      int column = 0;
      rest.colwise().norm().maxCoeff(&column);
      out.count = 1;
      out.axis = rest.col(column).normalized();
      out.stand_in = moments[2];
    }
    return out;
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
    if (!(moments[0] > 0.0) && !(moments[0] >= -1e-12 * moments[2]))
      throw ModelError(name,
                       "inertia must be positive definite (or zero for a point mass, or "
                       "zero about a slender rod's axis); principal moments are (" +
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
    const MasslessDirections missing = massless();
    if (missing.along(angular_velocity).norm() > 1e-12 * angular_velocity.norm())
      throw ModelError(name, std::string("a ") + missing.what() + " has no inertia to spin " +
                                 (missing.count == 3 ? "with" : "about its axis") +
                                 ", so it cannot be given an angular velocity (" +
                                 to_text(angular_velocity.transpose()) + " rad/s) " +
                                 (missing.count == 3 ? "" : "along its axis ") +
                                 "(see docs/bodies.md)");
  }
};

}  // namespace odyn::spatial
