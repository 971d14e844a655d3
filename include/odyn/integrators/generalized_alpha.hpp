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

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/linalg/dense_lu.hpp"

namespace odyn {

struct GeneralizedAlphaSettings {
  /// Spectral radius at infinite frequency: 1 keeps every mode, 0 damps the highest at once.
  double rho_inf = 0.9;
  /// HHT-alpha flavour (alpha_m = 0, rho_inf in [0.5, 1]) instead of Chung-Hulbert's.
  bool hht = false;
  /// Newton stops when the velocity correction is below atol + rtol |v| in every entry...
  double newton_rtol = 1e-9;
  double newton_atol = 1e-10;
  /// ... and |Phi| is below this in every entry.
  double constraint_tolerance = 1e-11;
  int max_iterations = 8;
  /// Keep the factorization while a step needs no more than this many iterations.
  int reuse_iterations = 2;
};

struct IntegratorStatistics {
  long steps = 0;
  long newton_iterations = 0;
  long factorizations = 0;
  long residual_evaluations = 0;
  long rejected_steps = 0;
};

template <class Model, class LinearSolver = DenseLu>
class GeneralizedAlpha {
 public:
  using Settings = GeneralizedAlphaSettings;
  static constexpr int nv = Model::nv;
  static constexpr int nq = Model::nq;

  GeneralizedAlpha(const Model& model, Workspace<Model>& ws, Settings settings = {})
      : model_(model), ws_(ws), settings_(settings) {
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

    nv_total_ = model.num_velocities();
    m_ = model.num_equations();
    const int n = nv_total_ + m_;
    matrix_ = Eigen::MatrixXd::Zero(n, n);
    residual_ = Eigen::VectorXd::Zero(n);
    correction_ = Eigen::VectorXd::Zero(n);
    q_n_ = ws.q;
    v_n_ = ws.v;
    vdot_n_ = ws.vdot;
    a_n_ = ws.vdot;
    increment_ = Eigen::VectorXd::Zero(nv_total_);
    solver_.analyze_pattern(matrix_);
  }

  /// Starts from the workspace's state, which must be consistent (see assemble) with v' and
  /// lambda solved from it: a_0 = v'_0.
  void initialize() {
    q_n_ = ws_.q;
    v_n_ = ws_.v;
    vdot_n_ = ws_.vdot;
    a_n_ = ws_.vdot;
    lambda_n_ = ws_.lambda;
    factorized_ = false;
  }

  /// Advances the workspace by one step of size h. Throws SolverError if Newton fails.
  void step(double h) {
    if (h != h_) {
      h_ = h;
      factorized_ = false;
    }
    const double t_new = ws_.t + h;
    for (int attempt = 0; attempt < 2; ++attempt) {
      const bool fresh = !factorized_;
      if (solve_step(t_new)) {
        accept(t_new);
        return;
      }
      // A stale factorization may be the cause: retry once with a fresh one.
      ++statistics_.rejected_steps;
      factorized_ = false;
      if (fresh) break;
    }
    restore();
    throw SolverError(t_new, failure_message());
  }

  const IntegratorStatistics& statistics() const { return statistics_; }
  const Settings& settings() const { return settings_; }

 private:
  /// The state at t_{n+1} from the current guess of v'_{n+1}, written into the workspace.
  void update_state(double t_new) {
    const double h = h_;
    const double one_minus_am = 1.0 - alpha_m_;
    // a_{n+1} stored in increment_ first, then turned into the configuration increment.
    increment_ =
        ((1.0 - alpha_f_) * ws_.vdot + alpha_f_ * vdot_n_ - alpha_m_ * a_n_) / one_minus_am;
    ws_.v = v_n_ + h * (1.0 - gamma_) * a_n_ + h * gamma_ * increment_;
    increment_ = h * v_n_ + h * h * (0.5 - beta_) * a_n_ + h * h * beta_ * increment_;
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::integrate(q_n_.template segment<nq>(b * nq),
                              increment_.template segment<nv>(b * nv),
                              ws_.q.template segment<nq>(b * nq));
    ws_.t = t_new;
  }

  /// Residual of the step equations at the workspace's state; false if it is not finite.
  bool evaluate_residual() {
    ++statistics_.residual_evaluations;
    update_frames(model_, ws_);
    evaluate_constraints(model_, ws_);
    evaluate_forces(model_, ws_);
    auto dynamics = residual_.head(nv_total_);
    mass_times(model_, ws_.vdot, dynamics);
    dynamics -= ws_.force;
    add_jacobian_transpose_times(model_, ws_, ws_.lambda, dynamics);
    residual_.tail(m_) = ws_.phi / position_factor();
    return residual_.allFinite();
  }

