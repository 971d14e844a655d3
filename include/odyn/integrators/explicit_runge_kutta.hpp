#pragma once
// Explicit Runge-Kutta methods with step-size control, on the index-1 form of the equations of
// motion, with the state projected back onto the constraints after every step and a continuous
// extension for dense output. The method (stages, coefficients, error estimate, dense output)
// is a compile-time parameter: dormand_prince.hpp (5(4), "dopri5") and dop853.hpp (8(5,3),
// "dop853") are each a tableau and an alias of the class below.
//
// The state y = (q, v) follows q' = rate(q, v) (the quaternion as 4 numbers, renormalized) and
// v' from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] at every stage. Index 1 lets the
// positions and velocities drift off Phi = 0 and Phi_q v + Phi_t = 0 by the local error; after
// each step both are projected back in the mass metric (the nearest consistent state), which
// keeps the order and stops the drift. One solve of the saddle-point system per stage, no
// Newton iteration on the dynamics: cheap per step when the problem is not stiff. Since the
// projection removes the local error's part across the constraints, the error estimate holds
// the part along them to the tolerance and bounds the part across (see estimate_error).
//
// Near a singular configuration (the constraint Jacobian nearly loses rank, the branches of
// Phi = 0 cross) the index-1 accelerations of a state off the constraints are amplified by
// about 1/sigma^2 (sigma the Jacobian's smallest singular value): the stages, which lie off
// them by the stages' own error, then send the step astray or onto the other branch. There the
// integrator projects every stage onto the constraints first (to rounding), which evaluates
// the same vector field on the constraint manifold and keeps the order (see project_stage).
//
// Step control as in Hairer, Norsett & Wanner, "Solving Ordinary Differential Equations I",
// Sect. II.4; continuous extensions as in Sect. II.6.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <string>

#include "odyn/analysis/absolute_coordinates.hpp"
#include "odyn/analysis/diagnosis.hpp"
#include "odyn/analysis/saddle_point.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/integrators/integrator.hpp"
#include "odyn/linalg/all_finite.hpp"

namespace odyn {

/// Settings of the explicit Runge-Kutta integrators (dopri5, dop853): the projection.
struct DormandPrinceSettings {
  /// Positions are projected until every entry of Phi is below this.
  double projection_tolerance = 1e-12;
  int max_projection_iterations = 6;
  /// The factorization of the saddle-point systems (linalg/linear_solver.hpp).
  LinearSolver linear_solver = LinearSolver::automatic;
  /// A step rejected far off its target at a state whose constraint Jacobian has pivots this
  /// far below its largest (a rank-revealing QR, for models of up to m^2 n = 2e7) makes every
  /// stage be projected onto the constraints, until 8 steps in a row go well. 0: never.
  double singular_threshold = 0.05;
};

/// What a method type gives the integrator below, with s = stages (k_0 = f at the committed
/// state; k_s = f at the projected end of the step; k_{s+1}.. the extra stages of the dense
/// output):
///   name, order;
///   c[s], a[s][s]: stage i at t_n + c_i h, y_n + h sum_{j<i} a_ij k_j;
///   b[s]: y_{n+1} = y_n + h sum b_i k_i, unless last_stage_is_new_point (first same as last:
///     the last stage sits at y_{n+1}, so the solver already holds the matrix there);
///   error_weights[s]: h sum e_i k_i estimates the local error, of order error_order + 1 in h;
///   min_step_factor, max_step_factor: bounds of the step-size change;
///   stabilization_exponent: beta of the PI step control (0: plain I control);
///   stiffness_bound: h |lambda| beyond which stability, not accuracy, holds the step (about
///     the stability interval on the negative real axis; Hairer's stiffness test);
///   extra_stages, extra_c, extra_a[e][s + 1 + e]: stages only the dense output needs;
///   dense_rows, dense[r][s + 1 + extra_stages]: the continuous extension (see dense_state).
template <class M>
concept ExplicitRungeKuttaMethod = requires {
  { M::name } -> std::convertible_to<const char*>;
  { M::order } -> std::convertible_to<int>;
  { M::error_order } -> std::convertible_to<int>;
  { M::stages } -> std::convertible_to<int>;
  { M::extra_stages } -> std::convertible_to<int>;
  { M::dense_rows } -> std::convertible_to<int>;
  { M::last_stage_is_new_point } -> std::convertible_to<bool>;
  { M::min_step_factor } -> std::convertible_to<double>;
  { M::max_step_factor } -> std::convertible_to<double>;
  { M::stabilization_exponent } -> std::convertible_to<double>;
  { M::stiffness_bound } -> std::convertible_to<double>;
  M::c[0] + M::a[0][0] + M::b[0] + M::error_weights[0] + M::dense[0][0];
};

/// `Coordinates` is what the method steps: AbsoluteCoordinates (the bodies' own, every joint a
/// constraint) or JointCoordinates (a spanning tree's joint coordinates, loop closures as
/// constraints); both keep the workspace's frames up to date for elements and observers.
template <ExplicitRungeKuttaMethod Method, class Model,
          class Coordinates = AbsoluteCoordinates<Model>>
class ExplicitRungeKutta {
 public:
  using Settings = DormandPrinceSettings;
  static constexpr int nv = Model::nv;
  static constexpr int nq = Model::nq;
  static constexpr int order = Method::order;

