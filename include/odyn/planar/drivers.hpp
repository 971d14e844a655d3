#pragma once
// Planar driving constraints: a joint's relative coordinate follows a prescribed motion g(t).
//   RevoluteDriver:       the joint angle (PairJoint::angle) minus g(t) = 0. The angle is a
//                         difference of body angles, so the equation is linear and holds for
//                         any number of turns.
//   TranslationalDriver:  displacement of b's point along a's axis, from a's point, minus g(t).

#include <string>

#include "odyn/core/motion.hpp"
#include "odyn/planar/pair_joint.hpp"
#include "odyn/planar/primitives.hpp"
#include "odyn/planar/revolute.hpp"
#include "odyn/planar/translational.hpp"

namespace odyn::planar {

class RevoluteDriver : public PairJoint {
 public:
  static constexpr int num_equations = 1;
  static constexpr ElementDescription description{
      "revolute_driver",
      "driver",
      "Revolute driver: the joint angle (b's angle minus a's, from the axes) follows g(t). 1 "
      "equation.",
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
    out.phi[0] = angle(in) - motion_.position(in.t);
    angle_row(out, 0);
    out.phi_t[0] = -motion_.velocity(in.t);
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    return Eigen::Matrix<double, 1, 1>(motion_.acceleration(in.t));
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
      "Translational driver: the slide of b's point along a's axis, from a's point, follows g(t). "
      "1 equation.",
      parameters::driver,
      {},
      {},
      parameters::translational_joints};
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
  /// Drives the slide of an existing translational joint.
  TranslationalDriver(std::string name, const Translational& joint, Motion motion)
      : PairJoint(joint), motion_(std::move(motion)) {
    name_ = std::move(name);
    motion_.require_complete(name_);
  }

  void evaluate(const Input& in, BlocksOf<TranslationalDriver>& out) const {
    primitive::on_line(in.body(0), on_a_.axis, on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi[0] -= motion_.position(in.t);
    out.phi_t[0] = -motion_.velocity(in.t);
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    return Eigen::Matrix<double, 1, 1>(
        primitive::on_line_gamma(in.body(0), on_a_.axis, on_a_.point, in.body(1), on_b_.point) +
        motion_.acceleration(in.t));
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 1, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::on_line_stiffness(in.body(0), on_a_.axis, in.body(1), on_b_.point, lambda[0], out);
  }

  const Motion& motion() const { return motion_; }

 private:
  Motion motion_;
};
static_assert(Constraint<TranslationalDriver>);

}  // namespace odyn::planar
