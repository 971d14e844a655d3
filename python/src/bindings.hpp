#pragma once
// What the two translation units of odyn._core share: the model type the bindings compile
// (every spatial element of the library, the engine's gas force and forces written in Python),
// and the bridge that lets a Python callable act as an element's function.
//
// Runs release the GIL; a Python callable takes it back only for its own call.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

#include "engine_model.hpp"  // examples/: the engine's gas force, exposed to scenes

namespace odyn::python {

namespace py = pybind11;
namespace sp = odyn::spatial;

/// Numbers a Python callable returned, checked for their count.
void read_numbers(py::handle value, double* out, int count, const std::string& what);

/// A body's frame as the Python callable sees it: a types.SimpleNamespace whose numpy arrays
/// (position, rotation, linear_velocity, angular_velocity; read-only) view a buffer that is
/// refreshed before every call. Reusing one object makes a call cost no allocation.
class FrameView {
 public:
  FrameView();
  void load(const Spatial::Frame& frame);
  const py::object& object() const { return object_; }

 private:
  // Layout of the buffer: offsets of the arrays, then its size.
  static constexpr int position = 0, rotation = 3, linear_velocity = 12, angular_velocity = 15,
                       size = 18;
  double* data_ = nullptr;  // (size) owned by a capsule that the arrays keep alive
  py::object object_;
};

/// A Python callable and the frame views it is handed. Calls take the GIL; the destructor too,
/// so that an element may be dropped from any thread.
class Callable {
 public:
  Callable(py::object function, int num_frames, std::string what);
  ~Callable();
  Callable(const Callable&) = delete;
  Callable& operator=(const Callable&) = delete;

  /// function(t, frame_0, ..., frame_{n-1}) with the frames loaded; the GIL must be held.
  py::object call_with_frames(double t, const Spatial::Frame* const* frames);
  /// function(a, b, c) for scalar arguments; the GIL must be held.
  py::object call_with_numbers(std::initializer_list<double> numbers);
  const std::string& what() const { return what_; }

 private:
  py::object function_;
  std::vector<FrameView> views_;
  std::string what_;  // "point force 'push'": names the element in errors
};

/// A force and torque on N bodies (global force at each centre of mass, global torque) from a
/// Python callable: function(t, body_0, ..., body_{N-1}) -> N x 6 numbers.
template <int N>
class UserForceT {
 public:
  using Space = Spatial;
  static constexpr int num_bodies = N;

  UserForceT(std::string name, const std::array<BodyId, N>& bodies,
             std::shared_ptr<Callable> function)
      : name_(std::move(name)), bodies_(bodies), function_(std::move(function)) {}

  const std::string& name() const { return name_; }
  const std::array<BodyId, N>& bodies() const { return bodies_; }

  void evaluate(const ElementInput<Space, N>& in, ForceBlocks<Space, N>& out) const {
    std::array<double, 6 * N> values;
    {
      py::gil_scoped_acquire gil;
      const py::object result = function_->call_with_frames(in.t, in.frames.data());
      read_numbers(result, values.data(), 6 * N, function_->what());
    }
    for (int k = 0; k < N; ++k) {
      const Eigen::Map<const Eigen::Vector3d> force(values.data() + 6 * k);
      const Eigen::Map<const Eigen::Vector3d> torque(values.data() + 6 * k + 3);
      out.force[k].template head<3>() = force;
      out.force[k].template tail<3>() = in.body(k).torque_to_body(torque);
    }
  }

 private:
  std::string name_;
  std::array<BodyId, N> bodies_;
  std::shared_ptr<Callable> function_;
};
static_assert(StatelessForce<UserForceT<1>> && StatelessForce<UserForceT<2>>);

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
class SignalWatch {
 public:
  using Space = Spatial;
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
static_assert(StatelessForce<SignalWatch>);

using EngineGasForce = engine::GasForce;

/// The model type of the bindings. Its element list and element_type_names below go together.
using Model =
    sp::Model<sp::Revolute, sp::Translational, sp::Spherical, sp::Universal, sp::Cylindrical,
              sp::Fixed, sp::Distance, sp::RevoluteDriver, sp::TranslationalDriver, sp::Gravity,
              sp::PointForce, sp::PointTorque, sp::Tsda, sp::Rsda, EngineGasForce, UserForceT<1>,
              UserForceT<2>, SignalWatch>;

inline constexpr std::array<const char*, Model::num_types> element_type_names = {
    "revolute",
    "translational",
    "spherical",
    "universal",
    "cylindrical",
    "fixed",
    "distance",
    "revolute_driver",
    "translational_driver",
    "gravity",
    "point_force",
    "point_torque",
    "tsda",
    "rsda",
    "engine_gas_force",
    "user_force",
    "user_force",
    "signal_watch"};
static_assert(element_type_names.back() != nullptr, "a name for every element type");

/// The model a Python odyn.Model holds, and whether an analysis is running on it (while the
/// GIL is released, another thread must not change it).
struct ModelBox {
  ModelBox() { model.add(SignalWatch(monitor)); }
  std::shared_ptr<RunMonitor> monitor = std::make_shared<RunMonitor>();
  Model model;
  bool running = false;
};

/// Registers the analyses (assembly, dynamics) on the module (analyses.cpp).
void bind_analyses(py::module_& m);

}  // namespace odyn::python
