#pragma once
// Rotational spring-damper-actuator about a revolute axis between two bodies.
// With the joint angle theta (b's reference about a's axis, zero at the initial pose unless
// references are given) the torque on b about the axis is
//   T = -(k (theta - free_angle) + c theta' ) + actuator(t, theta, theta'),
// and -T acts on a. The angle counts whole turns: the last accepted angle is kept in the
// workspace so that a spring wound past +-pi keeps its torque.

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"

namespace odyn::spatial {

class Rsda : public PairJoint {
 public:
  using Actuator = std::function<double(double t, double angle, double rate)>;
  struct Parameters {
    double stiffness = 0.0;   // k, N m/rad
    double damping = 0.0;     // c, N m s/rad
    double free_angle = 0.0;  // rad
    Actuator actuator = {};   // extra torque on b about the axis, N m (optional)
  };
  struct State {
    double angle = 0.0;  // unwrapped angle at the last accepted step
  };

  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::frame_pair, parameters::rotational_spring);
  static constexpr std::array<Output, 3> output_list{{
      {"angle", "rad", "theta, counting whole turns"},
      {"rate", "rad/s", "theta'"},
      {"torque", "N m", "the torque on b about the axis"},
  }};
  static constexpr std::array<Output, 1> state_list{{
      {"angle", "rad", "the unwrapped angle at the last accepted step"},
  }};
  static constexpr ElementDescription description{
      "rsda",
      "force",
      "Rotational spring-damper-actuator about a's axis: torque on b -(k (theta - free_angle) + c "
      "theta') + actuator(t, theta, theta').",
      parameter_list,
      output_list,
      state_list};
  template <class Reader>
  static Rsda from_parameters(Reader& r) {
    return parameters::from_frame_pair<Rsda, JointFrame>(
        r, parameters::spring_law<Parameters>(r, "free_angle"));
  }

  Rsda(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
       const JointFrame& on_b, Parameters parameters)
      : PairJoint(std::move(name), body_a, on_a, body_b, on_b), p_(std::move(parameters)) {
    if (!std::isfinite(p_.stiffness) || !std::isfinite(p_.damping) || !std::isfinite(p_.free_angle))
      throw ModelError(name_, "stiffness, damping and free angle must be finite");
  }

  static std::array<double, 1> state_values(const State& state) { return {state.angle}; }
  State initial_state(const Input& in) const { return {wrapped_angle(in)}; }
  void advance(const Input& in, State& state) const { state.angle = angle(in, state); }

  /// Joint angle, continuous from the state's angle (the step is far below half a turn).
  double angle(const Input& in, const State& state) const {
    const double turn = 2.0 * std::numbers::pi;
    const double raw = wrapped_angle(in);
    return raw + turn * std::round((state.angle - raw) / turn);
  }

  double rate(const Input& in) const { return direction(in).dot(velocities(in)); }

  void evaluate(const Input& in, const State& state, ForceBlocks<Space, 2>& out) const {
    const Eigen::Matrix<double, 12, 1> e = direction(in);
    const double theta_rate = e.dot(velocities(in));
    // The angle (an atan2) only for a spring or an actuator: a pure damper, such as the engine's
    // load, runs in every residual evaluation.
    const bool needs_angle = p_.stiffness != 0.0 || static_cast<bool>(p_.actuator);
    const double theta = needs_angle ? angle(in, state) : 0.0;
    const double torque = torque_at(in.t, theta, theta_rate);
    out.force[0] = torque * e.head<6>();
    out.force[1] = torque * e.tail<6>();
  }

  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    const Eigen::Matrix<double, 12, 1> e = direction(in);
    out.stiffness = p_.stiffness * e * e.transpose();
    out.damping = p_.damping * e * e.transpose();
  }

  std::array<double, 3> outputs(const Input& in, const State& state) const {
    const double theta = angle(in, state), theta_rate = rate(in);
    return {theta, theta_rate, torque_at(in.t, theta, theta_rate)};
  }

  /// The spring's energy at the unwrapped angle, so that it stays continuous past +-pi.
  double potential_energy(const Input& in, const State& state) const {
    const double stretch = angle(in, state) - p_.free_angle;
    return 0.5 * p_.stiffness * stretch * stretch;
  }

 private:
  double torque_at(double t, double theta, double theta_rate) const {
    return -p_.stiffness * (theta - p_.free_angle) - p_.damping * theta_rate +
           (p_.actuator ? p_.actuator(t, theta, theta_rate) : 0.0);
  }
  double wrapped_angle(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Vector3d u_b = b.direction(on_b_.u);
    return std::atan2(a.direction(on_a_.v).dot(u_b), a.direction(on_a_.u).dot(u_b));
  }
  /// d(theta)/d(v_a, v_b): the axis, in each body's frame, on the angular parts.
  Eigen::Matrix<double, 12, 1> direction(const Input& in) const {
    const Eigen::Vector3d axis = in.body(0).direction(on_a_.w);
    Eigen::Matrix<double, 12, 1> e = Eigen::Matrix<double, 12, 1>::Zero();
    e.segment<3>(3) = -in.body(0).rotation.transpose() * axis;
    e.segment<3>(9) = in.body(1).rotation.transpose() * axis;
    return e;
  }
  Eigen::Matrix<double, 12, 1> velocities(const Input& in) const {
    Eigen::Matrix<double, 12, 1> v;
    v << in.body(0).linear_velocity, in.body(0).angular_velocity, in.body(1).linear_velocity,
        in.body(1).angular_velocity;
    return v;
  }

  Parameters p_;
};
static_assert(StatefulForce<Rsda>);

}  // namespace odyn::spatial
