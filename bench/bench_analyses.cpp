// Statics and modes of a large model on the sparse path (analysis/sparse_linearization.hpp)
// against the dense one: a hanging chain of N hinged links (tests/hinge_chain.hpp), its lowest
// 20 modes about the equilibrium, which statics first find from the chain turned by 0.1 rad.
// One whole analysis per iteration (equilibrium, tangent, eigenvalues).
// Run: build/bench/odyn_bench --benchmark_filter=HingeChain --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <string>

#include <odyn/analysis/modes.hpp>

#include "hinge_chain.hpp"

namespace bench_analyses {

/// Arguments: links, and 1 for the sparse method, 0 for the dense one (absolute coordinates).
void HingeChainModes(benchmark::State& state) {
  const hinge_chain::Model model = hinge_chain::build(static_cast<int>(state.range(0)), 0.1);
  odyn::ModeSettings settings;
  settings.count = 20;
  settings.method = state.range(1) == 1 ? "sparse" : "dense";
  double lowest = 0.0;
  for (auto _ : state) {
    odyn::Workspace<hinge_chain::Model> ws(model);
    const odyn::Modes modes = odyn::natural_modes(model, ws, settings);
    lowest = modes.frequencies[0];
  }
  state.counters["lowest_hz"] = lowest;
  state.SetLabel(settings.method);
}
BENCHMARK(HingeChainModes)
    ->Args({50, 0})
    ->Args({50, 1})
    ->Args({200, 1})
    ->Args({1000, 1})
    ->Args({4000, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace bench_analyses
