#pragma once
// Assembly, dynamic, kinematic, static and modal analysis and the model report from Python, for
// any model type of a module (odyn._core compiles its two models' in python/src/dynamics*.cpp and
// analyses*.cpp). A run releases the GIL; at every output time it records the state, the
// energies, the residuals, every constraint's reactions, every stateful force's state and every
// element's outputs (core/outputs.hpp), then briefly takes the GIL to let Python handle signals
// (Ctrl-C) and report progress. A run that stops early keeps what it recorded.

#include <Python.h>
#include <pybind11/complex.h>

#include <chrono>
#include <exception>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <odyn/analysis/kinematics.hpp>
#include <odyn/analysis/linear_model.hpp>
#include <odyn/analysis/modes.hpp>
#include <odyn/analysis/quasi_statics.hpp>
#include <odyn/analysis/statics.hpp>
#include <odyn/python/errors.hpp>
#include <odyn/python/models.hpp>

namespace odyn::python {

namespace analysis {

template <class T>
T get(const py::dict& d, const char* key, T fallback) {
  return d.contains(key) && !d[key].is_none() ? d[key].cast<T>() : fallback;
}

/// d[key], a dict of settings by their C++ names (the typed settings of odyn/settings.py come
/// so), or an empty one.
inline py::dict section(const py::dict& d, const char* key) {
  return d.contains(key) && !d[key].is_none() ? d[key].cast<py::dict>() : py::dict();
}

inline AssemblySettings assembly_settings(const py::dict& d) {
  AssemblySettings s;
  s.tolerance = get(d, "assembly_tolerance", s.tolerance);
  s.max_iterations = get(d, "assembly_max_iterations", s.max_iterations);
  s.linear_solver = linear_solver_from_name(get(d, "linear_solver", std::string("auto")));
  const py::dict a = section(d, "assembly");
  s.tolerance = get(a, "tolerance", s.tolerance);
  s.max_iterations = get(a, "max_iterations", s.max_iterations);
  s.warn_translation = get(a, "warn_translation", s.warn_translation);
  s.warn_rotation = get(a, "warn_rotation", s.warn_rotation);
  return s;
}

/// Every setting of each integrator, from its section of d (see section).
inline void integrator_sections(const py::dict& d, DynamicsSettings& s) {
  const py::dict g = section(d, "generalized_alpha");
  auto& ga = s.generalized_alpha;
  ga.rho_inf = get(g, "rho_inf", ga.rho_inf);
  ga.newton_rtol = get(g, "newton_rtol", ga.newton_rtol);
  ga.newton_atol = get(g, "newton_atol", ga.newton_atol);
  ga.constraint_tolerance = get(g, "constraint_tolerance", ga.constraint_tolerance);
  ga.max_iterations = get(g, "max_iterations", ga.max_iterations);
  ga.reuse_iterations = get(g, "reuse_iterations", ga.reuse_iterations);
  ga.adaptive = get(g, "adaptive", ga.adaptive);
  ga.max_growth = get(g, "max_growth", ga.max_growth);
  ga.consistent_outputs = get(g, "consistent_outputs", ga.consistent_outputs);
  const py::dict e = section(d, "dormand_prince");
  auto& dp = s.dormand_prince;
  dp.projection_tolerance = get(e, "projection_tolerance", dp.projection_tolerance);
  dp.max_projection_iterations = get(e, "max_projection_iterations", dp.max_projection_iterations);
  dp.singular_threshold = get(e, "singular_threshold", dp.singular_threshold);
  const py::dict b = section(d, "bdf");
  s.bdf.max_order = get(b, "max_order", s.bdf.max_order);
  s.bdf.local_error_fraction = get(b, "local_error_fraction", s.bdf.local_error_fraction);
  s.bdf.newton_tolerance = get(b, "newton_tolerance", s.bdf.newton_tolerance);
  s.bdf.constraint_tolerance = get(b, "constraint_tolerance", s.bdf.constraint_tolerance);
  s.bdf.max_iterations = get(b, "max_iterations", s.bdf.max_iterations);
  s.bdf.reuse_iterations = get(b, "reuse_iterations", s.bdf.reuse_iterations);
  s.bdf.reuse_band = get(b, "reuse_band", s.bdf.reuse_band);
  s.bdf.max_growth = get(b, "max_growth", s.bdf.max_growth);
  const py::dict a = section(d, "adams");
  s.adams.order = get(a, "order", s.adams.order);
  s.adams.projection_tolerance = get(a, "projection_tolerance", s.adams.projection_tolerance);
  s.adams.velocity_tolerance = get(a, "velocity_tolerance", s.adams.velocity_tolerance);
  s.adams.max_projection_iterations =
      get(a, "max_projection_iterations", s.adams.max_projection_iterations);
}

inline DynamicsSettings dynamics_settings(const py::dict& d) {
  DynamicsSettings s;
  s.step = get(d, "step", s.step);
  s.t_end = get(d, "t_end", s.t_end);
  s.output_interval = get(d, "output_interval", s.output_interval);
  s.integrator = get(d, "integrator", s.integrator);
  s.coordinates = get(d, "coordinates", s.coordinates);
  s.linear_solver = linear_solver_from_name(get(d, "linear_solver", std::string("auto")));
  s.rtol = get(d, "rtol", s.rtol);
  s.atol = get(d, "atol", s.atol);
  s.max_step = get(d, "max_step", s.max_step);
  auto& ga = s.generalized_alpha;
  ga.rho_inf = get(d, "rho_inf", ga.rho_inf);
  ga.adaptive = get(d, "adaptive", ga.adaptive);
  ga.newton_rtol = get(d, "newton_rtol", ga.newton_rtol);
  ga.newton_atol = get(d, "newton_atol", ga.newton_atol);
  ga.constraint_tolerance = get(d, "constraint_tolerance", ga.constraint_tolerance);
  ga.max_iterations = get(d, "max_iterations", ga.max_iterations);
  auto& dp = s.dormand_prince;
  dp.projection_tolerance = get(d, "projection_tolerance", dp.projection_tolerance);
  s.adams.order = get(d, "order", s.adams.order);
  integrator_sections(d, s);
  s.assembly = assembly_settings(d);
  return s;
}

inline StaticSettings static_settings(const py::dict& d) {
  StaticSettings s;
  s.tolerance = get(d, "tolerance", s.tolerance);
  s.max_iterations = get(d, "max_iterations", s.max_iterations);
  s.load_stepping = get(d, "load_stepping", s.load_stepping);
  s.max_load_steps = get(d, "max_load_steps", s.max_load_steps);
  s.relaxation = get(d, "relaxation", s.relaxation);
  s.coordinates = get(d, "coordinates", s.coordinates);
  s.method = get(d, "method", s.method);
  return s;
}

/// The run's watches (analysis/watches.hpp) from settings["events"], as the Python layer checked
/// and resolved them: [{"name", "direction", "terminal", "value", "kind", ...}], kind "output"
/// (with "element", "output"), "point" (with "body" index, "at", "quantity", "component") or
/// "function" (with "function", "bodies" indices). Each watch is its quantity minus "value".
/// Built with the GIL held (a function's callable is made here).
template <class Model>
std::vector<Watch<Model>> watches_from(const Model& model, const py::dict& settings) {
  using Space = typename Model::Space;
  std::vector<Watch<Model>> watches;
  if (!settings.contains("events")) return watches;
  const py::list events = settings["events"];
  for (const py::handle item : events) {
    const py::dict e = py::reinterpret_borrow<py::dict>(item);
    Watch<Model> watch;
    watch.name = e["name"].cast<std::string>();
    const auto direction = e["direction"].cast<std::string>();
    watch.crossing = direction == "rising"    ? Crossing::rising
                     : direction == "falling" ? Crossing::falling
                                              : Crossing::either;
    watch.terminal = e["terminal"].cast<bool>();
    const double value = e["value"].cast<double>();
    const auto kind = e["kind"].cast<std::string>();
    if (kind == "output") {
      watch.function = [&model, element = e["element"].cast<std::string>(),
                        output = e["output"].cast<std::string>(),
                        value](const odyn::Workspace<Model>& ws) {
        return element_output(model, ws, element, output) - value;
      };
    } else if (kind == "point") {
      const int body = e["body"].cast<int>();
      const auto at = e["at"].cast<std::vector<double>>();
      typename Space::Vector local;
      for (int i = 0; i < Space::dim; ++i) local[i] = at.at(static_cast<std::size_t>(i));
      const bool velocity = e["quantity"].cast<std::string>() == "velocity";
      const int component = e["component"].cast<int>();
      watch.function = [=](const odyn::Workspace<Model>& ws) {
        const auto& frame = ws.frames[static_cast<std::size_t>(body)];
        return (velocity ? frame.point_velocity(local) : frame.point(local))[component] - value;
      };
    } else {
      const auto bodies = e["bodies"].cast<std::vector<int>>();
      auto callable = std::make_shared<Callable<Space>>(
          e["function"], static_cast<int>(bodies.size()), "event '" + watch.name + "'");
      watch.function = [callable, bodies, value](const odyn::Workspace<Model>& ws) {
        std::array<const typename Space::Frame*, 2> frames{};
        for (std::size_t k = 0; k < bodies.size(); ++k)
          frames[k] = &ws.frames[static_cast<std::size_t>(bodies[k])];
        double x = 0.0;
        py::gil_scoped_acquire gil;
        read_numbers(callable->call_with_frames(ws.t, frames.data()), &x, 1, callable->what());
        return x - value;
      };
    }
    watches.push_back(std::move(watch));
  }
  return watches;
}

/// A run's events as [{"name", "time", "direction" ("rising" or "falling"), "terminal"}].
inline py::list event_list(const std::vector<Event>& events) {
  py::list out;
  for (const Event& e : events) {
    py::dict d;
    d["name"] = e.watch;
    d["time"] = e.time;
    d["direction"] = e.direction > 0 ? "rising" : "falling";
    d["terminal"] = e.terminal;
    out.append(d);
  }
  return out;
}

inline py::array_t<double> to_array(const std::vector<double>& data, py::ssize_t rows,
                                    std::vector<py::ssize_t> shape_of_row = {}) {
  std::vector<py::ssize_t> shape{rows};
  shape.insert(shape.end(), shape_of_row.begin(), shape_of_row.end());
  py::array_t<double> array(shape);
  std::copy(data.begin(), data.end(), array.mutable_data());
  return array;
}

/// One row per output time.
template <class Model>
class Recorder {
 public:
  using Workspace = odyn::Workspace<Model>;
  using Space = typename Model::Space;
  static constexpr int wrench = Space::dim + Space::nw;  // force and torque of a reaction

