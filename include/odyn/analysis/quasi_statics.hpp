#pragma once
// Quasi-static analysis: a sequence of static equilibria along time, which moves the drivers
// (and any load given as a function of time) slowly enough that the mechanism stays at rest at
// every instant. Each equilibrium starts from the last one, so the sequence follows one branch
// of equilibria as a driver turns or a load grows; a time whose equilibrium is not found from
// the last is reached in halves of the step. At each output time the workspace holds the
// equilibrium: q, v = v' = 0 and lambda, whose reactions hold the mechanism and whose drivers'
// efforts hold their motions (the torque a slowly turned crank needs, say).

#include <algorithm>
#include <cmath>
#include <vector>

#include "odyn/analysis/output_times.hpp"
#include "odyn/analysis/statics.hpp"

namespace odyn {

struct QuasiStaticSettings {
  StaticSettings statics = {};  // how each equilibrium is found
  /// A time whose equilibrium fails is reached in halves of the step, down to this many.
  int max_halvings = 8;
};

/// Equilibria from ws.t to t_end, recorded at ws.t, every `interval` after it and at t_end
/// (see the file's comment): record(ws, summary) with the equilibrium in the workspace.
/// Throws SolverError, with the last time reached, when an equilibrium is not found even in
/// the smallest step.
template <class Model, class Record>
void quasi_static_analysis(const Model& model, Workspace<Model>& ws, double t_end, double interval,
                           Record&& record, const QuasiStaticSettings& s = {}) {
  if (!(interval > 0.0) || !std::isfinite(interval))
    throw ModelError("quasi-static analysis",
                     "expected an output interval > 0, got " + to_text(interval));
  if (!(t_end >= ws.t) || !std::isfinite(t_end))
    throw ModelError("quasi-static analysis", "expected an end time >= the start time " +
                                                  to_text(ws.t) + ", got " + to_text(t_end));
  detail::output_count("quasi-static analysis", ws.t, t_end, interval);  // refuses a tiny interval
  if (!(s.max_halvings >= 0))
    throw ModelError("quasi-static analysis",
                     "max_halvings must be 0 or more, got " + std::to_string(s.max_halvings));
  record(static_cast<const Workspace<Model>&>(ws), static_equilibrium(model, ws, s.statics));

  // The equilibrium at time `to` from the one in ws; false (ws unchanged) if none is found.
  StaticSummary last;
  const auto step = [&](double to) {
    const Eigen::VectorXd q = ws.q, lambda = ws.lambda;
    const double from = ws.t;
    ws.t = to;
    try {
      last = static_equilibrium(model, ws, s.statics);
      return true;
    } catch (const Error&) {
      ws.t = from;
      ws.q = q;
      ws.lambda = lambda;
      return false;
    }
  };
  detail::step_through_outputs(
      "quasi-static analysis", ws.t, t_end, interval, s.max_halvings, step,
      [&](double h, double next) {
        const double reached = ws.t;
        ws.t = next;
        static_equilibrium(model, ws, s.statics);  // throws the reason
        throw SolverError(
            reached, "no static equilibrium found a " + to_text(h) + " s step after this time");
      },
      [&] { record(static_cast<const Workspace<Model>&>(ws), last); });
}

}  // namespace odyn
