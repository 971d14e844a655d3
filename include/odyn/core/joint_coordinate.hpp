#pragma once
// A scalar coordinate of a joint between two bodies (an angle, a slide) with its rate and its
// gradient: what a stop or a spring on that coordinate needs to act along it.

#include <Eigen/Core>

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

}  // namespace odyn
