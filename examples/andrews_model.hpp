#pragma once
// Andrews' squeezing mechanism (shared/specs/andrews.md; a copy of its numbers lives in this
// file): seven planar bodies, ten pins, a stiff spring and a motor torque. The classic index-3
// benchmark of Hairer & Wanner and of the Test Set for IVP Solvers, in absolute coordinates.

#include <array>
#include <string>

#include <odyn/odyn.hpp>

namespace andrews {

namespace pl = odyn::planar;
using Eigen::Vector2d;

/// Just the element types the mechanism uses.
using Model = pl::Model<pl::Revolute, pl::Tsda, pl::PointTorque>;

struct Mechanism {
  Model model;
  std::array<odyn::BodyId, 7> bodies;  // crank, rod FE, triangle, rod GE, link AG, rod HE, link AH
  std::array<odyn::Handle<pl::Revolute>, 10> pins;  // J1 .. J10
};

/// Builds the mechanism at the spec's consistent initial pose, at rest.
inline Mechanism build() {
  struct BodyData {
    const char* name;
    double mass, inertia, x, y, phi;
  };
  // Centres of mass and angles at t = 0 (the spec's 40-digit poses, rounded to doubles).
  static constexpr std::array<BodyData, 7> data{{
      {"crank", 0.04325, 2.194e-6, 9.182485980307614359956e-4, -5.674074562905483222436e-5,
       -0.06171389001427644963589},
      {"rod FE", 0.00365, 4.410e-7, -4.491433359933072241283e-3, 2.775362557942899402279e-4,
       -0.06171389001427644963589},
      {"triangle", 0.02373, 5.255e-6, -1.874218667031545762186e-2, 2.048510678907393047663e-2,
       0.4552798191630703802559},
      {"rod GE", 0.00706, 5.667e-7, -3.022293983015888742160e-2, 1.207118235666393932334e-2,
       0.7100333697097284349001},
      {"link AG", 0.07050, 1.169e-5, -5.323682815570413865568e-2, 1.663184796661630721002e-2,
       0.4873649795438425502256},
      {"rod HE", 0.00706, 5.667e-7, -2.854326853678360407221e-2, -1.072225470725228785757e-2,
       1.007879054383935307823},
      {"link AH", 0.05498, 1.912e-5, -5.926240280179171659320e-2, -1.060069833271284384241e-2,
       1.230547444549821192497},
  }};
  Mechanism m;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const BodyData& d = data[i];
    m.bodies[i] = m.model.add_body(pl::Body{.name = d.name,
                                            .mass = d.mass,
                                            .inertia = d.inertia,
                                            .position = {d.x, d.y},
                                            .angle = d.phi});
  }
  const auto [crank, rod, triangle, rod_ge, link_ag, rod_he, link_ah] = m.bodies;
  const odyn::BodyId ground = odyn::ground;
  // Ground points and body points (from each body's centre of mass).
  const Vector2d O{0.0, 0.0}, A{-0.06934, -0.00227}, B{-0.03635, 0.03273}, C{0.014, 0.072};
  auto pin = [&](const char* name, odyn::BodyId a, Vector2d on_a, odyn::BodyId b, Vector2d on_b) {
    return m.model.add(pl::Revolute(name, a, {on_a}, b, {on_b}));
  };
  m.pins = {
      pin("J1", crank, {-0.00092, 0.0}, ground, O),
      pin("J2", crank, {0.00608, 0.0}, rod, {0.0115, 0.0}),
      pin("J3", rod, {-0.0165, 0.0}, triangle, {-0.01043, -0.01626}),
      pin("J4", triangle, {-0.01043, 0.01874}, ground, B),
      pin("J5", rod, {-0.0165, 0.0}, rod_ge, {0.0, -0.01421}),
      pin("J6", rod_ge, {0.0, 0.00579}, link_ag, {0.01692, -0.00916}),
      pin("J7", link_ag, {-0.02308, -0.00916}, ground, A),
      pin("J8", rod, {-0.0165, 0.0}, rod_he, {0.01421, 0.0}),
      pin("J9", rod_he, {-0.00579, 0.0}, link_ah, {0.00449, -0.02772}),
      pin("J10", link_ah, {0.00449, 0.01228}, ground, A),
  };
  m.model.add(pl::Tsda("spring", triangle, {0.00957, 0.00074}, ground, C,
                       {.stiffness = 4530.0, .free_length = 0.07785}));
  m.model.add(pl::PointTorque("motor", crank, 0.033));
  return m;
}

/// The seven test-set angles beta, Theta, gamma, Phi, delta, Omega, epsilon (or their rates) from
/// the body angles (or rates) phi1 .. phi7.
inline std::array<double, 7> test_set_angles(const std::array<double, 7>& phi) {
  return {phi[0], phi[1] - phi[0], phi[2], phi[3] - phi[4], phi[4], phi[5] - phi[6], phi[6]};
}

/// Body angles and angular velocities from a workspace.
template <class Workspace>
std::array<double, 7> body_angles(const Mechanism& m, const Workspace& ws) {
  std::array<double, 7> phi;
  for (int i = 0; i < 7; ++i) phi[i] = ws.frames[m.bodies[i].index].angle;
  return phi;
}
template <class Workspace>
std::array<double, 7> body_rates(const Mechanism& m, const Workspace& ws) {
  std::array<double, 7> w;
  for (int i = 0; i < 7; ++i) w[i] = ws.frames[m.bodies[i].index].omega();
  return w;
}

}  // namespace andrews
