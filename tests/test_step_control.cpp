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
  odyn::DynamicsSettings settings = with_tolerance("dopri5", 1e-11);
  const EngineRun run = run_planar_engine(settings);
  REQUIRE(run.times.size() == 1001);
  for (std::size_t k = 0; k < run.times.size(); ++k)
    REQUIRE(run.times[k] == Approx(1e-3 * static_cast<double>(k)).margin(1e-14));
  // Outputs fall inside steps and are interpolated, yet the piston follows the reference at
  // every one of them (measured: 4.1e-10 m) as closely as the steps follow it: theta(1) to
  // 9.9e-9 rad, in 2401 steps.
  CHECK(run.summary.statistics.steps < 3000);
  CHECK(run.z_error < 2e-9);
  CHECK(run.theta_error < 2e-8);
  CHECK(run.summary.max_position_residual < 1e-11);
}

TEST_CASE("The explicit methods' error estimate keeps the error's part along the constraints",
          "[step-control][joint]") {
  // keep_tangential(e) must leave a vector that moves no constraint to first order (checked
  // by moving the positions along it and by the crank pin's relative point velocity, computed
  // from the bodies' frames) and differs from e by a part orthogonal to it in the kinetic
  // energy metric (computed from the bodies' masses and velocities): the least-distance
  // projection that ends each step removes exactly that part.
  auto e = engine::build();
  using Model = engine::Model;
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws, {});
  const auto kinetic_energy = [&] {
    double energy = 0.0;
    for (int b = 1; b <= e.model.num_bodies(); ++b) {
      const auto& body = e.model.body(odyn::BodyId{b});
      const auto& frame = ws.frames[b];
      energy += 0.5 * body.mass * frame.linear_velocity.squaredNorm() +
                0.5 * frame.angular_velocity.dot(body.inertia * frame.angular_velocity);
    }
    return energy;
  };
  // The crank pin's two points (crank {0, 0, r}, rod {0, 0, -L / 2}) and their velocities.
  const engine::Parameters p;
  const auto pin_gap = [&] {
    const auto& crank = ws.frames[e.crank.index];
    const auto& rod = ws.frames[e.rod.index];
    const Eigen::Vector3d on_crank = crank.rotation * Eigen::Vector3d(0, 0, p.r);
    const Eigen::Vector3d on_rod = rod.rotation * Eigen::Vector3d(0, 0, -p.L / 2);
    const Eigen::Vector3d gap = crank.position + on_crank - rod.position - on_rod;
    const Eigen::Vector3d rate =
        crank.linear_velocity + (crank.rotation * crank.angular_velocity).cross(on_crank) -
        rod.linear_velocity - (rod.rotation * rod.angular_velocity).cross(on_rod);
    return std::pair{gap.norm(), rate.norm()};
  };
  const auto check = [&](auto& coordinates) {
    const Eigen::Index nq = coordinates.num_positions(), nv = coordinates.num_velocities();
    Eigen::VectorXd y(nq + nv);
    coordinates.read_state(y);
    coordinates.load(0.0, y);
    coordinates.evaluate_constraints();
    REQUIRE(coordinates.factorize());
    Eigen::VectorXd error = Eigen::VectorXd::LinSpaced(nq + nv, 1.0, -0.7);
    error += 0.3 * Eigen::VectorXd::LinSpaced(nq + nv, 0.0, 5.0).array().sin().matrix();
    Eigen::VectorXd tangential = error;
    coordinates.keep_tangential(tangential);
    // Moved by 1e-7 along each, the pin opens by O(1e-7) along e and by O(1e-14) along the
    // kept part; rates along the kept part leave the pin's points moving together (the
    // constraint is linear in the rates, and no driver moves it).
    const double step = 1e-7;
    const auto moved = [&](const Eigen::VectorXd& along) {
      Eigen::VectorXd z = y;
      z.head(nq) += step * along.head(nq);
      z.tail(nv).setZero();
      coordinates.load(0.0, z);
      const double gap = pin_gap().first;
      z.head(nq) = y.head(nq);
      z.tail(nv) = along.tail(nv);
      coordinates.load(0.0, z);
      return std::pair{gap, pin_gap().second};
    };
    const auto [gap_whole, rate_whole] = moved(error);
    const auto [gap_kept, rate_kept] = moved(tangential);
    INFO("pin gap " << gap_whole << " and " << gap_kept << " m, pin rate " << rate_whole << " and "
                    << rate_kept << " m/s");
    CHECK(gap_whole > 1e-8);
    CHECK(gap_kept < 1e-13);
    CHECK(rate_whole > 1e-2);
    CHECK(rate_kept < 1e-13);
    // <e - kept, kept> = 0 in the kinetic energy metric, for either part, by polarization.
    const auto energy_of = [&](const Eigen::VectorXd& rates) {
      Eigen::VectorXd z = y;
      z.tail(nv) = rates;
      coordinates.load(0.0, z);
      return kinetic_energy();
    };
    const auto metric = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
      return energy_of(a + b) - energy_of(a) - energy_of(b);
    };
    const Eigen::VectorXd removed = error - tangential;
    // The position part in rate coordinates: the same numbers in joint coordinates; the
    // velocity part as it is.
    const Eigen::VectorXd removed_v = removed.tail(nv), kept_v = tangential.tail(nv);
    const double scale = std::sqrt(std::abs(metric(removed_v, removed_v) * metric(kept_v, kept_v)));
    CHECK(std::abs(metric(removed_v, kept_v)) < 1e-10 * scale);
    if (nq == nv) {
      const Eigen::VectorXd removed_q = removed.head(nq), kept_q = tangential.head(nq);
      const double scale_q =
          std::sqrt(std::abs(metric(removed_q, removed_q) * metric(kept_q, kept_q)));
      CHECK(std::abs(metric(removed_q, kept_q)) < 1e-10 * scale_q);
    }
    // Applied twice, it changes nothing more.
    Eigen::VectorXd again = tangential;
    coordinates.keep_tangential(again);
    CHECK((again - tangential).lpNorm<Eigen::Infinity>() < 1e-12 * error.lpNorm<Eigen::Infinity>());
  };
  SECTION("joint coordinates") {
    odyn::JointCoordinates<Model> joint(e.model, ws);
    check(joint);
  }
  SECTION("absolute coordinates") {
    odyn::AbsoluteCoordinates<Model> absolute(e.model, ws);
    check(absolute);
  }
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
