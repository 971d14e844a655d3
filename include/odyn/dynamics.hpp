#pragma once
// Dynamic analysis: assemble, then integrate with the chosen integrator (fixed steps, or steps
// under error control with outputs interpolated where the integrator can), end steps exactly on
// the switches of force laws, locate the events of watched functions (analysis/watches.hpp),
// and hand the workspace to an observer at t0 and at each output.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/massless_motion.hpp"
#include "odyn/analysis/output_times.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/analysis/watches.hpp"
#include "odyn/analysis/zero_crossing.hpp"
#include "odyn/integrators/adams.hpp"
#include "odyn/integrators/bdf.hpp"
#include "odyn/integrators/dop853.hpp"
#include "odyn/integrators/dormand_prince.hpp"
#include "odyn/integrators/generalized_alpha.hpp"
#include "odyn/integrators/integrator.hpp"

namespace odyn {

struct RunSummary;

struct DynamicsSettings {
  /// s: the step of a fixed-step run (shortened so that steps land on output times), or the
  /// first step of a run with error control; for "auto", also generalized-alpha's step where
  /// dop853 and bdf fail.
  double step = 1e-4;
  double t_end = 1.0;             // s
  double output_interval = 1e-3;  // s
  /// By name (see integrator_names()): "auto" (error control: dop853, bdf when stiff,
  /// generalized-alpha where both fail; see simulate_auto), "generalized-alpha" or "hht"
  /// (fixed step, or error control when generalized_alpha.adaptive is set), "dopri5", "dop853"
  /// and "bdf" (error control), "adams" (fixed step, order adams.order).
  std::string integrator = "auto";
  /// What the integrator steps: "absolute" (every body's position and orientation, every joint
  /// a constraint) or "joint" (a spanning tree's joint coordinates, only the joints that close
  /// loops as constraints; see analysis/joint_coordinates.hpp), with every integrator; "auto"
  /// picks one by the model and the integrator (see choose_coordinates).
  std::string coordinates = "auto";
  /// The factorization of the linear systems, in the assembly and the integrator: "auto"
  /// (dense for small models, sparse for large ones), "dense", "cholmod" or "klu"; see
  /// linalg/linear_solver.hpp.
  LinearSolver linear_solver = LinearSolver::automatic;
  /// Local error tolerances of the runs with error control, per component of (q, v).
  double rtol = 1e-6;
  double atol = 1e-6;
  double max_step = 0.0;  // s; 0: no limit
  GeneralizedAlphaSettings generalized_alpha = {};
  DormandPrinceSettings dormand_prince = {};  // dopri5 and dop853
  BdfSettings bdf = {};
  AdamsSettings adams = {};
  AssemblySettings assembly = {};
  /// If set, a run that ends in an exception (a failed step, an error in an element, an
  /// interrupt from the observer) first leaves there what it counted so far: the statistics,
  /// outputs, residuals, events and wall time of its summary.
  RunSummary* partial = nullptr;
};

/// Something a run did that its user should know although it succeeded.
struct RunWarning {
  /// "tolerance": rtol was below what double precision delivers and was raised;
  /// "assembly": assembly moved bodies beyond the thresholds of AssemblySettings.
  std::string kind;
  std::string text;
};

/// The steps of bdf after which integrator "auto" compares their mean with dop853's (see
/// simulate_auto).
inline constexpr long auto_trial_steps = 200;

struct RunSummary {
  IntegratorStatistics statistics;
  AssemblyReport assembly;
  bool assembly_reused = false;  // started from an AssembledStart's state, not assembled again
  long outputs = 0;
  double wall_seconds = 0.0;           // the whole run
  double setup_seconds = 0.0;          // of which assembly (unless reused), integrator setup
  double max_position_residual = 0.0;  // max |Phi| at the output times
  double max_velocity_residual = 0.0;  // max |Phi_q v + Phi_t| at the output times
  /// Constraint equations that repeat others at the assembled pose (Phi_q rank-deficient): the
  /// run goes on with the minimum-norm multipliers, and the reactions of these joints are then
  /// one choice among many (see analysis/saddle_point.hpp). Empty for an ordinary mechanism.
  std::vector<RedundantEquation> redundant_equations;
  std::vector<RunWarning> warnings;
  /// What integrated: the settings' integrator, or for "auto" the ones it chose ("dop853",
  /// "dop853, then bdf from t = 0.31 s"), and why (empty unless "auto").
  std::string integrator;
  std::string integrator_choice;
  /// The coordinates the run stepped ("absolute" or "joint") and, for coordinates "auto", why.
  std::string coordinates;
  std::string coordinates_choice;
  /// The located crossings of the run's watches, in time order; `ended_by` names the terminal
  /// watch whose crossing ended the run (the last output is then at its time), else "".
  std::vector<Event> events;
  std::string ended_by;
};

/// An assembled initial state kept to start runs from, so that the setup runs once for several
/// runs of one model (Python keeps one per model until the model changes). simulate() fills an
/// empty one when it assembles; given a filled one, it starts from that state instead of
/// assembling again, if the settings' assembly settings are the same and the state still is
/// assembled (see check_assembled): else it assembles afresh. Accelerations and multipliers that no
/// longer solve the equations of motion (a Python force that changed) are solved again.
template <class Model>
struct AssembledStart {
  std::optional<Workspace<Model>> state;  // right after the assembly
  AssemblyReport report;
  std::vector<RedundantEquation> redundant_equations;
  AssemblySettings settings;  // those it was assembled with

