// The fixed-step Adams-Bashforth integrator (index 1 + projection) against independent
// references: a large-amplitude compound pendulum against its elliptic-integral solution (order
// k on fixed steps), the engine in spatial (absolute and joint) and planar coordinates against
// the minimal-coordinate reference (events, restarts, the constraint residuals), and a clear
// error beyond the explicit stability limit.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <string>

#include <odyn/odyn.hpp>

#include "engine_model.hpp"
#include "reference/engine_reference.hpp"
#include "stiff_chain_model.hpp"
#include "swinging_bar.hpp"

namespace test_adams {

namespace {

namespace pl = odyn::planar;

odyn::DynamicsSettings adams(double step, int order) {
  odyn::DynamicsSettings settings;
  settings.integrator = "adams";
  settings.step = step;
  settings.adams.order = order;
  return settings;
}

/// A 1 m, 1 kg bar swinging about one end, released at rest from 2 rad: after one period
/// T = 4 sqrt(I_O / (m g d)) K(sin 1) it is back at 2 rad, at rest. Returns the largest error
/// of angle and angular velocity there, after `steps` equal steps.
double pendulum_error(int steps, int order) {
  using namespace swinging_bar;
  const double period = swinging_bar::period();
  pl::DefaultModel model = build();
  odyn::Workspace<pl::DefaultModel> ws(model);
  auto settings = adams(period / steps, order);
  // Drift projected at once, so that what is measured is the truncation error.
  settings.adams.projection_tolerance = 1e-14;
  settings.adams.velocity_tolerance = 1e-13;
  settings.t_end = settings.output_interval = period;
  const auto summary =
      odyn::simulate_with<odyn::AdamsBashforth>(model, ws, settings, [](const auto&) {});
  CHECK(summary.statistics.steps == steps);
  return std::max(std::abs(ws.q[2] - theta0), std::abs(ws.v[2]));
}

}  // namespace

TEST_CASE("adams: order k on a large-amplitude pendulum against its elliptic-integral solution",
          "[adams][pendulums]") {
  for (const int order : {2, 3, 4, 5}) {
    const double coarse = pendulum_error(800, order), fine = pendulum_error(1600, order);
    INFO("order " << order << ": errors " << coarse << " and " << fine);
    // Halving the step divides the error by about 2^k.
    CHECK(coarse / fine > 0.6 * std::pow(2.0, order));
    CHECK(coarse / fine < 1.5 * std::pow(2.0, order));
    CHECK(fine < 3e-3 * std::pow(0.05, order - 2));
  }
}

TEST_CASE("adams: the engine against the minimal-coordinate reference at h = 1e-4",
          "[adams][engine]") {
  const auto reference = engine_reference::solve(1.0, 1e-3);
  double peak_reaction = 0.0;
  for (const auto& sample : reference)
    peak_reaction = std::max(peak_reaction, std::abs(sample.R_z));

  // The same method in absolute and in joint coordinates (4 coordinates and the crank pin's 3
  // closure equations instead of 18 and 17). Each by its type: the selection by name is
  // test_step_control's and test_joint_coordinates'.
  const auto run = [&]<template <class> class Integrator>(const char* coordinates) {
    auto e = engine::build();
    odyn::Workspace<engine::Model> ws(e.model);
    std::size_t k = 0;
    double z_error = 0.0, reaction_error = 0.0, velocity_residual = 0.0;
    const auto settings = adams(1e-4, 5);
    const auto summary =
        odyn::simulate_with<Integrator>(e.model, ws, settings, [&](const auto& state) {
          const auto& expected = reference.at(k++);
          z_error =
              std::max(z_error, std::abs(engine::piston_height(e, state) - expected.z_piston));
          // Away from the jumps of the gas force, where an output may sit on either side.
          if (std::abs(engine::crank_angle(e, state) / std::numbers::pi -
                       std::round(engine::crank_angle(e, state) / std::numbers::pi)) > 1e-3)
            reaction_error = std::max(reaction_error,
                                      std::abs(engine::bearing_force_z(e, state) - expected.R_z));
          velocity_residual =
              std::max(velocity_residual, odyn::constraint_residuals(e.model, state).second);
        });
    const double theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    INFO(coordinates << " coordinates: theta(1) error " << theta_error << ", z error " << z_error
                     << ", R_z error " << reaction_error / peak_reaction << " of the peak, |Phi| "
                     << summary.max_position_residual << ", |Phi_q v| " << velocity_residual);
    CHECK(k == reference.size());
    // Generalized-alpha at this step: 5.1e-4 rad and 2.1e-5 m. Measured here: 8.6e-7 rad
    // in absolute and 8.7e-7 rad in joint coordinates.
    CHECK(theta_error < 3e-6);
    CHECK(z_error < 1.5e-7);
    CHECK(reaction_error < 1e-5 * peak_reaction);
    CHECK(summary.max_position_residual < 1e-10);
    CHECK(velocity_residual < 1e-7);
    // Every switch of the gas force is located and restarts the method.
    CHECK(summary.statistics.events >= 45);
    CHECK(summary.statistics.restarts == summary.statistics.events + 1);
    // About one factorization per step: the start-up steps after each restart take 7.
    CHECK(summary.statistics.factorizations < 1.4 * static_cast<double>(summary.statistics.steps));
  };
  run.operator()<odyn::AdamsBashforth>("absolute");
  run.operator()<odyn::JointAdamsBashforth>("joint");

  SECTION("planar, order 4 and 6: the error falls with the order") {
    double errors[2] = {0.0, 0.0};
    int i = 0;
    for (const int order : {4, 6}) {
      auto e = engine::planar::build();
      odyn::Workspace<engine::planar::Model> ws(e.model);
      odyn::simulate_with<odyn::AdamsBashforth>(e.model, ws, adams(1e-4, order),
                                                [](const auto&) {});
      errors[i++] = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    }
    INFO("theta(1) errors " << errors[0] << " (order 4), " << errors[1] << " (order 6)");
    CHECK(errors[0] < 3e-5);
    CHECK(errors[1] < 0.05 * errors[0]);
  }
}

TEST_CASE("adams: beyond the explicit stability limit, a clear error; bad settings refused",
          "[adams][errors]") {
  auto chain = stiff_chain::build({.displacement2 = 1e-3});
  odyn::Workspace<stiff_chain::Model> ws(chain.model);
  SECTION("a step ten times the stiff mode's limit") {
    auto settings = adams(2e-3, 4);
    settings.t_end = 1.0;
    try {
      odyn::simulate_with<odyn::AdamsBashforth>(chain.model, ws, settings, [](const auto&) {});
      FAIL("the run went through");
    } catch (const odyn::SolverError& error) {
      const std::string message = error.what();
      CHECK_THAT(message, Catch::Contains("adams") && Catch::Contains("stability") &&
                              Catch::Contains("implicit"));
      CHECK(error.time() < 1.0);
    }
  }
  SECTION("orders outside 1 to 6") {
    for (const int order : {0, 7})
      CHECK_THROWS_WITH(odyn::simulate_with<odyn::AdamsBashforth>(
                            chain.model, ws, adams(1e-4, order), [](const auto&) {}),
                        Catch::Contains("adams") && Catch::Contains("order"));
  }
}

}  // namespace test_adams
