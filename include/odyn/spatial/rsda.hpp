#pragma once
// Rotational spring-damper-actuator about a revolute axis between two bodies.
// With the joint angle theta (b's reference about a's axis, zero at the initial pose unless
// references are given) the torque on b about the axis is
//   T = -(k (theta - free_angle) + c theta' ) + actuator(t, theta, theta'),
// and -T acts on a. The angle counts whole turns (joint_angle.hpp), so that a spring wound past
// +-pi keeps its torque.

#include <cmath>
#include <functional>
#include <string>

#include "odyn/spatial/joint_angle.hpp"
#include "odyn/spatial/primitives.hpp"

namespace odyn::spatial {

class Rsda : public JointAngle {
 public:
  using Actuator = std::function<double(double t, double angle, double rate)>;
  struct Parameters {
    double stiffness = 0.0;   // k, N m/rad
    double damping = 0.0;     // c, N m s/rad
    double free_angle = 0.0;  // rad
    Actuator actuator = {};   // extra torque on b about the axis, N m (optional)
  };
  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::frame_pair, parameters::rotational_spring);
  static constexpr std::array<Output, 3> output_list{{
      {"angle", "rad", "theta, counting whole turns"},
      {"rate", "rad/s", "theta'"},
      {"torque", "N m", "the torque on b about the axis"},
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
      : JointAngle(std::move(name), body_a, on_a, body_b, on_b), p_(std::move(parameters)) {
    if (!std::isfinite(p_.stiffness) || !std::isfinite(p_.damping) || !std::isfinite(p_.free_angle))
      throw ModelError(name_, "stiffness, damping and free angle must be finite");
  }

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

  Parameters p_;
};
static_assert(StatefulForce<Rsda>);

}  // namespace odyn::spatial
