#pragma once
// Index-3 generalized-alpha integration on the rotation group (Arnold & Bruls 2007; Bruls,
// Cardona & Arnold 2012). One step from t_n to t_n + h solves, for v'_{n+1} and lambda_{n+1},
//   M v'_{n+1} + Phi_q^T lambda_{n+1} = Q(q_{n+1}, v_{n+1}, t_{n+1}),   Phi(q_{n+1}) = 0,
// with  q_{n+1} = q_n o exp(h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}),
//       v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1},
//       (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) v'_{n+1} + alpha_f v'_n.
// Newton runs on the scaled iteration matrix [M + gamma' C + beta' K, Phi_q^T; Phi_q, 0]
// (constraint rows divided by beta h^2 (1-alpha_f)/(1-alpha_m)), whose factorization is kept
// across iterations and steps until convergence slows down.
//
// What it steps is a template parameter (analysis/absolute_coordinates.hpp): the bodies' own
// coordinates (GeneralizedAlpha), or a spanning tree's joint coordinates with the loop
// closures as constraints (JointGeneralizedAlpha), where q, v and v' are joint coordinates,
// rates and their rates, and the Newton matrix holds the mass matrix in joint coordinates with
// each body's own spring and damper blocks, factorized by the articulated-body algorithm (the
// blocks that join two bodies and the tree's velocity terms' derivatives stay out of it there:
// a modified Newton iteration).

#include <Eigen/Core>
#include <algorithm>
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

namespace odyn {

struct GeneralizedAlphaSettings {
  /// Spectral radius at infinite frequency: 1 keeps every mode, 0 damps the highest at once.
  double rho_inf = 0.9;
  /// HHT-alpha flavour (alpha_m = 0, rho_inf in [0.5, 1]) instead of Chung-Hulbert's.
  bool hht = false;
  /// Newton stops when the velocity correction is below atol + rtol max|v| in every entry, or
  /// below the step's own accuracy if that is smaller (see newton_tolerance())...
  double newton_rtol = 1e-9;
  double newton_atol = 1e-10;
  /// ... and |Phi| is below this in every entry.
  double constraint_tolerance = 1e-11;
  int max_iterations = 8;
  /// Keep the factorization while a step needs no more than this many iterations.
  int reuse_iterations = 2;
  /// Step-size control from the local error estimate, with the tolerances of StepControl;
  /// otherwise fixed steps.
  bool adaptive = false;
  /// Largest factor by which an adaptive step may grow from one step to the next. Kept small:
  /// every change of h costs the index-3 scheme some accuracy (on the engine, 1.2 gives 3 to 8
  /// times smaller errors than 2 for the same number of steps).
  double max_growth = 1.2;
  /// The factorization of the saddle-point systems (linalg/linear_solver.hpp).
  LinearSolver linear_solver = LinearSolver::automatic;
  /// At output times, v' and lambda (and so every reaction and driver effort) solved from the
  /// index-1 equations [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] at the step's q and v,
  /// rather than the step's own. The index-3 step's lambda carries errors of its Newton
  /// iteration and of the start, which grow as h shrinks (the multipliers' part of its
  /// iteration matrix scales as 1/h^2); these follow q and v, at second order. One more
  /// factorization per output, in a slot of its own.
  bool consistent_outputs = true;
};

template <class Model, class Coordinates = AbsoluteCoordinates<Model>>
class GeneralizedAlphaMethod {
 public:
  using Settings = GeneralizedAlphaSettings;
  static constexpr bool retries_shorter_steps = true;  // a failure is Newton's (see attempt)

