#pragma once
// Variable-step, variable-order BDF (orders 1-5) on the stabilized index-2 formulation of
// Gear, Gupta & Leimkuhler, with error control on positions and velocities:
//   q' = T(q) (v + M^-1 Phi_q^T mu),   M v' + Phi_q^T lambda = Q(q, v, t),
//   Phi(q, t) = 0,                      Phi_q v + Phi_t = 0.
// T is the configuration rate (the quaternion rate of spatial bodies); the quaternion is kept
// as 4 numbers and renormalized after every step. mu vanishes on the exact solution; it moves
// q back onto Phi = 0 in the mass metric (M^-1 keeps the units of q' consistent).
//
// q and v follow the variable-coefficient BDF of order k: the derivative at t_{n+1} of the
// polynomial through y_{n+1} and the k last values, y_{n+1} = beta + c y'_{n+1}, c = h / alpha_0.
// Given u = M^-1 Phi_q^T mu, q_{n+1} = beta_q + c T(q_{n+1}) (v + u) is linear in q_{n+1} (T is
// affine in q), so it is solved exactly body by body; the unknowns of the simplified Newton
// iteration are v, lambda and u. The (v, lambda) correction solves
//   [M + c C + c^2 K, Phi_q^T; Phi_q, 0] [dv; c dlambda] = -[c R_dyn; Phi_q v + Phi_t]
// (the library's saddle-point solver; the K u coupling is left out), and the u correction is the
// least correction in the mass metric that removes the rest of Phi:
//   [M, Phi_q^T; Phi_q, 0] [du; .] = [0; -Phi / c - Phi_q dv].
// Both factorizations are kept across iterations and steps while Newton converges well and c
// stays within a band (c enters the right-hand sides, so only the stiff blocks see its change).
//
// Error estimate, step and order selection follow DASSL, against a fraction of rtol and atol
// (settings.local_error_fraction: the global error sums the local ones). The local error of
// order k is (h / (t_{n+1} - t_{n-k})) |y_{n+1} - y_pred| with y_pred the polynomial
// extrapolation of the last k+1 values (lambda and mu, of index 3 and 2, stay out of the test);
// estimates at orders k-1 and k+1 from the positions' divided differences choose the order
// (see divided_difference_terms for why not the velocities'); the step doubles at most and
// shrinks on rejection. A (re)start begins at order 1 with a step from an estimate of y'' and a
// fictitious past value y_n - h y'_n; order and step then grow every step until the first
// rejection. Output times inside a step are interpolated by the step's BDF polynomial.
// Near a singular configuration (Phi_q momentarily losing rank) rounding becomes noise above
// the local tolerance; Newton and the error test allow for the noise they measure there
// (rounding_floor, estimate_error) instead of shortening the step without end.
//
// K. E. Brenan, S. L. Campbell, L. R. Petzold, "Numerical Solution of Initial-Value Problems in
// Differential-Algebraic Equations", SIAM 1996, Ch. 3 and 5 (DASSL); C. W. Gear, B. Leimkuhler,
// G. K. Gupta, "Automatic integration of Euler-Lagrange equations with constraints", J. Comput.
// Appl. Math. 12-13 (1985) 77-90.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "odyn/analysis/absolute_coordinates.hpp"
#include "odyn/analysis/diagnosis.hpp"
#include "odyn/analysis/joint_coordinates.hpp"
#include "odyn/analysis/saddle_point.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/integrators/integrator.hpp"
#include "odyn/linalg/all_finite.hpp"
#include "odyn/linalg/pivoted_lu.hpp"

namespace odyn {

struct BdfSettings {
  int max_order = 5;  // 1 to 5
  /// The factorization of the saddle-point systems (linalg/linear_solver.hpp).
  LinearSolver linear_solver = LinearSolver::automatic;

  /// Each step's local error is held to this fraction of rtol and atol. The global error is
  /// the sum of the local ones, propagated: held to the whole tolerance it came out at up to
  /// 320 tolerances on a torque-free body; at 0.03 it stays within 10 on that body, the engine
  /// and a stiff governor from 1e-4 to 1e-10 (docs/integrators.md).
  double local_error_fraction = 0.03;
  /// Newton stops when the estimated distance to the solution, in units of the local error
  /// tolerance, is below this (DASSL takes 0.33; a corrector stopped early keeps part of the
  /// predictor's error, of one sign step after step)...
  double newton_tolerance = 0.01;
  /// ... and every entry of Phi is below this.
  double constraint_tolerance = 1e-10;
  int max_iterations = 5;
  /// A step that needs more iterations refactorizes for the next one.
  int reuse_iterations = 3;
  /// The factorization is kept while c = h / alpha_0 stays within this factor of its value.
  double reuse_band = 1.3;
  /// Largest factor by which a step may grow from one step to the next.
  double max_growth = 2.0;
};

/// BDF on a coordinates object, through the operations analysis/absolute_coordinates.hpp lists
/// (Bdf below in absolute coordinates, JointBdf in joint ones); three factorization slots hold
/// its matrices.
template <class Model, class Coordinates>
class BdfMethod {
 public:
  using Settings = BdfSettings;
  static constexpr int kMaxOrder = 5;
  static constexpr int kHistory = kMaxOrder + 2;  // past values the estimates need
  /// The fraction lowers the local rtol to this and no further: the error estimate is a
  /// difference of values of size |y| through predictor weights that add up to tens, and
  /// below about 1000 machine epsilons it measures rounding (Andrews' mechanism at rtol 1e-12
  /// failed with a local rtol of 1e-13 and passed with 2e-13).
  static constexpr double local_rtol_floor = 1000.0 * std::numeric_limits<double>::epsilon();

