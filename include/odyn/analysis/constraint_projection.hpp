#pragma once
// The steps that integrators take with a saddle-point solver factorized on the mass terms,
// [M Phi_q^T; Phi_q 0]: the accelerations and multipliers at a state, and the corrections that
// move a state onto Phi = 0 and Phi_q v + Phi_t = 0 by the least distance in the mass metric.
// The integrators differ in when they factorize and how many corrections they take (explicit
// methods after every step, Adams only where the state has drifted, BDF at output points); the
// steps themselves are written once, here.

#include <Eigen/Core>
#include <string>

#include "odyn/analysis/system.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/linalg/all_finite.hpp"

namespace odyn {

template <class Model>
class ConstraintProjection {
 public:
  static constexpr int nq = Model::nq;
  static constexpr int nv = Model::nv;

  /// Sizes the buffers for the model: the steps below allocate nothing.
  explicit ConstraintProjection(const Model& model)
      : nv_total_(model.num_velocities()),
        m_(model.num_equations()),
        rhs_(Eigen::VectorXd::Zero(nv_total_ + m_)),
        solution_(rhs_),
        velocity_residual_(Eigen::VectorXd::Zero(m_)) {}

  /// v' and lambda at the workspace's state (frames and constraints evaluated, the solver
  /// factorized there): forces and gamma are evaluated, then [M Phi_q^T; Phi_q 0] [v'; lambda]
  /// = [Q; gamma] is solved. False if the solution is not finite.
  ///
  /// With forces that read their joints' reactions (joint friction), Q depends on lambda: the
  /// solve is repeated, each time with the forces of the last lambda (from the workspace's, the
  /// last solve's, at first), until lambda changes by at most reaction_tolerance of its size.
  /// The change shrinks by about mu times the ratio of the friction's lever to the joint's at
  /// each pass; throws SolverError, naming the friction, where it does not shrink (a friction
  /// coefficient so large that the reactions have no unique value: Painleve's paradox).
  template <class Solver>
  bool solve_accelerations(const Model& model, Workspace<Model>& ws, Solver& solver) {
    evaluate_gamma(model, ws);
    rhs_.tail(m_) = ws.gamma;
    constexpr int passes = reads_joint_reactions<Model>() ? max_reaction_passes : 1;
    double change = 0.0, size = 0.0;
    for (int pass = 0; pass < passes; ++pass) {
      evaluate_forces(model, ws);
      rhs_.head(nv_total_) = ws.force;
      solver.solve(rhs_, solution_);
      if constexpr (passes > 1)
        if (m_ > 0) change = (solution_.tail(m_) - ws.lambda).cwiseAbs().maxCoeff();
      ws.vdot = solution_.head(nv_total_);
      ws.lambda = solution_.tail(m_);
      if (passes == 1 || m_ == 0 || !all_finite(solution_)) return all_finite(solution_);
      size = ws.lambda.cwiseAbs().maxCoeff();
      if (change <= reaction_tolerance * size) return true;
    }
    // Rounding can keep the last digits moving; a change that has not shrunk far is a failure.
    if (change > 1e-8 * size)
      throw SolverError(ws.t, "the reactions that " + first_reaction_reader(model) +
                                  " reads did not settle in " + std::to_string(passes) +
                                  " passes (they still change by " + to_text(change / size) +
                                  " of their size): the friction is too large for the joint's "
                                  "geometry (Painleve's paradox); reduce its coefficient, its "
                                  "pin radius or its moments' share (a longer bending_arm)");
    return true;
  }

  /// How closely the reactions that joint friction reads must settle, relative to the largest
  /// multiplier, and in how many passes at most.
  static constexpr double reaction_tolerance = 1e-12;
  static constexpr int max_reaction_passes = 100;

  /// One correction of the positions towards Phi = 0: [M Phi_q^T; Phi_q 0] [dq; mu] = [0; -Phi]
  /// with the solver's matrix (factorized at these positions, or near them: a chord step), each
  /// body moved by its dq on its configuration space. Frames and constraints are then evaluated
  /// at the new positions.
  template <class Solver>
  void correct_positions(const Model& model, Workspace<Model>& ws, Solver& solver) {
    rhs_.head(nv_total_).setZero();
    rhs_.tail(m_) = -ws.phi;
    solver.solve(rhs_, solution_);
    for (int b = 0; b < model.num_bodies(); ++b)
      Model::Space::integrate(Eigen::Matrix<double, nq, 1>(ws.q.template segment<nq>(b * nq)),
                              solution_.template segment<nv>(b * nv),
                              ws.q.template segment<nq>(b * nq));
    update_frames(model, ws);
    evaluate_constraints(model, ws);
  }

  /// Phi_q v + Phi_t at the workspace's state (constraints evaluated there).
  const Eigen::VectorXd& velocity_residual(const Model& model, const Workspace<Model>& ws) {
    jacobian_times(model, ws, ws.v, velocity_residual_);
    velocity_residual_ += ws.phi_t;
    return velocity_residual_;
  }

  /// x minus the part of it that Phi_q measures, along M^-1 Phi_q^T (the direction in which
  /// the corrections move): [M Phi_q^T; Phi_q 0] [dx; mu] = [0; -Phi_q x], x += dx.
  template <class Solver>
  void remove_normal_part(const Model& model, const Workspace<Model>& ws, Solver& solver,
                          Eigen::Ref<Eigen::VectorXd> x) {
    rhs_.head(nv_total_).setZero();
    jacobian_times(model, ws, x, rhs_.tail(m_));
    rhs_.tail(m_) = -rhs_.tail(m_);
    solver.solve(rhs_, solution_);
    x += solution_.head(nv_total_);
  }

  /// Removes the velocity residual that velocity_residual() computed last:
  /// [M Phi_q^T; Phi_q 0] [dv; mu] = [0; -(Phi_q v + Phi_t)], then the frames at the new v.
  template <class Solver>
  void correct_velocities(const Model& model, Workspace<Model>& ws, Solver& solver) {
    rhs_.head(nv_total_).setZero();
    rhs_.tail(m_) = -velocity_residual_;
    solver.solve(rhs_, solution_);
    ws.v += solution_.head(nv_total_);
    update_frames(model, ws);
  }

 private:
  Eigen::Index nv_total_ = 0, m_ = 0;
  Eigen::VectorXd rhs_, solution_, velocity_residual_;
};

}  // namespace odyn
