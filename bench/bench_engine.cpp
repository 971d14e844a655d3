// Speed on the flagship engine (shared/specs/engine.md):
//  - one time step per integrator setting and per saddle-point solver (generalized-alpha, HHT,
//    explicit Adams-Bashforth),
//  - a whole 1 s run with its crank-angle error against the minimal-coordinate reference,
//  - the evaluation of Phi, Phi_q, M and Q, and an explicit stage's parts (evaluations,
//    saddle-point factorization, solve),
//  - per-type pools against std::variant dispatch for the same constraint evaluations.
// Run: build/bench/odyn_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <memory>
#include <variant>
#include <vector>

#include "engine_model.hpp"
#include "reference/engine_reference.hpp"

namespace bench_engine {

using Model = engine::Model;

/// Steps of h = 1e-4 s of an integrator with its settings, through whole cycles.
template <class Integrator>
void step_with(benchmark::State& state, typename Integrator::Settings settings) {
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  auto integrator = std::make_unique<Integrator>(e.model, ws, settings);
  const double h = 1e-4;
  for (auto _ : state) {
    // Steps through the whole cycle (events included); start over after a simulated second.
    if (integrator->time() > 1.0) {
      state.PauseTiming();
      ws = odyn::Workspace<Model>(e.model);
      odyn::assemble(e.model, ws);
      integrator = std::make_unique<Integrator>(e.model, ws, settings);
      state.ResumeTiming();
    }
    odyn::advance_to(e.model, ws, *integrator, integrator->time() + h, h);
  }
  const auto& stats = integrator->statistics();
  state.counters["newton_per_step"] = double(stats.newton_iterations) / double(stats.steps);
  state.counters["factorizations_per_step"] = double(stats.factorizations) / double(stats.steps);
}

template <class Solver>
void step(benchmark::State& state, odyn::GeneralizedAlphaSettings settings) {
  step_with<odyn::GeneralizedAlpha<Model, Solver>>(state, settings);
}

void StepGeneralizedAlpha(benchmark::State& state) {
  step<odyn::BlockSchurSaddlePoint<Model>>(state, {.rho_inf = 0.9});
}
void StepGeneralizedAlphaDenseLu(benchmark::State& state) {
  step<odyn::DenseSaddlePoint<Model>>(state, {.rho_inf = 0.9});
}
void StepGeneralizedAlphaRho05(benchmark::State& state) {
  step<odyn::BlockSchurSaddlePoint<Model>>(state, {.rho_inf = 0.5});
}
void StepHht(benchmark::State& state) {
  step<odyn::BlockSchurSaddlePoint<Model>>(state, {.rho_inf = 0.9, .hht = true});
}
BENCHMARK(StepGeneralizedAlpha);
BENCHMARK(StepGeneralizedAlphaDenseLu);
BENCHMARK(StepGeneralizedAlphaRho05);
BENCHMARK(StepHht);

/// Explicit Adams-Bashforth of the order given as the argument (start-up steps included).
void StepAdams(benchmark::State& state) {
  step_with<odyn::AdamsBashforth<Model>>(state, {.order = int(state.range(0))});
}
BENCHMARK(StepAdams)->Arg(5)->Arg(6);

/// The standard 1 s run at step h (in microseconds as the first argument), with its error;
/// generalized-alpha, or with a second argument, Adams-Bashforth of that order.
void Run(benchmark::State& state) {
  const double h = double(state.range(0)) * 1e-6;
  const int adams_order = state.range(1) > 0 ? int(state.range(1)) : 0;
  static const auto reference = engine_reference::solve(1.0, 1e-3);
  double theta_error = 0.0, z_error = 0.0, seconds = 0.0;
  long steps = 0;
  for (auto _ : state) {
    engine::Engine e = engine::build();
    odyn::Workspace<Model> ws(e.model);
    odyn::DynamicsSettings settings;
    settings.integrator = "generalized-alpha";
    settings.step = h;
    if (adams_order > 0) settings.integrator = "adams", settings.adams.order = adams_order;
    std::size_t k = 0;
    z_error = 0.0;
    const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& s) {
      z_error = std::max(z_error,
                         std::abs(s.frames[e.piston.index].position.z() - reference[k++].z_piston));
    });
    theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    steps = summary.statistics.steps;
    seconds = summary.wall_seconds;
  }
  state.counters["theta_error"] = theta_error;
  state.counters["z_max_error"] = z_error;
  state.counters["steps"] = double(steps);
  state.counters["us_per_step"] = 1e6 * seconds / double(steps);  // of the last run
}
BENCHMARK(Run)
    ->Args({200, 0})
    ->Args({100, 0})
    ->Args({50, 0})
    ->Args({25, 0})
    ->Args({200, 6})
    ->Args({100, 5})
    ->Args({100, 6})
    ->Unit(benchmark::kMillisecond);