  BdfMethod(const Model& model, Workspace<Model>& ws, Settings settings = {},
            StepControl control = {})
      : model_(model),
        ws_(ws),
        settings_(settings),
        control_(control),
        coordinates_(model, ws, settings.linear_solver, 3),
        proposed_step_(std::min(control.first_step, control.max_step)) {
    if (!(control.rtol > 0.0) || !(control.atol > 0.0))
      throw ModelError("bdf", "rtol and atol must be positive, got " + to_text(control.rtol) +
                                  " and " + to_text(control.atol));
    if (!(proposed_step_ > 0.0))
      throw ModelError("bdf", "the first step must be positive, got " + to_text(proposed_step_));
    if (settings.max_order < 1 || settings.max_order > kMaxOrder)
      throw ModelError("bdf",
                       "max_order must lie in [1, 5], got " + std::to_string(settings.max_order));
    if (!(settings.local_error_fraction > 0.0) || !(settings.local_error_fraction <= 1.0))
      throw ModelError("bdf", "local_error_fraction must lie in (0, 1], got " +
                                  to_text(settings.local_error_fraction));
    // The local tolerance: a fraction of the user's, not below what rounding lets a step meet.
    // atol follows rtol, so that their ratio stays the user's.
    control_.rtol = std::max({settings.local_error_fraction * control.rtol,
                              std::min(control.rtol, local_rtol_floor), rtol_floor});
    control_.atol = control.atol * std::min(control_.rtol / control.rtol, 1.0);
    rounding_ = 10.0 * std::numeric_limits<double>::epsilon() / control_.rtol;
    if (!(settings.newton_tolerance > 0.0) || !(settings.constraint_tolerance > 0.0) ||
        settings.max_iterations < 1 || !(settings.reuse_band >= 1.0) ||
        !(settings.max_growth > 1.0))
      throw ModelError("bdf",
                       "newton_tolerance and constraint_tolerance must be positive, "
                       "max_iterations at least 1, reuse_band at least 1 and max_growth above 1");
    nq_total_ = coordinates_.num_positions();
    nv_total_ = coordinates_.num_velocities();
    m_ = coordinates_.num_equations();
    ny_ = nq_total_ + nv_total_;
    const Eigen::Index size = ny_ + m_;  // history values carry lambda for the predictor
    for (auto& y : history_) y = Eigen::VectorXd::Zero(size);
    for (auto& w : differences_) w = Eigen::VectorXd::Zero(nq_total_);
    predicted_ = Eigen::VectorXd::Zero(size);
    beta_ = Eigen::VectorXd::Zero(ny_);
    y_new_ = Eigen::VectorXd::Zero(size);
    scratch_ = Eigen::VectorXd::Zero(ny_);
    derivative_ = Eigen::VectorXd::Zero(ny_);
    u_ = Eigen::VectorXd::Zero(nv_total_);
    w_ = Eigen::VectorXd::Zero(nv_total_);
    error_scale_ = Eigen::VectorXd::Zero(nv_total_);
    dv_ = Eigen::VectorXd::Zero(nv_total_);
    du_ = Eigen::VectorXd::Zero(nv_total_);
    vdot_probe_ = Eigen::VectorXd::Zero(nv_total_);
    rhs_ = Eigen::VectorXd::Zero(nv_total_ + m_);
    solution_ = rhs_;
    probe_ = rhs_;  // its velocity part stays zero
    velocity_residual_ = Eigen::VectorXd::Zero(m_);
    q_n_ = coordinates_.positions();
    v_n_ = coordinates_.velocities();
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    q_trial_ = q_n_;
    v_trial_ = v_n_;
    vdot_trial_ = vdot_n_;
    lambda_trial_ = lambda_n_;
    initialize();
  }

  /// Takes the workspace's state as the committed one and starts afresh at order 1.
  void initialize() {
    t_n_ = ws_.t;
    q_n_ = coordinates_.positions();
    v_n_ = coordinates_.velocities();
    restart();
  }

  /// Tries a step of size h from the committed state (which it leaves untouched). The
  /// workspace then holds the trial state with its v' and lambda. False if Newton failed.
  bool attempt(double h) {
    h_ = h;
    newton_failed_ = true;
    stalled_step_ = noisy_step_ = false;
    error_ = std::numeric_limits<double>::infinity();
    coefficients(h);
    for (int tries = 0; tries < 2; ++tries) {
      const bool fresh =
          !factorized_ || std::abs(std::log(c_ / c_factorized_)) > std::log(settings_.reuse_band);
      if (fresh) factorized_ = false;
      if (solve_step(t_n_ + h)) {
        newton_failed_ = false;
        estimate_error();
        q_trial_ = coordinates_.positions();
        v_trial_ = coordinates_.velocities();
        vdot_trial_ = coordinates_.accelerations();
        lambda_trial_ = coordinates_.multipliers();
        return std::isfinite(error_);
      }
      factorized_ = false;  // a stale matrix may be the cause: once more with a fresh one
      if (fresh) break;
    }
    return false;
  }