  bool matches(const AssemblySettings& s) const {
    return state && s.tolerance == settings.tolerance &&
           s.max_iterations == settings.max_iterations && s.linear_solver == settings.linear_solver;
  }
  void keep(const Workspace<Model>& ws, const AssemblyReport& assembly,
            std::vector<RedundantEquation> redundant, const AssemblySettings& s) {
    state = ws;
    report = assembly;
    redundant_equations = std::move(redundant);
    settings = s;
  }
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

/// What an observer becomes inside the analyses: whatever callable a caller passes, the
/// integrators are instantiated once per model type, not again for each lambda (each of which
/// would compile every integrator anew). One indirect call per output.
template <class Model>
using ObserverFunction = std::function<void(const Workspace<Model>&)>;

namespace detail {

/// A step of size h from the committed state has just carried an element's event function from
/// g_start < 0 to g_end >= 0. Cuts the step back to end on the switch (the Illinois variant of
/// regula falsi on the step size), commits it and restarts the integrator under the new law.
/// `before_commit()` runs on the final trial state, just before it is committed. With
/// `from_dense_output`, the bracketing probes the attempted step's interpolant (positions
/// only) instead of attempting shorter steps: one step attempt per event instead of ten.
template <class Model, class Integrator, class BeforeCommit = void (*)()>
void end_step_on_switch(
    const Model& model, Workspace<Model>& ws, Integrator& integrator, double h, double g_start,
    double g_end, double event_time_tolerance, BeforeCommit&& before_commit = [] {},
    bool from_dense_output = false) {
  // Bracket [lo, hi] on the step size with g(lo) < 0 <= g(hi). Trials stay a little longer
  // than nothing: an index-3 step of a few femtoseconds turns the rounding in Phi into large
  // velocity errors (the switch is then located to within min_trial).
  const double min_trial = std::max(event_time_tolerance, 1e-6 * h);
  const auto g = [&](double trial) {
    if constexpr (DenseOutputIntegrator<Integrator>) {
      if (from_dense_output)
        integrator.interpolate_frames(integrator.time() + trial);
      else if (!integrator.attempt(trial))
        integrator.fail();
    } else if (!integrator.attempt(trial)) {
      integrator.fail();
    }
    return event_function(model, ws);
  };
  const double hi =
      narrow_crossing({0.0, h, g_start, g_end}, event_time_tolerance, min_trial, g).hi;
  // End just past the switch, so that the element moves on to its next law. Solved again, the
  // step may land a hair before it (Newton stops within its tolerance, on another path): then
  // end a little later, or the next step would meet the same switch.
  double end = hi;
  for (int extension = 0;; ++extension) {
    if (!integrator.attempt(end)) integrator.fail();
    if (event_function(model, ws) >= 0.0 || extension == 10 || end >= h) break;
    end = std::min(h, end + std::ldexp(min_trial, extension));
  }
  before_commit();
  integrator.commit();
  integrator.restart();
  integrator.count_event();
}

/// Locates the crossings of the watches in the step the integrator has just attempted, on its
/// dense output (`dense`) or by shorter attempts, and leaves its trial state in the workspace:
/// cut to end on the first terminal crossing if there is one (its time returned).
template <class Model, class Integrator>
std::optional<double> watch_trial(Workspace<Model>& ws, Integrator& integrator,
                                  Watcher<Model>* watcher, bool dense) {
  if (watcher == nullptr || watcher->empty()) return std::nullopt;
  const double t_n = integrator.time(), h = ws.t - t_n;
  bool moved = false;
  const auto state_at = [&](double dt) {
    moved = true;
    if constexpr (DenseOutputIntegrator<Integrator>) {
      if (dense) return integrator.interpolate_frames(t_n + dt);
    }
    if (!integrator.attempt(dt)) integrator.fail();
  };
  // Attempts a few femtoseconds long would turn the rounding in Phi into velocity errors (see
  // end_step_on_switch); the interpolant has no such limit.
  const std::optional<double> terminal = watcher->locate(ws, t_n, state_at, dense ? 0.0 : 1e-6 * h);
  if (terminal) {
    if (!integrator.attempt(*terminal - t_n)) integrator.fail();
  } else if (moved) {
    bool restored = false;
    if constexpr (DenseOutputIntegrator<Integrator>) {
      if (dense) integrator.restore_trial(), restored = true;
    }
    if (!restored && !integrator.attempt(h)) integrator.fail();
  }
  return terminal;
}

/// After the commit, at `t`, of a step that watch_trial saw: its events recorded, and the run
/// ended if one was terminal.
template <class Model>
void watched_step_committed(Watcher<Model>* watcher, bool terminal, double t) {
  if (watcher == nullptr || watcher->empty()) return;
  if (terminal)
    watcher->end_at(t);
  else
    watcher->committed();
}

}  // namespace detail

/// How far a fixed step is cut after failed attempts (see advance_to); kept from one call to the
/// next, so that a run does not try the full step again right after it failed.
struct StepCut {
  static constexpr int max_halvings = 4;  // down to 1/16 of the fixed step
  int halvings = 0;
  int good_steps = 0;  // since the last change
  int needed = 1;      // good steps before the step doubles again; grows while failures recur
};

/// Advances an integrator to `t_target`, landing on it exactly. A fixed-step integrator takes
/// equal steps no longer than `fixed_step`; where one fails to converge (RetriesShorterSteps),
/// it is tried again at half the size, down to 1/16, and the size doubles back after a few good
/// steps (`cut` keeps that state across calls; the run stops when the smallest step fails too). An
/// adaptive integrator takes the steps its error control proposes (never longer than `max_step`),
/// and a rejected step is tried again shorter. A step in which an element's event function crosses
/// zero is cut back to end on the switch, then the integrator restarts. With `watcher`, the
/// watches' crossings in each step are located; a terminal one ends the advance on it (see
/// Watcher::ended).
template <class Model, StepIntegrator Integrator>
void advance_to(const Model& model, Workspace<Model>& ws, Integrator& integrator, double t_target,
                double fixed_step, double event_time_tolerance = 1e-12, StepCut* cut = nullptr,
                detail::Watcher<Model>* watcher = nullptr) {
  constexpr bool can_adapt = AdaptiveIntegrator<Integrator>;
  const bool adaptive = can_adapt && integrator.adaptive();
  StepCut local_cut;
  StepCut& step_cut = cut ? *cut : local_cut;
  while (integrator.time() < t_target - 1e-12 * std::max(1.0, std::abs(t_target))) {
    const double remaining = t_target - integrator.time();
    double h = 0.0;
    if constexpr (can_adapt) h = integrator.proposed_step();
    // An element that counts turns from its state may ask for shorter steps (LimitsSteps).
    const double limit = element_step_limit(model, ws);
    if (!adaptive) {
      const double step = std::min(std::ldexp(fixed_step, -step_cut.halvings), limit);
      const double steps = std::ceil(remaining / step - 1e-9);
      h = remaining / std::max(1.0, steps);
    } else if (std::min(h, limit) >= remaining) {
      h = remaining;
    } else if (std::min(h, limit) > 0.5 * remaining) {
      h = 0.5 * remaining;  // two even steps rather than a sliver before the target
    } else {
      h = std::min(h, limit);
    }
    double g_start = 0.0;
    if constexpr (has_events<Model>()) g_start = event_function(model, ws);
    const bool computed = integrator.attempt(h);
    if constexpr (can_adapt) {
      if (adaptive && !(computed && integrator.error_norm() <= 1.0)) {
        integrator.reject();
        continue;
      }
    }
    if (!computed) {
      if (RetriesShorterSteps<Integrator> && step_cut.halvings < StepCut::max_halvings) {
        integrator.rollback();
        ++step_cut.halvings;
        step_cut.good_steps = 0;
        step_cut.needed = std::min(64, 2 * step_cut.needed);
        continue;
      }
      if (step_cut.halvings == 0) integrator.fail();
      try {
        integrator.fail();
      } catch (const SolverError& error) {
        throw SolverError(error.time(), error.message() + " (The fixed step had been cut to 1/" +
                                            std::to_string(1 << step_cut.halvings) +
                                            " of its size there and still failed.)");
      }
    }
    if constexpr (has_events<Model>()) {
      const double g_end = event_function(model, ws);
      if (g_end >= 0.0 && g_start < 0.0) {
        std::optional<double> terminal;
        detail::end_step_on_switch(
            model, ws, integrator, h, g_start, g_end, event_time_tolerance,
            [&] { terminal = detail::watch_trial(ws, integrator, watcher, false); });
        detail::watched_step_committed(watcher, terminal.has_value(), ws.t);
        if (terminal) return;
        continue;
      }
    }
    const std::optional<double> terminal = detail::watch_trial(ws, integrator, watcher, false);
    if constexpr (can_adapt) {
      if (adaptive) {
        integrator.accept();
        detail::watched_step_committed(watcher, terminal.has_value(), ws.t);
        if (terminal) return;
        continue;
      }
    }
    integrator.commit();
    detail::watched_step_committed(watcher, terminal.has_value(), ws.t);
    if (terminal) return;
    if (step_cut.halvings > 0 && ++step_cut.good_steps >= step_cut.needed) {
      --step_cut.halvings;
      step_cut.good_steps = 0;
      step_cut.needed = std::max(2, step_cut.needed / 2);
    }
  }
}

/// The output times of a run, t0 + k dt for k = 1 .. count - 1 and then `last` (t0 itself is
/// recorded before the first step), and the next one to hand over: a run that changes
/// integrator midway goes on from there. `last` is t0 + count dt, or t_end when it falls
/// between two outputs, so that the run ends where it was asked to.
struct OutputGrid {
  double t0 = 0.0;
  double interval = 1e-3;
  long count = 0;
  long next = 1;
  double last = 0.0;
  double time(long k) const { return k == count ? last : t0 + static_cast<double>(k) * interval; }
  bool done() const { return next > count; }
};

/// Advances an adaptive integrator with dense output (interpolate, restore_trial) through the
/// grid's remaining output times, stepping as its error control proposes: outputs inside a step
/// are interpolated (so they do not cut the steps), and `record()` sees each one with the
/// stateful elements advanced to it. Ends exactly at the last output time; events as in
/// advance_to. `stop()`, asked after every accepted step, ends the run there early (the
/// workspace then holds the committed state): false if it did. With `watcher`, the watches'
/// crossings are located on the dense output; a terminal one ends the run on it, with one more
/// output there (the grid is then done).
template <class Model, DenseOutputIntegrator Integrator, class Record, class Stop>
bool advance_with_dense_output(const Model& model, Workspace<Model>& ws, Integrator& integrator,
                               OutputGrid& grid, Record&& record, Stop&& stop,
                               double event_time_tolerance = 1e-12,
                               detail::Watcher<Model>* watcher = nullptr) {
  const double t_end = grid.time(grid.count);
  const double time_tolerance = 1e-12 * std::max(1.0, std::abs(t_end));
  auto saved_states = ws.states;  // sized once: the copies below allocate nothing
  long& k = grid.next;
  // Hands over every output time up to the trial state now in the workspace, then puts the
  // trial state back for its commit.
  const auto emit = [&] {
    const double trial_end = ws.t;
    bool interpolated = false;
    for (; k <= grid.count && grid.time(k) <= trial_end + time_tolerance; ++k) {
      if (grid.time(k) < trial_end - time_tolerance) {
        if (!integrator.interpolate(grid.time(k))) integrator.fail();
        interpolated = true;
      } else if (interpolated) {  // the output is the trial state itself
        integrator.restore_trial();
        interpolated = false;
      }
      saved_states = ws.states;
      advance_states(model, ws);  // as if a step ended here
      record();
      ws.states = saved_states;
    }
    if (interpolated) integrator.restore_trial();
  };
  // The run ends on a terminal crossing: an output there too, unless one of the grid's was.
  const auto end_on_event = [&] {
    if (k == 1 || std::abs(grid.time(k - 1) - ws.t) > time_tolerance) record();
    k = grid.count + 1;
    return true;
  };
  while (k <= grid.count) {
    const double remaining = t_end - integrator.time();
    double h = std::min({integrator.proposed_step(), element_step_limit(model, ws), remaining});
    if (h < remaining && h > 0.5 * remaining) h = 0.5 * remaining;  // no sliver before the end
    double g_start = 0.0;
    if constexpr (has_events<Model>()) g_start = event_function(model, ws);
    if (!integrator.attempt(h) || !(integrator.error_norm() <= 1.0)) {
      integrator.reject();
      continue;
    }
    if constexpr (has_events<Model>()) {
      const double g_end = event_function(model, ws);
      if (g_end >= 0.0 && g_start < 0.0) {
        std::optional<double> terminal;
        detail::end_step_on_switch(
            model, ws, integrator, h, g_start, g_end, event_time_tolerance,
            [&] {
              terminal = detail::watch_trial(ws, integrator, watcher, true);
              emit();
            },
            true);
        detail::watched_step_committed(watcher, terminal.has_value(), ws.t);
        if (terminal) return end_on_event();
        continue;
      }
    }
    const std::optional<double> terminal = detail::watch_trial(ws, integrator, watcher, true);
    emit();
    integrator.accept();
    detail::watched_step_committed(watcher, terminal.has_value(), ws.t);
    if (terminal) return end_on_event();
    if (k <= grid.count && stop()) return false;
  }
  return true;
}

namespace detail {
/// Each integrator's own settings, taken from the analysis settings: its own member of them,
/// with the analysis's linear solver.
template <class Settings>
Settings integrator_settings(const DynamicsSettings& s) {
  Settings settings;
  if constexpr (std::is_same_v<Settings, GeneralizedAlphaSettings>) {
    settings = s.generalized_alpha;
    settings.hht = settings.hht || s.integrator == "hht";
  } else if constexpr (std::is_same_v<Settings, DormandPrinceSettings>) {
    settings = s.dormand_prince;
  } else if constexpr (std::is_same_v<Settings, BdfSettings>) {
    settings = s.bdf;
  } else {
    static_assert(std::is_same_v<Settings, AdamsSettings>, "an integrator without settings here");
    settings = s.adams;
  }
  settings.linear_solver = s.linear_solver;
  return settings;
}

/// The step control of the settings, rtol raised to rtol_floor.
inline StepControl step_control(const DynamicsSettings& s) {
  return StepControl{
      .rtol = std::max(s.rtol, rtol_floor),
      .atol = s.atol,
      .first_step = s.step,
      .max_step = s.max_step > 0.0 ? s.max_step : std::numeric_limits<double>::infinity()};
}
}  // namespace detail

/// The integrators that `simulate` knows by name, with what they are.
inline const std::vector<std::pair<std::string, std::string>>& integrator_names() {
  static const std::vector<std::pair<std::string, std::string>> names = {
      {"auto",
       "dop853 while not stiff, then bdf (stiffness detected) or generalized-alpha (dop853 "
       "failed, at a singular configuration say), rtol/atol"},
      {"generalized-alpha",
       "index-3 generalized-alpha (Chung-Hulbert), fixed step h or, with adaptive, rtol/atol"},
      {"hht", "index-3 HHT-alpha, fixed step h or, with adaptive, rtol/atol"},
      {"dopri5", "explicit Dormand-Prince 5(4), index 1 with projection, rtol/atol"},
      {"dop853", "explicit Dormand-Prince 8(5,3), index 1 with projection, rtol/atol"},
      {"bdf", "implicit BDF of orders 1-5, stabilized index 2 (GGL), rtol/atol"},
      {"adams", "explicit Adams-Bashforth of order 1-6, index 1 with projection, fixed step h"},
  };
  return names;
}

namespace detail {

/// The start of every run: the settings checked, the workspace assembled (or the kept start
/// taken, see AssembledStart), and what the assembly did that deserves a warning.
template <class Model>
RunSummary start_run(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                     AssembledStart<Model>* start) {
  // Without a moving body there is nothing to integrate (and empty vectors all the way down).
  if (model.num_bodies() == 0)
    throw ModelError("dynamics",
                     "the model has no moving bodies, so there is nothing to simulate; add a "
                     "body (and the joints and forces that act on it) before running");
  if (!(s.step > 0.0) || !(s.output_interval > 0.0) || !(s.t_end >= ws.t))
    throw ModelError("dynamics",
                     "step and output interval must be positive and t_end >= t0 "
                     "(got step " +
                         to_text(s.step) + ", output interval " + to_text(s.output_interval) +
                         ", t_end " + to_text(s.t_end) + ")");
  if (!(s.rtol > 0.0) || !(s.atol > 0.0))
    throw ModelError("dynamics", "rtol and atol must be positive (got rtol " + to_text(s.rtol) +
                                     ", atol " + to_text(s.atol) + ")");
  // Below about 5 machine epsilons of the start time, t + step rounds back to t.
  if (const double least = 1e-15 * std::max(1.0, std::abs(ws.t)); s.step < least)
    throw ModelError(
        "dynamics", "a step of " + to_text(s.step) +
                        " s is below what double precision resolves at t = " + to_text(ws.t) +
                        " s, so time would not advance; give a step of at least " + to_text(least) +
                        " s");
  // rtol = 1 (with a large atol) has a use: an adaptive method that never rejects a step.
  if (!(s.rtol <= 1.0))
    throw ModelError("dynamics", "rtol " + to_text(s.rtol) +
                                     " is a relative error above 100%, which controls nothing; "
                                     "give a fraction of at most 1 (1e-6 by default)");
  RunSummary summary;
  AssemblySettings assembly = s.assembly;
  assembly.linear_solver = s.linear_solver;
  if (start != nullptr && start->matches(assembly)) {
    Workspace<Model> kept = *start->state;
    const AssembledCheck check = check_assembled(model, kept, assembly, start->report);
    if (check == AssembledCheck::forces_changed) assemble_accelerations(model, kept, assembly);
    if (check != AssembledCheck::not_assembled) {
      ws = std::move(kept);
      summary.assembly = start->report;
      summary.redundant_equations = start->redundant_equations;
      summary.assembly_reused = true;
    }
  }
  if (!summary.assembly_reused) {
    summary.assembly = assemble(model, ws, assembly);
    summary.redundant_equations = redundant_equations(model, ws);
    if (start != nullptr) start->keep(ws, summary.assembly, summary.redundant_equations, assembly);
  }
  if (const std::string moved = assembly_motion_warning(summary.assembly, assembly); !moved.empty())
    summary.warnings.push_back({"assembly", moved});
  return summary;
}

/// The warning for an rtol below rtol_floor (which step_control raised), if the integrator
/// controls its error.
inline void note_tolerance_floor(const DynamicsSettings& s, bool adaptive, RunSummary& summary) {
  if (s.rtol < rtol_floor && adaptive)
    summary.warnings.push_back(
        {"tolerance", "rtol " + to_text(s.rtol) +
                          " is below what double precision can deliver; the run used " +
                          to_text(rtol_floor) +
                          " (100 machine epsilons): a smaller one only adds steps and rounding"});
}

/// The run's output times: every output_interval from t0 (a count too large to hold is refused
/// by name), and t_end when it falls between two of them.
inline OutputGrid output_grid(const DynamicsSettings& s, double t0) {
  const long whole = output_count("dynamics", t0, s.t_end, s.output_interval);
  const double whole_end = t0 + static_cast<double>(whole) * s.output_interval;
  const bool partial = s.t_end - whole_end > 1e-12 * std::max(1.0, std::abs(s.t_end));
  return {.t0 = t0,
          .interval = s.output_interval,
          .count = whole + (partial ? 1 : 0),
          .next = 1,
          .last = partial ? s.t_end : whole_end};
}

/// Hands the workspace to the observer at an output, with the blocks of every element up to
/// date, keeps the largest constraint residuals, and checks that no point mass or slender rod
/// turns where it has no inertia (after the observer, so that partial results show it).
template <class Model, class Observer>
struct OutputRecorder {
  const Model& model;
  Workspace<Model>& ws;
  Observer& observe;
  RunSummary& summary;
  MasslessMotionCheck<Model> check_massless{};

