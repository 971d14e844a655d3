#pragma once
// Dynamic analysis: assemble, then integrate with fixed steps that land on every output time,
// and hand the workspace to an observer at t0 and at each output time.

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>

#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/integrators/generalized_alpha.hpp"

namespace odyn {

struct DynamicsSettings {
  double step = 1e-4;             // h, s (rounded down so that steps land on output times)
  double t_end = 1.0;             // s
  double output_interval = 1e-3;  // s
  std::string integrator = "generalized-alpha";  // or "hht"
  GeneralizedAlphaSettings generalized_alpha = {};
  AssemblySettings assembly = {};
};

struct RunSummary {
  IntegratorStatistics statistics;
  AssemblyReport assembly;
  long outputs = 0;
  double wall_seconds = 0.0;
  double max_position_residual = 0.0;  // max |Phi| at the output times
  double max_velocity_residual = 0.0;  // max |Phi_q v + Phi_t| at the output times
};

/// Norms of the position and velocity constraint residuals at the workspace's last evaluation.
template <class Model>
std::pair<double, double> constraint_residuals(const Model& model, const Workspace<Model>& ws) {
  if (model.num_equations() == 0) return {0.0, 0.0};
  Eigen::VectorXd velocity_residual(model.num_equations());
  jacobian_times(model, ws, ws.v, velocity_residual);
  velocity_residual += ws.phi_t;
  return {ws.phi.norm(), velocity_residual.norm()};
}

/// Advances the integrator to `t_target` in equal steps no longer than `max_step`. A step in
/// which an element's event function crosses zero is cut back to end on the switch (found by
/// the Illinois variant of regula falsi on the step size), then the integrator restarts.
template <class Model, class Integrator>
void advance_to(const Model& model, Workspace<Model>& ws, Integrator& integrator, double t_target,
                double max_step, double event_time_tolerance = 1e-12) {
  while (integrator.time() < t_target - 1e-12 * std::max(1.0, std::abs(t_target))) {
    const double remaining = t_target - integrator.time();
    const double steps = std::ceil(remaining / max_step - 1e-9);
    const double h = remaining / std::max(1.0, steps);
    double g_start = 0.0;
    if constexpr (has_events<Model>()) g_start = event_function(model, ws);
    if (!integrator.attempt(h)) integrator.fail();
    if constexpr (has_events<Model>()) {
      double g_end = event_function(model, ws);
      if (g_end >= 0.0 && g_start < 0.0) {
        // Bracket [lo, hi] on the step size with g(lo) < 0 <= g(hi). Trials stay a little
        // longer than nothing: an index-3 step of a few femtoseconds turns the rounding in
        // Phi into large velocity errors (the switch is then located to within min_trial).
        const double min_trial = std::max(event_time_tolerance, 1e-6 * h);
        double lo = 0.0, hi = h, g_lo = g_start, g_hi = g_end;
        int stale_side = 0;
        while (hi - lo > event_time_tolerance) {
          double trial = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
          if (!(trial > lo && trial < hi)) trial = 0.5 * (lo + hi);
          trial = std::max(trial, min_trial);
          if (trial >= hi) break;
          if (!integrator.attempt(trial)) integrator.fail();
          const double g = event_function(model, ws);
          if (g >= 0.0) {
            hi = trial, g_hi = g;
            if (stale_side == 1) g_lo *= 0.5;  // Illinois: keep the other end moving
            stale_side = 1;
          } else {
            lo = trial, g_lo = g;
            if (stale_side == -1) g_hi *= 0.5;
            stale_side = -1;
          }
        }
        // End just past the switch, so that the element moves on to its next law. Solved
        // again, the step may land a hair before it (Newton stops within its tolerance, on
        // another path): then end a little later, or the next step would meet the same switch.
        double end = hi;
        for (int extension = 0;; ++extension) {
          if (!integrator.attempt(end)) integrator.fail();
          if (event_function(model, ws) >= 0.0 || extension == 10 || end >= h) break;
          end = std::min(h, end + std::ldexp(min_trial, extension));
        }
        integrator.commit();
        integrator.restart();
        integrator.count_event();
        continue;
      }
    }
    integrator.commit();
  }
}

/// Runs a dynamic analysis from the workspace's state (assembled first). `observe(ws)` sees the
/// workspace at t0 and at every output time, with frames and element blocks up to date.
template <class Model, class Observer>
RunSummary simulate(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                    Observer&& observe) {
  if (!(s.step > 0.0) || !(s.output_interval > 0.0) || !(s.t_end >= ws.t))
    throw ModelError("dynamics",
                     "step and output interval must be positive and t_end >= t0 "
                     "(got step " +
                         to_text(s.step) + ", output interval " + to_text(s.output_interval) +
                         ", t_end " + to_text(s.t_end) + ")");
  if (s.integrator != "generalized-alpha" && s.integrator != "hht")
    throw ModelError("dynamics",
                     "unknown integrator '" + s.integrator + "'; choose generalized-alpha or hht");
  const auto start = std::chrono::steady_clock::now();
  RunSummary summary;
  summary.assembly = assemble(model, ws, s.assembly);
  require_independent_constraints(model, ws);

  GeneralizedAlphaSettings integrator_settings = s.generalized_alpha;
  integrator_settings.hht = s.integrator == "hht";
  GeneralizedAlpha<Model> integrator(model, ws, integrator_settings);

  auto record = [&] {
    const auto [phi_norm, phid_norm] = constraint_residuals(model, ws);
    summary.max_position_residual = std::max(summary.max_position_residual, phi_norm);
    summary.max_velocity_residual = std::max(summary.max_velocity_residual, phid_norm);
    ++summary.outputs;
    observe(std::as_const(ws));
  };
  record();
  const double t0 = ws.t;
  const long outputs = static_cast<long>(std::floor((s.t_end - t0) / s.output_interval + 1e-9));
  for (long k = 1; k <= outputs; ++k) {
    advance_to(model, ws, integrator, t0 + static_cast<double>(k) * s.output_interval, s.step);
    record();
  }
  summary.statistics = integrator.statistics();
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace odyn
