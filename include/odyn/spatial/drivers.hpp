#pragma once
// Driving constraints: a joint's relative coordinate follows a prescribed motion g(t).
// The coordinate is zero at the initial pose unless the joint frames give reference directions.
//   RevoluteDriver:       angle of b's reference u_b about a's axis, from a's reference u_a.
//                         Phi = sin(angle - g) written as (v_a . u_b) cos g - (u_a . u_b) sin g,
//                         smooth for any number of turns.
//   TranslationalDriver:  displacement of b's point along a's axis: (w_a . d) - g = 0.

#include <cmath>
#include <string>

#include "odyn/core/motion.hpp"
#include "odyn/spatial/cylindrical.hpp"
#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/revolute.hpp"
#include "odyn/spatial/translational.hpp"

namespace odyn::spatial {

class RevoluteDriver : public PairJoint {
 public:
  static constexpr int num_equations = 1;
  static constexpr ElementDescription description{"revolute_driver",
                                                  "driver",
                                                  "Revolute driver: the angle of b about a's axis, "
                                                  "from a's reference, follows g(t). 1 equation.",
                                                  parameters::driver,
                                                  {},
                                                  {},
                                                  parameters::revolute_joints};
  /// From two bodies and their frames (a front end resolves `joint` into them).
  template <class Reader>
  static RevoluteDriver from_parameters(Reader& r) {
    return parameters::from_frame_pair<RevoluteDriver, JointFrame>(r,
                                                                   parameter<Motion>(r, "motion"));
  }

  RevoluteDriver(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
                 const JointFrame& on_b, Motion motion)
      : PairJoint(std::move(name), body_a, on_a, body_b, on_b), motion_(std::move(motion)) {
    motion_.require_complete(name_);
  }
  /// Drives the angle of an existing revolute joint (same bodies and frames).
  RevoluteDriver(std::string name, const Revolute& joint, Motion motion)
      : PairJoint(joint), motion_(std::move(motion)) {
    name_ = std::move(name);
    motion_.require_complete(name_);
  }

  void evaluate(const Input& in, BlocksOf<RevoluteDriver>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    const double g = motion_.position(in.t), g_rate = motion_.velocity(in.t);
    const double c = std::cos(g), s = std::sin(g);
    BlocksOf<RevoluteDriver> sine_part, cosine_part;
    primitive::dot1(a, on_a_.v, b, on_b_.u, sine_part, 0);
    primitive::dot1(a, on_a_.u, b, on_b_.u, cosine_part, 0);
    const double sin_angle = sine_part.phi[0], cos_angle = cosine_part.phi[0];
    out.phi[0] = sin_angle * c - cos_angle * s;
    out.jacobian[0] = c * sine_part.jacobian[0] - s * cosine_part.jacobian[0];
    out.jacobian[1] = c * sine_part.jacobian[1] - s * cosine_part.jacobian[1];
    out.phi_t[0] = -g_rate * (sin_angle * s + cos_angle * c);
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    const double g = motion_.position(in.t), g1 = motion_.velocity(in.t),
                 g2 = motion_.acceleration(in.t);
    const double c = std::cos(g), s = std::sin(g);
    // Derivatives of c = cos g and s = sin g along the motion.
    const double c1 = -s * g1, s1 = c * g1;
    const double c2 = -c * g1 * g1 - s * g2, s2 = -s * g1 * g1 + c * g2;
    BlocksOf<RevoluteDriver> unused;
    primitive::dot1(a, on_a_.v, b, on_b_.u, unused, 0);
    const double d1 = unused.phi[0];
    primitive::dot1(a, on_a_.u, b, on_b_.u, unused, 0);
    const double d2 = unused.phi[0];
    const double d1_rate = primitive::dot1_rate(a, on_a_.v, b, on_b_.u);
    const double d2_rate = primitive::dot1_rate(a, on_a_.u, b, on_b_.u);
    const double value = c * primitive::dot1_gamma(a, on_a_.v, b, on_b_.u) -
                         s * primitive::dot1_gamma(a, on_a_.u, b, on_b_.u) -
                         2.0 * (c1 * d1_rate - s1 * d2_rate) - (c2 * d1 - s2 * d2);
    return Eigen::Matrix<double, 1, 1>(value);
  }

  const Motion& motion() const { return motion_; }

 private:
  Motion motion_;
};
static_assert(Constraint<RevoluteDriver>);

class TranslationalDriver : public PairJoint {
 public:
  static constexpr int num_equations = 1;
  static constexpr ElementDescription description{
      "translational_driver",
      "driver",
      "Translational driver: the slide of b's point along a's axis follows g(t). 1 equation.",
      parameters::driver,
      {},
      {},
      parameters::sliding_joints};
  /// From two bodies and their frames (a front end resolves `joint` into them).
  template <class Reader>
  static TranslationalDriver from_parameters(Reader& r) {
    return parameters::from_frame_pair<TranslationalDriver, JointFrame>(
        r, parameter<Motion>(r, "motion"));
  }

  TranslationalDriver(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
                      const JointFrame& on_b, Motion motion)
      : PairJoint(std::move(name), body_a, on_a, body_b, on_b), motion_(std::move(motion)) {
    motion_.require_complete(name_);
  }
  /// Drives the slide of an existing translational or cylindrical joint.
  template <class Joint>
  requires std::same_as<Joint, Translational> || std::same_as<Joint, Cylindrical>
  TranslationalDriver(std::string name, const Joint& joint, Motion motion)
      : PairJoint(joint), motion_(std::move(motion)) {
    name_ = std::move(name);
    motion_.require_complete(name_);
  }

  void evaluate(const Input& in, BlocksOf<TranslationalDriver>& out) const {
    primitive::dot2(in.body(0), on_a_.w, on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi[0] -= motion_.position(in.t);
    out.phi_t[0] = -motion_.velocity(in.t);
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    return Eigen::Matrix<double, 1, 1>(
        primitive::dot2_gamma(in.body(0), on_a_.w, on_a_.point, in.body(1), on_b_.point) +
        motion_.acceleration(in.t));
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 1, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::dot2_stiffness(in.body(0), on_a_.w, in.body(1), on_b_.point, lambda[0], out);
  }

  const Motion& motion() const { return motion_; }

 private:
  Motion motion_;
};
static_assert(Constraint<TranslationalDriver>);

}  // namespace odyn::spatial