  GeneralizedAlphaMethod(const Model& model, Workspace<Model>& ws, Settings settings = {},
                         StepControl control = {})
      : model_(model),
        ws_(ws),
        settings_(settings),
        control_(control),
        proposed_step_(std::min(control.first_step, control.max_step)),
        coordinates_(model, ws, settings.linear_solver, settings.consistent_outputs ? 2 : 1) {
    if (settings.adaptive &&
        (!(control.rtol > 0.0) || !(control.atol > 0.0) || !(proposed_step_ > 0.0)))
      throw ModelError(settings.hht ? "hht" : "generalized-alpha",
                       "rtol, atol and the first step must be positive, got " +
                           to_text(control.rtol) + ", " + to_text(control.atol) + " and " +
                           to_text(proposed_step_));
    if (!(settings.newton_rtol > 0.0) || !(settings.newton_atol > 0.0) ||
        !(settings.constraint_tolerance > 0.0) || settings.max_iterations < 1 ||
        settings.reuse_iterations < 0)
      throw ModelError(settings.hht ? "hht" : "generalized-alpha",
                       "newton_rtol, newton_atol and constraint_tolerance must be positive, "
                       "max_iterations at least 1 and reuse_iterations at least 0; got " +
                           to_text(settings.newton_rtol) + ", " + to_text(settings.newton_atol) +
                           ", " + to_text(settings.constraint_tolerance) + ", " +
                           std::to_string(settings.max_iterations) + " and " +
                           std::to_string(settings.reuse_iterations));
    const double rho = settings.rho_inf;
    if (!(rho >= 0.0 && rho <= 1.0))
      throw ModelError("generalized-alpha", "rho_inf must lie in [0, 1], got " + to_text(rho));
    if (settings.hht) {
      if (rho < 0.5)
        throw ModelError("hht", "rho_inf must lie in [0.5, 1] for HHT-alpha, got " + to_text(rho));
      alpha_m_ = 0.0;
      alpha_f_ = (1.0 - rho) / (1.0 + rho);
    } else {
      alpha_m_ = (2.0 * rho - 1.0) / (rho + 1.0);
      alpha_f_ = rho / (rho + 1.0);
    }
    gamma_ = 0.5 + alpha_f_ - alpha_m_;
    beta_ = 0.25 * (gamma_ + 0.5) * (gamma_ + 0.5);

    nv_total_ = static_cast<int>(coordinates_.num_velocities());
    m_ = static_cast<int>(coordinates_.num_equations());
    const int n = nv_total_ + m_;
    residual_ = Eigen::VectorXd::Zero(n);
    correction_ = Eigen::VectorXd::Zero(n);
    probe_ = Eigen::VectorXd::Zero(n);
    probe_correction_ = Eigen::VectorXd::Zero(n);
    increment_ = Eigen::VectorXd::Zero(nv_total_);
    jerk_ = Eigen::VectorXd::Zero(nv_total_);
    a_step_ = Eigen::VectorXd::Zero(nv_total_);
    a_previous_ = Eigen::VectorXd::Zero(nv_total_);
    local_error_ = Eigen::VectorXd::Zero(nv_total_);
    error_scale_ = Eigen::VectorXd::Zero(nv_total_);
    // q(t + h) - q_{n+1} = c h^3 (d/dt)^3 q + O(h^4) when a_n stands for v' at
    // t_n + (alpha_m - alpha_f) h: the constant c of the position update's local error.
    error_constant_ = beta_ - 1.0 / 6.0 + 0.5 * (alpha_m_ - alpha_f_);
    initialize();
  }

  /// Starts from the workspace's state, which must be consistent (see assemble) with v' and
  /// lambda solved from it: a_0 = v'_0.
  void initialize() {
    t_n_ = ws_.t;
    q_n_ = coordinates_.positions();
    v_n_ = coordinates_.velocities();
    vdot_n_ = coordinates_.accelerations();
    a_n_ = vdot_n_;
    lambda_n_ = coordinates_.multipliers();
    vdot_previous_ = vdot_n_;
    lambda_previous_ = lambda_n_;
    restart();
  }

  /// Advances the workspace by one step of size h. Throws SolverError if Newton fails.
  void step(double h) {
    if (!attempt(h)) fail();
    commit();
  }

  /// Tries a step of size h from the last committed state; the workspace then holds the trial
  /// state with its frames; the element blocks may be one Newton iterate behind until
  /// refresh_blocks(). False if Newton failed even with a fresh matrix.
  bool attempt(double h) {
    h_ = h;
    blocks_stale_ = false;
    // a_n stands for v' at t_n + (alpha_m - alpha_f) h: shift it to this step's size (Arnold &
    // Bruls' starting value after a restart, a first-order correction after a change of h).
    if (starting_)
      a_step_ = vdot_n_ + (alpha_m_ - alpha_f_) * h * jerk_;
    else if (h != previous_step_)
      a_step_ = a_n_ + ((alpha_m_ - alpha_f_) * (h - previous_step_) / previous_step_) *
                           (a_n_ - a_previous_);
    else
      a_step_ = a_n_;
    const double t_new = t_n_ + h;
    if (h < 1e-3 * usual_step()) {
      taylor_step(t_new);
      estimate_error();
      return true;
    }
    for (int attempt = 0; attempt < 2; ++attempt) {
      const bool fresh = !factorized_;
      if (solve_step(t_new)) {
        estimate_error();
        return true;
      }
      // A stale factorization may be the cause: retry once with a fresh one.
      ++statistics_.rejected_steps;
      factorized_ = false;
      if (fresh) break;
    }
    return false;
  }