  /// Starts from the workspace's consistent state (see assemble), with the first step and the
  /// tolerances of `control`.
  ExplicitRungeKutta(const Model& model, Workspace<Model>& ws, Settings settings = {},
                     StepControl control = {})
      : model_(model),
        ws_(ws),
        settings_(settings),
        control_(control),
        coordinates_(model, ws, settings.linear_solver),
        proposed_step_(std::min(control.first_step, control.max_step)) {
    if (!(control.rtol > 0.0) || !(control.atol > 0.0))
      throw ModelError(Method::name, "rtol and atol must be positive, got " +
                                         to_text(control.rtol) + " and " + to_text(control.atol));
    if (!(proposed_step_ > 0.0))
      throw ModelError(Method::name,
                       "the first step must be positive, got " + to_text(proposed_step_));
    if (!(settings.projection_tolerance > 0.0) || settings.max_projection_iterations < 1)
      throw ModelError(Method::name,
                       "projection_tolerance must be positive and max_projection_iterations at "
                       "least 1, got " +
                           to_text(settings.projection_tolerance) + " and " +
                           std::to_string(settings.max_projection_iterations));
    nq_total_ = coordinates_.num_positions();
    nv_total_ = coordinates_.num_velocities();
    m_ = coordinates_.num_equations();
    size_ = nq_total_ + nv_total_;
    y_n_ = Eigen::VectorXd::Zero(size_);
    y_new_ = y_n_;
    y_trial_ = y_n_;
    y_dense_ = y_n_;
    stage_ = y_n_;
    y_stiffness_ = y_n_;
    projected_stage_ = y_n_;
    for (auto& k : k_) k = y_n_;
    for (auto& term : dense_terms_) term = y_n_;
    vdot_trial_ = Eigen::VectorXd::Zero(nv_total_);
    lambda_trial_ = Eigen::VectorXd::Zero(m_);
    vdot_n_ = vdot_trial_;
    lambda_n_ = lambda_trial_;
    initialize();
  }

  /// Takes the workspace's state as the committed one (v' and lambda solved afresh).
  void initialize() {
    t_n_ = ws_.t;
    coordinates_.read_state(y_n_);
    restart();
  }

  /// After a switch of a force law (and at the start): the first stage again, at the
  /// committed state with the new law.
  void restart() {
    rollback();
    if (!derivative(t_n_, y_n_, k_[0]))
      throw SolverError(t_n_,
                        "the mass-constraint matrix is singular at the start of a step; "
                        "check for redundant or locked constraints");
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    ++statistics_.restarts;
  }

