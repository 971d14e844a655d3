#pragma once
// Explicit Adams-Bashforth integration of order k (1 to 6) on fixed steps, on the index-1 form
// of the equations of motion, with positions and velocities projected back onto the
// constraints after every step: one evaluation of the blocks and one factorization per step,
// where an explicit Runge-Kutta method of the same order needs k or more. The class of the
// predictor of ADAMS' ABAM; for problems that are not stiff, when steps are fixed anyway (a
// fixed output rate, a real-time budget) and the accuracy of a higher order is wanted.
//
// With y = (q, v) and f = (rate(q, v), v') (the quaternion as 4 numbers, renormalized),
//   y_{n+1} = y_n + h sum_{j<k} b_j f_{n-j},   b_j = int_0^1 l_j(s) ds,
// where l_j is the Lagrange polynomial of the nodes s_j = (t_{n-j} - t_n) / h: the classical
// coefficients on equal steps, and the right ones when a step ends early on an output time or
// a switch. v' and lambda come from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] at the
// projected state. The local error is estimated by the difference of the orders k + 1 and k.
//
// Near a singular configuration (Phi_q nearly loses rank, which the step's factorization tells
// by its smallest pivot) the positions are projected to rounding by Newton first: there what
// a projection to its tolerance leaves of Phi is amplified into v', and from v' into the next
// k steps (docs/hard-cases.md, "Singular configurations").
//
// After a restart (the start, a switch of a force law) the history is gone: the first k - 1
// steps are taken by the Dormand-Prince 5(4) method on the same steps (about 7 evaluations
// each), whose error is of the size of the multistep method's or below it for k <= 6.
//
// Stability: explicit, so h |lambda| must stay below the method's limit for every mode (on the
// negative real axis 2, 1, 0.55, 0.3, 0.16, 0.085 for k = 1..6). A stiff spring or a fast
// rotation at too long a step makes the state grow until the projection fails; the error then
// says to shorten the step or to take an implicit method.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "odyn/analysis/absolute_coordinates.hpp"
#include "odyn/analysis/joint_coordinates.hpp"
#include "odyn/analysis/saddle_point.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/integrators/dormand_prince.hpp"
#include "odyn/integrators/integrator.hpp"

namespace odyn {

struct AdamsSettings {
  /// Order k of the method, 1 to 6: k past derivatives per step.
  int order = 5;
  /// The factorization of the saddle-point systems (linalg/linear_solver.hpp).
  LinearSolver linear_solver = LinearSolver::automatic;

  /// Positions are projected when an entry of Phi exceeds this (|Phi| then stays below about
  /// 4e-11 on the engine)...
  double projection_tolerance = 1e-11;
  /// ... and velocities when an entry of Phi_q v + Phi_t exceeds this. The drift of both is
  /// of the size of the local error, so most steps need neither projection.
  double velocity_tolerance = 1e-8;
  int max_projection_iterations = 6;
};

template <class Model, class Coordinates = AbsoluteCoordinates<Model>>
class Adams {
 public:
  using Settings = AdamsSettings;
  static constexpr int kMaxOrder = 6;

  /// Starts from the workspace's consistent state (see assemble). `control` gives the
  /// tolerances that the reported error estimate is measured against.
  Adams(const Model& model, Workspace<Model>& ws, Settings settings = {}, StepControl control = {})
      : model_(model),
        ws_(ws),
        settings_(settings),
        control_(control),
        starter_(model, ws,
                 DormandPrinceSettings{settings.projection_tolerance,
                                       settings.max_projection_iterations, settings.linear_solver},
                 control),
        coordinates_(starter_.coordinates()) {
    if (settings.order < 1 || settings.order > kMaxOrder)
      throw ModelError("adams", "the order must lie in [1, " + std::to_string(kMaxOrder) +
                                    "], got " + std::to_string(settings.order));
    if (!(settings.projection_tolerance > 0.0) || !(settings.velocity_tolerance > 0.0))
      throw ModelError("adams", "the projection tolerances must be positive, got " +
                                    to_text(settings.projection_tolerance) + " and " +
                                    to_text(settings.velocity_tolerance));
    nq_total_ = coordinates_.num_positions();
    nv_total_ = coordinates_.num_velocities();
    m_ = coordinates_.num_equations();
    const Eigen::Index size = nq_total_ + nv_total_;
    y_n_ = Eigen::VectorXd::Zero(size);
    y_new_ = y_n_;
    estimate_ = y_n_;
    loaded_ = y_n_;
    for (auto& f : history_) f = y_n_;
    initialize();
  }
  // coordinates_ refers into starter_: a copy would step the original's coordinates.
  Adams(const Adams&) = delete;
  Adams& operator=(const Adams&) = delete;