  explicit Recorder(const Model& model) : model_(model) {
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
      for (std::size_t i = 0; i < pool.size(); ++i) {
        if constexpr (Constraint<E>) {
          constraints_.push_back(
              {pool[i].name(), model.row(Handle<E>{i}), static_cast<int>(E::num_equations)});
        }
        if constexpr (RecordsState<E>)
          stateful_.push_back({pool[i].name(), names_of(E::description.state_fields)});
        if constexpr (HasOutputs<E>)
          reporting_.push_back({pool[i].name(), names_of(E::description.outputs)});
      }
    });
    for (const auto& s : stateful_) state_width_ += static_cast<int>(s.fields.size());
    for (const auto& r : reporting_) output_width_ += static_cast<int>(r.fields.size());
  }

  void record(const Workspace& ws) {
    ++rows_;
    t_.push_back(ws.t);
    q_.insert(q_.end(), ws.q.begin(), ws.q.end());
    v_.insert(v_.end(), ws.v.begin(), ws.v.end());
    vdot_.insert(vdot_.end(), ws.vdot.begin(), ws.vdot.end());
    lambda_.insert(lambda_.end(), ws.lambda.begin(), ws.lambda.end());
    const auto [phi_norm, phid_norm] = constraint_residuals(model_, ws);
    phi_norm_.push_back(phi_norm);
    phid_norm_.push_back(phid_norm);
    kinetic_.push_back(kinetic_energy(model_, ws));
    potential_.push_back(potential_energy(model_, ws));
    model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      for (std::size_t i = 0; i < pool.size(); ++i) {
        if constexpr (Constraint<E>) {
          for (const Side side : {Side::a, Side::b})
            for (const ReactionAxes axes : {ReactionAxes::global, ReactionAxes::joint}) {
              const auto w = reaction(model_, ws, Handle<E>{i}, side, axes);
              reactions_.insert(reactions_.end(), w.force.begin(), w.force.end());
              reactions_.insert(reactions_.end(), w.torque.begin(), w.torque.end());
            }
        }
        if constexpr (RecordsState<E>) {
          const auto values = E::state_values(std::get<type>(ws.states)[i]);
          states_.insert(states_.end(), values.begin(), values.end());
        }
        if constexpr (HasOutputs<E>) {
          const auto values = element_outputs(model_, ws, Handle<E>{i});
          outputs_.insert(outputs_.end(), values.begin(), values.end());
        }
      }
    });
  }

  long rows() const { return rows_; }

  py::dict to_python() const {
    py::dict out;
    out["t"] = to_array(t_, rows_);
    out["q"] = to_array(q_, rows_, {model_.num_coordinates()});
    out["v"] = to_array(v_, rows_, {model_.num_velocities()});
    out["vdot"] = to_array(vdot_, rows_, {model_.num_velocities()});
    out["lambda"] = to_array(lambda_, rows_, {model_.num_equations()});
    out["phi_norm"] = to_array(phi_norm_, rows_);
    out["phid_norm"] = to_array(phid_norm_, rows_);
    out["kinetic_energy"] = to_array(kinetic_, rows_);
    out["potential_energy"] = to_array(potential_, rows_);
    py::list bodies;
    for (int b = 1; b <= model_.num_bodies(); ++b) bodies.append(model_.body(BodyId{b}).name);
    out["bodies"] = bodies;
    out["space"] = std::is_same_v<Space, Planar> ? "planar" : "spatial";
    // Reactions of each constraint: (outputs, side a/b, global/joint axes, force + torque).
    const std::size_t num_constraints = constraints_.size();
    py::dict reactions, rows;
    for (std::size_t c = 0; c < num_constraints; ++c) {
      py::array_t<double> r(
          {static_cast<py::ssize_t>(rows_), py::ssize_t{2}, py::ssize_t{2}, py::ssize_t{wrench}});
      double* target = r.mutable_data();
      constexpr int row = 4 * wrench;
      for (long k = 0; k < rows_; ++k)
        std::copy_n(reactions_.data() + (static_cast<std::size_t>(k) * num_constraints + c) * row,
                    row, target + k * row);
      reactions[py::str(constraints_[c].name)] = r;
      rows[py::str(constraints_[c].name)] =
          py::make_tuple(constraints_[c].row, constraints_[c].size);
    }
    out["reactions"] = reactions;
    out["constraint_rows"] = rows;
    out["states"] = by_field(stateful_, states_, state_width_);
    out["outputs"] = by_field(reporting_, outputs_, output_width_);
    return out;
  }

 private:
  struct ConstraintInfo {
    std::string name;
    int row, size;
  };
  /// An element's recorded fields (a state's or its outputs), `width` numbers per row in all.
  struct FieldInfo {
    std::string name;
    std::vector<std::string> fields;
  };

  static std::vector<std::string> names_of(std::span<const Output> fields) {
    std::vector<std::string> names;
    for (const Output& field : fields) names.emplace_back(field.name);
    return names;
  }

  /// {element: {field: array over the outputs}} from rows of `width` numbers.
  py::dict by_field(const std::vector<FieldInfo>& elements, const std::vector<double>& data,
                    int width) const {
    py::dict out;
    int column = 0;
    for (const auto& e : elements) {
      py::dict fields;
      for (const auto& field : e.fields) {
        py::array_t<double> values(static_cast<py::ssize_t>(rows_));
        for (long k = 0; k < rows_; ++k)
          values.mutable_data()[k] = data[static_cast<std::size_t>(k * width + column)];
        fields[py::str(field)] = values;
        ++column;
      }
      out[py::str(e.name)] = fields;
    }
    return out;
  }
  const Model& model_;
  std::vector<ConstraintInfo> constraints_;
  std::vector<FieldInfo> stateful_, reporting_;
  int state_width_ = 0, output_width_ = 0;
  long rows_ = 0;
  std::vector<double> t_, q_, v_, vdot_, lambda_, phi_norm_, phid_norm_, kinetic_, potential_;
  std::vector<double> reactions_, states_, outputs_;
};