  /// Accepts the last attempt and proposes the next step size from its error.
  void accept() {
    commit();
    const double grown = h_ * step_factor(error_, 2, 0.2, settings_.max_growth);
    // A step cut short to land on an output time says nothing against the longer step.
    proposed_step_ =
        std::min(control_.max_step, h_ < proposed_step_ ? std::max(proposed_step_, grown) : grown);
  }

  /// Rejects the last attempt and proposes a shorter step; throws once it is hopelessly short.
  void reject() {
    ++statistics_.rejected_steps;
    const bool computed = std::isfinite(error_);
    proposed_step_ = h_ * (computed ? std::min(0.9, step_factor(error_, 2, 0.2, 0.9)) : 0.25);
    if (proposed_step_ < control_.min_step * std::max(1.0, std::abs(t_n_))) {
      if (!computed) fail();
      rollback();
      throw SolverError(t_n_ + h_, "the step size fell below " + to_text(control_.min_step) +
                                       " s without meeting the tolerances; loosen rtol/atol or "
                                       "look for a discontinuity that no event locates");
    }
    rollback();
  }

  /// Accepts the trial state of the last successful attempt.
  void commit() {
    // Redundant constraints never take the contraction shortcut, so the blocks are current here.
    coordinates_.make_multipliers_unique();
    statistics_.max_error_estimate = std::max(statistics_.max_error_estimate, error_);
    a_previous_ = a_step_;
    a_n_ = ((1.0 - alpha_f_) * coordinates_.accelerations() + alpha_f_ * vdot_n_ -
            alpha_m_ * a_step_) /
           (1.0 - alpha_m_);
    vdot_previous_ = vdot_n_;
    lambda_previous_ = lambda_n_;
    previous_step_ = h_;
    previous_local_error_ = local_error_.cwiseAbs().maxCoeff();
    starting_ = false;
    q_n_ = coordinates_.positions();
    v_n_ = coordinates_.velocities();
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    t_n_ = ws_.t;
    advance_states(model_, ws_);
    ++statistics_.steps;
    // A step far shorter than the usual one (one that lands on an output time just after a
    // switch of the forces, say) corrects Phi in a tiny time: the correction is an impulse of
    // order Phi / h^2 in v' and a, which the following steps would carry on and turn into
    // velocity errors (|Phi_q v| up to 0.4 in long engine runs, or a divergence). Starting
    // afresh from the committed state, as after a switch, removes it.
    const bool short_step = h_ < 0.1 * usual_step();
    reference_step_ = std::max(h_, 0.5 * reference_step_);
    if (short_step) restart();
  }

  /// Restarts after a discontinuity of the forces (and at the start of a run): v' and lambda
  /// consistent with the committed state, and the perturbed starting value of Arnold & Bruls,
  ///   a_n = v'_n + (alpha_m - alpha_f) h v''_n,
  /// which keeps the index-3 scheme free of the spurious O(h) oscillations that a_n = v'_n
  /// starts in v' and lambda. v'' comes from consistent accelerations a short time later.
  void restart() {
    consistent_accelerations();
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    // A short Taylor step along the motion, then v'' by a finite difference.
    const double delta = 1e-6 * std::max(std::abs(t_n_), 1.0) + (h_ > 0.0 ? 1e-2 * h_ : 0.0);
    increment_ = delta * v_n_ + 0.5 * delta * delta * vdot_n_;
    move_positions();
    coordinates_.velocities() = v_n_ + delta * vdot_n_;
    ws_.t = t_n_ + delta;
    consistent_accelerations();
    jerk_ = (coordinates_.accelerations() - vdot_n_) / delta;
    a_n_ = vdot_n_;
    starting_ = true;
    previous_step_ = 0.0;  // no extrapolation across the discontinuity
    ++statistics_.restarts;
    rollback();
  }

