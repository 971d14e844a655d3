#pragma once
// A stop on a joint coordinate x (an angle or a slide): past the lower limit, by delta =
// lower - x, the stop pushes x back up with the Hunt-Crossley force
//   F = k delta^n (1 + d delta'),  kept >= 0 (no pull as the joint leaves the stop),
// and past the upper limit, by delta = x - upper, pushes it back down the same way. Between the
// limits the stop exerts nothing. A limit left out (no value) has no stop on that side.
//
// An impact at the rate v_in leaves at v_out with d v_in - ln(1 + d v_in) = -d v_out - ln(1 -
// d v_out) when nothing else acts on the coordinate, as for contact (forces/contact.hpp):
// odyn.hunt_crossley_dissipation(e, v_in) gives the d for a restitution e.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/joint_coordinate.hpp"
#include "odyn/core/parameter_blocks.hpp"
#include "odyn/forces/hunt_crossley.hpp"

namespace odyn {

/// The stops' limits and their Hunt-Crossley law.
struct LimitLaw {
  // The coordinate's limits; none: no stop on that side.
  std::optional<double> lower = std::nullopt, upper = std::nullopt;
  double stiffness = 0.0;    // k, N/m^n or N m/rad^n
  double exponent = 1.0;     // n
  double dissipation = 0.0;  // d, s/m or s/rad

  /// The stop's generalized force along the coordinate and its derivatives, with the signs of
  /// a Newton matrix: stiffness = -dF/dx, damping = -dF/dx'.
  struct Response {
    double force = 0.0, stiffness = 0.0, damping = 0.0;
  };

  /// The distance to the nearer limit, negative past it: its falling zero is a stop's onset.
  double clearance(double x) const {
    return std::min(upper ? *upper - x : std::numeric_limits<double>::infinity(),
                    lower ? x - *lower : std::numeric_limits<double>::infinity());
  }

  /// The penetration past the nearer limit (> 0 inside a stop) and the side: +1 pushes x up.
  std::pair<double, double> penetration(double x) const {
    if (lower && x < *lower) return {*lower - x, 1.0};
    if (upper && x > *upper) return {x - *upper, -1.0};
    return {0.0, 0.0};
  }

  /// The stops' law on the penetration.
  HuntCrossley push_law() const { return {stiffness, exponent, dissipation}; }

  Response at(double x, double rate) const {
    const auto [depth, side] = penetration(x);
    const HuntCrossley::Push push = push_law().at(depth, side * -rate);
    // dF/dx = side * dF_n/d(delta) * d(delta)/dx = -dF_n/d(delta): the same on both sides.
    return {side * push.force, push.stiffness, push.damping};
  }

  /// The elastic energy stored at `x`.
  double energy(double x) const { return push_law().energy(penetration(x).first); }

  /// Refuses limits or a law that cannot work, naming the element.
  void check(const std::string& name) const {
    if (!lower && !upper)
      throw ModelError(name, "neither lower nor upper is given; a stop needs at least one limit");
    if ((lower && !std::isfinite(*lower)) || (upper && !std::isfinite(*upper)))
      throw ModelError(name, "the limits must be finite (leave one out for no stop on that side)");
    if (lower && upper && !(*lower < *upper))
      throw ModelError(name, "lower is " + to_text(*lower) + " and upper " + to_text(*upper) +
                                 "; lower must be below upper");
    push_law().check(name);
  }

