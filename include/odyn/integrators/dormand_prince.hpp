#pragma once
// Explicit Dormand-Prince 5(4) with step-size control, on the index-1 form of the equations of
// motion, with the state projected back onto the constraints after every step.
//
// The state y = (q, v) follows q' = rate(q, v) (the quaternion as 4 numbers, renormalized) and
// v' from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] at every stage. Index 1 lets the
// positions and velocities drift off Phi = 0 and Phi_q v + Phi_t = 0 by the local error; after
// each step both are projected back in the mass metric (the nearest consistent state), which
// keeps the order and stops the drift. Seven solves of the saddle-point system per step, no
// Newton iteration on the dynamics: cheap per step when the problem is not stiff.
//
// Coefficients: J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta formulae",
// J. Comput. Appl. Math. 6 (1980); the error estimate and step control as in Hairer, Norsett &
// Wanner, "Solving Ordinary Differential Equations I", Sect. II.4.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/integrators/integrator.hpp"
#include "odyn/linalg/saddle_point.hpp"

namespace odyn {

struct DormandPrinceSettings {
  /// Positions are projected until every entry of Phi is below this.
  double projection_tolerance = 1e-12;
  int max_projection_iterations = 6;
};

template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
class DormandPrince {
 public:
  using Settings = DormandPrinceSettings;
  static constexpr int nv = Model::nv;
  static constexpr int nq = Model::nq;
  static constexpr int order = 5;  // of the solution; the error estimate is of order 4

  /// Starts from the workspace's consistent state (see assemble), with the first step and the
  /// tolerances of `control`.
  DormandPrince(const Model& model, Workspace<Model>& ws, Settings settings = {},
                StepControl control = {})
      : model_(model),
        ws_(ws),
        settings_(settings),
        control_(control),
        proposed_step_(std::min(control.first_step, control.max_step)) {
    if (!(control.rtol > 0.0) || !(control.atol > 0.0))
      throw ModelError("dopri5", "rtol and atol must be positive, got " + to_text(control.rtol) +
                                     " and " + to_text(control.atol));
    if (!(proposed_step_ > 0.0))
      throw ModelError("dopri5", "the first step must be positive, got " + to_text(proposed_step_));
    nq_total_ = model.num_coordinates();
    nv_total_ = model.num_velocities();
    m_ = model.num_equations();
    size_ = nq_total_ + nv_total_;
    y_n_ = Eigen::VectorXd::Zero(size_);
    y_new_ = y_n_;
    y_trial_ = y_n_;
    y_dense_ = y_n_;
    stage_ = y_n_;
    k_new_ = y_n_;
    vdot_trial_ = Eigen::VectorXd::Zero(nv_total_);
    lambda_trial_ = Eigen::VectorXd::Zero(m_);
    for (auto& k : k_) k = Eigen::VectorXd::Zero(size_);
    rhs_ = Eigen::VectorXd::Zero(nv_total_ + m_);
    velocity_residual_ = Eigen::VectorXd::Zero(m_);
    solution_ = rhs_;
    solver_.analyze(model);
    initialize();
  }

  /// Takes the workspace's state as the committed one (v' and lambda solved afresh).
  void initialize() {
    t_n_ = ws_.t;
    y_n_ << ws_.q, ws_.v;
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
    vdot_n_ = ws_.vdot;
    lambda_n_ = ws_.lambda;
    ++statistics_.restarts;
  }