inline py::dict assembly_report(const AssemblyReport& r) {
  py::dict d;
  d["iterations"] = r.iterations;
  d["position_residual"] = r.position_residual;
  d["velocity_residual"] = r.velocity_residual;
  d["kept_velocity_components"] = r.kept_velocity_components;
  d["adjusted_velocity_components"] = r.adjusted_velocity_components;
  py::list moved;
  for (const BodyDisplacement& b : r.moved_bodies) {
    py::dict body;
    body["body"] = b.body;
    body["translation"] = b.translation;
    body["rotation"] = b.rotation;
    moved.append(body);
  }
  d["moved_bodies"] = moved;
  return d;
}

/// A run's warnings as [{"kind", "text"}] (Python turns each into a warning of its class).
inline py::list warning_list(const std::vector<RunWarning>& warnings) {
  py::list out;
  for (const RunWarning& w : warnings) {
    py::dict d;
    d["kind"] = w.kind;
    d["text"] = w.text;
    out.append(d);
  }
  return out;
}

/// Constraint equations that repeat others (the run uses minimum-norm multipliers for them).
inline py::list redundant_list(const std::vector<RedundantEquation>& equations) {
  py::list out;
  for (const auto& e : equations) {
    py::dict d;
    d["joint"] = e.joint;
    d["equation"] = e.equation;
    d["row"] = e.row;
    out.append(d);
  }
  return out;
}