  /// Local error of the last attempt in units of the tolerance (accept when <= 1).
  double error_norm() const { return error_; }

  /// The state at t within the last attempted step from the BDF polynomial of its order
  /// (through the trial value and the k last ones), projected onto the constraints, with v'
  /// and lambda there (a solver of its own, so the step's factorizations stay as they are).
  bool interpolate(double t) {
    interpolate_frames(t);
    if (!coordinates_.factorize(IterationFactors{}, output)) return false;
    ++statistics_.factorizations;
    if (m_ > 0) {
      // One correction of Phi in the mass metric, then of Phi_q v + Phi_t: the interpolant is
      // off the constraints by the local error only.
      coordinates_.correct_positions(output);
      coordinates_.correct_velocities(output);
    }
    return coordinates_.solve_accelerations(output) && coordinates_.state_finite();
  }

  /// Positions and velocities at t from the last attempt's polynomial, and the frames.
  void interpolate_frames(double t) {
    const int k = order_;
    std::array<double, kHistory + 1> tau{};
    tau[0] = t_n_ + h_;
    for (int j = 1; j <= k; ++j) tau[j] = times_[j - 1];
    scratch_.setZero();
    for (int j = 0; j <= k; ++j) {
      double weight = 1.0;
      for (int i = 0; i <= k; ++i)
        if (i != j) weight *= (t - tau[i]) / (tau[j] - tau[i]);
      if (j == 0) {
        scratch_.head(nq_total_) += weight * q_trial_;
        scratch_.tail(nv_total_) += weight * v_trial_;
      } else {
        scratch_ += weight * history_[j - 1].head(ny_);
      }
    }
    coordinates_.load(t, scratch_);
    coordinates_.evaluate_constraints();
  }

  /// Before an output: in joint coordinates, fills in the workspace as an absolute-coordinate
  /// run leaves it (see JointCoordinates::complete_workspace); in absolute ones, makes the
  /// multipliers of redundant equations minimum-norm (the steps' corrections leave those of
  /// pinned equations where they were; see AbsoluteCoordinates::make_multipliers_unique).
  void refresh_blocks() {
    if constexpr (requires(Coordinates& c) { c.complete_workspace(); })
      coordinates_.complete_workspace();
    else
      coordinates_.make_multipliers_unique(newton, true);
  }

  /// Puts the last attempt's trial state back into the workspace (after interpolate()).
  void restore_trial() {
    ws_.t = t_n_ + h_;
    coordinates_.positions() = q_trial_;
    coordinates_.velocities() = v_trial_;
    coordinates_.accelerations() = vdot_trial_;
    coordinates_.multipliers() = lambda_trial_;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    coordinates_.evaluate_forces();
  }

  /// Commits the last attempt and chooses the next order and step (Brenan et al., Sect. 5.2).
  void accept() {
    commit();
    failures_ = 0;
    const int k = order_;
    // Terms ~ |h^(j+1) q^(j+1)| from the positions' divided differences through the new value,
    // scaled so that order k's is (k + 1) times the error estimate.
    double term_lower = std::numeric_limits<double>::infinity();
    double term_higher = std::numeric_limits<double>::infinity();
    const bool can_raise = k < settings_.max_order && count_ >= k + 3;
    divided_difference_terms(k, can_raise, term_lower, term_higher);
    const double term = (k + 1) * error_;
    if (std::isfinite(term_lower)) term_lower *= term;
    if (std::isfinite(term_higher)) term_higher *= term;
    int new_order = k;
    double estimate = error_;
    if (k > 1 && term_lower <= term && term_lower <= term_higher) {
      new_order = k - 1;
      estimate = term_lower / k;
    } else if (starting_ && k < settings_.max_order) {
      new_order = k + 1;  // starting phase: raise until the first rejection
    } else if (can_raise && steps_at_order_ >= k + 1 && term_higher < term) {
      new_order = k + 1;
      estimate = term_higher / (k + 2);
    }
    if (new_order == k - 1 || (starting_ && new_order == k)) starting_ = false;
    if (hold_ > 0) --hold_;
    double factor = std::pow(2.0 * estimate + 1e-4, -1.0 / (new_order + 1));
    if (starting_ && factor >= 1.0) factor = settings_.max_growth;
    // Keep h (and the factorization) unless the error allows doubling or asks for less.
    if (factor >= settings_.max_growth)
      factor = hold_ > 0 ? 1.0 : settings_.max_growth;
    else if (factor <= 1.0)
      factor = noisy_step_ ? 1.0 : std::clamp(factor, 0.5, 0.9);  // noise asks for no shorter h
    else
      factor = 1.0;
    if (new_order != k) steps_at_order_ = 0;
    order_ = new_order;
    const double grown = h_ * factor;
    // A step cut short to land on an output time says nothing against the longer step.
    proposed_step_ =
        std::min(control_.max_step, h_ < proposed_step_ ? std::max(proposed_step_, grown) : grown);
  }

