#pragma once
// The single-cylinder four-stroke engine of the O-DYN paper, exactly as
// shared/specs/engine.md fixes it (a copy of its numbers lives in this file).
//
// The gas force is written here, outside the library, as the paper intends: a new element is
// one class that satisfies odyn's force concept and knows nothing else of the library.

#include <cmath>
#include <numbers>
#include <string>

#include <odyn/odyn.hpp>

namespace engine {

using odyn::spatial::Body;
using odyn::spatial::JointFrame;

struct Parameters {
  double r = 0.04, L = 0.14, D = 0.08, C = 9.0;          // crank radius, rod length, bore, ratio
  double p_atm = 101325.0, kappa = 1.4, p_comb = 3.0e6;  // Pa, -, Pa
  double c_load = 0.1;                                   // N m s
  double omega0 = 157.08;                                // rad/s
  double area() const { return std::numbers::pi * D * D / 4.0; }
  double clearance_volume() const { return area() * 2.0 * r / (C - 1.0); }
};

/// Otto-cycle gas force on the piston along the cylinder axis (Z; the plane's y axis in the planar
/// model). It reads the crank angle theta from the crank's rotation about X (the plane's normal);
/// its state keeps the cumulative angle and the half-turn the cycle is in (intake, compression,
/// power, exhaust), which fixes the pressure law for a whole step. Its event function tells the
/// integrator where the next half-turn starts, so that no step straddles ignition or the exhaust
/// valve opening.
template <class SpaceT>
class GasForceT {
 public:
  using Space = SpaceT;
  static constexpr int up = Space::dim - 1;  // index of the cylinder axis in points and forces
  static constexpr int num_bodies = 2;       // crank (for the angle), piston (where it acts)
  using Input = odyn::ElementInput<Space, 2>;
  struct State {
    double theta = 0.0;  // cumulative crank angle at the last accepted step
    long half_turn = 0;  // the stroke is half_turn mod 4
  };

  GasForceT(std::string name, odyn::BodyId crank, odyn::BodyId piston, Parameters p)
      : name_(std::move(name)), bodies_{crank, piston}, p_(p) {
    if (!(p.r > 0.0) || !(p.L > p.r) || !(p.D > 0.0) || !(p.C > 1.0) || !(p.p_atm > 0.0) ||
        !(p.kappa > 0.0) || !(p.p_comb >= 0.0) || !std::isfinite(p.L + p.C + p.p_comb))
      throw odyn::ModelError(name_,
                             "expected finite r > 0, L > r, D > 0, compression ratio C > 1, "
                             "p_atm > 0, kappa > 0 and p_comb >= 0; got r = " +
                                 odyn::to_text(p.r) + ", L = " + odyn::to_text(p.L) +
                                 ", D = " + odyn::to_text(p.D) + ", C = " + odyn::to_text(p.C));
  }

  // How front ends (Python, scene files) see it; the defaults are the spec's.
  static constexpr std::array<odyn::Parameter, 10> parameter_list{{
      {"name", "name", nullptr, "", "the element's name"},
      {"crank", "body", nullptr, "", "the crank, whose angle sets the cycle"},
      {"piston", "body", nullptr, "", "the piston, on which the force acts"},
      {"r", "positive", "0.04", "m", "crank radius"},
      {"L", "positive", "0.14", "m", "connecting rod length"},
      {"D", "positive", "0.08", "m", "bore"},
      {"C", "positive", "9.0", "", "compression ratio"},
      {"p_atm", "positive", "101325.0", "Pa", "atmospheric pressure"},
      {"kappa", "positive", "1.4", "", "ratio of specific heats"},
      {"p_comb", "nonnegative", "3.0e6", "Pa", "pressure rise of combustion"},
  }};
  static constexpr std::array<odyn::Output, 4> output_list{{
      {"crank_angle", "rad", "the cumulative crank angle"},
      {"stroke", "", "0 intake, 1 compression, 2 power, 3 exhaust"},
      {"pressure", "Pa", "the cylinder pressure"},
      {"force", "N", "the gas force on the piston along the cylinder axis"},
  }};
  static constexpr std::array<odyn::Output, 2> state_list{{
      {"theta", "rad", "the cumulative crank angle at the last accepted step"},
      {"half_turn", "", "half turns completed (the stroke is half_turn mod 4)"},
  }};
  static constexpr odyn::ElementDescription description{
      "engine_gas_force",
      "force",
      "The engine's Otto-cycle gas force on the piston along the cylinder axis (Z; y in the "
      "plane), the crank angle read from the crank's rotation; events at each half turn.",
      parameter_list,
      output_list,
      state_list};
  template <class Reader>
  static GasForceT from_parameters(Reader& r) {
    using odyn::parameter;
    Parameters p;
    p.r = parameter<double>(r, "r"), p.L = parameter<double>(r, "L");
    p.D = parameter<double>(r, "D"), p.C = parameter<double>(r, "C");
    p.p_atm = parameter<double>(r, "p_atm"), p.kappa = parameter<double>(r, "kappa");
    p.p_comb = parameter<double>(r, "p_comb");
    return GasForceT(parameter<std::string>(r, "name"), parameter<odyn::BodyId>(r, "crank"),
                     parameter<odyn::BodyId>(r, "piston"), p);
  }

