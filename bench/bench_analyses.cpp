// The analyses of a large model on the sparse path against the dense one:
//  - statics and modes (analysis/sparse_linearization.hpp): a hanging chain of N hinged links
//    (tests/hinge_chain.hpp), its lowest 20 modes about the equilibrium, which statics first
//    find from the chain turned by 0.1 rad; one whole analysis per iteration (equilibrium,
//    tangent, eigenvalues);
//  - kinematics (analysis/kinematics.hpp): a planar chain of N links, each hinge driven
//    (tests/driven_chain.hpp), from its assembly over 0.1 s with an output every 0.01 s.
// Run: build/bench/odyn_bench --benchmark_filter='HingeChain|DrivenChain'
//      --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <string>

#include <odyn/analysis/kinematics.hpp>
#include <odyn/analysis/modes.hpp>

#include "driven_chain.hpp"
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

/// Arguments: links, and the path: 0 dense matrices, 1 sparse rows, 2 joint coordinates.
void DrivenChainKinematics(benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  const driven_chain::Chain chain = driven_chain::build(links);
  odyn::KinematicSettings settings;
  settings.linear_solver =
      state.range(1) == 1 ? odyn::LinearSolver::klu : odyn::LinearSolver::dense;
  if (state.range(1) == 2) settings.coordinates = "joint";
  double tip_angle = 0.0;
  for (auto _ : state) {
    odyn::Workspace<driven_chain::Model> ws(chain.model);
    odyn::kinematic_analysis(
        chain.model, ws, 0.1, 0.01, [&](const auto& s) { tip_angle = s.frames[links].angle; },
        settings);
  }
  // Against forward kinematics at the end.
  state.counters["tip_angle_error"] =
      std::abs(tip_angle - driven_chain::chain_at(links, 0.1).back().angle);
  state.SetLabel(state.range(1) == 2 ? "joint" : state.range(1) == 1 ? "sparse" : "dense");
}
BENCHMARK(DrivenChainKinematics)
    ->Args({100, 0})
    ->Args({100, 1})
    ->Args({100, 2})
    ->Args({400, 2})
    ->Args({1000, 1})
    ->Args({4000, 1})
    ->Args({16000, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace bench_analyses