inline py::dict run_summary(const RunSummary& s) {
  py::dict d;
  const auto& st = s.statistics;
  d["steps"] = st.steps;
  d["newton_iterations"] = st.newton_iterations;
  d["jacobian_evaluations"] = st.jacobian_evaluations;
  d["factorizations"] = st.factorizations;
  d["residual_evaluations"] = st.residual_evaluations;
  d["rejected_steps"] = st.rejected_steps;
  d["restarts"] = st.restarts;
  d["events"] = st.events;
  d["singular_steps"] = st.singular_steps;
  d["max_error_estimate"] = st.max_error_estimate;
  d["outputs"] = s.outputs;
  d["wall_seconds"] = s.wall_seconds;
  d["setup_seconds"] = s.setup_seconds;
  d["max_position_residual"] = s.max_position_residual;
  d["max_velocity_residual"] = s.max_velocity_residual;
  d["warnings"] = warning_list(s.warnings);
  d["integrator"] = s.integrator;
  d["integrator_choice"] = s.integrator_choice;
  d["coordinates"] = s.coordinates;
  d["coordinates_choice"] = s.coordinates_choice;
  py::dict assembly = assembly_report(s.assembly);
  assembly["redundant_equations"] = redundant_list(s.redundant_equations);
  assembly["reused"] = s.assembly_reused;
  d["assembly"] = assembly;
  return d;
}