  const std::string& name() const { return name_; }
  const std::array<odyn::BodyId, 2>& bodies() const { return bodies_; }

  static std::array<double, 2> state_values(const State& state) {
    return {state.theta, static_cast<double>(state.half_turn)};
  }

  State initial_state(const Input& in) const {
    const double theta = wrapped_angle(in);
    return {theta, static_cast<long>(std::floor(theta / std::numbers::pi))};
  }

  void advance(const Input& in, State& state) const {
    state.theta = angle(in, state);
    while (state.theta >= static_cast<double>(state.half_turn + 1) * std::numbers::pi)
      ++state.half_turn;
  }

  /// Negative until the crank reaches the next half-turn.
  double event_function(const Input& in, const State& state) const {
    return angle(in, state) - static_cast<double>(state.half_turn + 1) * std::numbers::pi;
  }

  /// Cumulative crank angle, continuous from the state (a step turns far less than pi).
  double angle(const Input& in, const State& state) const {
    const double turn = 2.0 * std::numbers::pi;
    const double raw = wrapped_angle(in);
    return raw + turn * std::round((state.theta - raw) / turn);
  }

  void evaluate(const Input& in, const State& state, odyn::ForceBlocks<Space, 2>& out) const {
    out.force[0].setZero();
    out.force[1].setZero();
    out.force[1][up] = force(stroke(state.half_turn), in.body(1).position[up]);
  }

  std::array<double, 4> outputs(const Input& in, const State& state) const {
    const int s = stroke(state.half_turn);
    const double z_piston = in.body(1).position[up];
    return {angle(in, state), static_cast<double>(s), pressure(s, z_piston), force(s, z_piston)};
  }

  /// The stroke (0 intake, 1 compression, 2 power, 3 exhaust) of a half-turn count.
  static int stroke(long half_turn) { return static_cast<int>(((half_turn % 4) + 4) % 4); }

  /// The cylinder pressure P in a stroke at a piston height.
  double pressure(int stroke, double z_piston) const {
    const double area = p_.area(), v_c = p_.clearance_volume();
    const double volume = v_c + area * ((p_.r + p_.L) - z_piston);
    if (stroke == 1) return p_.p_atm * std::pow((v_c + 2.0 * p_.r * area) / volume, p_.kappa);
    if (stroke == 2)
      return (p_.p_atm * std::pow(p_.C, p_.kappa) + p_.p_comb) * std::pow(v_c / volume, p_.kappa);
    return p_.p_atm;
  }

  /// F_z = -(P - P_atm) A, with the pressure law of the stroke.
  double force(int stroke, double z_piston) const {
    return -(pressure(stroke, z_piston) - p_.p_atm) * p_.area();
  }