  /// Tries a step of size h from the committed state. The workspace then holds the projected
  /// trial state with its v' and lambda; error_norm() says whether the step is accurate
  /// enough. False if a stage or the projection failed.
  bool attempt(double h) {
    h_ = h;
    error_ = std::numeric_limits<double>::infinity();  // until estimated
    dense_ready_ = false;
    for (int i = 1; i < s; ++i) {
      combine(stage_, y_n_, h, Method::a[i], i);
      if (!derivative(t_n_ + Method::c[i] * h, stage_, k_[i])) return false;
      if (i == stiffness_stage) y_stiffness_ = project_stages_ ? projected_stage_ : stage_;
    }
    if constexpr (Method::last_stage_is_new_point)
      y_new_ = stage_;
    else
      combine(y_new_, y_n_, h, Method::b, s);
    error_ = estimate_error(h);
    if (!std::isfinite(error_)) return false;
    if (!project_or_newton(t_n_ + h, y_new_, held_after_last_stage)) return false;
    // The trial state, kept for restore_trial() and, with k at it, for the dense output.
    coordinates_.read_state(y_trial_);
    // The projection moves the state by about the local error's part across the constraints,
    // which the estimate bounds (by normal_error_allowance). Near a singular configuration,
    // where two branches of Phi = 0 cross, it can land on the other branch instead: a jump far
    // beyond that bound, which the estimate cannot see. Beyond ten times the bound it counts as
    // error, and the step shrinks until the projection stays on its branch (or the run stops
    // with the singular configuration named). Elsewhere it changes nothing: on the engine, one
    // step more in 900 at rtol 1e-10.
    stage_ = y_trial_ - y_new_;
    error_ =
        std::max(error_, weighted_rms_norm(stage_, y_n_, y_new_, control_.rtol, control_.atol) /
                             (10.0 * normal_error_allowance));
    vdot_trial_ = coordinates_.accelerations();
    lambda_trial_ = coordinates_.multipliers();
    derivative_at_workspace(k_[new_point]);
    return true;
  }

  /// The state at t within the last attempted step (t_n <= t <= t_n + h), from the method's
  /// continuous extension, projected onto the constraints, with v' and lambda there: the
  /// workspace holds it as after an attempt.
  bool interpolate(double t) {
    if (!prepare_dense_output()) return false;
    dense_state(t);
    return project_or_newton(t, y_dense_, HeldMatrix::none);
  }

  /// The interpolated positions and velocities at t and the frames from them, unprojected.
  void interpolate_frames(double t) {
    if (!prepare_dense_output()) fail();
    dense_state(t);
    coordinates_.load(t, y_dense_);
  }

  /// Puts the last attempt's trial state back into the workspace (after interpolate()).
  void restore_trial() {
    load_solved_state(t_n_ + h_, y_trial_, vdot_trial_, lambda_trial_);
    coordinates_.evaluate_forces();
  }

  /// The workspace's blocks, v' and lambda for every element at the loaded state, when the
  /// coordinates keep only some of them up to date while stepping (joint coordinates).
  void refresh_blocks() requires requires(Coordinates& c) { c.complete_workspace(); }
  { coordinates_.complete_workspace(); }

  /// Local error of the last attempt in units of the tolerance (accept when <= 1).
  double error_norm() const { return error_; }

  /// Accepts the last attempt and proposes the next step from its error and, with
  /// stabilization_exponent > 0, the previous step's error (PI control, Hairer, Norsett &
  /// Wanner, Sect. IV.2): fewer rejections where the error changes quickly. No growth right
  /// after a rejection.
  void accept() {
    commit();
    ++steps_since_check_;
    if (project_stages_) {
      ++statistics_.singular_steps;
      // Past the configuration the steps go well again: back to plain stages.
      if (++calm_steps_ >= calm_steps_to_leave) project_stages_ = false;
    }
    detect_stiffness();
    statistics_.max_error_estimate = std::max(statistics_.max_error_estimate, error_);
    constexpr double beta = Method::stabilization_exponent;
    constexpr double alpha = 1.0 / (Method::error_order + 1) - 0.75 * beta;
    double factor = Method::max_step_factor;
    if (error_ > 0.0)
      factor = std::clamp(0.9 * std::pow(error_, -alpha) * std::pow(previous_error_, beta),
                          Method::min_step_factor, Method::max_step_factor);
    if (!std::isfinite(factor)) factor = Method::min_step_factor;
    if (rejected_) factor = std::min(factor, 1.0);
    previous_error_ = std::max(error_, 1e-4);
    rejected_ = false;
    const double grown = h_ * factor;
    // A step cut short to land on an output time says nothing against the longer step.
    proposed_step_ =
        std::min(control_.max_step, h_ < proposed_step_ ? std::max(proposed_step_, grown) : grown);
  }