/// The Python exception object for an exception caught during a run (the GIL held).
inline py::object python_exception(const std::exception_ptr& error) {
  if (const auto [name, message] = odyn_error(error); name != nullptr)
    return py::module_::import("odyn._core").attr(name)(message);
  try {
    std::rethrow_exception(error);
  } catch (py::error_already_set& e) {
    return e.value();
  } catch (const py::builtin_exception& e) {
    e.set_error();
    return py::error_already_set().value();
  } catch (const std::exception& e) {
    return py::module_::import("builtins").attr("RuntimeError")(e.what());
  }
}

/// Marks a model busy for the lifetime of an analysis.
template <class Box>
class Running {
 public:
  explicit Running(Box& box) : box_(box) {
    if (box.running) throw ModelError("model", "an analysis is already running on this model");
    box.running = true;
  }
  ~Running() {
    box_.monitor->stop();
    box_.running = false;
  }
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;

 private:
  Box& box_;
};

template <class Box>
py::dict assemble(Box& box, const py::dict& settings) {
  using M = typename Box::ModelType;
  Running<Box> running(box);  // (the settings are read before the GIL is released)
  odyn::Workspace<M> ws(box.model);
  Recorder<M> recorder(box.model);
  const AssemblySettings s = assembly_settings(settings);
  AssemblyReport report;
  std::vector<RedundantEquation> redundant;
  {
    py::gil_scoped_release release;
    box.monitor->start();
    report = odyn::assemble(box.model, ws, s);
    redundant = odyn::redundant_equations(box.model, ws);
    box.assembled.keep(ws, report, redundant, s);
    recorder.record(ws);
  }
  py::dict out = recorder.to_python();
  py::dict assembly = assembly_report(report);
  assembly["redundant_equations"] = redundant_list(redundant);
  out["assembly"] = assembly;
  std::vector<RunWarning> warnings;
  if (std::string moved = assembly_motion_warning(report, s); !moved.empty())
    warnings.push_back({"assembly", std::move(moved)});
  out["warnings"] = warning_list(warnings);
  return out;
}

/// The callback of a run's output times (the GIL released): records the state, then briefly
/// takes the GIL to let Python handle signals (Ctrl-C raises there) and report progress(t) about
/// every `interval` seconds of wall time.
template <class M>
auto reporting(Recorder<M>& recorder, const py::object& progress, double interval) {
  using Clock = std::chrono::steady_clock;
  return [&recorder, &progress, interval,
          last_report = Clock::now()](const odyn::Workspace<M>& state) mutable {
    recorder.record(state);
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!progress.is_none() &&
        std::chrono::duration<double>(Clock::now() - last_report).count() >= interval) {
      progress(state.t);
      last_report = Clock::now();
    }
  };
}

template <class Box>
py::dict simulate(Box& box, const py::dict& settings, py::object progress,
                  double progress_interval) {
  using M = typename Box::ModelType;
  DynamicsSettings s = dynamics_settings(settings);
  RunSummary partial;  // what a run that fails counted so far
  s.partial = &partial;
  Running<Box> running(box);
  odyn::Workspace<M> ws(box.model);
  Recorder<M> recorder(box.model);
  const std::vector<Watch<M>> watches = watches_from(box.model, settings);
  RunSummary summary;
  std::exception_ptr error;
  {
    py::gil_scoped_release release;
    box.monitor->start();
    try {
      summary = odyn::simulate(box.model, ws, s, reporting(recorder, progress, progress_interval),
                               &box.assembled, watches);
    } catch (...) {
      error = std::current_exception();
    }
  }
  if (error) summary = partial;
  py::dict out = recorder.to_python();
  out["summary"] = run_summary(summary);
  out["events"] = event_list(summary.events);
  out["ended_by"] = summary.ended_by.empty() ? py::object(py::none()) : py::str(summary.ended_by);
  out["error"] = error ? python_exception(error) : py::object(py::none());
  return out;
}

