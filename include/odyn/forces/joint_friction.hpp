#pragma once
// Friction in a joint, from the load the joint carries: Coulomb friction with stiction (a
// Stribeck curve) plus viscous friction, on the slip of the joint's contact surfaces.
//
// The joint's free coordinates slip at its contact: a slider's slide s, a hinge's pin surface
// r theta (r the pin radius), a cylindrical joint's both. With u the slip velocity (s' and
// r theta') and v = |u|, the surfaces rub with the force
//   F(v) = mu(v) N tanh(v / v_t) + c v,   mu(v) = mu_k + (mu_s - mu_k) exp(-(v / v_s)^2),
// against u: a slide's force -F s'/v, a hinge's torque -r F (r theta')/v. The tanh regularizes
// the sign of the slip: a joint held by less than mu_s N creeps at v_t atanh(f / (mu_s N)) under
// the load f along it (v_t well below v_s), which is how this law sticks.
//
// N, the normal load, is the joint's reaction across its axis (a hinge's radial force, a
// slider's force normal to its rail), plus its moments across the axis over `bending_arm` (the
// couple of normal forces two bearings that far apart carry; 0 leaves moments out), plus a
// preload. A hinge's axial force is not counted. The reaction depends on the friction in turn:
// the analyses solve the accelerations and multipliers again until the loads settle
// (ConstraintProjection::solve_accelerations).

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/joint_coordinate.hpp"

namespace odyn {

/// The friction law of a joint's contact surfaces.
struct FrictionLaw {
  double coefficient = 0.0;           // mu_k, while slipping
  double static_coefficient = 0.0;    // mu_s >= mu_k, at rest
  double stribeck_velocity = 0.01;    // v_s, m/s: how fast mu falls from mu_s to mu_k
  double transition_velocity = 1e-4;  // v_t, m/s: the regularization's slip speed scale
  double viscous = 0.0;               // c, N s/m
  double preload = 0.0;               // N, normal load carried without any reaction
  double radius = 0.0;                // r, m: the pin radius (turning joints)
  double bending_arm = 0.0;           // m: moments over it add to N; 0: left out

  /// mu at slip speed v.
  double friction_coefficient(double v) const {
    if (static_coefficient == coefficient) return coefficient;
    const double x = v / stribeck_velocity;
    return coefficient + (static_coefficient - coefficient) * std::exp(-x * x);
  }

  /// The rubbing force F(v) under normal load `normal`.
  double force(double v, double normal) const {
    return friction_coefficient(v) * normal * std::tanh(v / transition_velocity) + viscous * v;
  }

  /// g = F(v)/v and h = g'(v)/v, both finite as v -> 0: the friction on the slip u is -g u,
  /// and its derivative with respect to u is -(g I + h u u^T).
  std::pair<double, double> slopes(double v, double normal) const {
    const double vt = transition_velocity, x = v / vt;
    // tanh(x)/x and (x sech^2 x - tanh x)/x^3, by their series near 0.
    double ratio, curvature;
    if (x < 1e-3) {
      ratio = 1.0 - x * x / 3.0;
      curvature = -2.0 / 3.0 + 8.0 * x * x / 15.0;
    } else {
      const double t = std::tanh(x);
      ratio = t / x;
      curvature = (x * (1.0 - t * t) - t) / (x * x * x);
    }
    const double mu = friction_coefficient(v);
    double mu_slope = 0.0;  // mu'(v)/v
    if (static_coefficient != coefficient) {
      const double s = v / stribeck_velocity;
      mu_slope = -2.0 * (static_coefficient - coefficient) * std::exp(-s * s) /
                 (stribeck_velocity * stribeck_velocity);
    }
    const double g = normal * mu * ratio / vt + viscous;
    const double h = normal * (mu_slope * ratio / vt + mu * curvature / (vt * vt * vt));
    return {g, h};
  }

  /// Refuses a law that cannot work, naming the element; `turns`: the joint has a pin.
  void check(const std::string& name, bool turns) const {
    const auto finite_at_least = [&](double value, const char* what, double minimum,
                                     const char* advice) {
      if (!(value >= minimum) || !std::isfinite(value))
        throw ModelError(name, std::string(what) + " is " + to_text(value) + "; " + advice);
    };
    finite_at_least(coefficient, "coefficient", 0.0, "give mu_k, zero or positive");
    finite_at_least(static_coefficient, "static_coefficient", coefficient,
                    "give mu_s, at least the (kinetic) coefficient");
    if (!(stribeck_velocity > 0.0) || !std::isfinite(stribeck_velocity))
      throw ModelError(
          name, "stribeck_velocity is " + to_text(stribeck_velocity) + "; it must be positive");
    if (!(transition_velocity > 0.0) || !std::isfinite(transition_velocity))
      throw ModelError(name, "transition_velocity is " + to_text(transition_velocity) +
                                 "; it must be positive (the smaller, the stiffer the law)");
    finite_at_least(viscous, "viscous", 0.0, "it must be zero or positive");
    finite_at_least(preload, "preload", 0.0, "it must be zero or positive");
    finite_at_least(bending_arm, "bending_arm", 0.0,
                    "it must be zero (moments left out) or positive");
    if (turns && (!(radius > 0.0) || !std::isfinite(radius)))
      throw ModelError(name, "radius is " + to_text(radius) +
                                 "; a turning joint's friction needs its pin radius, positive");
    finite_at_least(radius, "radius", 0.0, "it must be zero or positive");
  }