  /// Rejects the last attempt and shrinks the step; throws once it is hopelessly short.
  void reject() {
    ++statistics_.rejected_steps;
    rejected_ = true;
    proposed_step_ =
        h_ * std::min(0.9, step_factor(error_, Method::error_order, Method::min_step_factor, 0.9));
    rollback();
    // A step far off its error target (not the controller's usual overshoot) at a nearly
    // singular configuration: from now on the stages are projected.
    if (!(error_ <= suspicious_error)) {
      if (project_stages_) {
        calm_steps_ = 0;
      } else if (steps_since_check_ >= calm_steps_to_leave && near_singular()) {
        project_stages_ = true;
        calm_steps_ = 0;
      }
    }
    if (proposed_step_ < control_.min_step * std::max(1.0, std::abs(t_n_))) {
      const std::string singular = diagnosis::rank_drop(model_, ws_, coordinates_);
      const std::string head = std::string(Method::name) + ": the step size fell below " +
                               to_text(control_.min_step) + " s";
      if (!singular.empty()) throw SolverError(t_n_, head + "." + singular + singular_advice);
      throw SolverError(t_n_, head +
                                  "; the problem may be stiff (try bdf or generalized-alpha) "
                                  "or the model singular");
    }
  }

  /// Makes the trial state of the last attempt the committed one (no step-size change).
  void commit() {
    t_n_ += h_;
    y_n_ = y_trial_;
    k_[0] = k_[new_point];
    vdot_n_ = vdot_trial_;
    lambda_n_ = lambda_trial_;
    dense_ready_ = false;
    advance_states(model_, ws_);
    ++statistics_.steps;
  }

  /// Puts the workspace back at the last committed state.
  void rollback() { load_solved_state(t_n_, y_n_, vdot_n_, lambda_n_); }

  [[noreturn]] void fail() {
    const double t_failed = t_n_ + h_;
    rollback();
    const std::string head =
        std::string(Method::name) + ": a stage or the projection onto the constraints failed";
    if (const std::string singular = diagnosis::rank_drop(model_, ws_, coordinates_);
        !singular.empty())
      throw SolverError(t_failed, head + "." + singular + singular_advice);
    throw SolverError(t_failed, head +
                                    " (singular mass-constraint matrix or non-finite forces); "
                                    "check for locked or redundant constraints and the force "
                                    "elements' parameters");
  }

  /// Whether the step size has been held by stability rather than accuracy for a while
  /// (Hairer's test, below): the problem is stiff, and an implicit method would take longer
  /// steps.
  bool stiffness_detected() const { return stiff_steps_ >= stiff_steps_needed; }
  /// The last estimate of h |lambda|, lambda the dominant eigenvalue of the Jacobian of f.
  double stiffness_estimate() const { return h_lambda_; }

  /// Its name in integrator_names().
  static std::string name() { return Method::name; }
  bool adaptive() const { return true; }
  double time() const { return t_n_; }
  double proposed_step() const { return proposed_step_; }
  void count_event() { ++statistics_.events; }
  const IntegratorStatistics& statistics() const { return statistics_; }
  const Settings& settings() const { return settings_; }
  /// The coordinates it steps, with the workspace's state loaded (a multistep method started
  /// by this one steps the same object).
  Coordinates& coordinates() { return coordinates_; }

 private:
  static constexpr int s = Method::stages;
  static constexpr double normal_error_allowance = 30.0;
  static constexpr const char* singular_advice =
      " Its accelerations are singular there; generalized-alpha (integrator "
      "'generalized-alpha') steps through such configurations.";
  /// A rejected step's error beyond this many tolerances asks whether the Jacobian is nearly
  /// singular (the controller's own misses are a few tolerances).
  static constexpr double suspicious_error = 10.0;
  /// Accepted steps without a suspicious rejection that end the projected stages; also the
  /// fewest accepted steps between two rank checks.
  static constexpr int calm_steps_to_leave = 8;
  /// The rank check is a dense QR of Phi_q (m^2 n flops, twice): up to about 10 ms.
  static constexpr double largest_rank_check = 2e7;
  static constexpr int new_point = s;  // k_[s]: f at the projected end of the last attempt
  static constexpr int num_derivatives = s + 1 + Method::extra_stages;
  // y_{n+1} - y_n, h k_0 - (y_{n+1} - y_n), the Hermite term, then the method's dense rows.
  static constexpr int num_dense_terms = 3 + Method::dense_rows;

