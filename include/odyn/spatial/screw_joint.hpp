#pragma once
// A screw: b's point slides along a's axis by `pitch` for each turn of b about it,
// s - s0 = pitch (theta - theta0) / (2 pi), one equation (core/joint_coupling.hpp). With a
// cylindrical joint between the same frames it makes a lead screw or a nut; on its own it
// leaves the other five relative motions free (one equation removes one of the six).

#include <array>
#include <numbers>
#include <string>
#include <utility>

#include "odyn/core/gear_pairs.hpp"
#include "odyn/spatial/cylindrical.hpp"
#include "odyn/spatial/pair_joint.hpp"

namespace odyn::spatial {

inline constexpr std::array<Parameter, 7> screw_parameters =
    join(parameters::joint_or_frame_pair,
         std::array<Parameter, 1>{{{"pitch", "number", nullptr, "m",
                                    "the slide per turn, nonzero; negative for a left-handed "
                                    "thread"}}});

class ScrewJoint : public JointCouplingT<PairJoint, 2> {
  using Base = JointCouplingT<PairJoint, 2>;

 public:
  static constexpr ElementDescription description{
      "screw",
      "joint",
      "Screw: b slides along a's axis by `pitch` per turn of b about it (with a cylindrical "
      "joint: a lead screw). 1 equation.",
      screw_parameters,
      parameters::angle_and_slide,
      {},
      parameters::cylindrical_joints};
  /// From two bodies and their frames (a front end resolves `joint` into them).
  template <class Reader>
  static ScrewJoint from_parameters(Reader& r) {
    return parameters::from_frame_pair<ScrewJoint, JointFrame>(r, parameter<double>(r, "pitch"));
  }

  ScrewJoint(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
             const JointFrame& on_b, double pitch)
      : ScrewJoint(name, PairJoint(name, body_a, on_a, body_b, on_b), pitch) {}
  /// Couples the angle and the slide of an existing cylindrical joint.
  ScrewJoint(std::string name, const Cylindrical& joint, double pitch)
      : ScrewJoint(std::move(name), static_cast<const PairJoint&>(joint), pitch) {}

  double pitch() const { return -2.0 * std::numbers::pi * term(0).coefficient; }

  std::array<double, 4> outputs(const Input& in, const State& state,
                                const Eigen::Matrix<double, 1, 1>& lambda) const {
    return {coordinate(in, state, 0), coordinate(in, state, 1), effort(lambda, 0),
            effort(lambda, 1)};
  }

 private:
  ScrewJoint(std::string name, const PairJoint& joint, double pitch)
      : Base(std::move(name),
             {Term{joint, JointCoordinateKind::angle, -pitch / (2.0 * std::numbers::pi)},
              Term{joint, JointCoordinateKind::slide, 1.0}}) {
    require_nonzero(pitch, "pitch", "give the slide per turn, nonzero and finite");
  }
};

static_assert(StatefulConstraint<ScrewJoint>);

}  // namespace odyn::spatial