inline py::dict static_summary(const StaticSummary& s) {
  py::dict out;
  out["method"] = s.method;
  out["iterations"] = s.iterations;
  out["load_steps"] = s.load_steps;
  out["constraint_residual"] = s.constraint_residual;
  out["force_residual"] = s.force_residual;
  out["force_scale"] = s.force_scale;
  out["length_scale"] = s.length_scale;
  out["stable"] = s.stability.stable;
  out["neutral"] = s.stability.neutral;
  out["squared_frequencies"] = Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
      s.stability.squared_frequencies.data(),
      static_cast<Eigen::Index>(s.stability.squared_frequencies.size())));
  out["least_stiff"] = s.stability.least_stiff;
  return out;
}

/// Runs `analysis(ws)` on a fresh workspace with the GIL released, and records the state it
/// leaves as one output row: returns the row and what `analysis` returned.
template <class Box, class Analysis>
auto recorded(Box& box, Analysis&& analysis) {
  using M = typename Box::ModelType;
  Running<Box> running(box);
  odyn::Workspace<M> ws(box.model);
  Recorder<M> recorder(box.model);
  std::decay_t<decltype(analysis(ws))> found;
  {
    py::gil_scoped_release release;
    box.monitor->start();
    found = analysis(ws);
    recorder.record(ws);
  }
  return std::pair{recorder.to_python(), std::move(found)};
}

/// The static equilibrium (analysis/statics.hpp) as one output row, with its summary.
template <class Box>
py::dict statics(Box& box, const py::dict& settings) {
  const StaticSettings s = static_settings(settings);
  auto [out, summary] =
      recorded(box, [&](auto& ws) { return odyn::static_equilibrium(box.model, ws, s); });
  out["statics"] = static_summary(summary);
  return out;
}

/// The natural modes about the equilibrium (analysis/modes.hpp), with the equilibrium's row.
template <class Box>
py::dict modes(Box& box, const py::dict& settings) {
  ModeSettings s;
  s.statics = static_settings(settings);
  s.coordinates = s.statics.coordinates;
  s.method = s.statics.method;
  s.find_equilibrium = get(settings, "find_equilibrium", s.find_equilibrium);
  s.count = get(settings, "count", s.count);
  auto [out, found] =
      recorded(box, [&](auto& ws) { return odyn::natural_modes(box.model, ws, s); });
  py::dict m;
  m["squared_frequencies"] = found.squared_frequencies;
  m["frequencies"] = found.frequencies;
  m["shapes"] = found.shapes;
  m["eigenvalues"] = found.eigenvalues;
  m["natural_frequencies"] = found.natural_frequencies;
  m["damped_frequencies"] = found.damped_frequencies;
  m["damping_ratios"] = found.damping_ratios;
  std::vector<std::string> names;
  for (const VelocityCoordinate& c : found.coordinates) names.push_back(c.text());
  m["coordinates"] = names;
  m["body_shapes"] = found.body_shapes;
  const Linearization& l = found.linearization;
  m["basis"] = l.basis;
  m["mass"] = l.mass;
  m["damping"] = l.damping;
  m["stiffness"] = l.stiffness;
  m["state_matrix"] = l.state_matrix();
  out["modes"] = m;
  return out;
}

/// A Space vector from a list of numbers (the Python side checks their count).
template <class Vector>
Vector vector_from(const py::handle& values) {
  const auto numbers = values.cast<std::vector<double>>();
  Vector out;
  for (Eigen::Index i = 0; i < out.size(); ++i) out[i] = numbers.at(static_cast<std::size_t>(i));
  return out;
}