  /// Rejects the last attempt: a shorter step, and a lower order after repeated failures.
  /// Throws once the step is hopelessly short.
  void reject() {
    ++statistics_.rejected_steps;
    ++failures_;
    starting_ = false;
    double factor = 0.25;
    if (!newton_failed_ && failures_ == 1)
      factor = std::clamp(0.9 * std::pow(2.0 * error_ + 1e-4, -1.0 / (order_ + 1)), 0.25, 0.9);
    else if (failures_ == 2)
      order_ = std::max(1, order_ - 1);
    else if (failures_ > 2)
      order_ = 1;
    if (failures_ >= 2) steps_at_order_ = 0;
    // Newton failed amid the noise of a singular configuration: a shorter step would end nearer
    // it, with more noise; a longer one ends beyond it, where Phi_q has its rank back. Once.
    if (newton_failed_ && failures_ == 1 && noise_above_tolerance(rounding_floor_)) factor = 2.0;
    // No growth for a few steps after a rejection, or h would bounce between the two sizes.
    hold_ = order_ + 1;
    proposed_step_ = std::min(control_.max_step, h_ * factor);
    if (proposed_step_ < control_.min_step * std::max(1.0, std::abs(t_n_))) {
      if (newton_failed_) fail();
      const double t_failed = t_n_ + h_;
      rollback();
      throw SolverError(t_failed, "bdf: the step size fell below " + to_text(control_.min_step) +
                                      " s without meeting the tolerances (order " +
                                      std::to_string(order_) + ", error " + to_text(error_) +
                                      " times the tolerance); loosen rtol/atol or look for a "
                                      "discontinuity that no event locates");
    }
    rollback();
  }

  /// Makes the trial state of the last attempt the committed one (no step-size change).
  void commit() {
    coordinates_.make_multipliers_unique(newton);
    statistics_.max_error_estimate = std::max(statistics_.max_error_estimate, error_);
    if (stalled_step_ || noisy_step_) ++statistics_.singular_steps;
    y_new_ << coordinates_.positions(), coordinates_.velocities(), coordinates_.multipliers();
    push(y_new_, ws_.t);
    t_n_ = ws_.t;
    q_n_ = coordinates_.positions();
    v_n_ = coordinates_.velocities();
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    advance_states(model_, ws_);
    ++statistics_.steps;
    ++steps_at_order_;
  }

  /// After a switch of a force law (and at the start): v' and lambda afresh at the committed
  /// state, the history reduced to it and its derivative, order 1 and a step that suits it.
  void restart() {
    coordinates_.positions() = q_n_;
    coordinates_.velocities() = v_n_;
    consistent_accelerations(t_n_);
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    rates(vdot_n_, derivative_);
    // y'' by a finite difference along the motion, for the first step: order 1 leaves an error
    // of about h^2 |y''| / 2 (DASSL's estimate); aim at a quarter of the tolerance.
    const double delta = 1e-7 * std::max(1.0, std::abs(t_n_));
    w_ = delta * v_n_;
    coordinates_.integrate(q_n_, w_, coordinates_.positions());
    coordinates_.velocities() = v_n_ + delta * vdot_n_;
    consistent_accelerations(t_n_ + delta);
    vdot_probe_ = coordinates_.accelerations();
    rates(vdot_probe_, scratch_);
    scratch_ = (scratch_ - derivative_) / delta;
    y_new_ << q_n_, v_n_, lambda_n_;
    const double curvature = weighted_rms_norm(scratch_, y_new_.head(ny_), y_new_.head(ny_),
                                               control_.rtol, control_.atol);
    double h0 = curvature > 0.0 ? std::sqrt(0.5 / curvature) : proposed_step_;
    if (statistics_.restarts == 0) h0 = std::min(h0, control_.first_step);
    h0 = std::min(h0, control_.max_step);
    proposed_step_ = h0;
    // The history: the committed value, and a fictitious one a step back along y'.
    history_[0] = y_new_;
    times_[0] = t_n_;
    history_[1] = y_new_;
    history_[1].head(ny_) -= h0 * derivative_;
    times_[1] = t_n_ - h0;
    count_ = 2;
    order_ = 1;
    steps_at_order_ = 0;
    failures_ = 0;
    hold_ = 0;
    starting_ = true;
    factorized_ = false;
    ++statistics_.restarts;
    rollback();
  }

  /// Puts the workspace back at the last committed state.
  void rollback() {
    ws_.t = t_n_;
    coordinates_.positions() = q_n_;
    coordinates_.velocities() = v_n_;
    coordinates_.accelerations() = vdot_n_;
    coordinates_.multipliers() = lambda_n_;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
  }

  /// Rolls back and throws the SolverError that explains the last failed attempt.
  [[noreturn]] void fail() {
    const std::string message = failure_message();
    const double t_failed = t_n_ + h_;
    rollback();
    throw SolverError(t_failed, message);
  }