/// Phi and Phi_q, M (the Newton matrix's mass part) and Q at one state.
void EvaluateBlocks(benchmark::State& state) {
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  odyn::BlockSchurSaddlePoint<Model> unused;
  Eigen::MatrixXd mass = Eigen::MatrixXd::Zero(e.model.num_velocities(), e.model.num_velocities());
  for (auto _ : state) {
    odyn::update_frames(e.model, ws);
    odyn::evaluate_constraints(e.model, ws);
    odyn::evaluate_forces(e.model, ws);
    odyn::add_iteration_blocks(e.model, ws, mass, 1.0, 0.0, 0.0);
    benchmark::DoNotOptimize(ws.phi.data());
    benchmark::DoNotOptimize(ws.force.data());
    benchmark::DoNotOptimize(mass.data());
  }
}
BENCHMARK(EvaluateBlocks);

/// What an explicit integrator's stage costs, part by part: the evaluations (frames, Phi and
/// Phi_q, gamma, Q), then the saddle-point factorization with mass terms only, then one solve.
void StageEvaluations(benchmark::State& state) {
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  for (auto _ : state) {
    odyn::update_frames(e.model, ws);
    odyn::evaluate_constraints(e.model, ws);
    odyn::evaluate_forces(e.model, ws);
    odyn::evaluate_gamma(e.model, ws);
    benchmark::DoNotOptimize(ws.gamma.data());
    benchmark::DoNotOptimize(ws.force.data());
  }
}
BENCHMARK(StageEvaluations);

template <class Solver>
void SaddlePointFactorize(benchmark::State& state) {
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  Solver solver;
  solver.analyze(e.model);
  for (auto _ : state) benchmark::DoNotOptimize(solver.factorize(e.model, ws, {}));
}
BENCHMARK(SaddlePointFactorize<odyn::BlockSchurSaddlePoint<Model>>);
BENCHMARK(SaddlePointFactorize<odyn::DenseSaddlePoint<Model>>);

template <class Solver>
void SaddlePointSolve(benchmark::State& state) {
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  Solver solver;
  solver.analyze(e.model);
  solver.factorize(e.model, ws, {});
  const Eigen::Index size = e.model.num_velocities() + e.model.num_equations();
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(size, -1.0, 1.0);
  Eigen::VectorXd solution = Eigen::VectorXd::Zero(size);
  for (auto _ : state) {
    solver.solve(rhs, solution);
    benchmark::DoNotOptimize(solution.data());
  }
}
BENCHMARK(SaddlePointSolve<odyn::BlockSchurSaddlePoint<Model>>);
BENCHMARK(SaddlePointSolve<odyn::DenseSaddlePoint<Model>>);

/// The same constraint evaluations through per-type pools (the library's way) and through a
/// vector of std::variant visited element by element.
void ConstraintsPools(benchmark::State& state) {
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  for (auto _ : state) {
    odyn::evaluate_constraints(e.model, ws);
    benchmark::DoNotOptimize(ws.phi.data());
  }
}
BENCHMARK(ConstraintsPools);

void ConstraintsVariant(benchmark::State& state) {
  namespace sp = odyn::spatial;
  engine::Engine e = engine::build();
  odyn::Workspace<Model> ws(e.model);
  odyn::assemble(e.model, ws);
  using Joint = std::variant<sp::Revolute, sp::Spherical, sp::Universal, sp::Translational>;
  std::vector<Joint> joints;
  std::vector<int> rows;
  e.model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (odyn::Constraint<E>)
      for (std::size_t i = 0; i < pool.size(); ++i) {
        joints.emplace_back(pool[i]);
        rows.push_back(e.model.template rows<E>()[i]);
      }
  });
  for (auto _ : state) {
    for (std::size_t i = 0; i < joints.size(); ++i)
      std::visit(
          [&]<class E>(const E& joint) {
            odyn::BlocksOf<E> blocks;
            joint.evaluate(odyn::detail::input_of(joint, ws.frames, ws.t), blocks);
            ws.phi.segment<E::num_equations>(rows[i]) = blocks.phi;
            ws.phi_t.segment<E::num_equations>(rows[i]) = blocks.phi_t;
            benchmark::DoNotOptimize(blocks.jacobian.data());
          },
          joints[i]);
    benchmark::DoNotOptimize(ws.phi.data());
  }
}
BENCHMARK(ConstraintsVariant);

}  // namespace bench_engine
