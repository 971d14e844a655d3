#pragma once
// The coordinates an explicit integrator steps, with the operations it needs on them. Here the
// model's own: every body's position and orientation (absolute coordinates), all joints as
// constraint equations. analysis/joint_coordinates.hpp offers the other choice.
//
// The integrator's state is y = (positions, velocities); an operation reads and writes the
// workspace, so that element blocks, events and observers see the bodies' frames either way.

#include <Eigen/Core>

#include "odyn/analysis/constraint_projection.hpp"
#include "odyn/analysis/saddle_point.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/linalg/all_finite.hpp"

namespace odyn {

template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
class AbsoluteCoordinates {
 public:
  static constexpr const char* name = "absolute";

  AbsoluteCoordinates(const Model& model, Workspace<Model>& ws,
                      LinearSolver linear_solver = LinearSolver::automatic)
      : model_(model),
        ws_(ws),
        projection_(model),
        increment_(Eigen::VectorXd::Zero(model.num_velocities())) {
    solver_.choose(linear_solver);
    solver_.analyze(model);
  }

  Eigen::Index num_positions() const { return model_.num_coordinates(); }
  Eigen::Index num_velocities() const { return model_.num_velocities(); }
  Eigen::Index num_equations() const { return model_.num_equations(); }

  /// y = (q, v) of the workspace.
  void read_state(Eigen::VectorXd& y) const { y << ws_.q, ws_.v; }

  /// The workspace at (t, y): unit quaternions, and the frames.
  void load(double t, const Eigen::VectorXd& y) {
    ws_.t = t;
    ws_.q = y.head(num_positions());
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::normalize(ws_.q.template segment<Model::nq>(b * Model::nq));
    ws_.v = y.tail(num_velocities());
    update_frames(model_, ws_);
  }

  /// The position rate q' for the velocities loaded last, at the positions held in y.
  void position_rate(const Eigen::VectorXd& y, Eigen::Ref<Eigen::VectorXd> rate) const {
    constexpr int nq = Model::nq, nv = Model::nv;
    for (int b = 0; b < model_.num_bodies(); ++b)
      rate.template segment<nq>(b * nq) = Model::Space::configuration_rate(
          y.template segment<nq>(b * nq), ws_.v.template segment<nv>(b * nv));
  }

  void evaluate_constraints() { odyn::evaluate_constraints(model_, ws_); }
  void evaluate_forces() { odyn::evaluate_forces(model_, ws_); }
  bool factorize() { return solver_.factorize(model_, ws_, IterationFactors{}); }
  /// v' and lambda at the loaded state with the matrix factorized last.
  bool solve_accelerations() { return projection_.solve_accelerations(model_, ws_, solver_); }

  const Eigen::VectorXd& accelerations() const { return ws_.vdot; }
  const Eigen::VectorXd& multipliers() const { return ws_.lambda; }
  /// Puts back accelerations and multipliers solved earlier for the loaded state.
  void restore_solution(const Eigen::VectorXd& vdot, const Eigen::VectorXd& lambda) {
    ws_.vdot = vdot;
    ws_.lambda = lambda;
  }

  bool state_finite() const { return all_finite(ws_.q) && all_finite(ws_.v); }

  /// max |Phi| at the loaded positions (constraints evaluated).
  double position_residual() const {
    return num_equations() > 0 ? ws_.phi.cwiseAbs().maxCoeff() : 0.0;
  }
  /// One (chord) correction towards Phi = 0, least distance in the mass metric.
  void correct_positions() { projection_.correct_positions(model_, ws_, solver_); }
  /// The part of a local error estimate e = (e_q, e_v) that outlives the projection ending the
  /// step: the corrections move along M^-1 Phi_q^T and remove what Phi_q measures, so to first
  /// order only e - M^-1 Phi_q^T (Phi_q M^-1 Phi_q^T)^-1 Phi_q e is kept, for each part, with the
  /// matrix factorized last (at a stage within the step, near its end). A quaternion's error
  /// is taken as a turn, its change of length dropped (load() normalizes).
  void keep_tangential(Eigen::Ref<Eigen::VectorXd> error) {
    if (num_equations() == 0) return;
    constexpr int nq = Model::nq, nv = Model::nv;
    for (int b = 0; b < model_.num_bodies(); ++b)
      increment_.template segment<nv>(b * nv) = Model::Space::increment_of(
          ws_.q.template segment<nq>(b * nq), error.template segment<nq>(b * nq));
    projection_.remove_normal_part(model_, ws_, solver_, increment_);
    for (int b = 0; b < model_.num_bodies(); ++b)
      error.template segment<nq>(b * nq) = Model::Space::configuration_rate(
          ws_.q.template segment<nq>(b * nq), increment_.template segment<nv>(b * nv));
    projection_.remove_normal_part(model_, ws_, solver_, error.tail(num_velocities()));
  }

  /// max |Phi_q v + Phi_t| at the loaded state (constraints evaluated).
  double velocity_residual() {
    return num_equations() > 0 ? projection_.velocity_residual(model_, ws_).cwiseAbs().maxCoeff()
                               : 0.0;
  }

  /// Removes Phi_q v + Phi_t, least change in the mass metric.
  void correct_velocities() {
    projection_.velocity_residual(model_, ws_);
    projection_.correct_velocities(model_, ws_, solver_);
  }

 private:
  const Model& model_;
  Workspace<Model>& ws_;
  Solver solver_;
  ConstraintProjection<Model> projection_;
  Eigen::VectorXd increment_;  // a position error in velocity coordinates
};

}  // namespace odyn
