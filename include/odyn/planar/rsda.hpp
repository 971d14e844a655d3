#pragma once
// Planar rotational spring-damper-actuator at a joint between two bodies. With the joint angle
// theta (PairJoint::angle: zero at the initial pose unless both axes are given) the torque on
// b is
//   T = -(k (theta - free_angle) + c theta') + actuator(t, theta, theta'),
// and -T acts on a. The planar angle counts turns by itself, so the element keeps no state.

#include <cmath>
#include <functional>
#include <string>

#include "odyn/planar/pair_joint.hpp"

namespace odyn::planar {

class Rsda : public PairJoint {
 public:
  using Actuator = std::function<double(double t, double angle, double rate)>;
  struct Parameters {
    double stiffness = 0.0;   // k, N m/rad
    double damping = 0.0;     // c, N m s/rad
    double free_angle = 0.0;  // rad
    Actuator actuator = {};   // extra torque on b, N m (optional)
  };

  /// The joint's points do not matter to the torque; only its axes (the angle's zero) do.
  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::frame_pair, parameters::rotational_spring);
  static constexpr std::array<Output, 3> output_list{{
      {"angle", "rad", "theta, counting whole turns"},
      {"rate", "rad/s", "theta'"},
      {"torque", "N m", "the torque on b"},
  }};
  static constexpr ElementDescription description{
      "rsda", "force",
      "Rotational spring-damper-actuator on the joint angle theta: torque on b -(k (theta - "
      "free_angle) + c theta') + actuator(t, theta, theta'), its opposite on a.",
      parameter_list, output_list};
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
  Rsda(std::string name, BodyId body_a, BodyId body_b, Parameters parameters)
      : Rsda(std::move(name), body_a, {}, body_b, {}, std::move(parameters)) {}

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    const double torque = torque_at(in.t, angle(in), angle_rate(in));
    out.force[0] << 0.0, 0.0, -torque;
    out.force[1] << 0.0, 0.0, torque;
  }

  void jacobians(const Input&, ForceBlocks<Space, 2>& out) const {
    Eigen::Matrix<double, 6, 1> e;  // d(theta)/d(v_a, v_b)
    e << 0.0, 0.0, -1.0, 0.0, 0.0, 1.0;
    out.stiffness = p_.stiffness * e * e.transpose();
    out.damping = p_.damping * e * e.transpose();
  }

  double potential_energy(const Input& in) const {
    const double stretch = angle(in) - p_.free_angle;
    return 0.5 * p_.stiffness * stretch * stretch;
  }

  std::array<double, 3> outputs(const Input& in) const {
    const double theta = angle(in), theta_rate = angle_rate(in);
    return {theta, theta_rate, torque_at(in.t, theta, theta_rate)};
  }

 private:
  double torque_at(double t, double theta, double theta_rate) const {
    return -p_.stiffness * (theta - p_.free_angle) - p_.damping * theta_rate +
           (p_.actuator ? p_.actuator(t, theta, theta_rate) : 0.0);
  }

  Parameters p_;
};
static_assert(StatelessForce<Rsda>);

}  // namespace odyn::planar