  template <class Integrator>
  void operator()(Integrator& integrator) {
    if constexpr (requires { integrator.refresh_blocks(); }) integrator.refresh_blocks();
    const auto [phi_norm, phid_norm] = constraint_residuals(model, ws);
    summary.max_position_residual = std::max(summary.max_position_residual, phi_norm);
    summary.max_velocity_residual = std::max(summary.max_velocity_residual, phid_norm);
    ++summary.outputs;
    observe(std::as_const(ws));
    check_massless(model, ws);
  }
};

/// Runs an integrator from the workspace's state through the grid's remaining outputs, or, if
/// it interpolates its outputs, until stop() after an accepted step: false if it stopped. A
/// terminal watch's crossing ends the run there, with an output at its time.
template <class Model, class Integrator, class Recorder, class Stop>
bool run_integrator(const Model& model, Workspace<Model>& ws, Integrator& integrator,
                    const DynamicsSettings& s, OutputGrid& grid, Recorder& recorder, Stop&& stop,
                    Watcher<Model>& watcher) {
  const auto record = [&] { recorder(integrator); };
  if constexpr (DenseOutputIntegrator<Integrator>)
    if (integrator.adaptive())
      return advance_with_dense_output(model, ws, integrator, grid, record, stop, 1e-12, &watcher);
  StepCut cut;
  for (; !grid.done(); ++grid.next) {
    advance_to(model, ws, integrator, grid.time(grid.next), s.step, 1e-12, &cut, &watcher);
    record();
    if (watcher.ended()) {
      grid.next = grid.count + 1;
      break;
    }
  }
  return true;
}

/// Puts an integrator's committed state into the whole workspace, before another integrator
/// starts from it. Joint coordinates keep the bodies' absolute positions and velocities up to
/// date only at outputs (refresh_blocks); between them the workspace's q and v are an output's,
/// and a run handed over there went on from that output's state at the later time.
template <class Integrator>
void complete_workspace(Integrator& integrator) {
  if constexpr (requires { integrator.refresh_blocks(); }) integrator.refresh_blocks();
}

/// Hands a run's summary so far to DynamicsSettings::partial when the run ends in an exception
/// (its destructor runs while the exception unwinds the run). `counted` completes the copy with
/// what the live integrators counted.
template <class Model, class Counted>
class PartialOnThrow {
 public:
  PartialOnThrow(const DynamicsSettings& s, const RunSummary& summary,
                 const Watcher<Model>& watcher, std::chrono::steady_clock::time_point started,
                 Counted counted)
      : s_(s), summary_(summary), watcher_(watcher), started_(started), counted_(counted) {}
  PartialOnThrow(const PartialOnThrow&) = delete;
  PartialOnThrow& operator=(const PartialOnThrow&) = delete;
  ~PartialOnThrow() {
    if (s_.partial == nullptr || std::uncaught_exceptions() <= unwinding_) return;
    try {
      *s_.partial = summary_;
      counted_(s_.partial->statistics);
      s_.partial->events = watcher_.events();
      s_.partial->wall_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    } catch (...) {  // out of memory while unwinding: the partial summary is lost, not the error
    }
  }

