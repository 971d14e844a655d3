#pragma once
// Events on requests (ADAMS's sensors): a run watches scalar functions of the state and
// locates their zero crossings within each step to the integrator's accuracy, records them, and
// ends the run at the first crossing of a terminal watch.
//
// After every step the integrator would keep, each watch is evaluated at the step's end and
// compared with its value at the step's start. A sign change is located by the Illinois variant
// of regula falsi on the time: on the step's dense output where the integrator has one (no
// extra steps), else on shorter steps attempted from the step's start (the integrator's own
// solution at each trial time). The step then goes on as it was, so that watching does not
// change the run, unless the crossing ends it: then the step is cut to end on it.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "odyn/analysis/zero_crossing.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/workspace.hpp"

namespace odyn {

/// Which sign changes of a watch are events.
enum class Crossing {
  rising,   // from negative to zero or positive
  falling,  // from positive to zero or negative
  either,
};

/// A scalar function of the state whose zero crossings are events. `function(ws)` may read
/// ws.t, the frames (positions and velocities) and what elements compute from them
/// (element_output, point_motion's position and velocity): not ws.q, ws.vdot or ws.lambda,
/// which are not kept current while a crossing is located.
template <class Model>
struct Watch {
  std::string name;
  std::function<double(const Workspace<Model>&)> function;
  Crossing crossing = Crossing::either;
  bool terminal = false;  // the run ends at its first event
};

/// The watches of a run, as the analyses take them (not used to deduce the model type).
template <class Model>
using WatchList = std::span<const Watch<std::type_identity_t<Model>>>;

/// A located zero crossing of a watch.
struct Event {
  std::string watch;
  double time = 0.0;  // s
  int direction = 0;  // +1 rising, -1 falling
  bool terminal = false;
};

namespace detail {

/// The watches of one run: their values at the last committed state and the events so far.
template <class Model>
class Watcher {
 public:
  explicit Watcher(std::span<const Watch<Model>> watches)
      : watches_(watches), previous_(watches.size()), current_(watches.size()) {
    crossed_.reserve(watches.size());
  }

  bool empty() const { return watches_.empty(); }
  bool ended() const { return ended_; }
  const std::vector<Event>& events() const { return events_; }
  /// The terminal watch that ended the run, or "".
  std::string ended_by() const { return ended_ ? events_.back().watch : std::string(); }

  /// Values at the committed start of a run (or of a run again from `ws`, see rewind).
  void start(const Workspace<Model>& ws) {
    for (std::size_t i = 0; i < watches_.size(); ++i) previous_[i] = value(i, ws);
    start_time_ = ws.t;
  }

  /// Forgets the events after `t` and ignores those up to it: a run that starts again from
  /// its beginning and hands over its outputs from t on (integrator "auto"'s fallback).
  void rewind(double t) {
    std::erase_if(events_, [&](const Event& e) { return e.time > t; });
    silent_until_ = t;
    ended_ = false;
  }

  /// For a step from t_n to the trial state in `ws`: evaluates the watches there and locates
  /// their crossings, `state_at(dt)` putting the state at t_n + dt into the workspace (which
  /// the caller restores afterwards). The time of the first terminal crossing, if any.
  template <class StateAt>
  std::optional<double> locate(Workspace<Model>& ws, double t_n, StateAt&& state_at,
                               double min_trial) {
    const double h = ws.t - t_n;
    const double tolerance = std::max(1e-12 * std::max(1.0, std::abs(ws.t)), 1e-10 * h);
    pending_.clear();
    crossed_.clear();
    for (std::size_t i = 0; i < watches_.size(); ++i) {
      current_[i] = value(i, ws);
      if (direction(i) != 0) crossed_.push_back(i);
    }
    for (const std::size_t i : crossed_) {
      const int dir = direction(i);
      // The crossing of dir * g, rising.
      const double hi =
          narrow_crossing({0.0, h, dir * previous_[i], dir * current_[i]}, tolerance, min_trial,
                          [&](double trial) {
                            state_at(trial);
                            return dir * value(i, ws);
                          })
              .hi;
      if (t_n + hi <= silent_until_) continue;  // handed over before a run started again
      // A run that starts on a crossing (the engine at top dead centre, its value zero up to
      // rounding) does not report it: nothing within a millionth of the first step, as close
      // as shorter attempts can tell.
      if (t_n == start_time_ && hi <= std::max(tolerance, 1e-6 * h)) continue;
      const Watch<Model>& watch = watches_[i];
      pending_.push_back({watch.name, t_n + hi, dir, watch.terminal});
    }
    std::stable_sort(pending_.begin(), pending_.end(),
                     [](const Event& a, const Event& b) { return a.time < b.time; });
    for (const Event& e : pending_)
      if (e.terminal) return e.time;
    return std::nullopt;
  }

  /// The step was committed at the trial state the watches were last evaluated at.
  void committed() {
    events_.insert(events_.end(), pending_.begin(), pending_.end());
    pending_.clear();
    previous_ = current_;
  }

  /// The step was cut to end on the first terminal crossing, and committed at t_end (its
  /// located time, up to the rounding of the step's length): the run ends there.
  void end_at(double t_end) {
    for (Event e : pending_) {
      if (e.terminal) e.time = t_end;  // the time of the run's last state, to the bit
      events_.push_back(e);
      if (e.terminal) break;
    }
    pending_.clear();
    ended_ = true;
  }

 private:
  double value(std::size_t i, const Workspace<Model>& ws) const {
    const double g = watches_[i].function(ws);
    if (!std::isfinite(g))
      throw ModelError(watches_[i].name, "the event's function returned " + to_text(g) +
                                             " at t = " + to_text(ws.t) +
                                             " s; it must return a finite number");
    return g;
  }

  /// +1 or -1 if watch i changed sign in the step as an event of its kind, else 0.
  int direction(std::size_t i) const {
    const double before = previous_[i], after = current_[i];
    int dir = 0;
    if (before < 0.0 && after >= 0.0) dir = 1;
    if (before > 0.0 && after <= 0.0) dir = -1;
    const Crossing kind = watches_[i].crossing;
    if ((dir == 1 && kind == Crossing::falling) || (dir == -1 && kind == Crossing::rising))
      return 0;
    return dir;
  }

  std::span<const Watch<Model>> watches_;
  std::vector<double> previous_, current_;  // (watches) at the committed state, at the trial
  std::vector<Event> events_, pending_;     // recorded; located in the step not yet committed
  std::vector<std::size_t> crossed_;        // the watches that changed sign in the trial step
  double silent_until_ = -std::numeric_limits<double>::infinity();
  double start_time_ = 0.0;
  bool ended_ = false;
};

}  // namespace detail

}  // namespace odyn
