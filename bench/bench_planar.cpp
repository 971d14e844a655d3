// Planar against spatial, and Andrews' mechanism:
//  - one generalized-alpha step of the same slider-crank (the engine of shared/specs/engine.md)
//    built from planar and from spatial elements, with the size of its iteration matrix;
//  - the planar slider-crank's whole 1 s run with its error against the minimal-coordinate
//    reference (the spatial one is bench_engine's Run);
//  - Andrews' mechanism to t = 0.03 with its error against the independent reference.
// Run: build/bench/odyn_bench --benchmark_filter='SliderCrank|Andrews' --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "andrews_model.hpp"
#include "engine_model.hpp"
#include "reference/andrews_reference.hpp"
#include "reference/engine_reference.hpp"

namespace bench_planar {

template <class Build>
void step(benchmark::State& state, Build build) {
  auto e = build();
  using Model = typename decltype(e)::Model;
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  auto integrator = std::make_unique<odyn::GeneralizedAlpha<Model>>(e.model, ws);
  const double h = 1e-4;
  for (auto _ : state) {
    if (integrator->time() > 1.0) {  // the whole cycle, then start over
      state.PauseTiming();
      ws = odyn::Workspace<Model>(e.model);
      odyn::assemble(e.model, ws);
      integrator = std::make_unique<odyn::GeneralizedAlpha<Model>>(e.model, ws);
      state.ResumeTiming();
    }
    odyn::advance_to(e.model, ws, *integrator, integrator->time() + h, h);
  }
  const auto& stats = integrator->statistics();
  state.counters["coordinates"] = e.model.num_velocities();
  state.counters["equations"] = e.model.num_equations();
  state.counters["matrix_size"] = e.model.num_velocities() + e.model.num_equations();
  state.counters["newton_per_step"] = double(stats.newton_iterations) / double(stats.steps);
}

void SliderCrankStepPlanar(benchmark::State& state) {
  step(state, [] { return engine::planar::build(); });
}
void SliderCrankStepSpatial(benchmark::State& state) {
  step(state, [] { return engine::build(); });
}
BENCHMARK(SliderCrankStepPlanar);
BENCHMARK(SliderCrankStepSpatial);

/// The planar engine's standard 1 s run at step h (microseconds as the argument), with its error.
void SliderCrankRunPlanar(benchmark::State& state) {
  const double h = double(state.range(0)) * 1e-6;
  static const auto reference = engine_reference::solve(1.0, 1e-3);
  double theta_error = 0.0, z_error = 0.0, seconds = 0.0;
  long steps = 0;
  for (auto _ : state) {
    auto e = engine::planar::build();
    odyn::Workspace<engine::planar::Model> ws(e.model);
    odyn::DynamicsSettings settings;
    settings.integrator = "generalized-alpha";
    settings.step = h;
    std::size_t k = 0;
    z_error = 0.0;
    const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& s) {
      z_error = std::max(z_error, std::abs(engine::piston_height(e, s) - reference[k++].z_piston));
    });
    theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    steps = summary.statistics.steps;
    seconds = summary.wall_seconds;
  }
  state.counters["theta_error"] = theta_error;
  state.counters["z_max_error"] = z_error;
  state.counters["us_per_step"] = 1e6 * seconds / double(steps);
}
BENCHMARK(SliderCrankRunPlanar)->Arg(200)->Arg(100)->Arg(50)->Unit(benchmark::kMillisecond);

/// Andrews' mechanism to t = 0.03 at step h (nanoseconds as the argument), Newton to 1e-12.
void AndrewsRun(benchmark::State& state) {
  const double h = double(state.range(0)) * 1e-9;
  static const auto reference = andrews_reference::solve(0.03);
  double angle_error = 0.0, seconds = 0.0;
  long steps = 0;
  for (auto _ : state) {
    andrews::Mechanism m = andrews::build();
    odyn::Workspace<andrews::Model> ws(m.model);
    odyn::DynamicsSettings settings;
    settings.integrator = "generalized-alpha";
    settings.step = h;
    settings.t_end = 0.03;
    settings.output_interval = 0.03;
    const auto summary = odyn::simulate(m.model, ws, settings, [](const auto&) {});
    const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
    angle_error = 0.0;
    for (int i = 0; i < 7; ++i)
      angle_error = std::max(
          angle_error, std::abs(angles[i] - reference.angle[i]) / std::abs(reference.angle[i]));
    steps = summary.statistics.steps;
    seconds = summary.wall_seconds;
  }
  state.counters["angle_rel_error"] = angle_error;
  state.counters["steps"] = double(steps);
  state.counters["us_per_step"] = 1e6 * seconds / double(steps);
}
BENCHMARK(AndrewsRun)->Arg(4000)->Arg(1000)->Arg(250)->Arg(62)->Unit(benchmark::kMillisecond);

}  // namespace bench_planar
