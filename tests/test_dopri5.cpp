// The explicit Dormand-Prince 5(4) integrator with error control (index 1 + projection):
// Andrews' mechanism and the engine against their independent references, the heavy top's
// steady precession against the gyroscope equation, and bad settings.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "andrews_model.hpp"
#include "engine_model.hpp"
#include "reference/andrews_reference.hpp"
#include "reference/engine_reference.hpp"
#include "reference/steady_top.hpp"

namespace test_dopri5 {

namespace {

odyn::DynamicsSettings dopri5(double tolerance) {
  odyn::DynamicsSettings settings;
  settings.integrator = "dopri5";
  settings.rtol = tolerance;
  settings.atol = tolerance;
  return settings;
}

}  // namespace

TEST_CASE("dopri5: Andrews' mechanism to ten digits", "[dopri5][andrews]") {
  const auto reference = andrews_reference::solve(0.03);
  auto largest_error = [&](double tolerance) {
    andrews::Mechanism m = andrews::build();
    odyn::Workspace<andrews::Model> ws(m.model);
    odyn::DynamicsSettings settings = dopri5(tolerance);
    settings.step = 1e-6;
    settings.t_end = 0.03;
    settings.output_interval = 1e-3;
    const auto summary =
        odyn::simulate_with<odyn::DormandPrince>(m.model, ws, settings, [](const auto&) {});
    CHECK(summary.max_position_residual < 1e-11);
    CHECK(summary.max_velocity_residual < 1e-11);
    const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
    double error = 0.0;
    for (int i = 0; i < 7; ++i)
      error =
          std::max(error, std::abs(angles[i] - reference.angle[i]) / std::abs(reference.angle[i]));
    return error;
  };
  // Measured: 5.0e-11 at 1e-10 and 1.1e-8 at 1e-8.
  CHECK(largest_error(1e-10) < 1e-9);
  CHECK(largest_error(1e-8) < 1e-7);
}

TEST_CASE("dopri5: the engine through its switches", "[dopri5][engine]") {
  const auto reference = engine_reference::solve(1.0, 1e-3);
  auto check = [&](auto e) {
    odyn::Workspace<typename decltype(e)::Model> ws(e.model);
    std::size_t k = 0;
    double z_error = 0.0;
    const auto summary = odyn::simulate_with<odyn::DormandPrince>(
        e.model, ws, dopri5(1e-11), [&](const auto& state) {
          z_error = std::max(
              z_error, std::abs(engine::piston_height(e, state) - reference.at(k++).z_piston));
        });
    const double theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    INFO("theta error " << theta_error << " rad, z error " << z_error << " m, steps "
                        << summary.statistics.steps);
    // Measured: 6.1e-9 rad and 2.5e-10 m (spatial), 9.9e-9 rad and 4.1e-10 m (planar). The
    // error estimate holds only the error along the constraints to the tolerance (see
    // explicit_runge_kutta.hpp), so a tolerance buys less accuracy than when the error across
    // them counted in full (4.9e-9 rad at 1e-10 then, 4.8e-8 rad now), in fewer steps.
    CHECK(theta_error < 2e-8);
    CHECK(z_error < 1e-9);
    CHECK(summary.statistics.events ==
          static_cast<long>(std::floor(reference.back().theta / std::numbers::pi)));
    CHECK(summary.max_position_residual < 1e-11);
  };
  check(engine::build());
  check(engine::planar::build());
}

TEST_CASE("dopri5: heavy symmetric top in steady precession", "[dopri5][pendulums]") {
  // Against the gyroscope equation; the quaternion is integrated as four numbers and
  // renormalized.
  const auto top = steady_top::run<odyn::DormandPrince>(dopri5(1e-11));
  steady_top::check_precession(top);
}

TEST_CASE("dopri5: bad tolerances are refused by name", "[dopri5][errors]") {
  auto e = engine::planar::build();
  odyn::Workspace<engine::planar::Model> ws(e.model);
  odyn::DynamicsSettings settings = dopri5(-1.0);
  CHECK_THROWS_WITH(
      odyn::simulate_with<odyn::DormandPrince>(e.model, ws, settings, [](const auto&) {}),
      Catch::Contains("rtol"));
}

}  // namespace test_dopri5