  /// Evaluates Phi, its Jacobian blocks and the forces at the workspace's state, if the last
  /// step was accepted on Newton's contraction estimate and left them one iterate behind.
  /// In joint coordinates, also fills in the workspace as an absolute-coordinate run leaves it
  /// (q, v, v', every joint's lambda; see JointCoordinates::complete_workspace).
  /// With consistent_outputs, then solves v' and lambda there from the index-1 equations (the
  /// step's own stay in the integrator: the next step starts from them).
  void refresh_blocks() {
    if (blocks_stale_) {
      coordinates_.evaluate_constraints();
      coordinates_.evaluate_forces();
      blocks_stale_ = false;
    }
    if (settings_.consistent_outputs && m_ > 0) {
      ++statistics_.factorizations;
      if (!coordinates_.factorize(IterationFactors{}, output_slot) ||
          !coordinates_.solve_accelerations(output_slot)) {
        coordinates_.accelerations() = vdot_n_;  // singular here: the step's own
        coordinates_.multipliers() = lambda_n_;
      }
    } else {
      coordinates_.make_multipliers_unique(0, true);  // the step's own: pinned ones unmoved
    }
    if constexpr (requires { coordinates_.complete_workspace(); })
      coordinates_.complete_workspace();
  }

  /// Puts the workspace back at the last committed state, its blocks and forces evaluated there
  /// (a restart leaves them at a probe a microsecond later otherwise).
  void rollback() {
    coordinates_.positions() = q_n_;
    coordinates_.velocities() = v_n_;
    coordinates_.accelerations() = vdot_n_;
    coordinates_.multipliers() = lambda_n_;
    ws_.t = t_n_;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    coordinates_.evaluate_forces();
    blocks_stale_ = false;
  }

  /// Rolls back and throws the SolverError that describes the last failed attempt.
  [[noreturn]] void fail() {
    const std::string message = failure_message();
    const double t_failed = t_n_ + h_;
    rollback();
    throw SolverError(t_failed, message);
  }

  /// Its name in integrator_names().
  std::string name() const { return settings_.hht ? "hht" : "generalized-alpha"; }
  bool adaptive() const { return settings_.adaptive; }
  double time() const { return t_n_; }
  double proposed_step() const { return proposed_step_; }
  /// Local error of the last attempt in units of the tolerance.
  double error_norm() const { return error_; }
  void count_event() { ++statistics_.events; }
  const IntegratorStatistics& statistics() const { return statistics_; }
  const Settings& settings() const { return settings_; }

 private:
  /// v' and lambda from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] at the workspace's
  /// state. Uses the iteration matrix's storage; the next step factorizes afresh.
  void consistent_accelerations() {
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    ++statistics_.factorizations;
    factorized_ = false;
    if (!coordinates_.factorize(IterationFactors{}))
      throw SolverError(ws_.t,
                        "the mass-constraint matrix is singular; check for redundant or "
                        "locked constraints");
    coordinates_.solve_accelerations();
  }

  /// The state at t_{n+1} from the current guess of v'_{n+1}, written into the workspace.
  void update_state(double t_new) {
    const double h = h_;
    const double one_minus_am = 1.0 - alpha_m_;
    // a_{n+1} stored in increment_ first, then turned into the configuration increment.
    increment_ = ((1.0 - alpha_f_) * coordinates_.accelerations() + alpha_f_ * vdot_n_ -
                  alpha_m_ * a_step_) /
                 one_minus_am;
    coordinates_.velocities() = v_n_ + h * (1.0 - gamma_) * a_step_ + h * gamma_ * increment_;
    increment_ = h * v_n_ + h * h * (0.5 - beta_) * a_step_ + h * h * beta_ * increment_;
    move_positions();
    ws_.t = t_new;
  }

  /// The step size that steps far shorter than it are measured against: the one that the
  /// error control proposes, or in fixed steps the recent steps' size. (A step that the error
  /// control shrank is not short: it is what the control asked for.)
  double usual_step() const { return settings_.adaptive ? proposed_step_ : reference_step_; }

  /// The positions = q_n moved by increment_ (translations added, rotations composed on the
  /// right).
  void move_positions() { coordinates_.integrate(q_n_, increment_, coordinates_.positions()); }