  /// Takes the workspace's state as the committed one (v' and lambda solved afresh).
  void initialize() {
    t_n_ = ws_.t;
    coordinates_.read_state(y_n_);
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    restart();
  }

  /// Forgets the history after a switch of a force law (and at the start): the next k steps
  /// are one-step ones, from v' and lambda solved at the committed state under the new law.
  void restart() {
    rollback();
    starter_.initialize();
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    known_ = 0;
    push_derivative();
    ++statistics_.restarts;
  }

  /// Tries a step of size h from the committed state; the workspace then holds the projected
  /// trial state with its v' and lambda. False if the projection failed or a value is not
  /// finite (a step beyond the stability limit ends so).
  bool attempt(double h) {
    h_ = h;
    if (starting()) {
      if (!starter_.attempt(h)) return false;
      error_ = starter_.error_norm();
      return true;
    }
    const int k = settings_.order;
    // Order k + 1 minus order k estimates the local error of the order-k step; on the first
    // step after the start-up, k minus k - 1 (larger: on the safe side).
    const int estimate_points = known_ > k ? k + 1 : k;
    update_weights(h, estimate_points);
    y_new_ = y_n_;
    estimate_.setZero();
    for (int j = 0; j < k; ++j) y_new_.noalias() += (h * weights_[j]) * past(j);
    for (int j = 0; j < estimate_points; ++j)
      estimate_.noalias() += (h * error_weights_[j]) * past(j);
    error_ = weighted_rms_norm(estimate_, y_n_, y_new_, control_.rtol, control_.atol);
    ++statistics_.residual_evaluations;
    return project(t_n_ + h, y_new_);
  }

  /// Accepts the trial state of the last attempt.
  void commit() {
    if (starting()) {
      starter_.commit();
    } else {
      advance_states(model_, ws_);
    }
    t_n_ = ws_.t;
    coordinates_.read_state(y_n_);
    flush_subnormal(y_n_);
    vdot_n_ = coordinates_.accelerations();
    lambda_n_ = coordinates_.multipliers();
    step_sizes_[(known_ - 1) % kHistory] = h_;
    push_derivative();
    statistics_.max_error_estimate = std::max(statistics_.max_error_estimate, error_);
    ++statistics_.steps;
  }

  /// Puts the workspace back at the last committed state, its blocks and forces evaluated.
  void rollback() {
    coordinates_.load(t_n_, y_n_);
    coordinates_.restore_solution(vdot_n_, lambda_n_);
    coordinates_.evaluate_constraints();
    coordinates_.evaluate_forces();
  }

  /// The workspace's blocks, v' and lambda for every element at the loaded state, when the
  /// coordinates keep only some of them up to date while stepping (joint coordinates).
  void refresh_blocks() requires requires(Coordinates& c) { c.complete_workspace(); }
  { coordinates_.complete_workspace(); }

  /// Rolls back and throws the SolverError that explains the last failed attempt.
  [[noreturn]] void fail() {
    const double t_failed = t_n_ + h_;
    rollback();
    throw SolverError(t_failed,
                      "adams: the projection onto the constraints failed or a value is not finite "
                      "(a step of " +
                          to_text(h_) +
                          " s beyond the explicit method's stability limit grows the "
                          "state until then, or the mechanism is locked); shorten the step, lower "
                          "the order, or take an implicit integrator (generalized-alpha, bdf)");
  }

  /// Its name in integrator_names().
  static std::string name() { return "adams"; }
  bool adaptive() const { return false; }
  double time() const { return t_n_; }
  /// Local error estimate of the last attempt in units of the tolerances of `control`.
  double error_norm() const { return error_; }
  void count_event() { ++statistics_.events; }
  /// The counters, the start-up steps' evaluations and factorizations included.
  IntegratorStatistics statistics() const {
    IntegratorStatistics s = statistics_;
    const IntegratorStatistics& start = starter_.statistics();
    s.residual_evaluations += start.residual_evaluations;
    s.factorizations += start.factorizations;
    s.newton_iterations += start.newton_iterations;
    s.rejected_steps += start.rejected_steps;
    return s;
  }
  const Settings& settings() const { return settings_; }

 private:
  static constexpr int kHistory = kMaxOrder + 2;  // derivatives kept: k + 1 for the estimate

  /// The first k - 1 steps after a restart (one for k = 1, so that the error estimate has two
  /// points) are the starter's: then k derivatives are known.
  bool starting() const { return known_ < std::max(settings_.order, 2); }