  /// Its name in integrator_names().
  static std::string name() { return "bdf"; }
  bool adaptive() const { return true; }
  double time() const { return t_n_; }
  double proposed_step() const { return proposed_step_; }
  int order() const { return order_; }
  void count_event() { ++statistics_.events; }
  const IntegratorStatistics& statistics() const { return statistics_; }
  const Settings& settings() const { return settings_; }

 private:
  /// Adds a committed value to the history (the oldest drops out; swaps allocate nothing).
  void push(const Eigen::VectorXd& y, double t) {
    for (int i = kHistory - 1; i > 0; --i) {
      history_[i].swap(history_[i - 1]);
      times_[i] = times_[i - 1];
    }
    history_[0] = y;
    times_[0] = t;
    count_ = std::min(count_ + 1, kHistory);
  }

  /// (q', v') at the coordinates' positions and velocities, for these v'.
  void rates(const Eigen::VectorXd& vdot, Eigen::VectorXd& out) const {
    coordinates_.position_rate(coordinates_.positions(), out.head(nq_total_));
    out.tail(nv_total_) = vdot;
  }

  /// v' and lambda from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] at the coordinates'
  /// positions and velocities and t.
  void consistent_accelerations(double t) {
    ws_.t = t;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    ++statistics_.residual_evaluations;
    ++statistics_.factorizations;
    factorized_ = false;  // the projector's factorization is reused here
    if (!coordinates_.factorize(IterationFactors{}, projection))
      throw SolverError(t,
                        "bdf: the mass-constraint matrix is singular; check for redundant or "
                        "locked constraints");
    coordinates_.solve_accelerations(projection);
  }

  /// Predictor weights (extrapolation through the last k+1 values) and the corrector
  /// y_{n+1} = beta + c y'_{n+1} of order k for a step h; also the predicted values.
  void coefficients(double h) {
    const int k = order_;
    const double t_new = t_n_ + h;
    // Corrector: derivative at t_new of the Lagrange basis through t_new, t_n, ..., t_{n+1-k}.
    std::array<double, kHistory + 1> tau{};
    tau[0] = t_new;
    for (int j = 1; j <= k + 1; ++j) tau[j] = times_[j - 1];
    double lead = 0.0;
    for (int i = 1; i <= k; ++i) lead += 1.0 / (t_new - tau[i]);
    c_ = 1.0 / lead;
    beta_.setZero();
    for (int j = 1; j <= k; ++j) {
      double numerator = 1.0, denominator = 1.0;
      for (int i = 0; i <= k; ++i) {
        if (i == j) continue;
        if (i != 0) numerator *= t_new - tau[i];
        denominator *= tau[j] - tau[i];
      }
      beta_.noalias() -= (c_ * numerator / denominator) * history_[j - 1].head(ny_);
    }
    // Predictor: the polynomial through t_n, ..., t_{n-k}, at t_new.
    predicted_.setZero();
    for (int j = 1; j <= k + 1; ++j) {
      double weight = 1.0;
      for (int i = 1; i <= k + 1; ++i)
        if (i != j) weight *= (t_new - tau[i]) / (tau[j] - tau[i]);
      predicted_.noalias() += weight * history_[j - 1];
    }
  }

  /// q_{n+1} from q = beta_q + c T(q) (v + u), body by body (T is affine in q), normalized; v'
  /// from the BDF formula; then frames, blocks and forces at the trial state.
  void set_state(double t_new) {
    w_ = coordinates_.velocities() + u_;
    coordinates_.implicit_positions(beta_.head(nq_total_), c_, w_);
    coordinates_.accelerations() = (coordinates_.velocities() - beta_.tail(nv_total_)) / c_;
    ws_.t = t_new;
    ++statistics_.residual_evaluations;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    coordinates_.evaluate_forces();
  }

  /// Newton's right-hand side at the workspace's state: -[c (M v' - Q + Phi_q^T lambda);
  /// Phi_q v + Phi_t]. False if it is not finite.
  bool residuals() {
    auto dynamics = rhs_.head(nv_total_);
    coordinates_.dynamics_residual(dynamics);
    dynamics *= -c_;
    if (m_ > 0) velocity_residual_ = coordinates_.velocity_constraint_values();
    rhs_.tail(m_) = -velocity_residual_;
    return all_finite(rhs_) && all_finite(coordinates_.constraint_values());
  }

  bool factorize() {
    ++statistics_.jacobian_evaluations;
    statistics_.factorizations += m_ > 0 ? 2 : 1;
    factorized_ = coordinates_.factorize(IterationFactors{1.0, c_ * c_, c_}, newton) &&
                  (m_ == 0 || coordinates_.factorize(IterationFactors{}, projection));
    c_factorized_ = c_;
    rate_factor_ = 100.0;  // no convergence rate known for a new matrix (DASSL's S)
    return factorized_;
  }