/// The state-space model about the model's state or its equilibrium (analysis/linear_model.hpp)
/// for the inputs and outputs listed in `settings` (bodies and points by index, as events give
/// them), with the state it was taken about as one output row.
template <class Box>
py::dict linearize(Box& box, const py::dict& settings) {
  using M = typename Box::ModelType;
  using Space = typename M::Space;
  LinearizeSettings s;
  s.statics = static_settings(settings);
  s.coordinates = s.statics.coordinates;
  s.find_equilibrium = get(settings, "find_equilibrium", s.find_equilibrium);
  s.assembly = assembly_settings(settings);
  std::vector<LinearInput<Space>> inputs;
  for (const py::handle item : settings["inputs"].cast<py::list>()) {
    const py::dict d = py::reinterpret_borrow<py::dict>(item);
    LinearInput<Space> input;
    input.name = d["name"].cast<std::string>();
    input.body = BodyId{d["body"].cast<int>()};
    input.force = vector_from<typename Space::Vector>(d["force"]);
    input.torque = vector_from<typename Space::Angular>(d["torque"]);
    input.point = vector_from<typename Space::Vector>(d["point"]);
    input.axes = d["axes"].cast<std::string>() == "body" ? Axes::body : Axes::global;
    inputs.push_back(std::move(input));
  }
  std::vector<LinearOutput<M>> outputs;
  for (const py::handle item : settings["outputs"].cast<py::list>()) {
    const py::dict d = py::reinterpret_borrow<py::dict>(item);
    const auto name = d["name"].cast<std::string>();
    if (d["kind"].cast<std::string>() == "output") {
      LinearOutput<M> output = element_linear_output(box.model, d["element"].cast<std::string>(),
                                                     d["output"].cast<std::string>());
      output.name = name;
      outputs.push_back(std::move(output));
      continue;
    }
    const auto body = static_cast<std::size_t>(d["body"].cast<int>());
    const auto local = vector_from<typename Space::Vector>(d["at"]);
    const bool velocity = d["quantity"].cast<std::string>() == "velocity";
    const int component = d["component"].cast<int>();
    outputs.push_back({name, [=](const odyn::Workspace<M>& ws) {
                         const auto& frame = ws.frames[body];
                         return (velocity ? frame.point_velocity(local)
                                          : frame.point(local))[component];
                       }});
  }
  auto [out, found] =
      recorded(box, [&](auto& ws) { return odyn::linearize(box.model, ws, inputs, outputs, s); });
  py::dict l;
  l["a"] = found.a;
  l["b"] = found.b;
  l["c"] = found.c;
  l["d"] = found.d;
  l["drift"] = found.drift;
  l["outputs"] = found.outputs;
  l["basis"] = found.basis;
  std::vector<std::string> names;
  for (const VelocityCoordinate& c : found.coordinates) names.push_back(c.text());
  l["coordinates"] = names;
  l["input_names"] = found.input_names;
  l["output_names"] = found.output_names;
  out["linear_model"] = l;
  return out;
}

inline KinematicSettings kinematic_settings(const py::dict& d) {
  KinematicSettings s;
  s.tolerance = get(d, "tolerance", s.tolerance);
  s.max_iterations = get(d, "max_iterations", s.max_iterations);
  s.max_halvings = get(d, "max_halvings", s.max_halvings);
  s.linear_solver = linear_solver_from_name(get(d, "linear_solver", std::string("auto")));
  s.coordinates = get(d, "coordinates", s.coordinates);
  return s;
}

