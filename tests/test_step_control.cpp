// Step-size control and dense output, through the driver every integrator shares: adaptive
// generalized-alpha and HHT against the engine's independent reference, output times that land
// exactly on the requested ones with interpolated states as accurate as the steps, and the
// error estimate reported by each run.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "engine_model.hpp"
#include "reference/engine_reference.hpp"

namespace test_step_control {

namespace {

struct EngineRun {
  double theta_error = 0.0, z_error = 0.0;
  std::vector<double> times;
  odyn::RunSummary summary;
};

EngineRun run_planar_engine(const odyn::DynamicsSettings& settings) {
  static const auto reference = engine_reference::solve(1.0, 1e-3);
  auto e = engine::planar::build();
  odyn::Workspace<engine::planar::Model> ws(e.model);
  EngineRun run;
  std::size_t k = 0;
  run.summary = odyn::simulate(e.model, ws, settings, [&](const auto& state) {
    run.times.push_back(state.t);
    run.z_error =
        std::max(run.z_error, std::abs(engine::piston_height(e, state) - reference.at(k).z_piston));
    // The crank angle from the stateful gas force: advanced to every output time.
    run.theta_error = std::abs(engine::crank_angle(e, state) - reference.at(k).theta);
    ++k;
  });
  return run;
}

odyn::DynamicsSettings with_tolerance(const char* integrator, double tolerance) {
  odyn::DynamicsSettings settings;
  settings.integrator = integrator;
  settings.rtol = settings.atol = tolerance;
  settings.generalized_alpha.adaptive = true;
  settings.step = 1e-5;
  return settings;
}

}  // namespace

TEST_CASE("Adaptive generalized-alpha and HHT follow the engine's reference",
          "[step-control][engine]") {
  for (const char* name : {"generalized-alpha", "hht"}) {
    INFO(name);
    const EngineRun loose = run_planar_engine(with_tolerance(name, 1e-5));
    const EngineRun tight = run_planar_engine(with_tolerance(name, 1e-7));
    INFO("theta(1) errors " << loose.theta_error << " and " << tight.theta_error << " rad in "
                            << loose.summary.statistics.steps << " and "
                            << tight.summary.statistics.steps << " steps");
    // Measured (generalized-alpha): 1.3e-2 rad and 5.5e-4 m in 2500 steps; 1.2e-4 to 4.6e-4
    // rad and 4.9e-6 to 1.9e-5 m in 10 000 steps. The tight run's error moves within that band
    // with rounding-level changes (a different but equally exact linear solver): they flip some
    // of its 1700 accept/reject decisions, and a different sequence of steps follows.
    CHECK(tight.theta_error < 1e-3);
    CHECK(tight.z_error < 5e-5);
    CHECK(tight.z_error < 0.1 * loose.z_error);
    CHECK(tight.summary.statistics.steps > loose.summary.statistics.steps);
    CHECK(tight.summary.statistics.max_error_estimate <= 1.0);
    CHECK(tight.summary.statistics.events == loose.summary.statistics.events);
    CHECK(tight.summary.max_position_residual < 1e-10);
  }
}

TEST_CASE("Outputs land on the output times; dense output is as accurate as the steps",
          "[step-control][dopri5]") {
  odyn::DynamicsSettings settings = with_tolerance("dopri5", 1e-10);
  const EngineRun run = run_planar_engine(settings);
  REQUIRE(run.times.size() == 1001);
  for (std::size_t k = 0; k < run.times.size(); ++k)
    REQUIRE(run.times[k] == Approx(1e-3 * static_cast<double>(k)).margin(1e-14));
  // Fewer steps than outputs: most outputs are interpolated, yet the piston follows the
  // reference at every one of them (measured: 2e-10 m) and theta(1) to 1.4e-9 rad.
  CHECK(run.summary.statistics.steps < 3000);
  CHECK(run.z_error < 2e-9);
  CHECK(run.theta_error < 1e-8);
  CHECK(run.summary.max_position_residual < 1e-11);
}

// Selection by name is the one path that instantiates every integrator for a model, so it is
// checked here, on the model whose runs already go through it.
TEST_CASE("An unknown integrator name is refused, with the known names", "[errors]") {
  auto e = engine::planar::build();
  odyn::Workspace<engine::planar::Model> ws(e.model);
  odyn::DynamicsSettings settings;
  settings.integrator = "euler";
  try {
    odyn::simulate(e.model, ws, settings, [](const auto&) {});
    FAIL("the run started");
  } catch (const odyn::ModelError& error) {
    const std::string message = error.what();
    CHECK_THAT(message, Catch::Contains("dynamics") && Catch::Contains("'euler'"));
    for (const auto& [name, what] : odyn::integrator_names())
      CHECK_THAT(message, Catch::Contains(name));
  }
}

}  // namespace test_step_control