  /// A step of less than a thousandth of the usual one: the motion continued by its Taylor
  /// expansion, v' and lambda kept. Phi changes by about h |Phi_q v + Phi_t| (tens of
  /// picometres on the engine), which the next regular step corrects, where a Newton
  /// correction here would be an impulse of order Phi / h^2; commit() then restarts with v'
  /// and lambda solved at the new state.
  void taylor_step(double t_new) {
    const double h = h_;
    increment_ = h * v_n_ + (0.5 * h * h) * vdot_n_;
    move_positions();
    coordinates_.velocities() = v_n_ + h * vdot_n_;
    coordinates_.accelerations() = vdot_n_;
    coordinates_.multipliers() = lambda_n_;
    ws_.t = t_new;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    coordinates_.evaluate_forces();
  }

  /// Residual of the step equations at the workspace's state; false if it is not finite.
  bool evaluate_residual() {
    ++statistics_.residual_evaluations;
    coordinates_.update_frames();
    coordinates_.evaluate_constraints();
    coordinates_.evaluate_forces();
    coordinates_.dynamics_residual(residual_.head(nv_total_));
    residual_.tail(m_) = coordinates_.constraint_values() / position_factor();
    return all_finite(residual_);
  }

  /// Local error of the positions, c h^2 (a_{n+1} - a_n) in the bodies' tangent coordinates
  /// (Geradin & Cardona, "Flexible Multibody Dynamics", Sect. 13.6), weighted by the tolerances.
  void estimate_error() {
    local_error_ = ((1.0 - alpha_f_) * coordinates_.accelerations() + alpha_f_ * vdot_n_ -
                    alpha_m_ * a_step_) /
                       (1.0 - alpha_m_) -
                   a_step_;
    local_error_ *= error_constant_ * h_ * h_;
    coordinates_.error_scale(error_scale_);
    error_ =
        weighted_rms_norm(local_error_, error_scale_, error_scale_, control_.rtol, control_.atol);
  }

  static constexpr int output_slot = 1;  // the factorization of consistent_outputs

  /// Newton contraction per iteration above which a matrix factorized at an earlier iterate is
  /// refreshed (see solve_step).
  static constexpr double refresh_contraction = 0.05;

  /// d(q_{n+1})/d(v'_{n+1}) and d(v_{n+1})/d(v'_{n+1}).
  double position_factor() const { return beta_ * h_ * h_ * (1.0 - alpha_f_) / (1.0 - alpha_m_); }
  double velocity_factor() const { return gamma_ * h_ * (1.0 - alpha_f_) / (1.0 - alpha_m_); }

  bool factorize() {
    ++statistics_.factorizations;
    ++statistics_.jacobian_evaluations;
    factorized_ = coordinates_.factorize(
        IterationFactors{1.0, position_factor(), velocity_factor(), geometric_});
    // The geometric stiffness leaves the matrix again once it weighs too little to matter.
    if (geometric_ && coordinates_.geometric_share() < 0.01) geometric_ = false;
    return factorized_;
  }