 private:
  /// The crank's rotation is a turn by theta in the plane of the last two axes (Y-Z in space).
  static double wrapped_angle(const Input& in) {
    const auto& rotation = in.body(0).rotation;
    return std::atan2(rotation(up, up - 1), rotation(up - 1, up - 1));
  }
  std::string name_;
  std::array<odyn::BodyId, 2> bodies_;
  Parameters p_;
};
using GasForce = GasForceT<odyn::Spatial>;
static_assert(odyn::HasEvents<GasForce>);

/// Just the element types the engine uses: nothing else is compiled or dispatched.
using Model = odyn::spatial::Model<odyn::spatial::Revolute, odyn::spatial::Spherical,
                                   odyn::spatial::Universal, odyn::spatial::Translational,
                                   odyn::spatial::Gravity, odyn::spatial::Rsda, GasForce>;

/// A built engine: its model and where its parts are.
template <class ModelT, class BearingT, class GasT>
struct EngineT {
  using Model = ModelT;
  using Space = typename ModelT::Space;
  using Gas = GasT;
  ModelT model;
  odyn::BodyId crank, rod, piston;
  odyn::Handle<BearingT> bearing;
  odyn::Handle<GasT> gas;
};
using Engine = EngineT<Model, odyn::spatial::Revolute, GasForce>;

/// Builds the engine at top dead centre; only the crank's angular velocity is given.
inline Engine build(const Parameters& p = {}) {
  using Eigen::Vector3d;
  namespace sp = odyn::spatial;
  Engine e;
  Body crank{.name = "crank", .mass = 1.399, .inertia = Body::principal(1.524, 1.291, 0.836)};
  crank.angular_velocity = {p.omega0, 0.0, 0.0};
  Body rod{.name = "rod",
           .mass = 0.253,
           .inertia = Body::principal(0.399, 0.372, 0.0349),
           .position = {0.0, 0.0, p.r + p.L / 2.0}};
  Body piston{.name = "piston",
              .mass = 0.643,
              .inertia = Body::principal(0.457, 0.506, 0.653),
              .position = {0.0, 0.0, p.r + p.L}};
  e.crank = e.model.add_body(crank);
  e.rod = e.model.add_body(rod);
  e.piston = e.model.add_body(piston);

  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  e.bearing = e.model.add(sp::Revolute("bearing", odyn::ground, JointFrame{{0, 0, 0}, x}, e.crank,
                                       JointFrame{{0, 0, 0}, x}));
  e.model.add(sp::Spherical("crank pin", e.crank, {0, 0, p.r}, e.rod, {0, 0, -p.L / 2.0}));
  e.model.add(sp::Universal("piston pin", e.rod, JointFrame{{0, 0, p.L / 2.0}, x}, e.piston,
                            JointFrame{{0, 0, 0}, y}));
  e.model.add(sp::Translational("cylinder", odyn::ground, JointFrame{{0, 0, p.r + p.L}, z},
                                e.piston, JointFrame{{0, 0, 0}, z}));
  e.model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  e.model.add(sp::Rsda("load", odyn::ground, JointFrame{{0, 0, 0}, x}, e.crank,
                       JointFrame{{0, 0, 0}, x}, {.damping = p.c_load}));
  e.gas = e.model.add(GasForce("gas force", e.crank, e.piston, p));
  return e;
}

namespace planar {
namespace pl = odyn::planar;

using GasForce = GasForceT<odyn::Planar>;
static_assert(odyn::HasEvents<GasForce>);

/// The same engine in the Y-Z plane: 3 bodies of 3 coordinates, 4 joints of 2 equations.
using Model = pl::Model<pl::Revolute, pl::Translational, pl::Gravity, pl::Rsda, GasForce>;
using Engine = EngineT<Model, pl::Revolute, GasForce>;

/// Builds the planar engine at top dead centre, the rod's and crank's Ixx as planar moments of
/// inertia (plane x = global Y, plane y = global Z, phi = rotation about X).
inline Engine build(const Parameters& p = {}) {
  using Eigen::Vector2d;
  Engine e;
  pl::Body crank{.name = "crank", .mass = 1.399, .inertia = 1.524};
  crank.angular_velocity = p.omega0;
  pl::Body rod{.name = "rod", .mass = 0.253, .inertia = 0.399, .position = {0.0, p.r + p.L / 2.0}};
  pl::Body piston{.name = "piston", .mass = 0.643, .inertia = 0.457, .position = {0.0, p.r + p.L}};
  e.crank = e.model.add_body(crank);
  e.rod = e.model.add_body(rod);
  e.piston = e.model.add_body(piston);

  e.bearing = e.model.add(pl::Revolute("bearing", odyn::ground, {}, e.crank, {}));
  e.model.add(pl::Revolute("crank pin", e.crank, {{0.0, p.r}}, e.rod, {{0.0, -p.L / 2.0}}));
  e.model.add(pl::Revolute("piston pin", e.rod, {{0.0, p.L / 2.0}}, e.piston, {}));
  e.model.add(pl::Translational("cylinder", odyn::ground, {{0.0, p.r + p.L}, Vector2d::UnitY()},
                                e.piston, {}));
  e.model.add(pl::Gravity("gravity", {0.0, -9.81}));
  e.model.add(pl::Rsda("load", odyn::ground, e.crank, {.damping = p.c_load}));
  e.gas = e.model.add(GasForce("gas force", e.crank, e.piston, p));
  return e;
}
}  // namespace planar

/// Cumulative crank angle, from the gas force's state.
template <class E>
double crank_angle(const E& e, const odyn::Workspace<typename E::Model>& ws) {
  using Model = typename E::Model;
  return std::get<Model::template type_index<typename E::Gas>>(ws.states)[e.gas.index].theta;
}

/// Crank angular velocity about X, piston height and the bearing's vertical force on the crank.
template <class E>
double crank_rate(const E& e, const odyn::Workspace<typename E::Model>& ws) {
  return ws.frames[e.crank.index].angular_velocity[0];
}
template <class E>
double piston_height(const E& e, const odyn::Workspace<typename E::Model>& ws) {
  return ws.frames[e.piston.index].position[E::Space::dim - 1];
}
template <class E>
double bearing_force_z(const E& e, const odyn::Workspace<typename E::Model>& ws) {
  return odyn::reaction(e.model, ws, e.bearing, odyn::Side::b).force[E::Space::dim - 1];
}

}  // namespace engine
