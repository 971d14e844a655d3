#pragma once
// Gear pairs in either space, as couplings of joint coordinates (core/joint_coupling.hpp):
//   GearT        theta_b - theta_b0 = ratio (theta_a - theta_a0): two hinges' angles (spur,
//                bevel or worm gears, a belt; the ratio's sign says which way b turns);
//   RackPinionT  s - s0 = radius (theta - theta0): a slider's slide and a hinge's angle.
// Each couples existing joints' coordinates (their bodies and frames), measured as their drivers
// measure them. The multiplier is the torque (gear) or force (rack) the mesh passes on to the
// second joint's coordinate; the reactions report it on the bodies, and the outputs as the
// torque or force on each joint's coordinate.

#include <array>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/joint_coupling.hpp"
#include "odyn/core/parameter_blocks.hpp"

namespace odyn {

namespace parameters {

inline constexpr std::array<Parameter, 4> gear{{
    {"name", "name", nullptr, "", "the element's name"},
    {"joint_a", "turning_joint", nullptr, "", "the first gear's joint (its angle theta_a)"},
    {"joint_b", "turning_joint", nullptr, "", "the second gear's joint (its angle theta_b)"},
    {"ratio", "number", nullptr, "",
     "theta_b' / theta_a', nonzero; negative when b turns against a about axes pointing alike"},
}};

inline constexpr std::array<Parameter, 4> rack_pinion{{
    {"name", "name", nullptr, "", "the element's name"},
    {"pinion", "turning_joint", nullptr, "", "the pinion's joint (its angle theta)"},
    {"rack", "sliding_joint", nullptr, "", "the rack's joint (its slide s)"},
    {"radius", "number", nullptr, "m",
     "s' / theta': the pinion's pitch radius, nonzero, its sign the rack's direction"},
}};

inline constexpr std::array<Output, 4> gear_outputs{{
    {"angle_a", "rad", "the first joint's angle, counting turns"},
    {"angle_b", "rad", "the second joint's angle, counting turns"},
    {"torque_a", "N m",
     "the mesh's torque on the first gear (joint_a's body b) about its axis; the tooth force is "
     "it over the gear's pitch radius"},
    {"torque_b", "N m", "the mesh's torque on the second gear about its axis"},
}};

inline constexpr std::array<Output, 4> angle_and_slide{{
    {"angle", "rad", "the turning joint's angle, counting turns"},
    {"slide", "m", "the sliding joint's slide"},
    {"torque", "N m", "the coupling's torque on the turning joint's body b about its axis"},
    {"force", "N", "the coupling's force on the sliding joint's body b along its axis"},
}};

}  // namespace parameters

/// Two hinges' angles in a fixed ratio. Pair: the space's pair joint; Frame: its joint frame.
template <class Pair, class Frame>
class GearT : public JointCouplingT<Pair, 2> {
  using Base = JointCouplingT<Pair, 2>;

 public:
  using typename Base::Input;
  using typename Base::State;
  static constexpr ElementDescription description{
      "gear", "joint",
      "Gear pair: joint_b's angle turns by `ratio` times joint_a's, for any number of turns. 1 "
      "equation.",
      parameters::gear, parameters::gear_outputs};
  template <class Reader>
  static GearT from_parameters(Reader& r) {
    const auto name = parameter<std::string>(r, "name");
    return GearT(name, parameters::pair_joint<Pair, Frame>(r, "joint_a", name),
                 parameters::pair_joint<Pair, Frame>(r, "joint_b", name),
                 parameter<double>(r, "ratio"));
  }

  /// joint_a and joint_b: the pair joints (revolute or cylindrical) whose angles it couples.
  GearT(std::string name, const Pair& joint_a, const Pair& joint_b, double ratio)
      : Base(std::move(name), {typename Base::Term{joint_a, JointCoordinateKind::angle, -ratio},
                               typename Base::Term{joint_b, JointCoordinateKind::angle, 1.0}}) {
    this->require_nonzero(ratio, "ratio", "give theta_b' / theta_a', nonzero and finite");
  }

  double ratio() const { return -this->term(0).coefficient; }

  std::array<double, 4> outputs(const Input& in, const State& state,
                                const Eigen::Matrix<double, 1, 1>& lambda) const {
    return {this->coordinate(in, state, 0), this->coordinate(in, state, 1), this->effort(lambda, 0),
            this->effort(lambda, 1)};
  }
};

/// A slider's slide and a hinge's angle in a fixed ratio (the pinion's pitch radius).
template <class Pair, class Frame>
class RackPinionT : public JointCouplingT<Pair, 2> {
  using Base = JointCouplingT<Pair, 2>;

 public:
  using typename Base::Input;
  using typename Base::State;
  static constexpr ElementDescription description{
      "rack_pinion", "joint",
      "Rack and pinion: the rack's joint slides by `radius` times the pinion's joint angle. 1 "
      "equation.",
      parameters::rack_pinion, parameters::angle_and_slide};
  template <class Reader>
  static RackPinionT from_parameters(Reader& r) {
    const auto name = parameter<std::string>(r, "name");
    return RackPinionT(name, parameters::pair_joint<Pair, Frame>(r, "pinion", name),
                       parameters::pair_joint<Pair, Frame>(r, "rack", name),
                       parameter<double>(r, "radius"));
  }

  /// pinion: a revolute or cylindrical joint; rack: a translational or cylindrical joint.
  RackPinionT(std::string name, const Pair& pinion, const Pair& rack, double radius)
      : Base(std::move(name), {typename Base::Term{pinion, JointCoordinateKind::angle, -radius},
                               typename Base::Term{rack, JointCoordinateKind::slide, 1.0}}) {
    this->require_nonzero(radius, "radius", "give the pinion's pitch radius, nonzero and finite");
  }

  double radius() const { return -this->term(0).coefficient; }

  std::array<double, 4> outputs(const Input& in, const State& state,
                                const Eigen::Matrix<double, 1, 1>& lambda) const {
    return {this->coordinate(in, state, 0), this->coordinate(in, state, 1), this->effort(lambda, 0),
            this->effort(lambda, 1)};
  }
};

}  // namespace odyn