  bool solve_step(double t_new) {
    // Predictor: v' and lambda extrapolated linearly from the last two steps.
    Eigen::VectorXd& vdot = coordinates_.accelerations();
    Eigen::VectorXd& lambda = coordinates_.multipliers();
    if (previous_step_ > 0.0) {
      const double ratio = h_ / previous_step_;
      vdot = vdot_n_ + ratio * (vdot_n_ - vdot_previous_);
      lambda = lambda_n_ + ratio * (lambda_n_ - lambda_previous_);
    } else {
      vdot = vdot_n_;
      lambda = lambda_n_;
    }
    update_state(t_new);
    // Correction sizes are measured in units of the tight tolerance; times `loose` they are in
    // units of the ordinary one.
    const NewtonTolerance newton = newton_tolerance();
    const double tolerance = newton.tight;
    const double loose = newton.tight / newton.ordinary;
    double previous_norm = 0.0, previous_phi_norm = 0.0, earlier_norm = 0.0;
    // Corrections until the ordinary tolerance was met: when rounding stops the iteration short
    // of the tight one, whether the factorization is worth keeping is judged on these alone.
    int ordinary_iterations = 0;
    bool ordinary_met = false;
    int refreshes = 0;
    factorized_at_ = -1;  // the iterate of the matrix in use: before this step
    rounding_floor_ = -1.0;
    for (int k = 0; k <= settings_.max_iterations; ++k) {
      if (!evaluate_residual()) return false;
      const double phi_norm =
          m_ == 0 ? 0.0 : coordinates_.constraint_values().cwiseAbs().maxCoeff();
      // Converged when Phi is satisfied and the last correction, or the next one as estimated
      // from the residual, is within tolerance.
      // The next correction is estimated from the residual with the mass matrix's diagonal.
      const double next_norm =
          k > 0 ? velocity_factor() * coordinates_.estimated_correction(residual_.head(nv_total_)) /
                      tolerance
                : 0.0;
      // Short of the tight tolerance, the ordinary one does when iterating no longer helps:
      // the corrections stopped shrinking (rounding), or the iterations ran out.
      const bool tight = previous_norm <= 1.0 || next_norm <= 1.0;
      const bool stalled =
          k == settings_.max_iterations || (k > 1 && previous_norm > 0.5 * earlier_norm);
      const bool phi_met = phi_norm <= settings_.constraint_tolerance;
      if (k > 0 && (tight || (stalled && previous_norm * loose <= 1.0)) && phi_met) {
        if ((tight ? k : ordinary_iterations) > settings_.reuse_iterations) factorized_ = false;
        return true;
      }
      // At a singular configuration the corrections stall above both tolerances, at the floor
      // that Phi's rounding sets (see rounding_floor): the step has converged as far as double
      // precision can tell.
      if (k > 1 && stalled && phi_met && within_rounding_floor(previous_norm, tolerance, k)) {
        ++statistics_.singular_steps;
        factorized_ = false;
        return true;
      }
      // With redundant constraints the solver decides the rank at every factorization, and a
      // singular configuration adds rows that it finds dependent for a while: their part of Phi
      // (the distance to the other branch, about sigma times the step's error) is left as it is
      // until the rank comes back. Converged corrections with Phi stalled a little above its
      // tolerance are that.
      if (k > 1 && stalled && coordinates_.rank_deficiency() > 0 &&
          (previous_norm * loose <= 1.0 || within_rounding_floor(previous_norm, tolerance, k)) &&
          phi_norm > 0.5 * previous_phi_norm &&
          phi_norm <= stalled_phi_factor * settings_.constraint_tolerance) {
        ++statistics_.singular_steps;
        factorized_ = false;
        return true;
      }
      if (k == settings_.max_iterations) return false;
      if (!factorized_) {
        if (!factorize()) return false;
        factorized_at_ = k;
      }
      coordinates_.solve(residual_, correction_);
      vdot -= correction_.head(nv_total_);
      lambda -= correction_.tail(m_);
      ++statistics_.newton_iterations;
      // Size of the velocity correction in units of the tolerance.
      const double norm =
          velocity_factor() * correction_.head(nv_total_).cwiseAbs().maxCoeff() / tolerance;
      if (!std::isfinite(norm)) return false;
      if (!ordinary_met) {
        ++ordinary_iterations;
        ordinary_met = norm * loose <= 1.0;
      }
      if (k > 0 && norm > 2.0 * previous_norm && norm * loose > 1.0 &&
          !within_rounding_floor(norm, tolerance, k + 1))
        return false;  // diverging
      update_state(t_new);
      const double rate = k > 0 ? norm / previous_norm : 0.0;
      // Newton contracts the correction by about rate = norm / previous_norm per iteration, so
      // the error left after this correction is about rate / (1 - rate) times it (Hairer &
      // Wanner, Sect. IV.8). When that is within tolerance, and Phi, extrapolated with its own
      // last contraction, is well within its tolerance, the step is accepted without the
      // residual evaluation that would only confirm it. (Phi's contraction slows down from one
      // iterate to the next by up to 7 times on the engine: hence the factor 10.) The element
      // blocks then stay those of the last iterate until refresh_blocks(), which the driver
      // calls at outputs. Redundant constraints get the confirming evaluation unless the solver
      // pinned them (see AbsoluteCoordinates::regular_corrections): minimum-norm corrections
      // do not contract as regularly.
      if (k > 0 && coordinates_.regular_corrections()) {
        const double phi_rate = m_ == 0 ? 0.0 : phi_norm / previous_phi_norm;
        if (rate < 0.5 && rate / (1.0 - rate) * norm <= 1.0 && phi_rate < 0.5 &&
            10.0 * phi_rate * phi_norm <= settings_.constraint_tolerance) {
          coordinates_.update_frames();
          blocks_stale_ = true;
          if (k + 1 > settings_.reuse_iterations) factorized_ = false;
          return true;
        }
      }
      // A slow contraction with a matrix factorized at an earlier iterate says that it no longer
      // fits: the constraint forces, whose geometric stiffness it holds, have moved a good
      // fraction (a long chain whipping round changes them by half within a step). When more
      // than two more iterations at that rate would be needed, factorize afresh at the next
      // iterate, at most twice a step.
      if (rate > refresh_contraction && rate * rate * norm > 1.0 && refreshes < 2 &&
          factorized_at_ < k) {
        factorized_ = false;
        ++refreshes;
        // From then on, the matrix holds the constraints' geometric stiffness while it weighs
        // in (see factorize): where the constraint forces are large against mass over h^2
        // Newton needs it (without, 1/10 an iteration on that chain); elsewhere it changes
        // nothing and costs some 10 % of a step.
        geometric_ = has_geometric_stiffness<Model>();
      }
      earlier_norm = previous_norm;
      previous_norm = norm;
      previous_phi_norm = phi_norm;
    }
    return false;
  }

