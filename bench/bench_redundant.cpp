// Redundant constraints at the cost of the non-redundant model: Bricard's linkage (30
// equations, one of them redundant at every pose) against the same linkage with J6 a
// cylindrical joint (29 independent equations, the same motion; examples/bricard_model.hpp).
// One whole 1.1 s swing per iteration; the counter us_per_step is the stepping time per step
// (setup left out), the figure to compare between the two models.
// Run: build/bench/odyn_bench --benchmark_filter=Bricard --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <array>
#include <string>

#include "bricard_model.hpp"

namespace bench_redundant {

/// Arguments: integrator (0 generalized-alpha at h = 1e-3, 1 dop853 and 2 bdf at tolerance
/// 1e-8), and 1 for the redundant linkage, 0 for its cylindrical twin.
void BricardSwing(benchmark::State& state) {
  static const std::array<std::string, 3> integrators{"generalized-alpha", "dop853", "bdf"};
  bricard::Parameters p;
  p.cylinder = state.range(1) == 0;
  const bricard::Linkage l = bricard::build(p);
  odyn::DynamicsSettings settings;
  settings.integrator = integrators[static_cast<std::size_t>(state.range(0))];
  settings.step = 1e-3;
  settings.rtol = settings.atol = 1e-8;
  settings.t_end = 1.1;
  settings.output_interval = 0.1;
  double stepping = 0.0;
  long steps = 0, redundant = 0;
  for (auto _ : state) {
    odyn::Workspace<bricard::Model> ws(l.model);
    const auto summary = odyn::simulate(l.model, ws, settings, [](const auto&) {});
    stepping += summary.wall_seconds - summary.setup_seconds;
    steps += summary.statistics.steps;
    redundant = static_cast<long>(summary.redundant_equations.size());
  }
  state.counters["us_per_step"] = 1e6 * stepping / double(steps);
  state.counters["redundant_equations"] = double(redundant);
  state.SetLabel(settings.integrator + (p.cylinder ? ", cylindrical J6" : ", redundant"));
}
BENCHMARK(BricardSwing)->ArgsProduct({{0, 1, 2}, {1, 0}})->Unit(benchmark::kMillisecond);

}  // namespace bench_redundant