  template <class Reader>
  static FrictionLaw read(Reader& r) {
    const double mu = parameter<double>(r, "coefficient");
    const auto mu_s = parameter<std::optional<double>>(r, "static_coefficient");
    return {mu,
            mu_s.value_or(mu),
            parameter<double>(r, "stribeck_velocity"),
            parameter<double>(r, "transition_velocity"),
            parameter<double>(r, "viscous"),
            parameter<double>(r, "preload"),
            parameter<double>(r, "radius"),
            parameter<double>(r, "bending_arm")};
  }
};

namespace parameters {

inline constexpr std::array<Parameter, 10> joint_friction{{
    {"name", "name", nullptr, "", "the element's name"},
    {"joint", "joint", nullptr, "", "the joint whose surfaces rub (added before)"},
    {"coefficient", "nonnegative", nullptr, "", "mu_k: the friction coefficient while slipping"},
    {"static_coefficient", "optional_number", "null", "",
     "mu_s >= mu_k: the coefficient at rest (stiction); null: mu_k"},
    {"stribeck_velocity", "positive", "0.01", "m/s", "v_s: mu falls from mu_s to mu_k over it"},
    {"transition_velocity", "positive", "1e-4", "m/s",
     "v_t: the slip speed over which the friction force builds up; a sticking joint creeps at "
     "about this speed (smaller is stiffer)"},
    {"viscous", "nonnegative", "0", "N s/m", "c: adds c times the slip speed"},
    {"preload", "nonnegative", "0", "N", "a normal load carried besides the reaction"},
    {"radius", "nonnegative", "0", "m",
     "the pin radius: the lever of a turning joint's friction (required there)"},
    {"bending_arm", "nonnegative", "0", "m",
     "the joint's moments across its axis over this arm add to the normal load; 0: left out"},
}};

inline constexpr std::array<Output, 6> joint_friction_outputs{{
    {"normal_load", "N", "N: the normal load, from the joint's reaction and the preload"},
    {"slip_speed", "m/s", "v: the speed at which the surfaces slip"},
    {"friction", "N", "F(v): the rubbing force"},
    {"force", "N", "its part along a sliding joint's axis, on b"},
    {"torque", "N m", "its torque about a turning joint's axis, on b"},
    {"power", "W", "the friction's power, <= 0: minus the rate at which it dissipates"},
}};

/// The joint types friction may sit on, in space and in the plane.
inline constexpr std::array<const char*, 3> rubbing_joints{"revolute", "translational",
                                                           "cylindrical"};
inline constexpr std::array<const char*, 2> planar_rubbing_joints{"revolute", "translational"};

}  // namespace parameters

/// Friction in an existing joint, in either space: Pair is the space's two-body joint base. The
/// model attaches it to its joint when it is added (OnJoint) and refreshes the joint's reaction
/// in its state before each evaluation (ReadsJointReaction).
template <class Pair>
class JointFrictionT {
 public:
  using Space = typename Pair::Space;
  using Input = ElementInput<Space, 2>;
  static constexpr int num_bodies = 2;
  static constexpr ElementDescription description{
      "joint_friction",
      "force",
      "Friction in a revolute, translational or cylindrical joint: Coulomb with stiction and "
      "viscous, from the joint's reaction.",
      parameters::joint_friction,
      parameters::joint_friction_outputs,
      {},
      Space::dim == 3 ? std::span<const char* const>(parameters::rubbing_joints)
                      : std::span<const char* const>(parameters::planar_rubbing_joints)};

  /// The joint's constraint force on body b (-Phi_q,b^T lambda: generalized, at b's centre).
  struct State {
    typename Space::Velocity reaction = Space::Velocity::Zero();
  };

  template <class Reader>
  static JointFrictionT from_parameters(Reader& r) {
    return JointFrictionT(parameter<std::string>(r, "name"), parameter<std::string>(r, "joint"),
                          FrictionLaw::read(r));
  }

  /// Friction in the joint named `joint`, attached when the element is added to a model.
  JointFrictionT(std::string name, std::string joint, FrictionLaw law)
      : name_(std::move(name)), joint_name_(std::move(joint)), law_(law) {
    law_.check(name_, false);
  }

  const std::string& name() const { return name_; }
  const std::array<BodyId, 2>& bodies() const { return bodies_; }
  const std::string& joint_name() const { return joint_name_; }
  const FrictionLaw& law() const { return law_; }
  bool turns() const { return turns_; }
  bool slides() const { return slides_; }
  /// Where the joint is in its model: its type's position in the list and its index there.
  std::size_t joint_type() const { return joint_type_; }
  std::size_t joint_index() const { return joint_index_; }

