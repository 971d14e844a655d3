#pragma once
// A planar rigid body: its mass, its moment of inertia and its initial state, as the user
// describes it. A moment of inertia of zero makes a point mass: the model stands a moment in
// for it (MasslessDirections), exact as long as nothing turns the body
// (analysis/massless_motion.hpp checks that nothing does).

#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "odyn/core/errors.hpp"
#include "odyn/core/planar.hpp"

namespace odyn::planar {

/// Whether a planar body lacks inertia (a point mass), and the moment the equations of motion
/// use instead: any positive one gives the same motion when nothing turns the body.
struct MasslessDirections {
  int count = 0;          // 0: a rigid body; 1: a point mass
  double stand_in = 0.0;  // kg m^2

  const char* what() const { return "point mass"; }
  double filled(double inertia) const { return count == 1 ? stand_in : inertia; }
  /// The part of an angular velocity about a massless direction, as a 1-vector.
  Eigen::Matrix<double, 1, 1> along(double angular_velocity) const {
    return Eigen::Matrix<double, 1, 1>(count == 1 ? angular_velocity : 0.0);
  }
};

struct Body {
  using Space = odyn::Planar;

  std::string name = {};
  double mass = 0.0;
  /// Moment of inertia about the centre of mass (kg m^2); zero for a point mass.
  double inertia = 0.0;
  /// Initial pose: centre of mass and angle (rad, counter-clockwise; it may exceed a turn).
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double angle = 0.0;
  /// Initial velocity: centre of mass and angular velocity.
  Eigen::Vector2d linear_velocity = Eigen::Vector2d::Zero();
  double angular_velocity = 0.0;
  /// Which of the 3 velocity components (x', y', phi') the user prescribes for assembly.
  /// Unset: the non-zero ones. Assembly keeps given components when the constraints allow it.
  std::optional<std::array<bool, 3>> velocity_given = std::nullopt;

  Space::Configuration configuration() const { return {position.x(), position.y(), angle}; }

  Space::Velocity velocity() const {
    return {linear_velocity.x(), linear_velocity.y(), angular_velocity};
  }

  std::array<bool, 3> given_components() const {
    if (velocity_given) return *velocity_given;
    const Space::Velocity v = velocity();
    return {v[0] != 0.0, v[1] != 0.0, v[2] != 0.0};
  }

  Space::MassBlock mass_block() const { return Space::mass_block(mass, inertia); }

  /// A point mass (no moment of inertia), or nowhere.
  MasslessDirections massless() const {
    return inertia == 0.0 ? MasslessDirections{1, mass * 1.0} : MasslessDirections{};
  }

  /// Throws ModelError if the body cannot be simulated.
  void validate() const {
    if (!(mass > 0.0) || !std::isfinite(mass))
      throw ModelError(name, "mass must be positive and finite, got " + to_text(mass) + " kg");
    if (!(inertia >= 0.0) || !std::isfinite(inertia))
      throw ModelError(name,
                       "moment of inertia must be positive and finite (or zero for a point "
                       "mass), got " +
                           to_text(inertia) + " kg m^2");
    if (!position.allFinite() || !std::isfinite(angle))
      throw ModelError(name, "initial pose contains NaN or infinity");
    if (!linear_velocity.allFinite() || !std::isfinite(angular_velocity))
      throw ModelError(name, "initial velocity contains NaN or infinity");
    if (inertia == 0.0 && angular_velocity != 0.0)
      throw ModelError(name,
                       "a point mass has no inertia to spin with, so it cannot be given an "
                       "angular velocity (" +
                           to_text(angular_velocity) + " rad/s) (see docs/bodies.md)");
  }
};

}  // namespace odyn::planar