  /// Tries a step of size h from the committed state. The workspace then holds the projected
  /// trial state with its v' and lambda; error_norm() says whether the step is accurate
  /// enough. False if a stage or the projection failed.
  bool attempt(double h) {
    h_ = h;
    static constexpr double c[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
    static constexpr double a[7][6] = {
        {},
        {1.0 / 5},
        {3.0 / 40, 9.0 / 40},
        {44.0 / 45, -56.0 / 15, 32.0 / 9},
        {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
        {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
        {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
    // Fifth-order weights minus fourth-order ones: the local error estimate.
    static constexpr double e[7] = {71.0 / 57600,      0.0,        -71.0 / 16695, 71.0 / 1920,
                                    -17253.0 / 339200, 22.0 / 525, -1.0 / 40};
    for (int i = 1; i < 7; ++i) {
      stage_ = y_n_;
      for (int j = 0; j < i; ++j)
        if (a[i][j] != 0.0) stage_.noalias() += (h * a[i][j]) * k_[j];
      if (!derivative(t_n_ + c[i] * h, stage_, k_[i])) return false;
    }
    y_new_ = stage_;  // the seventh stage sits at the new point (first same as last)
    stage_.setZero();
    for (int i = 0; i < 7; ++i)
      if (e[i] != 0.0) stage_.noalias() += (h * e[i]) * k_[i];
    error_ = weighted_rms_norm(stage_, y_n_, y_new_, control_.rtol, control_.atol);
    if (!std::isfinite(error_)) return false;
    if (!project(t_n_ + h, y_new_)) return false;
    // The trial state, kept for restore_trial() and, with k at it, for the dense output.
    y_trial_ << ws_.q, ws_.v;
    vdot_trial_ = ws_.vdot;
    lambda_trial_ = ws_.lambda;
    derivative_at_workspace(k_new_);
    return true;
  }

  /// The state at t within the last attempted step (t_n <= t <= t_n + h), from the continuous
  /// extension of order 4 (Shampine 1986; Hairer, Norsett & Wanner, Sect. II.6), projected onto
  /// the constraints, with v' and lambda there: the workspace holds it as after an attempt.
  bool interpolate(double t) {
    dense_state(t);
    return project(t, y_dense_, true);
  }

  /// The interpolated positions and velocities at t and the frames from them, unprojected.
  void interpolate_frames(double t) {
    dense_state(t);
    ws_.t = t;
    ws_.q = y_dense_.head(nq_total_);
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::normalize(ws_.q.template segment<nq>(b * nq));
    ws_.v = y_dense_.tail(nv_total_);
    update_frames(model_, ws_);
  }

  /// Puts the last attempt's trial state back into the workspace (after interpolate()).
  void restore_trial() {
    ws_.t = t_n_ + h_;
    ws_.q = y_trial_.head(nq_total_);
    ws_.v = y_trial_.tail(nv_total_);
    ws_.vdot = vdot_trial_;
    ws_.lambda = lambda_trial_;
    update_frames(model_, ws_);
    evaluate_constraints(model_, ws_);
    evaluate_forces(model_, ws_);
  }

  /// Local error of the last attempt in units of the tolerance (accept when <= 1).
  double error_norm() const { return error_; }

  /// Accepts the last attempt and proposes the next step from its error.
  void accept() {
    commit();
    statistics_.max_error_estimate = std::max(statistics_.max_error_estimate, error_);
    const double grown = h_ * step_factor(error_, order - 1);
    // A step cut short to land on an output time says nothing against the longer step.
    proposed_step_ =
        std::min(control_.max_step, h_ < proposed_step_ ? std::max(proposed_step_, grown) : grown);
  }

  /// Rejects the last attempt and shrinks the step; throws once it is hopelessly short.
  void reject() {
    ++statistics_.rejected_steps;
    proposed_step_ = h_ * std::min(0.9, step_factor(error_, order - 1, 0.2, 0.9));
    rollback();
    if (proposed_step_ < control_.min_step * std::max(1.0, std::abs(t_n_)))
      throw SolverError(t_n_, "dopri5: the step size fell below " + to_text(control_.min_step) +
                                  " s; the problem may be stiff (try bdf or generalized-alpha) "
                                  "or the model singular");
  }

  /// Makes the trial state of the last attempt the committed one (no step-size change).
  void commit() {
    t_n_ += h_;
    y_n_ = y_trial_;
    k_[0] = k_new_;
    vdot_n_ = ws_.vdot;
    lambda_n_ = ws_.lambda;
    advance_states(model_, ws_);
    ++statistics_.steps;
  }

  /// Puts the workspace back at the last committed state.
  void rollback() {
    ws_.t = t_n_;
    ws_.q = y_n_.head(nq_total_);
    ws_.v = y_n_.tail(nv_total_);
    ws_.vdot = vdot_n_;
    ws_.lambda = lambda_n_;
    update_frames(model_, ws_);
    evaluate_constraints(model_, ws_);
  }

  [[noreturn]] void fail() {
    const double t_failed = t_n_ + h_;
    rollback();
    throw SolverError(t_failed,
                      "dopri5: a stage or the projection onto the constraints failed (singular "
                      "mass-constraint matrix or non-finite forces); check for locked or "
                      "redundant constraints and the force elements' parameters");
  }

  bool adaptive() const { return true; }
  double time() const { return t_n_; }
  double proposed_step() const { return proposed_step_; }
  void count_event() { ++statistics_.events; }
  const IntegratorStatistics& statistics() const { return statistics_; }
  const Settings& settings() const { return settings_; }

 private:
  /// f(t, y): the configuration rate and v' (index 1) at a stage; leaves v' and lambda in the
  /// workspace. False if the saddle-point matrix is singular or a value is not finite.
  bool derivative(double t, const Eigen::VectorXd& y, Eigen::VectorXd& k) {
    ++statistics_.residual_evaluations;
    ws_.t = t;
    ws_.q = y.head(nq_total_);
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::normalize(ws_.q.template segment<nq>(b * nq));
    ws_.v = y.tail(nv_total_);
    update_frames(model_, ws_);
    evaluate_constraints(model_, ws_);
    if (!accelerations()) return false;
    for (int b = 0; b < model_.num_bodies(); ++b)
      k.template segment<nq>(b * nq) = Model::Space::configuration_rate(
          y.template segment<nq>(b * nq), ws_.v.template segment<nv>(b * nv));
    k.tail(nv_total_) = ws_.vdot;
    return k.allFinite();
  }

  /// The derivative at the workspace's (consistent) state, whose v' is already solved.
  void derivative_at_workspace(Eigen::VectorXd& k) {
    for (int b = 0; b < model_.num_bodies(); ++b)
      k.template segment<nq>(b * nq) = Model::Space::configuration_rate(
          ws_.q.template segment<nq>(b * nq), ws_.v.template segment<nv>(b * nv));
    k.tail(nv_total_) = ws_.vdot;
  }

  /// v' and lambda at the workspace's frames (constraints evaluated), factorizing afresh.
  bool accelerations() {
    evaluate_forces(model_, ws_);
    evaluate_gamma(model_, ws_);
    if (!factorize()) return false;
    rhs_.head(nv_total_) = ws_.force;
    rhs_.tail(m_) = ws_.gamma;
    solver_.solve(rhs_, solution_);
    ws_.vdot = solution_.head(nv_total_);
    ws_.lambda = solution_.tail(m_);
    return solution_.allFinite();
  }

  bool factorize() {
    ++statistics_.factorizations;
    return solver_.factorize(model_, ws_, IterationFactors{});
  }

  /// y_dense_ = the continuous extension of the last attempt at t.
  void dense_state(double t) {
    static constexpr double d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
                            d4 = -10690763975.0 / 1880347072.0,
                            d5 = 701980252875.0 / 199316789632.0, d6 = -1453857185.0 / 822651844.0,
                            d7 = 69997945.0 / 29380423.0;
    const double theta = (t - t_n_) / h_, rest = 1.0 - theta;
    // y(theta) = y_n + theta (dy + rest (b + theta (c + rest d))) with dy = y_{n+1} - y_n,
    // b = h k_1 - dy, c = dy - h k_7 - b and d = h (d1 k_1 + d3 k_3 + ... + d7 k_7).
    stage_ = h_ * (d1 * k_[0] + d3 * k_[2] + d4 * k_[3] + d5 * k_[4] + d6 * k_[5] + d7 * k_new_);
    y_dense_ = y_trial_ - y_n_;                                                   // dy
    stage_ = (y_dense_ - h_ * k_new_ - (h_ * k_[0] - y_dense_)) + rest * stage_;  // c + rest d
    stage_ = (h_ * k_[0] - y_dense_) + theta * stage_;                            // b + theta (...)
    y_dense_ = y_n_ + theta * (y_dense_ + rest * stage_);
  }

  /// Moves y onto Phi = 0 and Phi_q v + Phi_t = 0, the least distance in the mass metric, and
  /// solves v' and lambda there. The workspace then holds the projected state at t. With
  /// `one_factorization` the matrix at y serves every solve (chord iterations): for output
  /// points, whose v' and lambda then carry a relative error of the size of the correction but
  /// feed nothing back into the integration.
  bool project(double t, const Eigen::VectorXd& y, bool one_factorization = false) {
    ws_.t = t;
    ws_.q = y.head(nq_total_);
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::normalize(ws_.q.template segment<nq>(b * nq));
    ws_.v = y.tail(nv_total_);
    update_frames(model_, ws_);
    evaluate_constraints(model_, ws_);
    for (int k = 0; m_ > 0; ++k) {
      if ((k == 0 || !one_factorization) && !factorize()) return false;
      if (ws_.phi.cwiseAbs().maxCoeff() <= settings_.projection_tolerance) break;
      if (k == settings_.max_projection_iterations) return false;
      // [M Phi_q^T; Phi_q 0] [dq; mu] = [0; -Phi]: the smallest correction in the mass metric.
      rhs_.head(nv_total_).setZero();
      rhs_.tail(m_) = -ws_.phi;
      solver_.solve(rhs_, solution_);
      ++statistics_.newton_iterations;
      for (int b = 0; b < model_.num_bodies(); ++b)
        Model::Space::integrate(Eigen::Matrix<double, nq, 1>(ws_.q.template segment<nq>(b * nq)),
                                solution_.template segment<nv>(b * nv),
                                ws_.q.template segment<nq>(b * nq));
      update_frames(model_, ws_);
      evaluate_constraints(model_, ws_);
    }
    if (m_ > 0) {
      // Velocities: [M Phi_q^T; Phi_q 0] [dv; mu] = [0; -(Phi_q v + Phi_t)], same matrix.
      jacobian_times(model_, ws_, ws_.v, velocity_residual_);
      rhs_.head(nv_total_).setZero();
      rhs_.tail(m_) = -(velocity_residual_ + ws_.phi_t);
      solver_.solve(rhs_, solution_);
      ws_.v += solution_.head(nv_total_);
      update_frames(model_, ws_);
    }
    // v' and lambda at the projected state: the same matrix, new right-hand side.
    evaluate_forces(model_, ws_);
    evaluate_gamma(model_, ws_);
    rhs_.head(nv_total_) = ws_.force;
    rhs_.tail(m_) = ws_.gamma;
    if (m_ == 0 && !factorize()) return false;
    solver_.solve(rhs_, solution_);
    ws_.vdot = solution_.head(nv_total_);
    ws_.lambda = solution_.tail(m_);
    return ws_.q.allFinite() && ws_.v.allFinite() && solution_.allFinite();
  }

  const Model& model_;
  Workspace<Model>& ws_;
  Settings settings_;
  StepControl control_;
  Solver solver_;
  IntegratorStatistics statistics_;
  Eigen::Index nq_total_ = 0, nv_total_ = 0, m_ = 0, size_ = 0;
  double t_n_ = 0.0, h_ = 0.0, error_ = 0.0, proposed_step_ = 1e-4;
  Eigen::VectorXd y_n_, y_new_, stage_, rhs_, solution_, velocity_residual_, vdot_n_, lambda_n_;
  std::array<Eigen::VectorXd, 7> k_;  // stage derivatives of the last attempt
  // The last attempt's projected end state, its v', lambda and derivative; a dense-output point.
  Eigen::VectorXd y_trial_, vdot_trial_, lambda_trial_, k_new_, y_dense_;
};

}  // namespace odyn
