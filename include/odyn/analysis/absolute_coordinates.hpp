#pragma once
// The coordinates an integrator steps, with the operations it needs on them. Here the model's
// own: every body's position and orientation (absolute coordinates), all joints as constraint
// equations. analysis/joint_coordinates.hpp offers the other choice.
//
// Two views of one interface. An explicit integrator's state is y = (positions, velocities),
// loaded and read back whole. An implicit one (generalized-alpha) iterates in place on the
// coordinates' own vectors (positions(), velocities(), accelerations(), multipliers()), asks for
// the residual of the equations of motion and solves with the Newton matrix. Either way an
// operation reads and writes the workspace, so that element blocks, events and observers see
// the bodies' frames.
//
// Factorizations. Most integrators need one matrix at a time; BDF keeps three apart (its Newton
// matrix, the projection's mass-constraint matrix, and one for output points), so the
// operations that factorize or solve take a `slot`, 0 unless said otherwise, and the
// constructor says how many slots there are.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <vector>

#include "odyn/analysis/constraint_projection.hpp"
#include "odyn/analysis/minimum_norm.hpp"
#include "odyn/analysis/saddle_point.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/analysis/velocity_coordinates.hpp"
#include "odyn/core/implicit_configuration.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/linalg/all_finite.hpp"

namespace odyn {

template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
class AbsoluteCoordinates {
 public:
  static constexpr const char* name = "absolute";
  /// What an implicit integrator's failure message adds: nothing here.
  static constexpr const char* newton_advice = "";

  static constexpr int max_slots = 3;

  AbsoluteCoordinates(const Model& model, Workspace<Model>& ws,
                      LinearSolver linear_solver = LinearSolver::automatic, int slots = 1)
      : model_(model),
        ws_(ws),
        projection_(model),
        increment_(Eigen::VectorXd::Zero(model.num_velocities())),
        inverse_mass_diagonal_(Eigen::VectorXd::Zero(model.num_velocities())) {
    for (int slot = 0; slot < std::clamp(slots, 1, max_slots); ++slot) {
      solvers_[slot].choose(linear_solver);
      solvers_[slot].analyze(model);
    }
    for (int b = 1; b <= model.num_bodies(); ++b)
      inverse_mass_diagonal_.template segment<Model::nv>((b - 1) * Model::nv) =
          model.body(BodyId{b}).mass_block().diagonal().cwiseInverse();
  }

  Eigen::Index num_positions() const { return model_.num_coordinates(); }
  Eigen::Index num_velocities() const { return model_.num_velocities(); }
  Eigen::Index num_equations() const { return model_.num_equations(); }

  /// What each velocity coordinate is: a body's travel along a global axis, or its turn about
  /// one of its own axes (its angle, in the plane).
  std::vector<VelocityCoordinate> velocity_coordinates() const {
    using Space = typename Model::Space;
    std::vector<VelocityCoordinate> out;
    for (int b = 1; b <= model_.num_bodies(); ++b)
      for (int k = 0; k < Space::nv; ++k)
        out.push_back({model_.body(BodyId{b}).name, Space::velocity_labels[k], k >= Space::dim});
    return out;
  }

  /// y = (q, v) of the workspace.
  void read_state(Eigen::VectorXd& y) const { y << ws_.q, ws_.v; }

