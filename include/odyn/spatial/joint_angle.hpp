#pragma once
// The angle of b about a's joint axis (w), from a's reference direction (u) to b's, between two
// bodies: what a rotational spring or a stop on a revolute joint acts on. It counts whole turns:
// an element that uses it keeps the last accepted angle as its state, so that the angle stays
// continuous past +-pi (a step turns far less than half a turn).

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>

#include "odyn/core/description.hpp"
#include "odyn/core/joint_coordinate.hpp"
#include "odyn/spatial/pair_joint.hpp"

namespace odyn::spatial {

class JointAngle : public PairJoint {
 public:
  struct State {
    double angle = 0.0;  // unwrapped angle at the last accepted step
  };

  static constexpr std::array<Output, 1> state_list{{
      {"angle", "rad", "the unwrapped angle at the last accepted step"},
  }};

  using PairJoint::PairJoint;
  /// At an existing joint: its bodies and frames.
  explicit JointAngle(const PairJoint& joint) : PairJoint(joint) {}

  static std::array<double, 1> state_values(const State& state) { return {state.angle}; }
  State initial_state(const Input& in) const { return {wrapped_angle(in)}; }
  void advance(const Input& in, State& state) const { state.angle = angle(in, state); }

  /// The angle, continuous from the state's angle.
  double angle(const Input& in, const State& state) const {
    const double turn = 2.0 * std::numbers::pi;
    const double raw = wrapped_angle(in);
    return raw + turn * std::round((state.angle - raw) / turn);
  }

  double rate(const Input& in) const { return direction(in).dot(velocities(in)); }

  /// Each step must turn the angle by less than half a turn (see turn_step_limit).
  double step_limit(const Input& in, const State&) const { return turn_step_limit(rate(in)); }

 protected:
  /// The angle within (-pi, pi].
  double wrapped_angle(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Vector3d u_b = b.direction(on_b_.u);
    return std::atan2(a.direction(on_a_.v).dot(u_b), a.direction(on_a_.u).dot(u_b));
  }
  /// d(angle)/d(v_a, v_b): the axis, in each body's frame, on the angular parts.
  Eigen::Matrix<double, 12, 1> direction(const Input& in) const {
    const Eigen::Vector3d axis = in.body(0).direction(on_a_.w);
    Eigen::Matrix<double, 12, 1> e = Eigen::Matrix<double, 12, 1>::Zero();
    e.segment<3>(3) = -in.body(0).rotation.transpose() * axis;
    e.segment<3>(9) = in.body(1).rotation.transpose() * axis;
    return e;
  }
  static Eigen::Matrix<double, 12, 1> velocities(const Input& in) {
    Eigen::Matrix<double, 12, 1> v;
    v << in.body(0).linear_velocity, in.body(0).angular_velocity, in.body(1).linear_velocity,
        in.body(1).angular_velocity;
    return v;
  }
};

}  // namespace odyn::spatial