  /// What the solver holds when the projection starts: nothing useful, the matrix at the point
  /// to project (first same as last), or at a point within the local error of it (a last stage
  /// at t_n + h), good enough for chord iterations on the positions.
  enum class HeldMatrix { none, at_point, near_point };
  static constexpr HeldMatrix held_after_last_stage =
      Method::last_stage_is_new_point ? HeldMatrix::at_point
      : Method::c[s - 1] == 1.0       ? HeldMatrix::near_point
                                      : HeldMatrix::none;

  /// The last stage at t_n + h other than the new point itself: f there and at the new point
  /// give the stiffness estimate.
  static constexpr int stiffness_stage = [] {
    int stage = 0;
    for (int i = 1; i < s; ++i)
      if (Method::c[i] == 1.0 && !(Method::last_stage_is_new_point && i == s - 1)) stage = i;
    return stage;
  }();
  static_assert(stiffness_stage > 0, "the tableau needs a stage at t_n + h for the stiffness test");
  static constexpr int stiff_steps_needed = 15;    // as in Hairer's DOPRI5 and DOP853
  static constexpr int non_stiff_steps_reset = 6;  // steps without the sign that clear the count

  /// Hairer, Norsett & Wanner, Sect. IV.2: h |lambda| ~ h |f(y_1) - f(y_s)| / |y_1 - y_s| for two
  /// states at the step's end (the new point and the last stage there). Beyond the method's
  /// stability boundary on the negative real axis, stability holds the step, not accuracy.
  void detect_stiffness() {
    const double distance = (y_trial_ - y_stiffness_).norm();
    if (!(distance > 0.0)) return;
    h_lambda_ = h_ * (k_[new_point] - k_[stiffness_stage]).norm() / distance;
    if (h_lambda_ > Method::stiffness_bound) {
      non_stiff_steps_ = 0;
      ++stiff_steps_;
    } else if (++non_stiff_steps_ >= non_stiff_steps_reset) {
      stiff_steps_ = 0;
    }
  }

  /// out = base + h sum_{j < count} weights_j k_j.
  template <std::size_t N>
  void combine(Eigen::VectorXd& out, const Eigen::VectorXd& base, double h,
               const std::array<double, N>& weights, int count) {
    out = base;
    for (int j = 0; j < count; ++j)
      if (weights[j] != 0.0) out.noalias() += (h * weights[j]) * k_[j];
  }
  template <std::size_t N>
  void combine(Eigen::VectorXd& out, double h, const std::array<double, N>& weights, int count) {
    out.setZero();
    for (int j = 0; j < count; ++j)
      if (weights[j] != 0.0) out.noalias() += (h * weights[j]) * k_[j];
  }

  /// The local error of the step to y_new_ in units of the tolerance. The projection that ends
  /// the step removes the error's part across the constraints (in the mass metric), so only
  /// the part along them is a local error of the projected solution, held to the tolerance.
  /// The part across is still bounded, by normal_error_allowance tolerances: the projection
  /// then starts close by, and the continuous extension between the step's ends stays near
  /// the constraints (a mechanism with no degree of freedom left has no part along them).
  double estimate_error(double h) {
    combine(stage_, h, Method::error_weights, s);
    const auto norm = [&] {
      return weighted_rms_norm(stage_, y_n_, y_new_, control_.rtol, control_.atol);
    };
    if constexpr (requires { coordinates_.keep_tangential(stage_); }) {
      const double whole = norm();
      coordinates_.keep_tangential(stage_);
      return std::max(norm(), whole / normal_error_allowance);
    }
    return norm();
  }

  /// The workspace at a projected state (t, y) with its v' and lambda: frames and constraints.
  void load_solved_state(double t, const Eigen::VectorXd& y, const Eigen::VectorXd& vdot,
                         const Eigen::VectorXd& lambda) {
    coordinates_.load(t, y);
    coordinates_.restore_solution(vdot, lambda);
    coordinates_.evaluate_constraints();
  }