  /// d(q_{n+1})/d(v'_{n+1}) and d(v_{n+1})/d(v'_{n+1}).
  double position_factor() const { return beta_ * h_ * h_ * (1.0 - alpha_f_) / (1.0 - alpha_m_); }
  double velocity_factor() const { return gamma_ * h_ * (1.0 - alpha_f_) / (1.0 - alpha_m_); }

  bool factorize() {
    ++statistics_.factorizations;
    matrix_.setZero();
    add_iteration_blocks(model_, ws_, matrix_, 1.0, position_factor(), velocity_factor());
    write_jacobian(model_, ws_, matrix_, nv_total_, 0, true);
    factorized_ = solver_.factorize(matrix_);
    iterations_since_factorization_ = 0;
    return factorized_;
  }

  bool solve_step(double t_new) {
    // Predictor: the last acceleration and multipliers.
    ws_.vdot = vdot_n_;
    ws_.lambda = lambda_n_;
    update_state(t_new);
    double previous_norm = 0.0;
    for (int k = 0; k <= settings_.max_iterations; ++k) {
      if (!evaluate_residual()) return false;
      if (k > 0 && last_norm_ <= 1.0 &&
          ws_.phi.cwiseAbs().maxCoeff() <= settings_.constraint_tolerance) {
        if (k > settings_.reuse_iterations) factorized_ = false;
        return true;
      }
      if (k == settings_.max_iterations) return false;
      if (!factorized_ && !factorize()) return false;
      solver_.solve(residual_, correction_);
      ws_.vdot -= correction_.head(nv_total_);
      ws_.lambda -= correction_.tail(m_);
      ++statistics_.newton_iterations;
      // Size of the velocity correction in units of the tolerance.
      last_norm_ = 0.0;
      const double scale = velocity_factor();
      for (int i = 0; i < nv_total_; ++i)
        last_norm_ = std::max(
            last_norm_, scale * std::abs(correction_[i]) /
                            (settings_.newton_atol + settings_.newton_rtol * std::abs(ws_.v[i])));
      if (k > 0 && last_norm_ > 2.0 * previous_norm && last_norm_ > 1.0) return false;
      previous_norm = last_norm_;
      update_state(t_new);
    }
    return false;
  }

  void accept(double t_new) {
    a_n_ = ((1.0 - alpha_f_) * ws_.vdot + alpha_f_ * vdot_n_ - alpha_m_ * a_n_) / (1.0 - alpha_m_);
    q_n_ = ws_.q;
    v_n_ = ws_.v;
    vdot_n_ = ws_.vdot;
    lambda_n_ = ws_.lambda;
    ws_.t = t_new;
    advance_states(model_, ws_);
    ++statistics_.steps;
  }

  /// Puts the workspace back at the start of the failed step.
  void restore() {
    const double t_failed = ws_.t;
    ws_.q = q_n_;
    ws_.v = v_n_;
    ws_.vdot = vdot_n_;
    ws_.lambda = lambda_n_;
    ws_.t = t_failed - h_;
    update_frames(model_, ws_);
  }

  std::string failure_message() const {
    if (!residual_.allFinite()) {
      std::string culprit = "an element";
      model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
        if constexpr (ForceElement<E>) {
          const auto& blocks = std::get<type>(ws_.blocks);
          for (std::size_t i = 0; i < pool.size(); ++i)
            for (const auto& f : blocks[i].force)
              if (!f.allFinite()) culprit = "force element '" + pool[i].name() + "'";
        }
      });
      return "Newton iteration produced a non-finite value; " + culprit +
             " returned NaN or infinity. Check its parameters and inputs.";
    }
    Eigen::Index row = 0;
    const double worst = m_ > 0 ? ws_.phi.cwiseAbs().maxCoeff(&row) : 0.0;
    return "Newton iteration did not converge in " + std::to_string(settings_.max_iterations) +
           " iterations (largest constraint residual " + to_text(worst) + " at '" +
           (m_ > 0 ? model_.constraint_name(static_cast<int>(row)) : std::string("-")) +
           "'). Reduce the step size, or check for a locked or singular mechanism.";
  }

  const Model& model_;
  Workspace<Model>& ws_;
  Settings settings_;
  double alpha_m_ = 0.0, alpha_f_ = 0.0, gamma_ = 0.5, beta_ = 0.25;
  double h_ = 0.0;
  int nv_total_ = 0, m_ = 0;
  bool factorized_ = false;
  int iterations_since_factorization_ = 0;
  double last_norm_ = 0.0;

  Eigen::MatrixXd matrix_;      // (n x n) iteration matrix, n = nv_total + m
  Eigen::VectorXd residual_;    // (n)
  Eigen::VectorXd correction_;  // (n)
  Eigen::VectorXd q_n_, v_n_, vdot_n_, a_n_, lambda_n_;  // state at the start of the step
  Eigen::VectorXd increment_;                            // (nv_total) configuration increment
  LinearSolver solver_;
  IntegratorStatistics statistics_;
};

}  // namespace odyn