  /// Weighted RMS size of a correction (c (dv + du) in the tangent coordinates of q, and dv),
  /// in units of the tolerance.
  double correction_norm(const Eigen::VectorXd& dv_step, const Eigen::VectorXd& du_step) {
    coordinates_.error_scale(error_scale_);
    const Eigen::VectorXd& v = coordinates_.velocities();
    double sum = 0.0;
    for (Eigen::Index j = 0; j < nv_total_; ++j) {
      const double dq =
          c_ * (dv_step[j] + du_step[j]) / (control_.atol + control_.rtol * error_scale_[j]);
      const double dv = dv_step[j] / (control_.atol + control_.rtol * std::abs(v[j]));
      sum += dq * dq + dv * dv;
    }
    return nv_total_ > 0 ? std::sqrt(sum / static_cast<double>(2 * nv_total_)) : 0.0;
  }

  /// Simplified Newton from the predicted values; the workspace holds the result.
  bool solve_step(double t_new) {
    coordinates_.velocities() = predicted_.segment(nq_total_, nv_total_);
    coordinates_.multipliers() = predicted_.tail(m_);
    u_.setZero();
    set_state(t_new);
    if (!residuals()) return false;
    if (!factorized_ && !factorize()) return false;
    double first_norm = 0.0, last_norm = 0.0;
    rounding_floor_ = -1.0;
    for (int k = 0; k < settings_.max_iterations; ++k) {
      const double residual_before = m_ > 0 ? velocity_residual_.cwiseAbs().maxCoeff() : 0.0;
      coordinates_.solve(rhs_, solution_, newton);
      dv_ = solution_.head(nv_total_);
      coordinates_.multipliers() += solution_.tail(m_) / c_;
      if (m_ > 0) {
        // Phi_q dv = -(Phi_q v + Phi_t) holds for the matrix's Phi_q, so the rest of Phi is
        // -Phi / c + (Phi_q v + Phi_t).
        rhs_.head(nv_total_).setZero();
        rhs_.tail(m_) = -coordinates_.constraint_values() / c_ + velocity_residual_;
        coordinates_.solve(rhs_, solution_, projection);
        du_ = solution_.head(nv_total_);
      } else {
        du_.setZero();
      }
      ++statistics_.newton_iterations;
      const double norm = correction_norm(dv_, du_);
      coordinates_.velocities() += dv_;
      u_ += du_;
      set_state(t_new);
      if (!residuals() || !std::isfinite(norm)) return false;
      // Converged when the estimated distance to the solution, rate / (1 - rate) times the
      // last correction, is small (Brenan et al., Sect. 5.2.2); the rate from this step's
      // iterations, or the last one's while the matrix is the same.
      // A correction at the level of rounding says nothing about the rate; near rtol's floor
      // that level is what Newton can reach.
      const bool negligible = norm <= std::max(1e-3 * settings_.newton_tolerance, rounding_);
      // Corrections that stopped shrinking at the noise a nearly singular matrix makes of
      // rounding (a singular configuration draws near) are as converged as they can be.
      const bool stalled = k > 0 && !negligible && norm > 0.5 * last_norm &&
                           norm <= rounding_floor_factor * rounding_floor();
      last_norm = norm;
      if (k == 0) {
        first_norm = norm;
      } else if (!negligible && !stalled) {
        const double rate = first_norm > 0.0 ? std::pow(norm / first_norm, 1.0 / k) : 0.0;
        if (rate > 0.9) return false;
        rate_factor_ = rate / (1.0 - rate);
      }
      const bool small = negligible || stalled ||
                         rate_factor_ * norm <= std::max(settings_.newton_tolerance, rounding_);
      // The rate may be the last step's; the velocity constraints, linear in v but for the
      // positions' change, must have contracted with it. Near a singular configuration they
      // did not (the corrections grow as 1/sigma): an iteration more measures the rate anew.
      const bool contracted =
          m_ == 0 || negligible || stalled ||
          velocity_residual_.cwiseAbs().maxCoeff() <=
              std::max(0.5 * residual_before, residual_rounding * velocity_rounding());
      if (small && contracted &&
          (m_ == 0 || coordinates_.constraint_values().cwiseAbs().maxCoeff() <=
                          settings_.constraint_tolerance)) {
        stalled_step_ = stalled;
        if (k + 1 > settings_.reuse_iterations || stalled) factorized_ = false;
        return true;
      }
    }
    return false;
  }