  /// The workspace at (t, y): unit quaternions, and the frames.
  void load(double t, const Eigen::VectorXd& y) {
    ws_.t = t;
    ws_.q = y.head(num_positions());
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::normalize(ws_.q.template segment<Model::nq>(b * Model::nq));
    ws_.v = y.tail(num_velocities());
    odyn::update_frames(model_, ws_);
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
  bool factorize() { return solvers_[0].factorize(model_, ws_, IterationFactors{}); }
  /// The last factorization's smallest pivot relative to the diagonal of the Schur complement
  /// (see BlockSchurSaddlePoint::pivot_ratio): small near a singular configuration. 1 for a
  /// solver that does not tell.
  double pivot_ratio() const {
    if constexpr (requires(const Solver& solver) { solver.pivot_ratio(); })
      return solvers_[0].pivot_ratio();
    else
      return 1.0;
  }
  /// v' and lambda at the loaded state with the matrix factorized last (in that slot).
  bool solve_accelerations(int slot = 0) {
    return projection_.solve_accelerations(model_, ws_, solvers_[slot]);
  }

  const Eigen::VectorXd& accelerations() const { return ws_.vdot; }
  const Eigen::VectorXd& multipliers() const { return ws_.lambda; }
  // An implicit integrator's iterate: the workspace's own q, v, v' and lambda.
  Eigen::VectorXd& positions() { return ws_.q; }
  Eigen::VectorXd& velocities() { return ws_.v; }
  const Eigen::VectorXd& positions() const { return ws_.q; }
  const Eigen::VectorXd& velocities() const { return ws_.v; }
  Eigen::VectorXd& accelerations() { return ws_.vdot; }
  Eigen::VectorXd& multipliers() { return ws_.lambda; }
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
  void correct_positions(int slot = 0) {
    projection_.correct_positions(model_, ws_, solvers_[slot]);
  }
  /// The part of a local error estimate e = (e_q, e_v) that outlives the projection ending the
  /// step: the corrections move along M^-1 Phi_q^T and remove what Phi_q measures, so to first
  /// order only e - M^-1 Phi_q^T (Phi_q M^-1 Phi_q^T)^-1 Phi_q e is kept, for each part, with the
  /// matrix factorized last (at a stage within the step, near its end). A quaternion's error
  /// is taken as a turn, its change of length dropped (load() normalizes).
  void keep_tangential(Eigen::Ref<Eigen::VectorXd> error) {
    if (num_equations() == 0) return;
    constexpr int nq = Model::nq, nv = Model::nv;
    increment_of(ws_.q, error.head(num_positions()), increment_);
    projection_.remove_normal_part(model_, ws_, solvers_[0], increment_);
    for (int b = 0; b < model_.num_bodies(); ++b)
      error.template segment<nq>(b * nq) = Model::Space::configuration_rate(
          ws_.q.template segment<nq>(b * nq), increment_.template segment<nv>(b * nv));
    projection_.remove_normal_part(model_, ws_, solvers_[0], error.tail(num_velocities()));
  }

  /// max |Phi_q v + Phi_t| at the loaded state (constraints evaluated).
  double velocity_residual() {
    return num_equations() > 0 ? projection_.velocity_residual(model_, ws_).cwiseAbs().maxCoeff()
                               : 0.0;
  }

  /// Removes Phi_q v + Phi_t, least change in the mass metric.
  void correct_velocities(int slot = 0) {
    projection_.velocity_residual(model_, ws_);
    projection_.correct_velocities(model_, ws_, solvers_[slot]);
  }

  /// Phi_q v + Phi_t at the loaded state (constraints evaluated).
  const Eigen::VectorXd& velocity_constraint_values() {
    return projection_.velocity_residual(model_, ws_);
  }

  // ---- What an implicit integrator asks for besides (see the file's comment).

  /// The frames (positions and velocities) from positions() and velocities().
  void update_frames() { odyn::update_frames(model_, ws_); }

  /// to = from moved by a configuration increment (translations added, rotations composed on
  /// the right).
  void integrate(const Eigen::VectorXd& from, const Eigen::VectorXd& increment,
                 Eigen::VectorXd& to) const {
    constexpr int nq = Model::nq, nv = Model::nv;
    for (int b = 0; b < model_.num_bodies(); ++b)
      Model::Space::integrate(from.template segment<nq>(b * nq),
                              increment.template segment<nv>(b * nv),
                              to.template segment<nq>(b * nq));
  }

  /// The increment whose rate of the positions at q is `change` (the inverse of the
  /// configuration rate there): a quaternion's change along itself is dropped.
  void increment_of(const Eigen::Ref<const Eigen::VectorXd>& q,
                    const Eigen::Ref<const Eigen::VectorXd>& change,
                    Eigen::Ref<Eigen::VectorXd> out) const {
    constexpr int nq = Model::nq, nv = Model::nv;
    for (int b = 0; b < model_.num_bodies(); ++b)
      out.template segment<nv>(b * nv) = Model::Space::increment_of(
          q.template segment<nq>(b * nq), change.template segment<nq>(b * nq));
  }

  /// positions() = q with q = beta + c T(q) w, T the configuration rate (affine in q, so that
  /// each body's q solves a small linear system), then normalized: the implicit position
  /// update of a BDF step (see integrators/bdf.hpp) for the velocities w.
  void implicit_positions(const Eigen::Ref<const Eigen::VectorXd>& beta, double c,
                          const Eigen::VectorXd& w) {
    constexpr int nq = Model::nq, nv = Model::nv;
    for (int b = 0; b < model_.num_bodies(); ++b)
      implicit_configuration<typename Model::Space>(
          beta.template segment<nq>(b * nq), c,
          Eigen::Matrix<double, nv, 1>(w.template segment<nv>(b * nv)),
          ws_.q.template segment<nq>(b * nq));
  }

  /// M v' - Q + Phi_q^T lambda at the workspace's state (blocks and forces evaluated).
  void dynamics_residual(Eigen::Ref<Eigen::VectorXd> out) const {
    mass_times(model_, ws_.vdot, out);
    out -= ws_.force;
    add_jacobian_transpose_times(model_, ws_, ws_.lambda, out);
  }

  /// Phi at the loaded positions (constraints evaluated).
  const Eigen::VectorXd& constraint_values() const { return ws_.phi; }

  /// The Newton matrix [M + damping C + stiffness K, Phi_q^T; Phi_q, 0] (see IterationFactors).
  bool factorize(const IterationFactors& factors, int slot = 0) {
    return solvers_[slot].factorize(model_, ws_, factors);
  }
  /// x = the factorized matrix's inverse times rhs (velocities, then equations): a Newton
  /// correction, which leaves the multipliers of pinned redundant equations where they are.
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x, int slot = 0) {
    if constexpr (requires { solvers_[slot].solve_correction(rhs, x); })
      solvers_[slot].solve_correction(rhs, x);
    else
      solvers_[slot].solve(rhs, x);
  }
  /// Equations that repeat others in the last factorization (run with minimum-norm multipliers).
  int rank_deficiency(int slot = 0) const {
    return static_cast<int>(solvers_[slot].rank_deficiency());
  }
  /// How much the geometric stiffness weighed in the last factorization (see the solver).
  double geometric_share() const { return solvers_[0].geometric_share(); }
  /// With redundant equations, the multipliers of least norm among those that give the same
  /// constraint forces (their reactions are then one choice among many), unless the solver
  /// pinned the redundant ones (large models), or pinned them for the corrections alone (small
  /// models: then the iteration never moved them along the null space, and outputs, solved
  /// outright, are minimum-norm). `exact` computes them afresh from the current Jacobian in
  /// every case (an output that is not solved outright).
  void make_multipliers_unique(int slot = 0, bool exact = false) {
    Solver& solver = solvers_[slot];
    if (!needs_minimum_norm_multipliers(solver)) return;
    if constexpr (requires { solver.corrections_pinned(); })
      if (!exact && solver.corrections_pinned()) return;
    make_multipliers_minimum_norm(model_, ws_);
  }

