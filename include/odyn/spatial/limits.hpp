#pragma once
// Stops on a joint's coordinate (forces/joint_limit.hpp): on the angle of b about a's axis, as a
// revolute or cylindrical joint turns (RevoluteLimit), or on the slide of b's point along a's
// axis, as a translational or cylindrical joint slides (TranslationalLimit). Each takes the
// joint's bodies and frames, or two bodies and frames of its own; the coordinates are measured
// as the joint's drivers and spring-dampers measure them (zero at the initial pose unless the
// frames give references).

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <string>
#include <utility>

#include "odyn/forces/joint_limit.hpp"
#include "odyn/spatial/cylindrical.hpp"
#include "odyn/spatial/joint_angle.hpp"
#include "odyn/spatial/revolute.hpp"
#include "odyn/spatial/translational.hpp"

namespace odyn::spatial {

/// A stop on the angle of b about a's axis.
class RevoluteLimit : public JointAngle {
 public:
  static constexpr ElementDescription description{
      "revolute_limit",
      "force",
      "Stops on a revolute (or cylindrical) joint's angle: past a limit by delta, a torque k "
      "delta^n (1 + d delta') back towards it.",
      LimitDescription<true>::parameter_list,
      LimitDescription<true>::output_list,
      JointAngle::state_list,
      parameters::turning_joints};
  /// From two bodies and their frames (a front end resolves `joint` into them).
  template <class Reader>
  static RevoluteLimit from_parameters(Reader& r) {
    return parameters::from_frame_pair<RevoluteLimit, JointFrame>(r, LimitLaw::read(r));
  }

  RevoluteLimit(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
                const JointFrame& on_b, LimitLaw law)
      : JointAngle(std::move(name), body_a, on_a, body_b, on_b), law_(law) {
    law_.check(name_);
  }
  /// Stops the angle of an existing revolute or cylindrical joint.
  template <class Joint>
    requires std::same_as<Joint, Revolute> || std::same_as<Joint, Cylindrical>
  RevoluteLimit(std::string name, const Joint& joint, LimitLaw law) : JointAngle(joint), law_(law) {
    name_ = std::move(name);
    law_.check(name_);
  }

  const LimitLaw& law() const { return law_; }

  void evaluate(const Input& in, const State& state, ForceBlocks<Space, 2>& out) const {
    stop_force(law_, coordinate(in, state), out);
  }
  /// Newton blocks; the state keeps the angle's whole turns here too.
  void jacobians(const Input& in, const State& state, ForceBlocks<Space, 2>& out) const {
    stop_jacobians(law_, coordinate(in, state), out);
  }
  std::array<double, 4> outputs(const Input& in, const State& state) const {
    return stop_outputs(law_, coordinate(in, state));
  }
  double potential_energy(const Input& in, const State& state) const {
    return law_.energy(angle(in, state));
  }

 private:
  JointCoordinate<Space> coordinate(const Input& in, const State& state) const {
    JointCoordinate<Space> x;
    x.value = angle(in, state);
    x.direction = direction(in);
    x.set_rate(in);
    return x;
  }

  LimitLaw law_;
};

/// A stop on the slide of b's point along a's axis.
using TranslationalLimit = TranslationalLimitT<PairJoint, JointFrame, Translational, Cylindrical>;

static_assert(StatefulForce<RevoluteLimit> && StatelessForce<TranslationalLimit>);

}  // namespace odyn::spatial
