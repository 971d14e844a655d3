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

/// Otto-cycle gas force on the piston along Z. It reads the crank angle theta from the crank's
/// rotation about X; its state keeps the cumulative angle and the half-turn the cycle is in
/// (intake, compression, power, exhaust), which fixes the pressure law for a whole step. Its
/// event function tells the integrator where the next half-turn starts, so that no step
/// straddles ignition or the exhaust valve opening.
class GasForce {
 public:
  using Space = odyn::Spatial;
  static constexpr int num_bodies = 2;  // crank (for the angle), piston (where it acts)
  using Input = odyn::ElementInput<Space, 2>;
  struct State {
    double theta = 0.0;  // cumulative crank angle at the last accepted step
    long half_turn = 0;  // the stroke is half_turn mod 4
  };

  GasForce(std::string name, odyn::BodyId crank, odyn::BodyId piston, Parameters p)
      : name_(std::move(name)), bodies_{crank, piston}, p_(p) {}

  const std::string& name() const { return name_; }
  const std::array<odyn::BodyId, 2>& bodies() const { return bodies_; }

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
    out.force[1][2] = force(stroke(state.half_turn), in.body(1).position.z());
  }

  /// The stroke (0 intake, 1 compression, 2 power, 3 exhaust) of a half-turn count.
  static int stroke(long half_turn) { return static_cast<int>(((half_turn % 4) + 4) % 4); }

  /// F_z = -(P - P_atm) A, with the pressure law of the stroke.
  double force(int stroke, double z_piston) const {
    const double area = p_.area(), v_c = p_.clearance_volume();
    const double volume = v_c + area * ((p_.r + p_.L) - z_piston);
    double pressure = p_.p_atm;
    if (stroke == 1)
      pressure = p_.p_atm * std::pow((v_c + 2.0 * p_.r * area) / volume, p_.kappa);
    else if (stroke == 2)
      pressure =
          (p_.p_atm * std::pow(p_.C, p_.kappa) + p_.p_comb) * std::pow(v_c / volume, p_.kappa);
    return -(pressure - p_.p_atm) * area;
  }

 private:
  static double wrapped_angle(const Input& in) {
    const auto& rotation = in.body(0).rotation;  // a rotation about X by theta
    return std::atan2(rotation(2, 1), rotation(1, 1));
  }
  std::string name_;
  std::array<odyn::BodyId, 2> bodies_;
  Parameters p_;
};
static_assert(odyn::HasEvents<GasForce>);

/// Just the element types the engine uses: nothing else is compiled or dispatched.
using Model = odyn::spatial::Model<odyn::spatial::Revolute, odyn::spatial::Spherical,
                                   odyn::spatial::Universal, odyn::spatial::Translational,
                                   odyn::spatial::Gravity, odyn::spatial::Rsda, GasForce>;

struct Engine {
  Model model;
  odyn::BodyId crank, rod, piston;
  odyn::Handle<odyn::spatial::Revolute> bearing;
  odyn::Handle<GasForce> gas;
};

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

/// Cumulative crank angle, from the gas force's state.
inline double crank_angle(const Engine& e, const odyn::Workspace<Model>& ws) {
  return std::get<Model::type_index<GasForce>>(ws.states)[e.gas.index].theta;
}

}  // namespace engine