  /// True if Newton's corrections with the slot's last factorization contract as a regular
  /// matrix's do: no equation repeats others, or those that do keep their multipliers (see
  /// solve()).
  bool regular_corrections(int slot = 0) const {
    if constexpr (requires { solvers_[slot].corrections_pinned(); })
      if (solvers_[slot].corrections_pinned()) return true;
    return rank_deficiency(slot) == 0;
  }

  /// max |M^-1 r| by the mass matrix's diagonal: a cheap estimate of the next Newton correction
  /// of v' for the residual r.
  double estimated_correction(const Eigen::Ref<const Eigen::VectorXd>& r) const {
    return r.cwiseProduct(inverse_mass_diagonal_).cwiseAbs().maxCoeff();
  }

  /// The scale of each velocity coordinate's error (see Space::coordinate_scale).
  void error_scale(Eigen::VectorXd& out) const {
    for (int b = 0; b < model_.num_bodies(); ++b)
      out.template segment<Model::nv>(b * Model::nv) =
          Model::Space::coordinate_scale(ws_.q.template segment<Model::nq>(b * Model::nq));
  }

  /// The largest coordinate of a body's position: the rounding in Phi scales with it.
  double largest_position() const {
    double largest = 0.0;
    for (int b = 0; b < model_.num_bodies(); ++b)
      largest = std::max(
          largest, ws_.q.template segment<Model::Space::dim>(b * Model::nq).cwiseAbs().maxCoeff());
    return largest;
  }

 private:
  const Model& model_;
  Workspace<Model>& ws_;
  std::array<Solver, max_slots> solvers_;  // the slots' factorizations (see the file's comment)
  ConstraintProjection<Model> projection_;
  Eigen::VectorXd increment_;  // a position error in velocity coordinates
  Eigen::VectorXd inverse_mass_diagonal_;
};

}  // namespace odyn