  /// How far below the tolerance (`tolerance`, absolute) Newton's velocity corrections can fall
  /// at all: the velocity correction that a rounding-sized error of Phi alone produces through
  /// the iteration matrix, in units of the tolerance. Away from singular configurations it is
  /// about eps |q| / h, far below the tolerances. Where Phi_q's smallest singular value sigma
  /// nearly vanishes (a parallelogram's change point, any mechanism whose mobility jumps for an
  /// instant) the position along the extra mobility is fixed by Phi only to eps |q| / sigma,
  /// and the floor rises by 1/sigma above every tolerance. Measured by one solve with a
  /// right-hand side of Phi's rounding (signs that vary from row to row, so that it has a part
  /// along every direction), at most once a step.
  double rounding_floor(double tolerance, int iterate) {
    if (rounding_floor_ >= 0.0) return rounding_floor_;
    rounding_floor_ = 0.0;
    if (m_ == 0) return rounding_floor_;
    if (!factorized_) {
      if (!factorize()) return rounding_floor_;
      factorized_at_ = iterate;
    }
    const double phi_rounding = std::numeric_limits<double>::epsilon() *
                                std::max(coordinates_.largest_position(), 1.0) / position_factor();
    probe_.head(nv_total_).setZero();
    for (int i = 0; i < m_; ++i) probe_[nv_total_ + i] = rounding_probe_sign(i) * phi_rounding;
    coordinates_.solve(probe_, probe_correction_);
    rounding_floor_ =
        velocity_factor() * probe_correction_.head(nv_total_).cwiseAbs().maxCoeff() / tolerance;
    if (!std::isfinite(rounding_floor_)) rounding_floor_ = 0.0;
    return rounding_floor_;
  }

  /// A correction of this size (in units of the tolerance) is rounding noise of a nearly
  /// singular iteration matrix (see rounding_floor); only checked once the iteration stalls.
  bool within_rounding_floor(double norm, double tolerance, int iterate) {
    return norm <= rounding_floor_factor * rounding_floor(tolerance, iterate);
  }

  /// How far above constraint_tolerance Phi may stall while the rank is momentarily lower.
  static constexpr double stalled_phi_factor = 100.0;

  struct NewtonTolerance {
    double ordinary;  // atol + rtol max|v|, from the settings (or a few times the rounding)
    double tight;     // no larger: what the step's own accuracy asks for
  };

  /// Newton's tolerances on the velocity correction in this step. The settings' atol + rtol
  /// max|v| suits steps whose truncation error is far larger than it. Short steps are more
  /// accurate than that: each leaves its Newton error in the state, and the errors of many
  /// steps add up (Andrews' mechanism at h = 2.5e-7 s, 120 000 steps, lost a digit to it).
  /// The tight tolerance follows the step's local error instead: a small fraction of the last
  /// step's position error per unit time, scaled by (h / h_last)^3. Rounding may stop Newton
  /// short of it; the iteration then settles for the ordinary tolerance (see solve_step).
  NewtonTolerance newton_tolerance() const {
    const double largest_velocity = coordinates_.velocities().cwiseAbs().maxCoeff();
    // Rounding in v, and in Phi (whose terms are about as large as the bodies' positions),
    // divided by h to turn it into velocity. Far from the origin (a rope of 2 km) it exceeds
    // the settings' tolerance, which then cannot be met: the ordinary tolerance is never
    // below a few times the rounding.
    const double largest_position = coordinates_.largest_position();
    const double rounding =
        std::numeric_limits<double>::epsilon() * (largest_velocity + largest_position / h_);
    const double ordinary =
        std::max(settings_.newton_atol + settings_.newton_rtol * largest_velocity, 4.0 * rounding);
    if (!(previous_local_error_ > 0.0) || !(previous_step_ > 0.0)) return {ordinary, ordinary};
    constexpr double fraction = 1e-4;
    const double ratio = h_ / previous_step_;
    const double following = fraction * previous_local_error_ * ratio * ratio * ratio / h_;
    return {ordinary, std::min(ordinary, std::max(following, rounding))};
  }

