#pragma once
// The output times of the analyses that carry a solved state through time (kinematic,
// quasi-static): one every `interval` from the start, and the end time when it falls between.
// Each is reached from the last solved state by steps that are halved when one fails.

#include <algorithm>
#include <cmath>
#include <string>

#include "odyn/core/errors.hpp"

namespace odyn::detail {

/// The output times after t0 at whole multiples of `interval`, up to t_end (with a relative
/// allowance for rounding). Counted in doubles first, so that a tiny interval is refused by
/// name instead of overflowing the count.
inline long output_count(const std::string& analysis, double t0, double t_end, double interval) {
  const double count = std::floor((t_end - t0) / interval * (1.0 + 1e-12));
  constexpr double most_outputs = 1e9;
  if (!(count <= most_outputs))
    throw ModelError(analysis, "an output interval of " + to_text(interval) + " s from " +
                                   to_text(t0) + " s to " + to_text(t_end) + " s asks for " +
                                   to_text(count) + " outputs; give a longer interval");
  return static_cast<long>(count);
}

/// Carries the caller's solved state from its time `t` to each output time, calling record()
/// there. try_step(to) solves at time `to` from the state at `t`, moving `t` to `to`, and
/// returns whether it could (the state unchanged if not). A step that fails is retried in
/// halves, up to `max_halvings` times on the way to one output; then give_up(h, to) must throw,
/// h being the step that failed last. `analysis` names the analysis in an error.
template <class TryStep, class GiveUp, class Record>
void step_through_outputs(const std::string& analysis, const double& t, double t_end,
                          double interval, int max_halvings, TryStep&& try_step, GiveUp&& give_up,
                          Record&& record) {
  const auto advance = [&](double to) {
    double h = to - t;
    int halvings = 0;
    while (t < to) {
      const double next = to - t <= h * (1.0 + 1e-9) ? to : t + h;
      if (try_step(next)) continue;
      if (++halvings > max_halvings) {
        give_up(h, next);
        throw SolverError(t, "no solution a " + to_text(h) + " s step after this time");
      }
      h *= 0.5;
    }
  };
  const double t0 = t;
  const long outputs = output_count(analysis, t0, t_end, interval);
  for (long k = 1; k <= outputs; ++k) {
    advance(t0 + static_cast<double>(k) * interval);
    record();
  }
  if (t_end - t > 1e-12 * std::max(1.0, std::abs(t_end))) {
    advance(t_end);
    record();
  }
}

}  // namespace odyn::detail
