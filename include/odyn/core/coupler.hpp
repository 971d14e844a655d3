#pragma once
// A coupler in either space (ADAMS's COUPLER): a linear relation among two or three joints'
// coordinates,
//   scale_1 (x_1 - x_10) + scale_2 (x_2 - x_20) [+ scale_3 (x_3 - x_30)] = 0,
// x_i a hinge's angle or a slider's slide (a cylindrical joint has both), x_i0 its value at the
// initial pose. A gear mesh seen from a moving carrier is such a relation among three joints (the
// planet's on the carrier, the sun's and the carrier's), so planetary and differential gear
// trains are built from couplers. The multiplier's effort on each coordinate is what the
// coupling passes on to it: a torque on an angle, a force on a slide.

#include <array>
#include <optional>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/ids.hpp"
#include "odyn/core/joint_coupling.hpp"
#include "odyn/core/parameter_blocks.hpp"

namespace odyn {

namespace parameters {

inline constexpr std::array<Parameter, 10> coupler{{
    {"name", "name", nullptr, "", "the element's name"},
    {"joint_1", "coupled_joint", nullptr, "", "the first joint (its coordinate x_1)"},
    {"coordinate_1", "coordinate", "null", "",
     "x_1: \"angle\" or \"slide\"; null: the joint's own (a cylindrical joint needs one)"},
    {"scale_1", "number", nullptr, "", "c_1, nonzero (per rad of an angle, per m of a slide)"},
    {"joint_2", "coupled_joint", nullptr, "", "the second joint (its coordinate x_2)"},
    {"coordinate_2", "coordinate", "null", "", "x_2: as coordinate_1"},
    {"scale_2", "number", nullptr, "", "c_2, nonzero"},
    {"joint_3", "optional_coupled_joint", "null", "", "a third joint (x_3), or null for two"},
    {"coordinate_3", "coordinate", "null", "", "x_3: as coordinate_1 (with joint_3)"},
    {"scale_3", "optional_number", "null", "", "c_3, nonzero (with joint_3)"},
}};

inline constexpr std::array<Output, 6> coupler_outputs{{
    {"coordinate_1", "rad or m", "the first joint's angle (counting turns) or slide"},
    {"coordinate_2", "rad or m", "the second joint's angle or slide"},
    {"coordinate_3", "rad or m", "the third joint's angle or slide (0 without one)"},
    {"effort_1", "N m or N",
     "what the coupler passes on to the first joint's coordinate: a torque on its body b about "
     "the axis, or a force along it"},
    {"effort_2", "N m or N", "the same on the second joint's coordinate"},
    {"effort_3", "N m or N", "the same on the third joint's coordinate (0 without one)"},
}};

}  // namespace parameters

/// Two or three joints' coordinates in a linear relation. Pair: the space's pair joint; Frame:
/// its joint frame.
template <class Pair, class Frame>
class CouplerT : public JointCouplingT<Pair, 3> {
  using Base = JointCouplingT<Pair, 3>;

 public:
  using typename Base::Input;
  using typename Base::State;
  /// One coupled coordinate: a joint (revolute, translational or cylindrical, as its pair-joint
  /// base), which of its coordinates, and its scale c_i.
  using Coordinate = typename Base::Term;

  static constexpr ElementDescription description{
      "coupler", "joint",
      "Coupler: scale_1 (x_1 - x_10) + scale_2 (x_2 - x_20) [+ scale_3 (x_3 - x_30)] = 0, x_i "
      "the angle or slide of two or three joints, for any number of turns. 1 equation.",
      parameters::coupler, parameters::coupler_outputs};

  template <class Reader>
  static CouplerT from_parameters(Reader& r) {
    const auto name = parameter<std::string>(r, "name");
    const auto kind = [&](const char* key) {
      const auto given = parameter<std::optional<JointCoordinateKind>>(r, key);
      if (!given)
        throw ModelError(name, std::string(key) + " is not given; give \"angle\" or \"slide\"");
      return *given;
    };
    const Coordinate first{parameters::pair_joint<Pair, Frame>(r, "joint_1", name),
                           kind("coordinate_1"), parameter<double>(r, "scale_1")};
    const Coordinate second{parameters::pair_joint<Pair, Frame>(r, "joint_2", name),
                            kind("coordinate_2"), parameter<double>(r, "scale_2")};
    const auto third = parameter<std::optional<parameters::JointReference<Frame>>>(r, "joint_3");
    const auto third_kind = parameter<std::optional<JointCoordinateKind>>(r, "coordinate_3");
    const auto third_scale = parameter<std::optional<double>>(r, "scale_3");
    if (!third) {
      if (third_scale || third_kind)
        throw ModelError(name, std::string(third_scale ? "scale_3" : "coordinate_3") +
                                   " is given without joint_3; give joint_3 too, or leave both "
                                   "out for a coupler of two joints");
      return CouplerT(name, first, second);
    }
    if (!third_scale)
      throw ModelError(name, "joint_3 is given without scale_3; give its scale, nonzero");
    const Pair joint(name, third->body_a, third->on_a, third->body_b, third->on_b);
    return CouplerT(name, first, second, Coordinate{joint, kind("coordinate_3"), *third_scale});
  }

  /// A coupler of two joints: c_1 (x_1 - x_10) + c_2 (x_2 - x_20) = 0.
  CouplerT(std::string name, const Coordinate& first, const Coordinate& second)
      : Base(name, {first, second, absent(name)}, 2) {
    check_scales();
  }
  /// A coupler of three joints.
  CouplerT(std::string name, const Coordinate& first, const Coordinate& second,
           const Coordinate& third)
      : Base(std::move(name), {first, second, third}, 3) {
    check_scales();
  }

  double scale(int i) const { return this->term(i).coefficient; }

  std::array<double, 6> outputs(const Input& in, const State& state,
                                const Eigen::Matrix<double, 1, 1>& lambda) const {
    std::array<double, 6> out{};
    for (int i = 0; i < this->count(); ++i) {
      out[i] = this->coordinate(in, state, i);
      out[3 + i] = this->effort(lambda, i);
    }
    return out;
  }

 private:
  /// The unused third term: a joint of the ground with itself, which takes no part.
  static Coordinate absent(const std::string& name) {
    return Coordinate{Pair(name, ground, Frame{}, ground, Frame{}), JointCoordinateKind::angle,
                      0.0};
  }
  void check_scales() const {
    static constexpr const char* names[] = {"scale_1", "scale_2", "scale_3"};
    for (int i = 0; i < this->count(); ++i)
      this->require_nonzero(scale(i), names[i],
                            "give each coupled coordinate's scale, nonzero and finite");
  }
};

}  // namespace odyn