 private:
  const DynamicsSettings& s_;
  const RunSummary& summary_;
  const Watcher<Model>& watcher_;
  std::chrono::steady_clock::time_point started_;
  Counted counted_;
  int unwinding_ = std::uncaught_exceptions();
};

/// Adds the counters of a later part of a run.
inline void add_statistics(IntegratorStatistics& total, const IntegratorStatistics& part) {
  total.steps += part.steps;
  total.newton_iterations += part.newton_iterations;
  total.jacobian_evaluations += part.jacobian_evaluations;
  total.factorizations += part.factorizations;
  total.residual_evaluations += part.residual_evaluations;
  total.rejected_steps += part.rejected_steps;
  total.restarts += part.restarts;
  total.events += part.events;
  total.singular_steps += part.singular_steps;
  total.max_error_estimate = std::max(total.max_error_estimate, part.max_error_estimate);
}

}  // namespace detail

/// simulate_with, its observer a function: compiled once per model and integrator type.
template <template <class> class IntegratorType, class Model>
RunSummary simulate_with_function(const Model& model, Workspace<Model>& ws,
                                  const DynamicsSettings& s, const ObserverFunction<Model>& observe,
                                  AssembledStart<Model>* start, WatchList<Model> watches) {
  using Integrator = IntegratorType<Model>;
  static_assert(StepIntegrator<Integrator>);
  const auto started = std::chrono::steady_clock::now();
  RunSummary summary = detail::start_run(model, ws, s, start);
  Integrator integrator(model, ws, detail::integrator_settings<typename Integrator::Settings>(s),
                        detail::step_control(s));
  detail::note_tolerance_floor(s, integrator.adaptive(), summary);
  summary.integrator = integrator.name();
  summary.setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  detail::OutputRecorder<Model, const ObserverFunction<Model>> recorder{model, ws, observe,
                                                                        summary};
  detail::Watcher<Model> watcher(watches);
  const detail::PartialOnThrow<Model, std::function<void(IntegratorStatistics&)>> partial(
      s, summary, watcher, started,
      [&](IntegratorStatistics& counted) { counted = integrator.statistics(); });
  recorder(integrator);
  watcher.start(ws);
  OutputGrid grid = detail::output_grid(s, ws.t);
  detail::run_integrator(model, ws, integrator, s, grid, recorder, [] { return false; }, watcher);
  summary.statistics = integrator.statistics();
  summary.events = watcher.events();
  summary.ended_by = watcher.ended_by();
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

/// Runs a dynamic analysis with the integrator type chosen at compile time (only that one is
/// instantiated), from the workspace's state (assembled first, or taken from `start`, see
/// AssembledStart). `observe(ws)` sees the workspace at t0 and at every output time, with frames
/// and element blocks up to date, and at the end of a run that a terminal watch ended. The
/// crossings of `watches` are located and returned in the summary's events.
template <template <class> class IntegratorType, class Model, class Observer>
RunSummary simulate_with(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                         Observer&& observe,
                         AssembledStart<std::type_identity_t<Model>>* start = nullptr,
                         WatchList<Model> watches = {}) {
  return simulate_with_function<IntegratorType>(
      model, ws, s, ObserverFunction<Model>(std::ref(observe)), start, watches);
}

/// The integrator "auto": dop853 with error control (rtol, atol) while it does well; from a
/// step where its stiffness test fires (the step held by stability, not accuracy, for 15
/// steps), bdf with the same tolerances, unless its first auto_trial_steps steps are shorter
/// on average than dop853's were (an undamped stiff oscillation, which bdf resolves rather
/// than damps): then dop853 again to the end. If either fails (at a singular configuration, say,
/// where the accelerations of dop853 and bdf's iteration break down), generalized-alpha at the
/// fixed step settings.step, which steps through such configurations, runs again from the
/// start and hands over the outputs from where the failed method stopped: the outputs after
/// that are a generalized-alpha run's. The summary's `integrator` says what ran,
/// `integrator_choice` why. `Explicit`, `Stiff` and `Robust` are the three in the run's
/// coordinates.
template <template <class> class Explicit, template <class> class Stiff,
          template <class> class Robust, class Model>
RunSummary simulate_auto_function(const Model& model, Workspace<Model>& ws,
                                  const DynamicsSettings& s, const ObserverFunction<Model>& observe,
                                  AssembledStart<Model>* start, WatchList<Model> watches) {
  const auto started = std::chrono::steady_clock::now();
  RunSummary summary = detail::start_run(model, ws, s, start);
  const Workspace<Model> assembled = ws;  // for the robust run, if it comes to that
  const StepControl control = detail::step_control(s);
  std::optional<Explicit<Model>> explicit_method;
  explicit_method.emplace(model, ws, detail::integrator_settings<DormandPrinceSettings>(s),
                          control);
  detail::note_tolerance_floor(s, true, summary);
  summary.setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  detail::OutputRecorder<Model, const ObserverFunction<Model>> recorder{model, ws, observe,
                                                                        summary};
  detail::Watcher<Model> watcher(watches);
  // What the live dop853 counted (bdf's and generalized-alpha's count in the summary once they
  // end; an exception that ends the run inside them loses their part).
  const detail::PartialOnThrow<Model, std::function<void(IntegratorStatistics&)>> partial(
      s, summary, watcher, started, [&](IntegratorStatistics& counted) {
        if (explicit_method) detail::add_statistics(counted, explicit_method->statistics());
      });
  recorder(*explicit_method);
  watcher.start(ws);
  OutputGrid grid = detail::output_grid(s, ws.t);
  summary.integrator = "dop853";
  summary.integrator_choice = "auto: dop853 throughout (not stiff, no failure)";
  std::string failure;
  double failed_at = 0.0;
  try {
    const bool finished = detail::run_integrator(
        model, ws, *explicit_method, s, grid, recorder,
        [&] { return explicit_method->stiffness_detected(); }, watcher);
    if (!finished) {
      const double stiff_from = explicit_method->time();
      summary.integrator = "dop853, then bdf from t = " + to_text(stiff_from) + " s";
      summary.integrator_choice = "auto: stiff at t = " + to_text(stiff_from) + " s (h |lambda| " +
                                  to_text(explicit_method->stiffness_estimate()) +
                                  " beyond dop853's stability bound for 15 steps): bdf from there";
      // dop853's mean step, against which bdf's must pay off: an undamped stiff oscillation
      // holds bdf's steps as short (it resolves the oscillation rather than damping it).
      const double explicit_mean_step =
          (stiff_from - grid.t0) /
          static_cast<double>(std::max(1L, explicit_method->statistics().steps));
      detail::add_statistics(summary.statistics, explicit_method->statistics());
      detail::complete_workspace(*explicit_method);
      explicit_method.reset();
      std::optional<Stiff<Model>> stiff;
      bool paid_off = true;
      try {
        stiff.emplace(model, ws, detail::integrator_settings<BdfSettings>(s), control);
        paid_off = detail::run_integrator(
            model, ws, *stiff, s, grid, recorder,
            [&] {
              const long steps = stiff->statistics().steps;
              return steps == auto_trial_steps &&
                     (stiff->time() - stiff_from) / static_cast<double>(steps) < explicit_mean_step;
            },
            watcher);
      } catch (const SolverError& error) {
        failure = error.message();
        failed_at = error.time();
      }
      if (stiff) detail::add_statistics(summary.statistics, stiff->statistics());
      if (!paid_off) {  // back to dop853, held by stability, to the end
        const double back_at = stiff->time();
        detail::complete_workspace(*stiff);
        stiff.reset();
        summary.integrator += ", dop853 again from t = " + to_text(back_at) + " s";
        summary.integrator_choice += "; bdf's first " + std::to_string(auto_trial_steps) +
                                     " steps were shorter than dop853's on average: dop853 "
                                     "again";
        explicit_method.emplace(model, ws, detail::integrator_settings<DormandPrinceSettings>(s),
                                control);
        detail::run_integrator(
            model, ws, *explicit_method, s, grid, recorder, [] { return false; }, watcher);
      }
    }
  } catch (const SolverError& error) {
    failure = error.message();
    failed_at = error.time();
  }
  if (explicit_method) detail::add_statistics(summary.statistics, explicit_method->statistics());
  explicit_method.reset();
  if (!failure.empty()) {
    // Generalized-alpha from the start, silent up to the outputs already handed over.
    const std::string failed =
        "at t = " + to_text(failed_at) + " s: " + failure + " Generalized-alpha ran instead";
    summary.integrator_choice = summary.integrator == "dop853"
                                    ? "auto: dop853 failed " + failed
                                    : summary.integrator_choice + "; " + failed;
    summary.integrator +=
        ", then generalized-alpha (h = " + to_text(s.step) +
        " s) from the start, its outputs from t = " + to_text(grid.time(grid.next)) + " s";
    DynamicsSettings robust_settings = s;
    robust_settings.integrator = "generalized-alpha";
    robust_settings.generalized_alpha.adaptive = false;
    ws = assembled;
    Robust<Model> robust(
        model, ws, detail::integrator_settings<GeneralizedAlphaSettings>(robust_settings), control);
    // Its events count from the last output handed over, as its outputs do.
    watcher.rewind(grid.time(grid.next - 1));
    watcher.start(ws);
    try {
      StepCut cut;
      for (long k = 1; k < grid.next; ++k)
        advance_to(model, ws, robust, grid.time(k), s.step, 1e-12, &cut, &watcher);
      for (; !grid.done(); ++grid.next) {
        advance_to(model, ws, robust, grid.time(grid.next), s.step, 1e-12, &cut, &watcher);
        recorder(robust);
        if (watcher.ended()) break;
      }
    } catch (const SolverError& error) {
      throw SolverError(error.time(), error.message() + " (" + summary.integrator_choice + ")");
    }
    detail::add_statistics(summary.statistics, robust.statistics());
  }
  summary.events = watcher.events();
  summary.ended_by = watcher.ended_by();
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

/// The integrator "auto" (see simulate_auto_function) for any observer.
template <template <class> class Explicit, template <class> class Stiff,
          template <class> class Robust, class Model, class Observer>
RunSummary simulate_auto(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                         Observer&& observe,
                         AssembledStart<std::type_identity_t<Model>>* start = nullptr,
                         WatchList<Model> watches = {}) {
  return simulate_auto_function<Explicit, Stiff, Robust>(
      model, ws, s, ObserverFunction<Model>(std::ref(observe)), start, watches);
}

/// simulate()'s dispatch by the integrator's name, in the coordinates the settings name.
template <class Model, class Observer>
RunSummary simulate_by_name(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                            Observer&& observe,
                            AssembledStart<std::type_identity_t<Model>>* start = nullptr,
                            WatchList<Model> watches = {}) {
  if (s.coordinates == "joint") {
    if (s.integrator == "auto")
      return simulate_auto<JointDormandPrince853, JointBdf, JointGeneralizedAlpha>(
          model, ws, s, observe, start, watches);
    if (s.integrator == "dopri5")
      return simulate_with<JointDormandPrince>(model, ws, s, observe, start, watches);
    if (s.integrator == "dop853")
      return simulate_with<JointDormandPrince853>(model, ws, s, observe, start, watches);
    if (s.integrator == "adams")
      return simulate_with<JointAdamsBashforth>(model, ws, s, observe, start, watches);
    if (s.integrator == "generalized-alpha" || s.integrator == "hht")
      return simulate_with<JointGeneralizedAlpha>(model, ws, s, observe, start, watches);
    if (s.integrator == "bdf")
      return simulate_with<JointBdf>(model, ws, s, observe, start, watches);
    throw ModelError("dynamics",
                     "joint coordinates run with auto, generalized-alpha, hht, bdf, dopri5, "
                     "dop853 or adams, not '" +
                         s.integrator +
                         "'; choose one of those, or coordinates 'absolute' for this integrator");
  } else if (s.coordinates != "absolute") {
    throw ModelError("dynamics", "unknown coordinates '" + s.coordinates +
                                     "'; choose 'auto', 'absolute' or 'joint'");
  }
  if (s.integrator == "auto")
    return simulate_auto<DormandPrince853, Bdf, GeneralizedAlpha>(model, ws, s, observe, start,
                                                                  watches);
  if (s.integrator == "generalized-alpha" || s.integrator == "hht")
    return simulate_with<GeneralizedAlpha>(model, ws, s, observe, start, watches);
  if (s.integrator == "dopri5")
    return simulate_with<DormandPrince>(model, ws, s, observe, start, watches);
  if (s.integrator == "dop853")
    return simulate_with<DormandPrince853>(model, ws, s, observe, start, watches);
  if (s.integrator == "bdf") return simulate_with<Bdf>(model, ws, s, observe, start, watches);
  if (s.integrator == "adams")
    return simulate_with<AdamsBashforth>(model, ws, s, observe, start, watches);
  std::string known;
  for (const auto& [name, what] : integrator_names()) known += (known.empty() ? "" : ", ") + name;
  throw ModelError("dynamics", "unknown integrator '" + s.integrator + "'; choose one of " + known);
}

/// Closure equations up to which coordinates "auto" takes joint coordinates. Each factorization
/// there forms the closures' dense Schur complement from as many passes over the tree, which
/// beyond a few tens of equations costs more than the absolute coordinates' sparse path: dop853
/// on chains of spatial four-bars ran 4.0 to 4.6 times faster in joint coordinates with 10 to 25
/// closure equations, and 0.66 times as fast with 50 (docs/integrators.md, "Which coordinates").
inline constexpr int auto_joint_closure_limit = 30;

struct CoordinatesChoice {
  std::string coordinates;  // "absolute" or "joint"
  std::string reason;       // for RunSummary::coordinates_choice
};

/// What coordinates "auto" runs. Joint coordinates where they were measured faster at the same
/// error, and give the same answers: spatial models whose spanning tree leaves at most
/// auto_joint_closure_limit closure equations, run by the methods whose cost is evaluating the
/// accelerations (auto, dop853, dopri5, adams); the spatial engine runs 2.3 to 2.6 times faster
/// there. Absolute coordinates otherwise: planar models (joint coordinates ran 0.94 to 1.7
/// times as fast there), the implicit methods named (their Newton matrices in joint
/// coordinates leave out the blocks of springs that join two bodies), redundant constraints
/// (absolute coordinates give their minimum-norm reactions, joint ones pin them), and, for
/// "auto", a force element that joins two moving bodies (the run may turn to bdf).
template <class Model>
CoordinatesChoice choose_coordinates(const Model& model, const DynamicsSettings& s,
                                     const std::vector<RedundantEquation>& redundant) {
  const auto absolute = [](const std::string& why) {
    return CoordinatesChoice{"absolute", "auto: absolute coordinates (" + why + ")"};
  };
  if constexpr (!std::is_same_v<typename Model::Space, Spatial>) {
    return absolute("a planar model: joint coordinates would cost about as much");
  } else {
    if (const std::string friction = first_reaction_reader(model); !friction.empty())
      return absolute(friction +
                      " reads its joint's reaction, which joint coordinates do not solve while "
                      "stepping");
    const bool explicit_method =
        s.integrator == "dop853" || s.integrator == "dopri5" || s.integrator == "adams";
    if (!explicit_method && s.integrator != "auto")
      return absolute(s.integrator +
                      " is implicit: its Newton matrix in joint coordinates would leave out the "
                      "blocks of springs between bodies");
    if (!redundant.empty())
      return absolute(std::to_string(redundant.size()) + " redundant constraint equation" +
                      (redundant.size() == 1 ? "" : "s") +
                      ", whose reactions are the minimum-norm ones there");
    const int closures = JointCoordinates<Model>::closure_equations(model);
    if (closures > auto_joint_closure_limit)
      return absolute(std::to_string(closures) +
                      " closure equations beyond the spanning tree: their dense Schur "
                      "complement would cost more than the sparse path");
    if (s.integrator == "auto" && detail::couples_bodies(model))
      return absolute(
          "a force element joins two moving bodies: if the run turns stiff, bdf's Newton "
          "matrix in joint coordinates would leave its blocks out");
    return {"joint", "auto: joint coordinates (a spatial model whose spanning tree leaves " +
                         std::to_string(closures) + " closure equations)"};
  }
}

/// Runs a dynamic analysis with the integrator and the coordinates ("absolute" or "joint")
/// named in the settings.
template <class Model, class Observer>
RunSummary simulate_in_coordinates(const Model& model, Workspace<Model>& ws,
                                   const DynamicsSettings& s, Observer&& observe,
                                   AssembledStart<std::type_identity_t<Model>>* start = nullptr,
                                   WatchList<Model> watches = {}) {
  RunSummary summary = simulate_by_name(model, ws, s, observe, start, watches);
  summary.coordinates = s.coordinates;
  return summary;
}

/// simulate, its observer a function: the dispatch and every integrator compiled once per model.
template <class Model>
RunSummary simulate_function(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                             const ObserverFunction<Model>& observe, AssembledStart<Model>* start,
                             WatchList<Model> watches) {
  if (s.coordinates != "auto")
    return simulate_in_coordinates(model, ws, s, observe, start, watches);
  const auto& known = integrator_names();
  if (std::none_of(known.begin(), known.end(),
                   [&](const auto& entry) { return entry.first == s.integrator; })) {
    DynamicsSettings named = s;  // refused by name, before any assembly
    named.coordinates = "absolute";
    return simulate_in_coordinates(model, ws, named, observe, start, watches);
  }
  const auto started = std::chrono::steady_clock::now();
  AssembledStart<Model> local;
  AssembledStart<Model>* kept = start != nullptr ? start : &local;
  const RunSummary assembled = detail::start_run(model, ws, s, kept);
  const double assembly_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const CoordinatesChoice choice = choose_coordinates(model, s, assembled.redundant_equations);
  DynamicsSettings chosen = s;
  chosen.coordinates = choice.coordinates;
  RunSummary summary = simulate_in_coordinates(model, ws, chosen, observe, kept, watches);
  // The run started from the state assembled above: count that assembly as this run's.
  summary.assembly_reused = assembled.assembly_reused;
  summary.setup_seconds += assembly_seconds;
  summary.wall_seconds += assembly_seconds;
  summary.coordinates_choice = choice.reason;
  return summary;
}

/// Runs a dynamic analysis with the integrator named in the settings (see integrator_names()),
/// in the settings' coordinates; for "auto", those of choose_coordinates, after the assembly
/// (which finds redundant equations), the run starting from its state. With `start`, runs after
/// the first start from its assembled state (see AssembledStart). The crossings of `watches`
/// (events) are located in every step and returned in the summary; a terminal one ends the run.
template <class Model, class Observer>
RunSummary simulate(const Model& model, Workspace<Model>& ws, const DynamicsSettings& s,
                    Observer&& observe,
                    AssembledStart<std::type_identity_t<Model>>* start = nullptr,
                    WatchList<Model> watches = {}) {
  return simulate_function(model, ws, s, ObserverFunction<Model>(std::ref(observe)), start,
                           watches);
}

}  // namespace odyn
