#pragma once
// Planar stops on a joint's coordinate (forces/joint_limit.hpp): on the joint angle
// (PairJoint::angle, which counts turns by itself), as a revolute joint turns (RevoluteLimit),
// or on the slide of b's point along a's axis, as a translational joint slides
// (TranslationalLimit). Each takes the joint's bodies and frames, or two bodies and frames of
// its own; the coordinates are measured as the joint's drivers and spring-dampers measure them.

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>

#include "odyn/forces/joint_limit.hpp"
#include "odyn/planar/revolute.hpp"
#include "odyn/planar/translational.hpp"

namespace odyn::planar {

/// A stop on the joint angle.
class RevoluteLimit : public PairJoint {
 public:
  static constexpr ElementDescription description{
      "revolute_limit",
      "force",
      "Stops on a revolute joint's angle: past a limit by delta, a torque k delta^n (1 + d "
      "delta') back towards it.",
      LimitDescription<true>::parameter_list,
      LimitDescription<true>::output_list,
      {},
      parameters::revolute_joints};
  /// From two bodies and their frames (a front end resolves `joint` into them).
  template <class Reader>
  static RevoluteLimit from_parameters(Reader& r) {
    return parameters::from_frame_pair<RevoluteLimit, JointFrame>(r, LimitLaw::read(r));
  }

  RevoluteLimit(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
                const JointFrame& on_b, LimitLaw law)
      : PairJoint(std::move(name), body_a, on_a, body_b, on_b), law_(law) {
    law_.check(name_);
  }
  /// Stops the angle of an existing revolute joint.
  RevoluteLimit(std::string name, const Revolute& joint, LimitLaw law)
      : PairJoint(joint), law_(law) {
    name_ = std::move(name);
    law_.check(name_);
  }

  const LimitLaw& law() const { return law_; }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    stop_force(law_, coordinate(in), out);
  }
  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    stop_jacobians(law_, coordinate(in), out);
  }
  std::array<double, 4> outputs(const Input& in) const {
    return stop_outputs(law_, coordinate(in));
  }
  double potential_energy(const Input& in) const { return law_.energy(angle(in)); }

 private:
  JointCoordinate<Space> coordinate(const Input& in) const {
    JointCoordinate<Space> x;
    x.value = angle(in);
    x.rate = angle_rate(in);
    x.direction << 0.0, 0.0, -1.0, 0.0, 0.0, 1.0;
    return x;
  }

  LimitLaw law_;
};

/// A stop on the slide of b's point along a's axis.
using TranslationalLimit = TranslationalLimitT<PairJoint, JointFrame, Translational>;

static_assert(StatelessForce<RevoluteLimit> && StatelessForce<TranslationalLimit>);

}  // namespace odyn::planar