  /// f(t, y): the position rate and v' (index 1) at a stage; leaves v' and lambda in the
  /// coordinates. False if the saddle-point matrix is singular or a value is not finite.
  bool derivative(double t, const Eigen::VectorXd& y, Eigen::VectorXd& k) {
    ++statistics_.residual_evaluations;
    if (project_stages_ && m_ > 0) {
      if (!project_stage(t, y)) return false;
      coordinates_.position_rate(projected_stage_, k.head(nq_total_));
    } else {
      coordinates_.load(t, y);
      coordinates_.evaluate_constraints();
      if (!accelerations()) return false;
      coordinates_.position_rate(y, k.head(nq_total_));
    }
    k.tail(nv_total_) = coordinates_.accelerations();
    return all_finite(k);
  }

  /// Near a singular configuration: the stage y moved onto Phi = 0 and Phi_q v + Phi_t = 0 (the
  /// positions by Newton to rounding, not to the projection tolerance: what is left of Phi
  /// there turns Phi_q's null space by about |Phi| / sigma^2), v' and lambda solved there, and
  /// the projected stage in projected_stage_. f at the projection of y is a smooth extension of
  /// the vector field off the constraints that agrees with it on them, so the method keeps its
  /// order, while the stages no longer see the amplified accelerations off them. False if the
  /// projection does not converge.
  bool project_stage(double t, const Eigen::VectorXd& y) {
    coordinates_.load(t, y);
    coordinates_.evaluate_constraints();
    const double rounding =
        std::numeric_limits<double>::epsilon() * std::max(1.0, coordinates_.largest_position());
    double residual = coordinates_.position_residual();
    for (int k = 0; residual > stage_rounding_factor * rounding && k < max_stage_iterations; ++k) {
      // Newton, not chord: to rounding in few iterations even where sigma is small.
      if (!factorize()) return false;
      coordinates_.correct_positions();
      ++statistics_.newton_iterations;
      const double before = residual;
      residual = coordinates_.position_residual();
      // At rounding, or no longer converging (near a singular configuration Newton converges
      // only linearly, at about 1/2 a step).
      if (!(residual < 0.9 * before)) break;
    }
    if (!(residual <= settings_.projection_tolerance) || !factorize()) return false;
    coordinates_.correct_velocities();
    if (!coordinates_.solve_accelerations()) return false;
    coordinates_.read_state(projected_stage_);
    return true;
  }

  /// project(), or where its chord iterations do not converge (near a singular configuration,
  /// where the matrix changes fast with the positions), Newton's (project_stage).
  bool project_or_newton(double t, const Eigen::VectorXd& y, HeldMatrix held) {
    return project(t, y, held) || (m_ > 0 && project_stage(t, y));
  }

  static constexpr double stage_rounding_factor = 10.0;
  static constexpr int max_stage_iterations = 12;

  /// Whether the constraint Jacobian at the workspace's state nearly loses rank (pivots below
  /// settings_.singular_threshold of the largest); false for models too large for the dense
  /// check.
  bool near_singular() {
    const double m = static_cast<double>(m_), n = static_cast<double>(nv_total_);
    if (!(settings_.singular_threshold > 0.0) || m_ == 0 || m * m * n > largest_rank_check)
      return false;
    steps_since_check_ = 0;
    return !diagnosis::rank_drop(model_, ws_, coordinates_, settings_.singular_threshold).empty();
  }

  /// The derivative at the trial state (loaded and consistent), whose v' is already solved.
  void derivative_at_workspace(Eigen::VectorXd& k) {
    coordinates_.position_rate(y_trial_, k.head(nq_total_));
    k.tail(nv_total_) = coordinates_.accelerations();
  }

  /// v' and lambda at the loaded state (constraints evaluated), factorizing afresh.
  bool accelerations() { return factorize() && coordinates_.solve_accelerations(); }

  bool factorize() {
    ++statistics_.factorizations;
    return coordinates_.factorize();
  }