  template <class Reader>
  static LimitLaw read(Reader& r) {
    return {parameter<std::optional<double>>(r, "lower"),
            parameter<std::optional<double>>(r, "upper"), parameter<double>(r, "stiffness"),
            parameter<double>(r, "exponent"), parameter<double>(r, "dissipation")};
  }
};

namespace parameters {

/// A limit's law, on an angle (`angular`) or a slide.
inline constexpr std::array<Parameter, 5> limit_law(bool angular) {
  return {{
      {"lower", "optional_number", "null", angular ? "rad" : "m",
       "the lower limit of the coordinate; null: no stop below"},
      {"upper", "optional_number", "null", angular ? "rad" : "m",
       "the upper limit of the coordinate; null: no stop above"},
      {"stiffness", "positive", nullptr, angular ? "N m/rad^n" : "N/m^n",
       "k: the stop pushes back with k delta^n at rest, delta the penetration past the limit"},
      {"exponent", "positive", "1", "", "n >= 1"},
      {"dissipation", "nonnegative", "0", angular ? "s/rad" : "s/m",
       "d: the push is k delta^n (1 + d delta'); for a restitution e at an impact rate v, "
       "odyn.hunt_crossley_dissipation(e, v)"},
  }};
}

}  // namespace parameters

/// The parameters and outputs of a stop on an angle (`angular`) or on a slide, in both spaces.
template <bool angular>
struct LimitDescription {
  static constexpr std::array<Parameter, 11> parameter_list =
      join(parameters::joint_or_frame_pair, parameters::limit_law(angular));
  static constexpr std::array<Output, 4> output_list{{
      {angular ? "angle" : "position", angular ? "rad" : "m",
       angular ? "the joint angle, counting whole turns" : "the slide of b's point along a's axis"},
      {"rate", angular ? "rad/s" : "m/s", "the coordinate's rate"},
      {"clearance", angular ? "rad" : "m",
       "the distance to the nearer limit, negative past it (its falling zero: the onset)"},
      {angular ? "torque" : "force", angular ? "N m" : "N",
       "the stop's push on b along the coordinate (on a, its opposite)"},
  }};
};

/// The blocks of a stop on a coordinate: the law's push along its direction, and the law's
/// stiffness and damping along it (the direction's own change left out, as an Rsda leaves it).
template <class Space>
void stop_force(const LimitLaw& law, const JointCoordinate<Space>& x, ForceBlocks<Space, 2>& out) {
  const double push = law.at(x.value, x.rate).force;
  out.force[0] = push * x.direction.template head<Space::nv>();
  out.force[1] = push * x.direction.template tail<Space::nv>();
}
template <class Space>
void stop_jacobians(const LimitLaw& law, const JointCoordinate<Space>& x,
                    ForceBlocks<Space, 2>& out) {
  const LimitLaw::Response r = law.at(x.value, x.rate);
  out.stiffness = r.stiffness * x.direction * x.direction.transpose();
  out.damping = r.damping * x.direction * x.direction.transpose();
}
/// The outputs LimitDescription lists.
template <class Space>
std::array<double, 4> stop_outputs(const LimitLaw& law, const JointCoordinate<Space>& x) {
  return {x.value, x.rate, law.clearance(x.value), law.at(x.value, x.rate).force};
}

/// A stop on the slide of b's point along a's axis, in either space: Pair is the space's
/// two-body joint base (its slide(in) the coordinate), Frame its joint frame, Joints the joint
/// types whose slide it may stop.
template <class Pair, class Frame, class... Joints>
class TranslationalLimitT : public Pair {
 public:
  using Space = typename Pair::Space;
  using Input = typename Pair::Input;
  static constexpr std::array<const char*, sizeof...(Joints)> joint_types{
      Joints::description.type...};
  static constexpr ElementDescription description{
      "translational_limit",
      "force",
      "Stops on a translational joint's slide: past a limit by delta, a force k delta^n (1 + d "
      "delta') back towards it.",
      LimitDescription<false>::parameter_list,
      LimitDescription<false>::output_list,
      {},
      joint_types};
  template <class Reader>
  static TranslationalLimitT from_parameters(Reader& r) {
    return parameters::from_frame_pair<TranslationalLimitT, Frame>(r, LimitLaw::read(r));
  }

  TranslationalLimitT(std::string name, BodyId body_a, const Frame& on_a, BodyId body_b,
                      const Frame& on_b, LimitLaw law)
      : Pair(std::move(name), body_a, on_a, body_b, on_b), law_(law) {
    law_.check(this->name_);
  }
  /// Stops the slide of an existing joint.
  template <class Joint>
    requires(std::same_as<Joint, Joints> || ...)
  TranslationalLimitT(std::string name, const Joint& joint, LimitLaw law) : Pair(joint), law_(law) {
    this->name_ = std::move(name);
    law_.check(this->name_);
  }

  const LimitLaw& law() const { return law_; }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    stop_force(law_, this->slide(in), out);
  }
  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    stop_jacobians(law_, this->slide(in), out);
  }
  std::array<double, 4> outputs(const Input& in) const {
    return stop_outputs(law_, this->slide(in));
  }
  double potential_energy(const Input& in) const { return law_.energy(this->slide(in).value); }

 private:
  LimitLaw law_;
};

}  // namespace odyn
