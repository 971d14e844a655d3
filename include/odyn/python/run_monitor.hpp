#pragma once
// Ctrl-C inside a run: the monitor that lets Python run its signal handlers while an analysis
// holds no GIL, and the element through which every force evaluation polls it.

#include <chrono>
#include <memory>
#include <string>

#include <odyn/odyn.hpp>
#include <odyn/python/callable.hpp>

namespace odyn::python {

namespace py = pybind11;

/// Lets Python see Ctrl-C inside a long output interval: while an analysis runs (the GIL
/// released), poll() takes the GIL every 50 ms of wall time to run Python's signal handlers.
class RunMonitor {
 public:
  void start() {
    active_ = true;
    next_check_ = std::chrono::steady_clock::now() + period;
  }
  void stop() { active_ = false; }
  void poll() {
    if (!active_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now < next_check_) return;
    next_check_ = now + period;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }

 private:
  static constexpr std::chrono::milliseconds period{50};
  bool active_ = false;
  std::chrono::steady_clock::time_point next_check_;
};

/// A force element on the ground that applies nothing and polls the run monitor: every model
/// of the bindings holds one, so that each force evaluation gives Ctrl-C a chance.
template <class SpaceT>
class SignalWatch {
 public:
  using Space = SpaceT;
  static constexpr int num_bodies = 1;
  static inline const std::string reserved_name = "odyn: signal watch";

  explicit SignalWatch(std::shared_ptr<RunMonitor> monitor) : monitor_(std::move(monitor)) {}
  const std::string& name() const { return reserved_name; }
  const std::array<BodyId, 1>& bodies() const { return bodies_; }
  void evaluate(const ElementInput<Space, 1>&, ForceBlocks<Space, 1>& out) const {
    out.force[0].setZero();
    monitor_->poll();
  }

 private:
  std::array<BodyId, 1> bodies_{ground};
  std::shared_ptr<RunMonitor> monitor_;
};
static_assert(StatelessForce<SignalWatch<Spatial>> && StatelessForce<SignalWatch<Planar>>);

}  // namespace odyn::python