  /// f_{n-j}: the derivative j steps back.
  const Eigen::VectorXd& past(int j) const { return history_[(known_ - 1 - j) % kHistory]; }

  /// f at the workspace's state (v' solved there) becomes f_n.
  void push_derivative() {
    Eigen::VectorXd& f = history_[known_ % kHistory];
    coordinates_.read_state(loaded_);
    coordinates_.position_rate(loaded_, f.head(nq_total_));
    f.tail(nv_total_) = coordinates_.accelerations();
    flush_subnormal(f);
    ++known_;
  }

  /// Zeroes the entries below 1e-100 in magnitude. Coordinates that stay at zero in exact
  /// arithmetic (the out-of-plane motion of a planar mechanism) otherwise decay step by step
  /// towards the subnormal range, and their products (the squared angular velocities in gamma)
  /// reach it first; each subnormal operation costs about a hundred cycles: 18 % of a step's
  /// time on the engine at order 5.
  static void flush_subnormal(Eigen::VectorXd& x) {
    for (Eigen::Index i = 0; i < x.size(); ++i)
      if (std::abs(x[i]) < 1e-100) x[i] = 0.0;
  }

  /// The weights of order k for a step h from the last k derivatives' times, and those of
  /// the error estimate from the last `points` (k + 1 or k); kept while the steps keep their
  /// ratios (equal fixed steps recompute nothing).
  void update_weights(double h, int points) {
    const int k = settings_.order;
    std::array<double, kMaxOrder + 1> nodes{};
    double back = 0.0;
    bool same = points == estimate_points_;
    for (int j = 0; j < points; ++j) {
      nodes[j] = -back / h;
      same = same && std::abs(nodes[j] - nodes_[j]) <= 1e-9 * (1.0 + j);
      if (j + 1 < points) back += step_sizes_[(known_ - 2 - j) % kHistory];
    }
    if (same) return;
    nodes_ = nodes;
    estimate_points_ = points;
    const auto order_k = quadrature_weights(nodes, k);
    const auto other = quadrature_weights(nodes, points == k ? k - 1 : k + 1);
    for (int j = 0; j <= k; ++j) {
      weights_[j] = j < k ? order_k[j] : 0.0;
      error_weights_[j] = points == k ? order_k[j] - other[j] : other[j] - weights_[j];
    }
  }

  /// int_0^1 l_j(s) ds for the Lagrange polynomials l_j of the first `count` nodes, by
  /// expanding each product prod_{i != j} (s - s_i) / (s_j - s_i) into monomials.
  static std::array<double, kMaxOrder + 1> quadrature_weights(
      const std::array<double, kMaxOrder + 1>& nodes, int count) {
    std::array<double, kMaxOrder + 1> weights{};
    for (int j = 0; j < count; ++j) {
      std::array<double, kMaxOrder + 2> c{};  // coefficients of s^0 .. s^(count-1)
      c[0] = 1.0;
      int degree = 0;
      double denominator = 1.0;
      for (int i = 0; i < count; ++i) {
        if (i == j) continue;
        // c <- c (s - s_i)
        for (int d = degree + 1; d >= 1; --d) c[d] = c[d - 1] - nodes[i] * c[d];
        c[0] *= -nodes[i];
        ++degree;
        denominator *= nodes[j] - nodes[i];
      }
      double integral = 0.0;
      for (int d = 0; d <= degree; ++d) integral += c[d] / (d + 1);
      weights[j] = integral / denominator;
    }
    return weights;
  }

  /// The workspace at (t, y), moved onto Phi = 0 and Phi_q v + Phi_t = 0 (the least distance in
  /// the mass metric) where it has drifted beyond the tolerances, with v' and lambda solved
  /// there. One factorization, at the predicted positions, unless the positions moved.
  bool project(double t, const Eigen::VectorXd& y) {
    coordinates_.load(t, y);
    coordinates_.evaluate_constraints();
    if (!factorize()) return false;
    bool moved = false;
    bool rounded = near_singular();  // then Newton's, to rounding, instead of the chord
    if (rounded) {
      if (!project_to_rounding()) return false;
      moved = true;
    }
    for (int k = 0; !rounded && m_ > 0 &&
                    !(coordinates_.position_residual() <= settings_.projection_tolerance);
         ++k) {
      if (k == settings_.max_projection_iterations) {
        // Chord iterations that do not converge: the matrix changes fast with the positions,
        // as near a singular configuration. Newton's, from where they got to.
        ++statistics_.singular_steps;
        if (!factorize() || !project_to_rounding()) return false;
        rounded = true;
        break;
      }
      coordinates_.correct_positions();
      ++statistics_.newton_iterations;
      moved = true;
    }
    // v' and lambda feed the history: solved with the matrix at the final positions.
    if (moved && !factorize()) return false;
    // Near a singular configuration what the velocities keep of Phi_q v + Phi_t (up to the
    // tolerance, 1e-8) is amplified into v' as Phi is: it left 40 four-bars in joint
    // coordinates 2.3e-6 rad off at h = 1e-4 s, 4e-8 once corrected. One correction takes it
    // to rounding (the equations are linear).
    if (m_ > 0 &&
        (rounded || !(coordinates_.velocity_residual() <= settings_.velocity_tolerance))) {
      coordinates_.correct_velocities();
      ++statistics_.newton_iterations;
    }
    return coordinates_.solve_accelerations() && coordinates_.state_finite();
  }