/// A kinematic analysis (analysis/kinematics.hpp) from t = 0 to t_end, recorded as a run is:
/// the rows, a summary (None if it stopped early) and the exception that stopped it.
template <class Box>
py::dict kinematics(Box& box, const py::dict& settings, py::object progress,
                    double progress_interval) {
  using M = typename Box::ModelType;
  const KinematicSettings s = kinematic_settings(settings);
  const double t_end = get(settings, "t_end", 1.0);
  const double interval = get(settings, "output_interval", 1e-3);
  Running<Box> running(box);
  odyn::Workspace<M> ws(box.model);
  Recorder<M> recorder(box.model);
  std::exception_ptr error;
  double wall_seconds = 0.0;
  {
    py::gil_scoped_release release;
    box.monitor->start();
    const auto start = std::chrono::steady_clock::now();
    try {
      odyn::kinematic_analysis(box.model, ws, t_end, interval,
                               reporting(recorder, progress, progress_interval), s);
    } catch (...) {
      error = std::current_exception();
    }
    wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  py::dict out = recorder.to_python();
  py::dict summary;
  summary["outputs"] = recorder.rows();
  summary["wall_seconds"] = wall_seconds;
  out["kinematics"] = error ? py::object(py::none()) : py::object(summary);
  out["error"] = error ? python_exception(error) : py::object(py::none());
  return out;
}

/// A quasi-static analysis (analysis/quasi_statics.hpp) from t = 0 to t_end, recorded as a run
/// is: the rows, each row's static summary, and the exception that stopped it.
template <class Box>
py::dict quasi_statics(Box& box, const py::dict& settings, py::object progress,
                       double progress_interval) {
  using M = typename Box::ModelType;
  QuasiStaticSettings s;
  s.statics = static_settings(settings);
  s.max_halvings = get(settings, "max_halvings", s.max_halvings);
  const double t_end = get(settings, "t_end", 1.0);
  const double interval = get(settings, "output_interval", 1e-2);
  Running<Box> running(box);
  odyn::Workspace<M> ws(box.model);
  Recorder<M> recorder(box.model);
  std::vector<StaticSummary> summaries;
  std::exception_ptr error;
  double wall_seconds = 0.0;
  {
    py::gil_scoped_release release;
    box.monitor->start();
    const auto start = std::chrono::steady_clock::now();
    auto report = reporting(recorder, progress, progress_interval);
    try {
      odyn::quasi_static_analysis(
          box.model, ws, t_end, interval,
          [&](const odyn::Workspace<M>& state, const StaticSummary& summary) {
            summaries.push_back(summary);
            report(state);
          },
          s);
    } catch (...) {
      error = std::current_exception();
    }
    wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  py::dict out = recorder.to_python();
  py::list rows;
  for (const StaticSummary& summary : summaries) rows.append(static_summary(summary));
  out["statics"] = rows;
  out["wall_seconds"] = wall_seconds;
  out["error"] = error ? python_exception(error) : py::object(py::none());
  return out;
}

/// The model report at the assembled configuration: assembly's report and the mobility that
/// the constraint Jacobian's rank gives (analysis/kinematics.hpp), as one output row.
template <class Box>
py::dict check(Box& box, const py::dict& settings) {
  struct Found {
    AssemblyReport assembly;
    Mobility mobility;
    Eigen::VectorXd given;  // the velocities before assembly
  };
  const AssemblySettings s = assembly_settings(settings);
  auto [out, found] = recorded(box, [&](auto& ws) {
    Found f;
    f.given = ws.v;
    f.assembly = odyn::assemble(box.model, ws, s);
    f.mobility = odyn::mobility(box.model, ws, s.linear_solver);
    return f;
  });
  out["assembly"] = assembly_report(found.assembly);
  out["given_velocities"] = found.given;
  py::dict m;
  m["velocities"] = found.mobility.velocities;
  m["equations"] = found.mobility.equations;
  m["rank"] = found.mobility.rank;
  m["redundant_equations"] = redundant_list(found.mobility.repeated);
  m["drivers"] = found.mobility.drivers;
  out["mobility"] = m;
  return out;
}

/// Registers the dynamic analysis (simulate: every integrator, in both coordinates) and assembly
/// for one model type (pybind11 overloads by the model). The largest share of a module's build:
/// a module may compile it in a unit of its own.
template <class Box>
void bind_dynamics(py::module_& m) {
  m.def("assemble", &assemble<Box>, py::arg("model"), py::arg("settings"),
        "Assembles the model; returns its consistent initial state as one output row.");
  m.def("simulate", &simulate<Box>, py::arg("model"), py::arg("settings"),
        py::arg("progress") = py::none(), py::arg("progress_interval") = 0.2,
        "Runs a dynamic analysis; returns the recorded outputs, the summary (None if the run "
        "stopped early) and the exception that stopped it (None if it finished).");
}

/// Registers the kinematic analysis and the model report (kinematics, check) for one model type.
template <class Box>
void bind_kinematics(py::module_& m) {
  m.def("kinematics", &kinematics<Box>, py::arg("model"), py::arg("settings"),
        py::arg("progress") = py::none(), py::arg("progress_interval") = 0.2,
        "Runs a kinematic analysis; returns the recorded outputs, the summary (None if it "
        "stopped early) and the exception that stopped it (None if it finished).");
  m.def("check", &check<Box>, py::arg("model"), py::arg("settings"),
        "Assembles the model and reports its mobility; returns the assembled state as one "
        "output row, with the assembly's report and the mobility.");
}

/// Registers the analyses built on static equilibrium for one model type: statics,
/// quasi_statics, modes and linearize. With GCC they cost about as much to compile as the
/// dynamic analysis; a module of one's own that needs none of them leaves them out.
template <class Box>
void bind_statics(py::module_& m) {
  m.def("statics", &statics<Box>, py::arg("model"), py::arg("settings"),
        "Finds the static equilibrium; returns it as one output row, with its summary.");
  m.def("modes", &modes<Box>, py::arg("model"), py::arg("settings"),
        "Finds the natural modes about the static equilibrium; returns the equilibrium as one "
        "output row, with the modes.");
  m.def("linearize", &linearize<Box>, py::arg("model"), py::arg("settings"),
        "Linearizes about the model's state or its equilibrium for the given inputs and "
        "outputs; returns the state as one output row, with the state-space model.");
  m.def("quasi_statics", &quasi_statics<Box>, py::arg("model"), py::arg("settings"),
        py::arg("progress") = py::none(), py::arg("progress_interval") = 0.2,
        "Runs a quasi-static analysis; returns the recorded equilibria, each one's summary and "
        "the exception that stopped it (None if it finished).");
}

/// Registers every analysis for one model type: bind_dynamics, bind_kinematics and bind_statics.
template <class Box>
void bind(py::module_& m) {
  bind_dynamics<Box>(m);
  bind_kinematics<Box>(m);
  bind_statics<Box>(m);
}

}  // namespace analysis

}  // namespace odyn::python