  /// How small Newton's corrections can get at all, in units of the tolerance: the correction
  /// that rounding-sized errors of Phi (eps |q|) and of Phi_q v + Phi_t (eps |q| |v|) produce
  /// through the two factorized matrices. Far below 1 away from singular configurations; near
  /// one, where Phi_q's smallest singular value sigma nearly vanishes, it grows as 1/sigma (see
  /// GeneralizedAlphaMethod::rounding_floor). One probe solve each, at most once a step.
  double rounding_floor() {
    if (rounding_floor_ >= 0.0) return rounding_floor_;
    rounding_floor_ = 0.0;
    if (m_ == 0) return rounding_floor_;
    // Phi's terms are about as large as the positions (see velocity_rounding for Phi_q v's).
    const double position_rounding =
        std::numeric_limits<double>::epsilon() * std::max(coordinates_.largest_position(), 1.0);
    // The residuals a correction leaves count as rounding while within a thousand times that:
    // a solve through a nearly singular Schur complement leaves more (on the chain of
    // parallelograms, Phi_q v + Phi_t stayed at 1e-13, 20 times eps |q| |v|).
    const auto noise = [](double residual, double rounding) {
      return std::max(rounding, std::min(residual, residual_rounding * rounding));
    };
    const double position_noise =
        noise(coordinates_.constraint_values().cwiseAbs().maxCoeff(), position_rounding);
    const double velocity_noise =
        noise(velocity_residual_.cwiseAbs().maxCoeff(), velocity_rounding());
    // solution_ is free here (the next iteration overwrites it); rhs_ is not.
    for (Eigen::Index i = 0; i < m_; ++i)
      probe_[nv_total_ + i] = rounding_probe_sign(i) * velocity_noise;
    coordinates_.solve(probe_, solution_, newton);
    w_ = solution_.head(nv_total_);
    for (Eigen::Index i = 0; i < m_; ++i)
      probe_[nv_total_ + i] = rounding_probe_sign(i) * position_noise / c_;
    coordinates_.solve(probe_, solution_, projection);
    vdot_probe_ = solution_.head(nv_total_);
    rounding_floor_ = correction_norm(w_, vdot_probe_);
    if (!std::isfinite(rounding_floor_)) rounding_floor_ = 0.0;
    return rounding_floor_;
  }

  /// Rounding of Phi_q v + Phi_t: eps times the velocities times the lever arms, which the
  /// positions bound.
  double velocity_rounding() const {
    return std::numeric_limits<double>::epsilon() * std::max(coordinates_.largest_position(), 1.0) *
           std::max(coordinates_.velocities().cwiseAbs().maxCoeff(), 1.0);
  }

  /// Residuals up to this multiple of their rounding may be rounding too (see rounding_floor).
  static constexpr double residual_rounding = 1e3;

  /// Near a singular configuration, an error estimate up to this multiple of the rounding floor
  /// may be noise: |y_{n+1} - y_pred| carries the floor of y_{n+1} and of the k + 1 past values
  /// through the predictor's weights (their absolute sum is up to 2^(k+1) - 1), times
  /// h / (t_{n+1} - t_{n-k}), about 1 / (k + 1): up to 11 floors at order 5.
  static constexpr double noise_allowance = 30.0;

  /// Whether the noise of a rounding floor passes the local tolerance. Not for a local
  /// tolerance at its own floor (local_rtol_floor): there rounding is near the tolerance
  /// everywhere, singular or not, and allowing for it cost Andrews' mechanism at 1e-12 a
  /// factor 13 in accuracy.
  bool noise_above_tolerance(double floor) const {
    return control_.rtol > local_rtol_floor && noise_allowance * floor > 1.0;
  }

  /// The ratio to the largest pivot below which a failure at the noise floor names rank loss.
  /// The chain of parallelograms at rtol 1e-10 (local rtol 3e-12) fails with pivots within
  /// 3e-3 of the largest, 3 ms before its singular configuration.
  static constexpr double noisy_rank_loss = 1e-2;

  /// (h / (t_{n+1} - t_{n-k})) |y_{n+1} - y_pred| in units of the tolerance.
  void estimate_error() {
    const int k = order_;
    scratch_.head(nq_total_) = coordinates_.positions() - predicted_.head(nq_total_);
    scratch_.tail(nv_total_) = coordinates_.velocities() - predicted_.segment(nq_total_, nv_total_);
    y_new_ << coordinates_.positions(), coordinates_.velocities(), coordinates_.multipliers();
    const double span = ws_.t - times_[k];
    error_ = (h_ / span) * weighted_rms_norm(scratch_, predicted_.head(ny_), y_new_.head(ny_),
                                             control_.rtol, control_.atol);
    // Near a singular configuration the positions along the momentary extra mobility are fixed
    // by Phi only to eps |q| / sigma, and rounding alone moves every value by the rounding
    // floor: the tolerance is raised to that noise for this step (as a tolerance below double
    // precision is raised to its floor), and the step is not shortened for it: the floor grows
    // as c shrinks (Phi's rounding / c), and so would the noise. The floor is measured when the
    // error fails the test, or known already (Newton's corrections stopped shrinking).
    noisy_step_ = false;
    if (m_ > 0 && (error_ > 1.0 || rounding_floor_ >= 0.0) &&
        noise_above_tolerance(rounding_floor())) {
      error_ /= noise_allowance * rounding_floor_;
      noisy_step_ = true;
    }
  }

