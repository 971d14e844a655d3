#pragma once
// A scalar coordinate of a joint between two bodies (an angle, a slide) with its rate and its
// gradient, as a stop or a spring on it acts along it; or with its gamma, as a constraint that
// couples it to others writes it.

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "odyn/core/element.hpp"

namespace odyn {

/// A joint coordinate between two bodies: its value, its rate and its gradient with respect to
/// both bodies' velocities (the direction along which a stop's push acts on them).
template <class Space>
struct JointCoordinate {
  double value = 0.0, rate = 0.0;
  Eigen::Matrix<double, 2 * Space::nv, 1> direction;

  /// The rate from the bodies' velocities.
  void set_rate(const ElementInput<Space, 2>& in) {
    Eigen::Matrix<double, 2 * Space::nv, 1> v;
    v << in.body(0).linear_velocity, in.body(0).angular_velocity, in.body(1).linear_velocity,
        in.body(1).angular_velocity;
    rate = direction.dot(v);
  }
};

/// The longest step for an angle turning at `rate` whose element counts whole turns from its last
/// accepted angle (and so needs each step to turn it by less than half a turn): half a radian at
/// the step's rate, which leaves room for the turn the step's acceleration adds while the error
/// control grows the step (under 2 rad in all, even spinning up from rest).
inline double turn_step_limit(double rate) {
  return rate == 0.0 ? std::numeric_limits<double>::infinity() : 0.5 / std::abs(rate);
}

/// A joint coordinate as a constraint row: its value, its gradient with respect to both
/// bodies' velocities (a's block, then b's) and its gamma, the part of its second derivative
/// that the accelerations leave, with the sign changed (x'' = gradient . v' - gamma).
template <class Space>
struct JointRow {
  double value = 0.0, gamma = 0.0;
  Eigen::Matrix<double, 2 * Space::nv, 1> gradient;
};

}  // namespace odyn
