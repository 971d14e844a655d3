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
  const auto advance = [&](double to) {
    double h = to - ws.t;
    int halvings = 0;
    while (ws.t < to) {
      const double next = to - ws.t <= h * (1.0 + 1e-9) ? to : ws.t + h;
      if (step(next)) continue;
      if (++halvings > s.max_halvings) {
        const double reached = ws.t;
        ws.t = next;
        static_equilibrium(model, ws, s.statics);  // throws the reason
        throw SolverError(
            reached, "no static equilibrium found a " + to_text(h) + " s step after this time");
      }
      h *= 0.5;
    }
  };
  const double t0 = ws.t;
  const auto outputs = static_cast<long>(std::floor((t_end - t0) / interval * (1.0 + 1e-12)));
  for (long k = 1; k <= outputs; ++k) {
    advance(t0 + static_cast<double>(k) * interval);
    record(static_cast<const Workspace<Model>&>(ws), last);
  }
  if (t_end - ws.t > 1e-12 * std::max(1.0, std::abs(t_end))) {
    advance(t_end);
    record(static_cast<const Workspace<Model>&>(ws), last);
  }
}

}  // namespace odyn