  /// After commit: the terms DASSL compares to choose the order, |h^(j+1) (j+1)! [q_{n+1}, ...,
  /// q_{n-j}]| for j = k-1 (if k > 1) and k+1 (if asked), each divided by order k's. Positions
  /// alone: where a stiff force holds a motion quasi-static, its velocities are in effect the
  /// BDF derivative of its positions, whose error (of order h^k) jumps with every change of
  /// step or order; their differences measure those jumps, not the solution's smoothness, and
  /// kept a stiff spring at orders 1 and 2 (995 steps at tol 1e-7; positions alone take 56).
  void divided_difference_terms(int k, bool higher, double& lower, double& upper) {
    const int last = std::min(higher ? k + 2 : k + 1, count_ - 1);  // highest difference needed
    if (last < k + 1) return;  // too short a history to compare
    for (int i = 0; i <= last; ++i) differences_[i] = history_[i].head(nq_total_);
    double factorial = 1.0, power = 1.0, same = 0.0;
    for (int l = 1; l <= last; ++l) {
      for (int i = 0; i + l <= last; ++i)
        differences_[i] = (differences_[i] - differences_[i + 1]) / (times_[i] - times_[i + l]);
      factorial *= l;
      power *= h_;
      const double term =
          factorial * power *
          weighted_rms_norm(differences_[0], history_[0].head(nq_total_),
                            history_[0].head(nq_total_), control_.rtol, control_.atol);
      if (l == k && k > 1) lower = term;  // difference of order k: the order k-1 term
      if (l == k + 1) same = term;
      if (l == k + 2 && higher) upper = term;
    }
    // Positions that did not move say nothing: keep the order.
    if (!(same > 0.0)) {
      lower = upper = std::numeric_limits<double>::infinity();
      return;
    }
    lower /= same;
    upper /= same;
  }

  std::string failure_message() {
    if (!all_finite(rhs_) || !all_finite(ws_.force))
      return "bdf: Newton iteration produced a non-finite value; " +
             diagnosis::non_finite_force(model_, ws_) +
             " returned NaN or infinity. Check its parameters and inputs.";
    // Newton's corrections stalled at the noise that rounding makes through a nearly singular
    // matrix, a hundredth of the tolerance or more (see rounding_floor): the Jacobian is closer
    // to rank loss than its pivots show at the usual threshold, and rank loss is the cause.
    const bool noisy = rounding_floor_ >= 0.01;
    const std::string singular = diagnosis::rank_drop(
        model_, ws_, coordinates_, noisy ? noisy_rank_loss : diagnosis::near_rank_loss);
    const std::string head =
        "bdf: Newton iteration did not converge in " + std::to_string(settings_.max_iterations) +
        " iterations at order " + std::to_string(order_) + ", step " + to_text(h_) + " s (" +
        diagnosis::worst_constraint(model_, ws_) + diagnosis::strongest_force(model_, ws_) + ").";
    if (!singular.empty())
      return head + singular +
             " bdf's iteration does not pass such configurations yet; generalized-alpha "
             "(integrator 'generalized-alpha') steps through them.";
    return head +
           " Check the force elements' parameters, or look for a locked or singular mechanism.";
  }

  // The coordinates' factorization slots.
  static constexpr int newton = 0;      // [M + c C + c^2 K, Phi_q^T; Phi_q, 0]
  static constexpr int projection = 1;  // [M, Phi_q^T; Phi_q, 0]
  static constexpr int output = 2;      // the same matrix at interpolated output points

  const Model& model_;
  Workspace<Model>& ws_;
  Settings settings_;
  StepControl control_;
  Coordinates coordinates_;  // what the steps move: q, v, v' and lambda live there
  IntegratorStatistics statistics_;
  Eigen::Index nq_total_ = 0, nv_total_ = 0, m_ = 0, ny_ = 0;
  double t_n_ = 0.0, h_ = 0.0, c_ = 1.0, c_factorized_ = 1.0;
  double error_ = 0.0, proposed_step_ = 1e-4, rate_factor_ = 100.0;
  double rounding_ = 0.0;  // a correction's rounding, in units of the local tolerance
  double rounding_floor_ = -1.0;  // this step's, once measured (see rounding_floor)
  int order_ = 1, count_ = 0, steps_at_order_ = 0, failures_ = 0, hold_ = 0;
  bool factorized_ = false, newton_failed_ = false, starting_ = true;
  bool stalled_step_ = false, noisy_step_ = false;  // the last attempt ended at the noise floor

  std::array<Eigen::VectorXd, kHistory> history_;  // (q, v, lambda) at times_, newest first
  std::array<double, kHistory> times_{};
  std::array<Eigen::VectorXd, kHistory> differences_;  // q's divided differences
  Eigen::VectorXd predicted_, beta_, y_new_, scratch_, derivative_, vdot_probe_;
  Eigen::VectorXd u_, dv_, du_;  // u = M^-1 Phi_q^T mu and the corrections
  Eigen::VectorXd w_;            // (scratch) v + u, or a probe's increment
  Eigen::VectorXd error_scale_;  // (scratch) see Coordinates::error_scale
  Eigen::VectorXd rhs_, solution_, velocity_residual_;
  Eigen::VectorXd probe_;  // rounding_floor's right-hand side
  Eigen::VectorXd q_n_, v_n_, vdot_n_, lambda_n_;
  Eigen::VectorXd q_trial_, v_trial_, vdot_trial_, lambda_trial_;  // the last attempt's end
};

/// BDF in absolute coordinates, with the given saddle-point solver.
template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
using Bdf = BdfMethod<Model, AbsoluteCoordinates<Model, Solver>>;

/// BDF in joint coordinates (analysis/joint_coordinates.hpp).
template <class Model>
using JointBdf = BdfMethod<Model, JointCoordinates<Model>>;

}  // namespace odyn