  std::string failure_message() {
    if (!all_finite(residual_))
      return "Newton iteration produced a non-finite value; " +
             diagnosis::non_finite_force(model_, ws_) +
             " returned NaN or infinity. Check its parameters and inputs.";
    const std::string singular = diagnosis::rank_drop(model_, ws_, coordinates_);
    return "Newton iteration did not converge in " + std::to_string(settings_.max_iterations) +
           " iterations (" + diagnosis::worst_constraint(model_, ws_) +
           diagnosis::strongest_force(model_, ws_) + ")." + singular + " " +
           (settings_.adaptive
                ? std::string("Tighten rtol/atol or lower max_step, ")
                : "Reduce the step size (h = " + to_text(h_) +
                      " s) or let error control choose it (adaptive = true; in Python and on "
                      "the command line, give rtol/atol), ") +
           "check the force elements' parameters, or look for a locked or singular mechanism." +
           Coordinates::newton_advice;
  }

  const Model& model_;
  Workspace<Model>& ws_;
  Settings settings_;
  StepControl control_;
  double proposed_step_ = 0.0;
  double error_ = 0.0;           // local error of the last attempt, in units of the tolerance
  double error_constant_ = 0.0;  // of the position update's local error
  double alpha_m_ = 0.0, alpha_f_ = 0.0, gamma_ = 0.5, beta_ = 0.25;
  double h_ = 0.0;
  double t_n_ = 0.0;
  int nv_total_ = 0, m_ = 0;
  bool factorized_ = false;
  int factorized_at_ = -1;     // Newton iterate of this step at which the matrix was factorized
  bool geometric_ = false;     // the matrix holds the geometric stiffness (see solve_step)
  bool blocks_stale_ = false;  // the accepted state's blocks are one Newton iterate behind

  Eigen::VectorXd residual_;                             // (n)
  Eigen::VectorXd correction_;                           // (n)
  Eigen::VectorXd probe_, probe_correction_;             // (n) for rounding_floor
  double rounding_floor_ = -1.0;                         // this step's; < 0: not measured yet
  Eigen::VectorXd q_n_, v_n_, vdot_n_, a_n_, lambda_n_;  // state at the start of the step
  Eigen::VectorXd vdot_previous_, lambda_previous_;      // one step earlier, for the predictor
  double previous_step_ = 0.0;                           // its size; 0 after a (re)start
  double previous_local_error_ = 0.0;  // largest entry of its local position error estimate
  double reference_step_ = 0.0;        // the recent steps' size: max(h, half the last reference)
  Eigen::VectorXd jerk_;               // (nv_total) v'' at the last restart
  bool starting_ = false;              // the next step is the first after a restart
  Eigen::VectorXd increment_;          // (nv_total) configuration increment
  Eigen::VectorXd a_step_;             // (nv_total) a_n shifted to the size of the attempted step
  Eigen::VectorXd a_previous_;         // (nv_total) a_{n-1}
  Eigen::VectorXd local_error_, error_scale_;  // (nv_total)
  Coordinates coordinates_;  // what the steps move: q, v, v' and lambda live there
  IntegratorStatistics statistics_;
};

/// Generalized-alpha (and HHT) in absolute coordinates, with the saddle-point solver `Solver`.
template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
using GeneralizedAlpha = GeneralizedAlphaMethod<Model, AbsoluteCoordinates<Model, Solver>>;

/// Generalized-alpha (and HHT) in joint coordinates.
template <class Model>
using JointGeneralizedAlpha = GeneralizedAlphaMethod<Model, JointCoordinates<Model>>;

}  // namespace odyn