  /// The extra stages and the terms of the continuous extension of the last attempt, computed
  /// once per attempt and only when an output or an event asks for them.
  bool prepare_dense_output() {
    if (dense_ready_) return true;
    if constexpr (Method::extra_stages > 0)
      for (int e = 0; e < Method::extra_stages; ++e) {
        combine(stage_, y_n_, h_, Method::extra_a[e], new_point + 1 + e);
        if (!derivative(t_n_ + Method::extra_c[e] * h_, stage_, k_[new_point + 1 + e]))
          return false;
      }
    auto& step = dense_terms_[0];
    step = y_trial_ - y_n_;
    dense_terms_[1] = h_ * k_[0] - step;
    dense_terms_[2] = step - h_ * k_[new_point] - dense_terms_[1];
    for (int r = 0; r < Method::dense_rows; ++r)
      combine(dense_terms_[3 + r], h_, Method::dense[r], num_derivatives);
    dense_ready_ = true;
    return true;
  }

  /// y_dense_ = the continuous extension of the last attempt at t, in Hairer's nested form
  /// y_n + theta (r_0 + (1 - theta) (r_1 + theta (r_2 + (1 - theta) (r_3 + ...)))), r = the
  /// dense terms: a polynomial through both ends of the step with their derivatives.
  void dense_state(double t) {
    const double theta = (t - t_n_) / h_, rest = 1.0 - theta;
    y_dense_ = dense_terms_[num_dense_terms - 1];
    for (int r = num_dense_terms - 2; r >= 0; --r)
      y_dense_ = dense_terms_[r] + (r % 2 == 0 ? rest : theta) * y_dense_;
    y_dense_ = y_n_ + theta * y_dense_;
  }

  /// Moves y onto Phi = 0 and Phi_q v + Phi_t = 0, the least distance in the mass metric, and
  /// solves v' and lambda there. The workspace then holds the projected state at t.
  /// The positions take chord iterations with the matrix `held` (or factorized at y): the
  /// corrections are of the size of the local error. v' and lambda are solved with the matrix
  /// at the projected positions (factorized again after a correction).
  bool project(double t, const Eigen::VectorXd& y, HeldMatrix held) {
    coordinates_.load(t, y);
    coordinates_.evaluate_constraints();
    bool matrix_at_positions = held == HeldMatrix::at_point;
    if (held == HeldMatrix::none) {
      if (!factorize()) return false;
      matrix_at_positions = true;
    }
    for (int k = 0; m_ > 0 && !(coordinates_.position_residual() <= settings_.projection_tolerance);
         ++k) {
      if (k == settings_.max_projection_iterations) return false;
      coordinates_.correct_positions();
      ++statistics_.newton_iterations;
      matrix_at_positions = false;
    }
    if (!matrix_at_positions && !factorize()) return false;
    if (m_ > 0) coordinates_.correct_velocities();
    // v' and lambda at the projected state: the same matrix, new right-hand side.
    return coordinates_.solve_accelerations() && coordinates_.state_finite();
  }

  const Model& model_;
  Workspace<Model>& ws_;
  Settings settings_;
  StepControl control_;
  Coordinates coordinates_;
  IntegratorStatistics statistics_;
  Eigen::Index nq_total_ = 0, nv_total_ = 0, m_ = 0, size_ = 0;
  double t_n_ = 0.0, h_ = 0.0, error_ = 0.0, proposed_step_ = 1e-4;
  double previous_error_ = 1e-4;  // of the last accepted step, for PI control
  bool rejected_ = false;         // the last attempt was rejected
  Eigen::VectorXd y_n_, y_new_, stage_, vdot_n_, lambda_n_;
  Eigen::VectorXd y_stiffness_;  // the state of stiffness_stage in the last attempt
  double h_lambda_ = 0.0;
  int stiff_steps_ = 0, non_stiff_steps_ = 0;
  // Stage derivatives of the last attempt, f at its projected end, the extra dense stages.
  std::array<Eigen::VectorXd, num_derivatives> k_;
  // The last attempt's projected end state, its v' and lambda; a dense-output point.
  Eigen::VectorXd y_trial_, vdot_trial_, lambda_trial_, y_dense_;
  std::array<Eigen::VectorXd, num_dense_terms> dense_terms_;
  bool dense_ready_ = false;  // dense_terms_ (and the extra stages) belong to the last attempt
  bool project_stages_ = false;  // near a singular configuration: see project_stage
  int calm_steps_ = 0;  // accepted since the last suspicious rejection
  // Accepted steps since the last rank check (none yet: as if long ago).
  long steps_since_check_ = calm_steps_to_leave;
  Eigen::VectorXd projected_stage_;
};

}  // namespace odyn