  bool factorize() {
    ++statistics_.factorizations;
    return coordinates_.factorize();
  }

  /// Whether the factorization just made says that Phi_q nearly loses rank (a singular
  /// configuration). What the projection leaves of Phi there turns Phi_q's null space by
  /// about |Phi| / sigma^2, and v' with it: at the projection tolerance, 1e-11, the history
  /// of derivatives took errors that put 10 parallelogram four-bars 0.15 rad off after 20
  /// crossings at h = 1e-4 s, without a warning. Coordinates without pivot_ratio() never say.
  bool near_singular() {
    if constexpr (requires { coordinates_.pivot_ratio(); }) {
      if (m_ > 0 && coordinates_.pivot_ratio() < singular_pivot_ratio) {
        ++statistics_.singular_steps;
        return true;
      }
    }
    return false;
  }

  /// Newton (refactorizing) on the positions to rounding, 10 eps |q|, or until an iteration
  /// gains less than 10 % (near the configuration Newton converges only linearly), from the
  /// factorization at the loaded positions. False if a factorization fails or Phi is still
  /// above 100 projection tolerances (with redundant constraints near the configuration,
  /// Newton stalls at about 2 of them). The caller factorizes at the new positions.
  bool project_to_rounding() {
    const double rounding = 10.0 * std::numeric_limits<double>::epsilon() *
                            std::max(1.0, coordinates_.largest_position());
    double residual = coordinates_.position_residual();
    for (int k = 0; residual > rounding && k < max_rounding_iterations; ++k) {
      if (k > 0 && !factorize()) return false;
      coordinates_.correct_positions();
      ++statistics_.newton_iterations;
      const double before = residual;
      residual = coordinates_.position_residual();
      if (!(residual < 0.9 * before)) break;
    }
    return residual <= singular_residual_allowance * settings_.projection_tolerance;
  }

  /// Below this pivot ratio of the Schur complement (see BlockSchurSaddlePoint::pivot_ratio and
  /// JointCoordinates::pivot_ratio; about sigma^2) positions and velocities go to rounding.
  static constexpr double singular_pivot_ratio = 1e-4;
  static constexpr int max_rounding_iterations = 12;
  static constexpr double singular_residual_allowance = 100.0;

  const Model& model_;
  Workspace<Model>& ws_;
  Settings settings_;
  StepControl control_;
  // The start-up method; it owns the coordinates, which this class steps too.
  ExplicitRungeKutta<DormandPrince5Tableau, Model, Coordinates> starter_;
  Coordinates& coordinates_;
  IntegratorStatistics statistics_;
  Eigen::Index nq_total_ = 0, nv_total_ = 0, m_ = 0;
  double t_n_ = 0.0, h_ = 0.0, error_ = 0.0;
  long known_ = 0;  // derivatives in the history since the last restart
  std::array<Eigen::VectorXd, kHistory> history_;  // f, by step number modulo kHistory
  std::array<double, kHistory> step_sizes_{};      // of the steps between them
  std::array<double, kMaxOrder + 1> nodes_{};      // of the cached weights
  std::array<double, kMaxOrder + 1> weights_{}, error_weights_{};
  int estimate_points_ = 0;  // derivatives the cached estimate weights use; 0: none cached
  Eigen::VectorXd y_n_, y_new_, estimate_, vdot_n_, lambda_n_;
  Eigen::VectorXd loaded_;  // the coordinates' loaded state, read back
};

/// Adams-Bashforth on the bodies' own coordinates (every joint a constraint).
template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
using AdamsBashforth = Adams<Model, AbsoluteCoordinates<Model, Solver>>;

/// The same method on joint coordinates (see analysis/joint_coordinates.hpp).
template <class Model>
using JointAdamsBashforth = Adams<Model, JointCoordinates<Model>>;

}  // namespace odyn
