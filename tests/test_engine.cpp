// The flagship engine (shared/specs/engine.md) in absolute coordinates against an independent
// minimal-coordinate solution (tests/reference/engine_reference.hpp: the 1-DOF equation in the
// crank angle, integrated by RK4 at h = 1e-5 with exact stroke boundaries).

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "engine_model.hpp"
#include "reference/engine_reference.hpp"

namespace test_engine {

struct Errors {
  double theta = 0.0, z_piston = 0.0, reaction = 0.0, phi = 0.0, phid = 0.0, theta_end = 0.0;
};

/// Runs the engine to t_end and compares every output with the reference.
Errors run(double h, double t_end, const std::vector<engine_reference::Sample>& reference) {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> ws(e.model);
  odyn::DynamicsSettings settings;
  settings.step = h;
  settings.t_end = t_end;
  settings.output_interval = 1e-3;
  Errors errors;
  std::size_t k = 0;
  odyn::simulate(e.model, ws, settings, [&](const auto& state) {
    const auto& ref = reference.at(k++);
    REQUIRE(state.t == Approx(ref.t).margin(1e-12));
    const auto [phi, phid] = odyn::constraint_residuals(e.model, state);
    const double reaction = odyn::reaction(e.model, state, e.bearing).force.z();
    errors.theta = std::max(errors.theta, std::abs(engine::crank_angle(e, state) - ref.theta));
    errors.z_piston = std::max(errors.z_piston,
                               std::abs(state.frames[e.piston.index].position.z() - ref.z_piston));
    errors.reaction = std::max(errors.reaction, std::abs(reaction - ref.R_z));
    errors.phi = std::max(errors.phi, phi);
    errors.phid = std::max(errors.phid, phid);
    errors.theta_end = std::abs(engine::crank_angle(e, state) - ref.theta);
  });
  REQUIRE(k == reference.size());
  return errors;
}

TEST_CASE("engine: consistent start matches the minimal-coordinate equations", "[engine]") {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> ws(e.model);
  odyn::assemble(e.model, ws);
  const engine_reference::Parameters p;
  // The crank keeps its given speed; everything else follows from the constraints.
  CHECK(ws.v[3] == Approx(p.omega0).epsilon(1e-14));
  CHECK(ws.frames[e.piston.index].position.z() == Approx(0.18).epsilon(1e-14));
  // Crank angular acceleration and bearing reaction at t = 0.
  const double alpha = engine_reference::angular_acceleration(0.0, p.omega0);
  CHECK(ws.vdot[3] == Approx(alpha).epsilon(1e-9));
  const double reaction = odyn::reaction(e.model, ws, e.bearing).force.z();
  CHECK(reaction == Approx(engine_reference::reaction_z(0.0, p.omega0, alpha)).epsilon(1e-9));
  // The block exerts the opposite force on itself through the same joint.
  CHECK(odyn::reaction(e.model, ws, e.bearing, odyn::Side::a).force.z() ==
        Approx(-reaction).epsilon(1e-12));
}

TEST_CASE("engine: generalized-alpha against the reference, second order", "[engine]") {
  const auto reference = engine_reference::solve(1.0, 1e-3);
  const Errors fine = run(1e-4, 1.0, reference);
  // Second-order global error at h = 1e-4 (measured 5.0e-4 rad; see the README's table).
  CHECK(fine.theta < 7e-4);
  CHECK(fine.z_piston < 3e-5);
  CHECK(fine.reaction < 30.0);  // N, against a peak of 24.5 kN
  CHECK(fine.phi < 1e-10);
  CHECK(fine.phid < 2e-3);
  // Halving the step divides the error by about four.
  const Errors coarse = run(2e-4, 1.0, reference);
  CHECK(coarse.theta_end / fine.theta_end == Approx(4.0).epsilon(0.15));
}

}  // namespace test_engine