  /// Takes the joint's bodies and frames, and which of its coordinates slip.
  template <class Joint>
    requires std::derived_from<Joint, Pair> && Described<Joint>
  void attach(const Joint& joint, std::size_t type, std::size_t index) {
    const std::string_view kind = Joint::description.type;
    turns_ = kind == "revolute" || kind == "cylindrical";
    slides_ = kind == "translational" || kind == "cylindrical";
    if (!turns_ && !slides_)
      throw ModelError(name_, "'" + joint_name_ + "' is a " + std::string(kind) +
                                  " joint; friction sits on a revolute, translational or "
                                  "cylindrical joint");
    law_.check(name_, turns_);
    joint_.emplace(joint);
    bodies_ = joint.bodies();
    joint_type_ = type;
    joint_index_ = index;
  }

  State initial_state(const Input&) const { return {}; }
  void advance(const Input&, State&) const {}

  void evaluate(const Input& in, const State& state, ForceBlocks<Space, 2>& out) const {
    const Slip slip = slip_of(in, state);
    const Velocities force = -slip.g * slip.direction * slip.u;
    out.force[0] = force.template head<Space::nv>();
    out.force[1] = force.template tail<Space::nv>();
  }

  /// -dQ/dv with the normal load and the slip directions held; -dQ/dq left out.
  void jacobians(const Input& in, const State& state, ForceBlocks<Space, 2>& out) const {
    const Slip slip = slip_of(in, state);
    const Velocities along = slip.direction * slip.u;
    out.stiffness.setZero();
    out.damping =
        slip.g * slip.direction * slip.direction.transpose() + slip.h * along * along.transpose();
  }

  std::array<double, 6> outputs(const Input& in, const State& state) const {
    const Slip slip = slip_of(in, state);
    const double friction = law_.force(slip.speed, slip.normal);
    // The force along the slide and the torque about the axis, on b (the slip's own sign).
    const double force = slides_ ? -slip.g * slip.u[0] : 0.0;
    const double torque = turns_ ? -slip.g * slip.u[slides_ ? 1 : 0] * law_.radius : 0.0;
    return {slip.normal, slip.speed, friction, force, torque, -friction * slip.speed};
  }

  /// The normal load from a reaction on b (generalized, at b's centre) at the frame of b.
  double normal_load(const typename Space::Frame& b,
                     const typename Space::Velocity& reaction) const {
    const auto wrench =
        Space::in_axes(Space::wrench_at(b, joint_->frame(1).point, reaction), joint_->axes(1, b));
    double across = 0.0, moment = 0.0;
    if constexpr (Space::dim == 3) {  // axes (u, v, w), w along the joint
      across = wrench.force.template head<2>().norm();
      moment = turns_ ? wrench.torque.template head<2>().norm() : wrench.torque.norm();
    } else {  // axes (along, across)
      across = turns_ ? wrench.force.norm() : std::abs(wrench.force[1]);
      moment = turns_ ? 0.0 : std::abs(wrench.torque[0]);
    }
    const double bending = law_.bending_arm > 0.0 ? moment / law_.bending_arm : 0.0;
    return across + bending + law_.preload;
  }

 private:
  using Velocities = Eigen::Matrix<double, 2 * Space::nv, 1>;
  using Directions = Eigen::Matrix<double, 2 * Space::nv, 2>;

  /// The slip: its components u (the slide's rate, then r theta'), the gradients of s and
  /// r theta as columns of `direction`, its speed, the normal load and the law's slopes.
  struct Slip {
    Eigen::Vector2d u = Eigen::Vector2d::Zero();
    Directions direction = Directions::Zero();
    double speed = 0.0, normal = 0.0, g = 0.0, h = 0.0;
  };

  Slip slip_of(const Input& in, const State& state) const {
    if (!joint_)
      throw ModelError(name_, "is not attached to its joint '" + joint_name_ +
                                  "'; add it to the model that holds the joint");
    Slip slip;
    Velocities velocities;
    velocities << in.body(0).linear_velocity, in.body(0).angular_velocity,
        in.body(1).linear_velocity, in.body(1).angular_velocity;
    int column = 0;
    if (slides_) slip.direction.col(column++) = joint_->slide(in).direction;
    if (turns_) slip.direction.col(column++) = law_.radius * joint_->angle_row(in, 0.0).gradient;
    slip.u = slip.direction.transpose() * velocities;
    slip.speed = slip.u.norm();
    slip.normal = normal_load(in.body(1), state.reaction);
    std::tie(slip.g, slip.h) = law_.slopes(slip.speed, slip.normal);
    return slip;
  }

  std::string name_;
  std::string joint_name_;
  FrictionLaw law_;
  std::optional<Pair> joint_;
  std::array<BodyId, 2> bodies_{};
  bool turns_ = false, slides_ = false;
  std::size_t joint_type_ = 0, joint_index_ = 0;
};

}  // namespace odyn
