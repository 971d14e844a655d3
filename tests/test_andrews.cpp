// Andrews' squeezing mechanism (shared/specs/andrews.md) in absolute planar coordinates against
// the spec's t = 0 values and against an independent solution in the one minimal coordinate
// (tests/reference/andrews_reference.hpp: closed-form kinematics of the crank angle, integrated
// by extrapolated midpoint steps to 1e-13).

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>

#include "andrews_model.hpp"
#include "reference/andrews_reference.hpp"

namespace test_andrews {

namespace {

using Workspace = odyn::Workspace<andrews::Model>;

struct Run {
  double angle_error = 0.0;   // largest relative error of the seven angles at t_end
  double rate_error = 0.0;    // largest error of the seven rates at t_end, relative to max |rate|
  double energy_drift = 0.0;  // largest |E(t) - E(0)| / V(0), E = T + V - mom (phi1 - phi1(0))
};

// Default settings throughout: short steps must tighten Newton's tolerance by themselves.
Run run(double h) {
  andrews::Mechanism m = andrews::build();
  Workspace ws(m.model);
  odyn::DynamicsSettings settings;
  settings.t_end = 0.03;
  settings.step = h;
  settings.output_interval = 1e-3;
  const double phi1_start = m.model.body(m.bodies[0]).angle;
  const double v0 = andrews_reference::kSpecSpringEnergy0;
  Run result;
  odyn::simulate_with<odyn::GeneralizedAlpha>(m.model, ws, settings, [&](const Workspace& state) {
    const double energy =
        odyn::kinetic_energy(m.model, state) + odyn::potential_energy(m.model, state) -
        andrews_reference::kMotorTorque * (state.frames[m.bodies[0].index].angle - phi1_start);
    result.energy_drift = std::max(result.energy_drift, std::abs(energy - v0) / v0);
  });
  const auto reference = andrews_reference::solve(0.03);
  const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
  const auto rates = andrews::test_set_angles(andrews::body_rates(m, ws));
  double largest_rate = 0.0;
  for (double r : reference.rate) largest_rate = std::max(largest_rate, std::abs(r));
  for (int i = 0; i < 7; ++i) {
    result.angle_error = std::max(result.angle_error, std::abs(angles[i] - reference.angle[i]) /
                                                          std::abs(reference.angle[i]));
    result.rate_error =
        std::max(result.rate_error, std::abs(rates[i] - reference.rate[i]) / largest_rate);
  }
  return result;
}

}  // namespace

TEST_CASE("Andrews: consistent start reproduces the spec's accelerations and pin forces",
          "[andrews][planar]") {
  andrews::Mechanism m = andrews::build();
  Workspace ws(m.model);
  const auto report = odyn::assemble(m.model, ws);
  CHECK(report.position_residual < 1e-15);
  CHECK(m.model.num_velocities() == 21);
  CHECK(m.model.num_equations() == 20);
  CHECK(ws.v.cwiseAbs().maxCoeff() == 0.0);
  // Body angular accelerations: the spec's 40-digit values, and the reference's own.
  const auto angle_of = [&](int body) { return ws.vdot[3 * body + 2]; };
  CHECK(angle_of(0) == Approx(14222.44391995411387).epsilon(1e-11));
  CHECK(angle_of(1) == Approx(3555.610979988528468).epsilon(1e-11));
  CHECK(angle_of(0) == Approx(andrews_reference::initial_beta_ddot()).epsilon(1e-11));
  CHECK(angle_of(1) - angle_of(0) == Approx(andrews_reference::kSpecThetaDdot0).epsilon(1e-11));
  for (int body = 2; body < 7; ++body) CHECK(std::abs(angle_of(body)) < 1e-8);
  // Centre-of-mass accelerations of the crank and the rod.
  CHECK(ws.vdot[0] == Approx(0.8069920726856138607).epsilon(1e-11));
  CHECK(ws.vdot[1] == Approx(13.05973919006899208).epsilon(1e-11));
  CHECK(ws.vdot[3] == Approx(3.618306847639301278).epsilon(1e-11));
  CHECK(ws.vdot[4] == Approx(58.55589582503760038).epsilon(1e-11));
  // Pin forces: lambda_j is the force body a exerts on body b, i.e. the reaction on side b.
  const auto force = [&](int pin) {
    return odyn::reaction(m.model, ws, m.pins[pin], odyn::Side::b).force;
  };
  CHECK(force(2).x() == Approx(98.56687039624108961).epsilon(1e-11));  // J3, rod on triangle
  CHECK(force(2).y() == Approx(-6.122688344255662655).epsilon(1e-11));
  CHECK(force(0).x() == Approx(-98.61497962337862585).epsilon(1e-11));  // J1, crank on ground
  CHECK(force(0).y() == Approx(5.344125604523791506).epsilon(1e-11));
  CHECK(force(1).x() == Approx(98.58007721623497306).epsilon(1e-11));  // J2, crank on rod
  CHECK(force(1).y() == Approx(-5.908959324494275414).epsilon(1e-11));
  CHECK(force(3).x() == Approx(45.57577241791448361).epsilon(1e-11));  // J4, triangle on ground
  CHECK(force(3).y() == Approx(-107.1190195224529663).epsilon(1e-11));
  for (int pin = 4; pin < 10; ++pin) CHECK(force(pin).norm() < 1e-9);
  // The spring's energy.
  CHECK(odyn::potential_energy(m.model, ws) ==
        Approx(andrews_reference::kSpecSpringEnergy0).epsilon(1e-14));
}

TEST_CASE("Andrews: generalized-alpha against the reference, second order", "[andrews][planar]") {
  const Run fine = run(1e-6);
  // Measured: 2.0e-7 in the angles at h = 1e-6 (the crank turns 2.5 times).
  CHECK(fine.angle_error < 3e-7);
  CHECK(fine.rate_error < 1e-6);
  // No dissipation in the model: the energy balance holds to the integrator's error (measured
  // 3.5e-7 of the spring's initial energy), which also falls at second order.
  CHECK(fine.energy_drift < 1e-6);
  const Run coarse = run(2e-6);
  CHECK(coarse.angle_error / fine.angle_error == Approx(4.0).epsilon(0.1));
  CHECK(coarse.energy_drift / fine.energy_drift == Approx(4.0).epsilon(0.1));
}

#ifndef __SANITIZE_ADDRESS__  // 120 000 steps: Release builds only
TEST_CASE("Andrews: generalized-alpha keeps second order down to h = 2.5e-7", "[andrews][planar]") {
  // With Newton's tolerance fixed at its default for ordinary steps, 120 000 steps each left
  // their Newton error in the state: 1.1e-7 at h = 2.5e-7, no better than at 1e-6. Measured
  // now: 2.06e-7 at 1e-6 and 1.29e-8 at 2.5e-7, a ratio of 16.0.
  const Run coarse = run(1e-6);
  const Run fine = run(2.5e-7);
  CHECK(coarse.angle_error / fine.angle_error == Approx(16.0).epsilon(0.1));
  CHECK(fine.angle_error < 1.5e-8);
}
#endif

}  // namespace test_andrews
