#pragma once
// Joint coordinates: the bodies located through a spanning tree of the model's joints, so that
// only the joints that close loops stay constraint equations. The single-cylinder engine, for
// instance, becomes crank angle, piston travel and the two angles of the piston pin, closed by
// the crank pin's three equations: 4 coordinates and 3 equations instead of 18 and 17. A chain or
// a tree of ball joints has no equation left at all. Planar models work the same way in the
// plane (the planar engine: crank, rod and piston angles, closed by the cylinder's two
// equations), with motions and forces of 3 numbers instead of 6 (see tree_algebra.hpp).
//
// The tree. Joints that can carry a body (spatial::CarriesBody: revolute, translational,
// cylindrical, universal, fixed and spherical; planar::CarriesBody: revolute, translational
// and fixed) are taken greedily, most equations first
// (Kruskal), so that the joints left to close loops have the fewest equations; distances and
// drivers always close loops. A group of bodies that no tree joint ties to the ground gets a
// free root: one of its bodies keeps its own position and quaternion (angle, in the plane).
//
// The kinematics. A tree joint moves its child by a product of exponentials (see
// spatial/screw.hpp, planar/screw.hpp), measured from the assembled start (every joint coordinate 0
// there), or, for a ball joint, by a quaternion whose rates are the relative angular velocity in
// the child's axes (a free root's quaternion and rates work the same way). Every spatial quantity
// of a body (its twist (omega, v), its acceleration, its inertia, the wrenches on it) is given
// in global axes at the body's own centre of mass, so a parent and its child differ by the
// shift r = c_child - c_parent alone, and no lever arm grows with the distance from the global
// origin (a long chain loses no digits at its far end). Going down the tree gives every body's
// frame, its joint's motion columns S (twists per unit rate), its twist V and the acceleration
// its joint adds at zero coordinate acceleration, c.
//
// The equations. With A = J^T M J the mass matrix in joint coordinates (J maps joint rates to
// the bodies' twists) and C = Phi_q J the closures' Jacobian,
//     [A  C^T] [theta'']   [J^T (Q - velocity terms)]
//     [C  0  ] [lambda ] = [gamma - Phi_q c          ].
// A is never formed: the articulated-body algorithm (Featherstone, Rigid Body Dynamics
// Algorithms, 2008, ch. 7) factorizes it in one pass up the tree (factorize(): each body's
// articulated inertia, its joint's pivot block D = S^T I^A S) and solves A x = J^T w for any
// wrenches w in one pass up (the forces a subtree hands its parent) and one pass down (the
// accelerations): O(N) for N bodies, whatever the shape of the tree. The closures go through
// their Schur complement C A^-1 C^T (m x m, dense, from m tree solves at each factorization),
// so that each saddle-point solve is two tree solves and one solve with that complement; the
// cost is O(N (1 + m)): linear for trees and for models with few loops, while models with many
// loops (a ladder of four-bars) are better run in absolute coordinates. Models of a few bodies
// (up to dense_limit unknowns, the engine among them) form the saddle-point matrix instead (A
// by the composite-rigid-body algorithm) and factorize it L D L^T
// (linalg/saddle_point_ldlt.hpp): at that size, the passes cost more than the arithmetic.
//
// At output points complete_workspace() fills in what an absolute-coordinate run leaves in the
// workspace: q, v, v', every element's blocks and every lambda, the tree joints' from their
// bodies' own equations, leaves first (B B^T lambda = B (Q - M v' - the constraint forces
// already known), B the joint's block on its child; exact, since the equations are consistent).
//
// An implicit integrator (generalized-alpha, HHT, BDF) iterates on q, theta', theta'' and
// lambda in place: dynamics_residual() is the recursive Newton-Euler algorithm (the same passes
// with theta'' given), and its Newton matrix is [A C^T; C 0], factorized as above, with each
// body's own blocks of the springs' and dampers' stiffness and damping added to its inertia
// (see factorize(const IterationFactors&)). BDF keeps three such factorizations apart (slots:
// its Newton matrix, its projection's and its outputs').
//
// Redundant closures (Bricard's mechanism) are found at the start and their equations pinned
// (see check_closures): the factorizations cost what the model without them would.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "odyn/analysis/sparse_kkt.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/analysis/tree_algebra.hpp"
#include "odyn/analysis/velocity_coordinates.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/implicit_configuration.hpp"
#include "odyn/core/rotation.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/linalg/all_finite.hpp"
#include "odyn/linalg/linear_solver.hpp"
#include "odyn/linalg/pivoted_lu.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/saddle_point_ldlt.hpp"

namespace odyn {

namespace detail {

/// What the passes over the tree keep per body, in global axes at its centre (see
/// tree_algebra.hpp: a motion or a force has D = 6 numbers in space, 3 in the plane; a joint
/// has at most D degrees of freedom).
template <class Space>
struct TreeNodeState {
  using Algebra = TreeAlgebra<Space>;
  using Motion = typename Algebra::Motion;
  using MotionMatrix = typename Algebra::MotionMatrix;
  MotionMatrix motion = MotionMatrix::Zero();  // S: the joint's twists per unit rate (dof cols)
  Motion twist = Motion::Zero();               // V = (omega, v_centre)
  Motion bias = Motion::Zero();                // c: the joint's acceleration at zero theta''
  Motion pivot_force = Motion::Zero();         // u = -S^T p in a solve (dof entries)
  typename Algebra::Linear offset = Algebra::Linear::Zero();  // r = c_child - c_parent
};

/// One tree node's part of a factorization of A (the articulated-body algorithm's).
template <class Space>
struct NodeFactor {
  using MotionMatrix = typename TreeAlgebra<Space>::MotionMatrix;
  MotionMatrix articulated = MotionMatrix::Zero();    // I^A in factorize(), then I^A - U D^-1 U^T
  MotionMatrix projected = MotionMatrix::Zero();      // U = I^A S (dof cols)
  MotionMatrix inverse_pivot = MotionMatrix::Zero();  // D^-1 = (S^T I^A S)^-1 (dof x dof)
};

/// One closure's Jacobian block on one body in spatial form, G = [Phi_angular R^T,
/// Phi_linear], so that Phi_q v = G V with V the body's twist at its centre.
template <class Space>
struct ClosureBlock {
  static constexpr int max_rows = 6;  // an element's equations
  int node = 0;                       // the body's place in tree_
  int row = 0;                        // first row in the closures' equations
  int count = 0;                      // rows
  Eigen::Matrix<double, max_rows, TreeAlgebra<Space>::size> rows =
      Eigen::Matrix<double, max_rows, TreeAlgebra<Space>::size>::Zero();  // count rows used
};

}  // namespace detail

template <class Model>
class JointCoordinates {
  using Space = typename Model::Space;
  using Algebra = detail::TreeAlgebra<Space>;
  static constexpr bool spatial_model = std::is_same_v<Space, Spatial>;
  static constexpr int A = Algebra::angular;  // omega's components in a motion, at its head
  static constexpr int L = Algebra::linear;   // v's components, at its tail
  static constexpr int D = Algebra::size;
  using Motion = typename Algebra::Motion;
  using MotionMatrix = typename Algebra::MotionMatrix;
  using Linear = typename Algebra::Linear;
  using Quaternion = Eigen::Matrix<double, 4, 1>;  // (w, x, y, z)
  using Frame = typename Space::Frame;
  using Screw = typename Algebra::Screw;
  using ClosureBlock = detail::ClosureBlock<Space>;
  using NodeState = detail::TreeNodeState<Space>;
  using NodeFactor = detail::NodeFactor<Space>;

  /// A motion's angular part omega (a force's torque) and its linear part v (a force's force).
  template <class Vector>
  static auto angular(Vector& motion) {
    return motion.template head<A>();
  }
  template <class Vector>
  static auto linear(Vector& motion) {
    return motion.template tail<L>();
  }

 public:
  static constexpr const char* name = "joint";
  /// Up to this many unknowns (joint rates plus closure equations), the saddle-point matrix is
  /// formed and factorized whole (L D L^T, unrolled for small sizes), which costs less than the
  /// recursive passes on models of a few bodies, such as the engine; above it, the passes.
  static constexpr Eigen::Index dense_limit = 24;
  /// What an implicit integrator's failure message adds (see factorize(IterationFactors)).
  static constexpr const char* newton_advice =
      " In joint coordinates Newton's matrix keeps only each body's own blocks of the springs and "
      "dampers: where stiff ones join two bodies, absolute coordinates (coordinates 'absolute') "
      "converge better.";

  /// Builds the tree at the workspace's (assembled) state and takes that state as the start.
  /// (The closures' Schur complement is small and dense: `linear_solver` is not used.)
  /// Factorizations kept apart (see AbsoluteCoordinates): BDF's Newton matrix, its
  /// projection's and its outputs'. The operations without a slot use the one used last.
  static constexpr int max_slots = 3;

  JointCoordinates(const Model& model, Workspace<Model>& ws,
                   LinearSolver /*linear_solver*/ = LinearSolver::automatic, int slots = 1)
      : model_(model), ws_(ws), slots_(std::clamp(slots, 1, max_slots)) {
    if (const std::string friction = first_reaction_reader(model); !friction.empty())
      throw ModelError(friction,
                       "reads its joint's reaction, which joint coordinates do not solve while "
                       "stepping; run it in absolute coordinates (coordinates 'absolute' or "
                       "'auto')");
    odyn::update_frames(model, ws);
    build_tree();
    size_buffers();
    initial_state();
  }

  /// The closures' equations that the model's spanning tree leaves (the size of the dense
  /// Schur complement each factorization forms), from its joints alone: no state needed.
  static int closure_equations(const Model& model) {
    std::vector<Edge> edges;
    const TreeFlags in_tree = spanning_tree(model, edges);
    int count = 0;
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (Constraint<E>)
        for (std::size_t i = 0; i < pool.size(); ++i)
          if (!in_tree[type][i]) count += E::num_equations;
    });
    return count;
  }

  Eigen::Index num_positions() const { return q_.size(); }
  Eigen::Index num_velocities() const { return v_.size(); }
  Eigen::Index num_equations() const { return phi_.size(); }

  /// Names of the joints that carry bodies (tree joints) and of those that close loops.
  const std::vector<std::string>& tree_joints() const { return tree_names_; }
  const std::vector<std::string>& loop_closures() const { return closure_names_; }

  /// What each rate is: a tree joint's angle or travel (numbered where it has several), a ball
  /// joint's turn about the child's axes, a free root's travel along a global axis or turn about
  /// its own axes.
  std::vector<VelocityCoordinate> velocity_coordinates() const {
    std::vector<VelocityCoordinate> out;
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) {
        const std::string& body = model_.body(BodyId{node.body}).name;
        for (int k = 0; k < Space::nv; ++k)
          out.push_back({body, Space::velocity_labels[k], k >= Space::dim});
      } else if (node.kind == Kind::ball) {
        for (const char* turn : {"rx", "ry", "rz"}) out.push_back({node.joint, turn, true});
      } else {
        int turns = 0, travels = 0;
        for (const Screw& screw : node.screws)
          (screw.kind == Screw::Kind::rotation ? turns : travels) += 1;
        int turn = 0, travel = 0;
        for (const Screw& screw : node.screws) {
          const bool angular = screw.kind == Screw::Kind::rotation;
          const int number = angular ? ++turn : ++travel;
          // Appended piecewise: GCC 12's -Wrestrict misreads `" " + std::to_string(n)` at -O2.
          std::string label = angular ? "angle" : "travel";
          if ((angular ? turns : travels) > 1) {
            label += ' ';
            label += std::to_string(number);
          }
          out.push_back({node.joint, std::move(label), angular});
        }
      }
    }
    return out;
  }

  /// y = (joint coordinates, their rates).
  void read_state(Eigen::VectorXd& y) const { y << q_, v_; }

  /// The workspace at (t, y): every body's frame from the tree.
  void load(double t, const Eigen::VectorXd& y) {
    ws_.t = t;
    q_ = y.head(num_positions());
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) Space::normalize(q_.segment<Space::nq>(node.q_offset));
      if (node.kind == Kind::ball) q_.segment<4>(node.q_offset).normalize();
    }
    v_ = y.tail(num_velocities());
    update_kinematics();
  }

  /// The coordinates' rate for the rates loaded last, at the positions held in y: a joint
  /// coordinate moves with its rate, a quaternion as in Spatial.
  void position_rate(const Eigen::VectorXd& y, Eigen::Ref<Eigen::VectorXd> rate) const {
    configuration_change(y, v_, rate);
  }

  /// The closures' Phi and blocks, and their rows of C in spatial form (see ClosureBlock).
  void evaluate_constraints() {
    std::size_t next = 0;
    for_each_closure([&]<class E>(const E& element, const StateOf<E>& state, BlocksOf<E>& blocks,
                                  int row, int model_row) {
      constexpr int m = E::num_equations;
      evaluate_constraint(element, detail::input_of(element, ws_.frames, ws_.t), state, blocks);
      phi_.segment<m>(row) = blocks.phi;
      phi_t_.segment<m>(row) = blocks.phi_t;
      ws_.phi.template segment<m>(model_row) = blocks.phi;
      ws_.phi_t.template segment<m>(model_row) = blocks.phi_t;
      for (int k = 0; k < E::num_bodies; ++k) {
        const int b = element.bodies()[k].index;
        if (b == 0) continue;
        // Phi_q v = Phi_linear v_centre + Phi_angular R^T omega = G (omega, v_centre).
        ClosureBlock& block = closure_blocks_[next++];
        block.rows.template topLeftCorner<m, A>().noalias() =
            blocks.jacobian[k].template rightCols<A>() * Algebra::axes(ws_.frames[b]).transpose();
        block.rows.template topRightCorner<m, L>() = blocks.jacobian[k].template leftCols<L>();
      }
    });
  }

  void evaluate_forces() { odyn::evaluate_forces(model_, ws_); }

  /// Factorizes at the loaded positions, with C from evaluate_constraints: small models the
  /// whole saddle-point matrix (see dense_limit), others A by its articulated inertias (up the
  /// tree) and the closures' Schur complement C A^-1 C^T. False if A or the Schur complement
  /// is not positive definite (or the saddle-point matrix has a pivot of the wrong sign).
  bool factorize() {
    load_inertias();
    return factorize_loaded();
  }

  /// The bodies' inertias at their centres, global axes, into the articulated inertias that
  /// factorize_loaded() starts from.
  void load_inertias() {
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const auto& body = model_.body(BodyId{tree_[i].body});
      const auto& rotation = Algebra::axes(ws_.frames[tree_[i].body]);
      MotionMatrix& inertia = factor(i).articulated;
      inertia.setZero();
      inertia.template topLeftCorner<A, A>().noalias() =
          rotation * Algebra::inertia(body.inertia) * rotation.transpose();
      inertia.template bottomRightCorner<L, L>().diagonal().setConstant(body.mass);
    }
  }

  bool factorize_loaded() {
    if (dense_) return factorize_dense();
    for (std::size_t i = tree_.size(); i-- > 0;) {
      const bool positive = with_dof(tree_[i].dof(), [&]<int K>() { return factor_node<K>(i); });
      if (!positive) return false;
    }
    if (num_equations() == 0) return true;
    // Column j of C A^-1 C^T: the closures' rates of the tree's motion under the unit
    // multiplier e_j (the wrenches C^T e_j).
    const Eigen::Index m = num_equations();
    for (Eigen::Index j = 0; j < m; ++j) {
      multiplier_.setZero();
      multiplier_[j] = 1.0;
      clear(force_);
      add_closure_wrenches(multiplier_, -1.0, force_);  // p = -(C^T e_j)
      tree_solve(false, increment_, motion_);
      closure_rates(motion_, schur_.col(j));
    }
    if (!pinned_rows_.empty())  // LLT reads the lower triangle, which this clears
      pin_closure_rows(schur_, 0, schur_.diagonal().cwiseAbs().maxCoeff());
    schur_llts_[slot_].compute(schur_);
    return schur_llts_[slot_].info() == Eigen::Success;
  }

  /// theta'' and the closures' lambda at the loaded state, with the matrix factorized last.
  bool solve_accelerations(int slot) {
    slot_ = slot;
    return solve_accelerations();
  }
  bool solve_accelerations() {
    odyn::evaluate_forces(model_, ws_);
    // Each body's bias force: its velocity terms (m omega x v_centre in spatial form at the
    // centre; Q already holds the gyroscopic torque) less its applied wrench (global axes).
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const int b = tree_[i].body;
      const Frame& frame = ws_.frames[b];
      const Motion& twist = nodes_[i].twist;
      const double mass = model_.body(BodyId{b}).mass;
      angular(force_[i]).noalias() = -(Algebra::axes(frame) * torque_on(b));
      linear(force_[i]) = mass * Algebra::turn(angular(twist), linear(twist)) - force_on(b);
    }
    closure_gamma(closure_rhs_);
    saddle_solve(true, true, closure_rhs_, qdd_, lambda_);
    return all_finite(qdd_) && all_finite(lambda_);
  }

  const Eigen::VectorXd& accelerations() const { return qdd_; }
  const Eigen::VectorXd& multipliers() const { return lambda_; }
  // An implicit integrator's iterate: the joint coordinates, rates, their rates and lambda.
  Eigen::VectorXd& positions() { return q_; }
  Eigen::VectorXd& velocities() { return v_; }
  const Eigen::VectorXd& positions() const { return q_; }
  const Eigen::VectorXd& velocities() const { return v_; }
  Eigen::VectorXd& accelerations() { return qdd_; }
  Eigen::VectorXd& multipliers() { return lambda_; }
  void restore_solution(const Eigen::VectorXd& qdd, const Eigen::VectorXd& lambda) {
    qdd_ = qdd;
    lambda_ = lambda;
  }
  bool state_finite() const { return all_finite(q_) && all_finite(v_); }

  double position_residual() const {
    return num_equations() > 0 ? phi_.cwiseAbs().maxCoeff() : 0.0;
  }

  /// One (chord) correction towards the closures' Phi = 0, least distance in A:
  /// [A C^T; C 0] [dx; mu] = [0; -Phi].
  void correct_positions(int slot) {
    slot_ = slot;
    correct_positions();
  }
  void correct_positions() {
    closure_rhs_ = -phi_;
    saddle_solve(false, false, closure_rhs_, increment_, multiplier_);
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) {
        const Eigen::Matrix<double, Space::nq, 1> from = q_.segment<Space::nq>(node.q_offset);
        Space::integrate(from, increment_.segment<Space::nv>(node.v_offset),
                         q_.segment<Space::nq>(node.q_offset));
      } else if (node.kind == Kind::ball) {
        turn(q_.segment<4>(node.q_offset), increment_.segment<3>(node.v_offset));
      } else {
        q_.segment(node.q_offset, node.dof()) += increment_.segment(node.v_offset, node.dof());
      }
    }
    update_kinematics();
    evaluate_constraints();
  }

  /// The part of a local error estimate e = (e_q, e_v) that outlives the projection ending the
  /// step. correct_positions and correct_velocities move along A^-1 C^T and remove what C
  /// measures, so to first order only e - A^-1 C^T (C A^-1 C^T)^-1 C e is kept, for each part;
  /// the matrix is the one factorized last (at a stage within the step, near its end). A
  /// quaternion's error is taken as a turn, its change of length dropped (load() normalizes).
  void keep_tangential(Eigen::Ref<Eigen::VectorXd> error) {
    if (num_equations() == 0) return;
    increment_of(q_, error.head(num_positions()), increment_);
    remove_normal_part(increment_);
    configuration_change(q_, increment_, error);
    remove_normal_part(error.tail(num_velocities()));
  }

  /// max |C theta' + Phi_t| at the loaded state (constraints evaluated).
  double velocity_residual() {
    if (num_equations() == 0) return 0.0;
    closure_rates_of([&](int i) -> const Motion& { return nodes_[i].twist; }, closure_rhs_);
    return (closure_rhs_ + phi_t_).cwiseAbs().maxCoeff();
  }

  /// Removes C theta' + Phi_t, least change in A.
  void correct_velocities(int slot) {
    slot_ = slot;
    correct_velocities();
  }
  void correct_velocities() {
    closure_rates_of([&](int i) -> const Motion& { return nodes_[i].twist; }, closure_rhs_);
    closure_rhs_ = -(closure_rhs_ + phi_t_);
    saddle_solve(false, false, closure_rhs_, increment_, multiplier_);
    v_ += increment_;
    update_velocities();
  }

  // ---- What an implicit integrator (generalized-alpha) asks for besides: it iterates on
  // positions(), velocities(), accelerations() and multipliers() in place.

  /// The frames, motion columns and twists from positions() and velocities().
  void update_frames() { update_kinematics(); }

  /// The increment in rate coordinates whose rate of the coordinates at q is `change` (the
  /// inverse of the coordinates' rate there): a quaternion's change along itself is dropped.
  void increment_of(const Eigen::Ref<const Eigen::VectorXd>& q,
                    const Eigen::Ref<const Eigen::VectorXd>& change,
                    Eigen::Ref<Eigen::VectorXd> out) const {
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free)
        out.segment<Space::nv>(node.v_offset) = Space::increment_of(
            q.segment<Space::nq>(node.q_offset), change.segment<Space::nq>(node.q_offset));
      else if (node.kind == Kind::ball)
        out.segment<3>(node.v_offset) =
            turn_of(q.segment<4>(node.q_offset), change.segment<4>(node.q_offset));
      else
        out.segment(node.v_offset, node.dof()) = change.segment(node.q_offset, node.dof());
    }
  }

  /// to = from moved by an increment in rate coordinates: a joint coordinate by its increment,
  /// a ball joint's or free root's rotation composed on the right.
  void integrate(const Eigen::VectorXd& from, const Eigen::VectorXd& increment,
                 Eigen::VectorXd& to) const {
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) {
        Space::integrate(from.segment<Space::nq>(node.q_offset),
                         increment.segment<Space::nv>(node.v_offset),
                         to.segment<Space::nq>(node.q_offset));
      } else if (node.kind == Kind::ball) {
        to.segment<4>(node.q_offset) = from.segment<4>(node.q_offset);
        turn(to.segment<4>(node.q_offset), increment.segment<3>(node.v_offset));
      } else {
        to.segment(node.q_offset, node.dof()) =
            from.segment(node.q_offset, node.dof()) + increment.segment(node.v_offset, node.dof());
      }
    }
  }

  /// A theta'' + C^T lambda - J^T (Q - the velocity terms) at the loaded state, forces
  /// evaluated, for the held theta'' and lambda: the recursive Newton-Euler algorithm, the
  /// bodies' accelerations down the tree, then each body's unbalanced wrench, summed up the
  /// tree and projected on its joint's motions. O(N).
  void dynamics_residual(Eigen::Ref<Eigen::VectorXd> out) {
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const TreeBody& node = tree_[i];
      Motion acceleration = nodes_[i].bias;
      if (node.parent_node >= 0)
        acceleration += shifted_motion(motion_[node.parent_node], nodes_[i].offset);
      acceleration.noalias() +=
          nodes_[i].motion.leftCols(node.dof()) * qdd_.segment(node.v_offset, node.dof());
      motion_[i] = acceleration;
      // The body's inertia times its acceleration, plus its velocity terms, less what acts on
      // it (the gyroscopic torque is part of Q), at its centre in global axes.
      const int b = node.body;
      const auto& body = model_.body(BodyId{b});
      const auto& rotation = Algebra::axes(ws_.frames[b]);
      const Motion& twist = nodes_[i].twist;
      angular(force_[i]).noalias() =
          rotation *
          (Algebra::inertia(body.inertia) * (rotation.transpose() * angular(acceleration)) -
           torque_on(b));
      linear(force_[i]) =
          body.mass * (linear(acceleration) + Algebra::turn(angular(twist), linear(twist))) -
          force_on(b);
    }
    add_closure_wrenches(lambda_, 1.0, force_);
    for (std::size_t i = tree_.size(); i-- > 0;) {
      const TreeBody& node = tree_[i];
      out.segment(node.v_offset, node.dof()).noalias() =
          nodes_[i].motion.leftCols(node.dof()).transpose() * force_[i];
      if (node.parent_node >= 0)
        add_shifted_force(force_[i], nodes_[i].offset, force_[node.parent_node]);
    }
  }

  /// The closures' Phi at the loaded positions (constraints evaluated).
  const Eigen::VectorXd& constraint_values() const { return phi_; }

  /// C (m x n): the closures' Jacobian in the joint rates at the loaded positions (constraints
  /// evaluated), a pass down the tree per column. For the analyses that solve with C itself
  /// (a fully driven mechanism's kinematics), where A's conditioning has no part to play.
  void closure_jacobian(Eigen::MatrixXd& out) {
    out.resize(num_equations(), num_velocities());
    increment2_.setZero();
    for (Eigen::Index j = 0; j < num_velocities(); ++j) {
      increment2_[j] = 1.0;
      motions_of_rates(increment2_, motion2_);
      closure_rates(motion2_, out.col(j));
      increment2_[j] = 0.0;
    }
  }

  /// C theta'' - (gamma - Phi_q c) for the held theta'' at the loaded state (constraints
  /// evaluated), c the bodies' accelerations at zero theta'': what the closures' acceleration
  /// equations leave unmet.
  const Eigen::VectorXd& acceleration_constraint_values() {
    closure_gamma(closure_rhs_);
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      motion_[i] = nodes_[i].bias;
      if (tree_[i].parent_node >= 0)
        motion_[i] += shifted_motion(motion_[tree_[i].parent_node], nodes_[i].offset);
      motion_[i].noalias() += nodes_[i].motion.leftCols(tree_[i].dof()) *
                              qdd_.segment(tree_[i].v_offset, tree_[i].dof());
    }
    closure_rates(motion_, acceleration_values_);
    acceleration_values_ -= closure_rhs_;
    return acceleration_values_;
  }

  /// C theta' + Phi_t at the loaded state (constraints evaluated).
  const Eigen::VectorXd& velocity_constraint_values() {
    closure_rates_of([&](int i) -> const Motion& { return nodes_[i].twist; }, velocity_values_);
    velocity_values_ += phi_t_;
    return velocity_values_;
  }

  /// positions() = q with q = beta + c T(q) w (T the coordinates' rate, affine in q: each
  /// joint's q solves a small linear system), quaternions normalized: BDF's implicit position
  /// update (see integrators/bdf.hpp) for the rates w.
  void implicit_positions(const Eigen::Ref<const Eigen::VectorXd>& beta, double c,
                          const Eigen::VectorXd& w) {
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) {
        implicit_configuration<Space>(
            beta.segment<Space::nq>(node.q_offset), c,
            Eigen::Matrix<double, Space::nv, 1>(w.segment<Space::nv>(node.v_offset)),
            q_.segment<Space::nq>(node.q_offset));
      } else if (node.kind == Kind::ball) {
        // q' = q (0, w) / 2 = R(w) q: (1 - c R(w)) q = beta.
        const Eigen::Vector3d rate = w.segment<3>(node.v_offset);
        Eigen::Matrix4d matrix;
        matrix << 0.0, -rate[0], -rate[1], -rate[2],  //
            rate[0], 0.0, rate[2], -rate[1],          //
            rate[1], -rate[2], 0.0, rate[0],          //
            rate[2], rate[1], -rate[0], 0.0;
        matrix = Eigen::Matrix4d::Identity() - (0.5 * c) * matrix;
        auto q = q_.segment<4>(node.q_offset);
        q = solve_small<4>(matrix, Eigen::Vector4d(beta.segment<4>(node.q_offset)));
        q.normalize();
      } else {
        q_.segment(node.q_offset, node.dof()) =
            beta.segment(node.q_offset, node.dof()) + c * w.segment(node.v_offset, node.dof());
      }
    }
  }

  /// The Newton matrix of an implicit integrator: [A C^T; C 0] with A the mass matrix in joint
  /// coordinates plus J^T (stiffness K + damping C) J, where K and C keep only each body's own
  /// blocks of the force elements' stiffness and damping (and of its gyroscopic terms), their
  /// symmetric part: the blocks that couple two bodies would couple the whole tree, and leaving
  /// them out keeps A's recursive factorization. The derivatives of A itself and of the
  /// velocity terms of the tree are left out too: a modified Newton iteration, which converges
  /// wherever the mass over h^2 and the bodies' own blocks outweigh what it leaves out.
  bool factorize(const IterationFactors& factors, int slot = 0) {
    slot_ = slot;
    if (factors.stiffness == 0.0 && factors.damping == 0.0) return factorize();
    load_inertias();
    add_own_force_blocks(factors.stiffness, factors.damping);
    if (factorize_loaded()) return true;
    return factorize();  // the blocks spoiled positive definiteness: the mass matrix alone
  }

  /// x = [A C^T; C 0]^-1 rhs with the last factorization (rates, then closure equations).
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x, int slot = 0) {
    slot_ = slot;
    const Eigen::Index n = num_velocities(), m = num_equations();
    joint_rhs_ = rhs.head(n);
    closure_rhs_ = rhs.tail(m);
    clear(force_);
    saddle_solve(true, false, closure_rhs_, x.head(n), x.tail(m), &joint_rhs_);
  }

  // Redundant closures are pinned (check_closures): no minimum-norm projection; the matrix
  // leaves out the geometric stiffness.
  int rank_deficiency(int /*slot*/ = 0) const { return 0; }
  double geometric_share() const { return 0.0; }
  void make_multipliers_unique(int /*slot*/ = 0, bool /*exact*/ = false) {}
  bool regular_corrections(int /*slot*/ = 0) const { return true; }

  /// max |A^-1 r|, one solve along the tree (the closures left out): the next Newton
  /// correction of theta'' for the residual r, about.
  double estimated_correction(const Eigen::Ref<const Eigen::VectorXd>& r) {
    joint_rhs_ = r;
    if (dense_) {
      // The small models' factorization is of the whole saddle-point matrix: solve with it.
      closure_rhs_.setZero();
      clear(force_);
      saddle_solve(true, false, closure_rhs_, estimate_, multiplier_, &joint_rhs_);
    } else {
      clear(force_);
      tree_solve(false, estimate_, motion2_, &joint_rhs_);
    }
    return estimate_.cwiseAbs().maxCoeff();
  }

  /// The scale of each rate coordinate's error: a free root's as in Spatial, a sliding joint's
  /// its travel, turns 1.
  void error_scale(Eigen::VectorXd& out) const {
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) {
        out.segment<Space::nv>(node.v_offset) =
            Space::coordinate_scale(q_.segment<Space::nq>(node.q_offset));
      } else if (node.kind == Kind::ball) {
        out.segment<3>(node.v_offset).setOnes();
      } else {
        for (int k = 0; k < node.dof(); ++k)
          out[node.v_offset + k] =
              node.screws[k].kind == Screw::Kind::rotation ? 1.0 : std::abs(q_[node.q_offset + k]);
      }
    }
  }

  /// The smallest pivot of the closures' Schur complement S = C A^-1 C^T in the last
  /// factorization, relative to S's largest diagonal entry: about sigma^2 of C's rows, small
  /// near a singular configuration (as AbsoluteCoordinates::pivot_ratio). Pinned rows left
  /// out; 1 without closures.
  double pivot_ratio() const {
    double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
    const auto pinned = [&](int row) {
      return std::binary_search(pinned_rows_.begin(), pinned_rows_.end(), row);
    };
    const int m = static_cast<int>(num_equations());
    for (int i = 0; i < m; ++i) {
      if (pinned(i)) continue;
      double pivot, diagonal;
      if (dense_) {
        pivot = kkt_ldlts_[slot_].schur_pivot(i);
        diagonal = kkt_ldlts_[slot_].schur_diagonal(i);
      } else {  // S = L L^T: the pivot L(i, i)^2, the diagonal the squared norm of L's row
        const auto row = schur_llts_[slot_].matrixLLT().row(i).head(i + 1);
        pivot = row[i] * row[i];
        diagonal = row.squaredNorm();
      }
      smallest = std::min(smallest, pivot);
      largest = std::max(largest, diagonal);
    }
    return largest > 0.0 ? smallest / largest : 1.0;
  }

  /// The largest coordinate of a body's position: the rounding in Phi scales with it.
  double largest_position() const {
    double largest = 0.0;
    for (const TreeBody& node : tree_)
      largest = std::max(largest, ws_.frames[node.body].position.cwiseAbs().maxCoeff());
    return largest;
  }

  /// Brings the whole workspace to the loaded state as an absolute-coordinate run leaves it:
  /// q and v, every element's blocks, v' and lambda of every joint (tree joints included, for
  /// their reactions). Reads the forces of the last solve_accelerations, which the integrator
  /// has made at this state, and the theta'' held (solved or restored).
  void complete_workspace() {
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      const Frame& frame = ws_.frames[b];
      auto q = ws_.q.template segment<Space::nq>(Space::nq * (b - 1));
      q.template head<Space::dim>() = frame.position;
      if constexpr (spatial_model) {
        const Eigen::Quaterniond rotation(frame.rotation);
        Eigen::Vector4d quaternion(rotation.w(), rotation.x(), rotation.y(), rotation.z());
        // The axes fix the quaternion up to its sign: keep the one nearest the workspace's
        // last (the previous output's, or the assembled start's), so that the outputs run on
        // continuously, as an absolute-coordinate run's do (while a body turns by less than a
        // half turn between outputs).
        if (quaternion.dot(q.template tail<4>()) < 0.0) quaternion = -quaternion;
        q.template tail<4>() = quaternion;
      } else {
        q[2] = frame.angle;
      }
      ws_.v.template segment<L>(Space::nv * (b - 1)) = frame.linear_velocity;
      ws_.v.template segment<A>(Space::nv * (b - 1) + L) = frame.angular_velocity;
    }
    // v' from theta'': the spatial accelerations down the tree, then the centres' accelerations
    // (the spatial one plus omega x v_centre) and the body-frame angular accelerations.
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      Motion acceleration = nodes_[i].bias;
      if (tree_[i].parent_node >= 0)
        acceleration += shifted_motion(motion_[tree_[i].parent_node], nodes_[i].offset);
      acceleration.noalias() += nodes_[i].motion.leftCols(tree_[i].dof()) *
                                qdd_.segment(tree_[i].v_offset, tree_[i].dof());
      motion_[i] = acceleration;
      const int b = tree_[i].body;
      const Motion& twist = nodes_[i].twist;
      ws_.vdot.template segment<L>(Space::nv * (b - 1)) =
          linear(acceleration) + Algebra::turn(angular(twist), linear(twist));
      ws_.vdot.template segment<A>(Space::nv * (b - 1) + L).noalias() =
          Algebra::axes(ws_.frames[b]).transpose() * angular(acceleration);
    }
    // Each body's constraint forces Phi_q^T lambda, from the closures first.
    constraint_force_.setZero();
    for_each_closure([&]<class E>(const E& element, const StateOf<E>&, BlocksOf<E>& blocks, int row,
                                  int model_row) {
      const auto lambda = lambda_.segment<E::num_equations>(row);
      ws_.lambda.template segment<E::num_equations>(model_row) = lambda;
      for (int k = 0; k < E::num_bodies; ++k) {
        const int b = element.bodies()[k].index;
        if (b != 0)
          constraint_force_.segment<Space::nv>(Space::nv * (b - 1)).noalias() +=
              blocks.jacobian[k].transpose() * lambda;
      }
    });
    // Then up the tree: what the body's own equation leaves, Q - M v' - (the forces known so
    // far), is its tree joint's force B^T lambda; lambda follows from B B^T lambda = B (that),
    // exact as the equations are consistent, and its force on the parent joins the parent's.
    // The tree joints' blocks are evaluated here (the closures' are current from
    // evaluate_constraints(), which every state the integrator loads goes through).
    for (auto node = tree_.rbegin(); node != tree_.rend(); ++node) {
      if (node->kind == Kind::free) continue;
      const int b = node->body;
      const auto& body = model_.body(BodyId{b});
      const int at = Space::nv * (b - 1);
      const typename Space::Velocity left =
          ws_.force.template segment<Space::nv>(at) -
          Space::mass_times(body.mass, body.inertia, ws_.vdot.template segment<Space::nv>(at)) -
          constraint_force_.segment<Space::nv>(at);
      model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
        if constexpr (Algebra::template carries_body<E>) {
          if (type != node->joint_type) return;
          constexpr int m = E::num_equations;
          const E& joint = pool[node->joint_index];
          auto& blocks = std::get<type>(ws_.blocks)[node->joint_index];
          joint.evaluate(detail::input_of(joint, ws_.frames, ws_.t), blocks);
          const int row = model_.template rows<E>()[node->joint_index];
          ws_.phi.template segment<m>(row) = blocks.phi;
          ws_.phi_t.template segment<m>(row) = blocks.phi_t;
          // B has full row rank (a joint's equations are independent): B B^T is positive
          // definite, and its unrolled L D L^T costs a fraction of Eigen's LLT at this size.
          const auto& on_child = blocks.jacobian[node->child_side];
          const Eigen::Matrix<double, m, m> normal = on_child * on_child.transpose();
          Eigen::Matrix<double, m, 1> lambda = on_child * left;
          Eigen::Matrix<double, m, m> factor;
          Eigen::Matrix<double, m, 1> inverse_diagonal;
          if (detail::ldlt_factor<m>(m, m, normal.data(), factor.data(), inverse_diagonal.data()))
            detail::ldlt_solve<m>(m, factor.data(), inverse_diagonal.data(), lambda.data());
          else
            lambda = normal.completeOrthogonalDecomposition().solve(on_child * left);
          ws_.lambda.template segment<m>(row) = lambda;
          if (node->parent != 0)
            constraint_force_.segment<Space::nv>(Space::nv * (node->parent - 1)).noalias() +=
                blocks.jacobian[1 - node->child_side].transpose() * lambda;
        }
      });
    }
  }

 private:
  enum class Kind { screws, ball, free };

  struct TreeBody {
    int body = 0;          // the model's body index
    int parent = 0;        // the parent's body index (0: the ground)
    int parent_node = -1;  // the parent's place in tree_ (-1: the ground)
    Kind kind = Kind::screws;
    int q_offset = 0, v_offset = 0;
    std::size_t joint_type = 0, joint_index = 0;  // the tree joint: type in the model, index
    std::string joint;                            // its name (empty for a free root)
    int child_side = 1;                           // which of its bodies this one is
    std::vector<Screw> screws;                    // a screw joint's motions
    Linear pivot = Linear::Zero();                // a ball joint's point, parent's coords
    // The child's pose in the parent's frame at the start (a planar one's angle apart).
    typename Space::RotationMatrix rotation0 = Space::RotationMatrix::Identity();
    double angle0 = 0.0;
    Linear position0 = Linear::Zero();
    int dof() const {
      return kind == Kind::free   ? Space::nv
             : kind == Kind::ball ? 3
                                  : static_cast<int>(screws.size());
    }
    int num_positions() const {
      return kind == Kind::free ? Space::nq : kind == Kind::ball ? 4 : dof();
    }
  };

  /// f.template operator()<K>() with the number of degrees of freedom K as a constant.
  template <class F>
  static bool with_dof(int dof, F&& f) {
    switch (dof) {
      case 0:
        return f.template operator()<0>();
      case 1:
        return f.template operator()<1>();
      case 2:
        return f.template operator()<2>();
      default:
        if constexpr (D == 3) {
          return f.template operator()<3>();
        } else {
          switch (dof) {
            case 3:
              return f.template operator()<3>();
            case 4:
              return f.template operator()<4>();
            case 5:
              return f.template operator()<5>();
            default:
              return f.template operator()<6>();
          }
        }
    }
  }

  /// The applied force and torque (body axes) on body b, from the last evaluate_forces.
  auto force_on(int b) const { return ws_.force.template segment<L>(Space::nv * (b - 1)); }
  auto torque_on(int b) const { return ws_.force.template segment<A>(Space::nv * (b - 1) + L); }

  /// A motion vector (twist or acceleration) at the parent's centre, seen at the child's.
  static Motion shifted_motion(const Motion& motion, const Linear& offset) {
    Motion out;
    angular(out) = angular(motion);
    linear(out) = linear(motion) + Algebra::turn(angular(motion), offset);
    return out;
  }

  /// into += a wrench at a child's centre moved to its parent's: torque plus r x force.
  static void add_shifted_force(const Motion& force, const Linear& offset, Motion& into) {
    angular(into) += angular(force) + Algebra::moment(offset, linear(force));
    linear(into) += linear(force);
  }

  /// Adds to each body's inertia (factorize_loaded's start) the symmetric part of its own blocks
  /// stiffness_factor K_bb + damping_factor C_bb of the force elements and of the gyroscopic
  /// terms, turned from the bodies' velocity coordinates (v_centre, omega in body axes) to the
  /// spatial form at the centre (omega, v_centre in global axes): T^T B T, T = [0 1; R^T 0].
  void add_own_force_blocks(double stiffness_factor, double damping_factor) {
    using Block = typename Space::MassBlock;
    constexpr int nv = Space::nv;
    for (int b = 1; b <= model_.num_bodies(); ++b)
      own_blocks_[b] =
          damping_factor * Space::gyroscopic_damping(model_.body(BodyId{b}).inertia, ws_.frames[b]);
    model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (HasForceJacobians<E>) {
        ForceBlocksOf<E> blocks;
        for (std::size_t n = 0; n < pool.size(); ++n) {
          const E& element = pool[n];
          force_jacobians(element, detail::input_of(element, ws_.frames, ws_.t),
                          std::get<type>(ws_.states)[n], blocks);
          for (int k = 0; k < E::num_bodies; ++k) {
            const int b = element.bodies()[k].index;
            if (b == 0) continue;
            own_blocks_[b] +=
                stiffness_factor * blocks.stiffness.template block<nv, nv>(nv * k, nv * k) +
                damping_factor * blocks.damping.template block<nv, nv>(nv * k, nv * k);
          }
        }
      }
    });
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const int b = tree_[i].body;
      const Block symmetric = 0.5 * (own_blocks_[b] + own_blocks_[b].transpose());
      const auto& rotation = Algebra::axes(ws_.frames[b]);
      // B = [B_vv B_vw; B_wv B_ww] in (v, omega_body); spatial (omega, v): T^T B T.
      MotionMatrix& inertia = factor(i).articulated;
      inertia.template topLeftCorner<A, A>().noalias() +=
          rotation * symmetric.template bottomRightCorner<A, A>() * rotation.transpose();
      const Eigen::Matrix<double, A, L> coupling =
          rotation * symmetric.template bottomLeftCorner<A, L>();
      inertia.template topRightCorner<A, L>() += coupling;
      inertia.template bottomLeftCorner<L, A>() += coupling.transpose();
      inertia.template bottomRightCorner<L, L>() += symmetric.template topLeftCorner<L, L>();
    }
  }

  /// Node i's part of the factorization in the current slot.
  NodeFactor& factor(std::size_t i) { return factors_[slot_][i]; }

  /// ABA's inertia step for node i: U, D^-1, I^A - U D^-1 U^T, which the parent inherits
  /// shifted to its centre: X^T I X, X = [1 0; -[r] 1], r = c_child - c_parent.
  template <int K>
  bool factor_node(std::size_t i) {
    const NodeState& node = nodes_[i];
    NodeFactor& own = factor(i);
    if constexpr (K > 0) {
      const auto motion = node.motion.template leftCols<K>();
      auto projected = own.projected.template leftCols<K>();
      projected.noalias() = own.articulated * motion;
      const Eigen::Matrix<double, K, K> pivot = motion.transpose() * projected;
      const Eigen::LLT<Eigen::Matrix<double, K, K>> llt(pivot);
      if (llt.info() != Eigen::Success) return false;
      auto inverse = own.inverse_pivot.template topLeftCorner<K, K>();
      inverse = llt.solve(Eigen::Matrix<double, K, K>::Identity());
      own.articulated.noalias() -= projected * (inverse * projected.transpose());
    }
    const int parent = tree_[i].parent_node;
    if (parent >= 0)
      Algebra::add_shifted_inertia(own.articulated, node.offset, factor(parent).articulated);
    return true;
  }

  /// The saddle-point matrix [A C^T; C 0] of a small model, lower triangle, factorized L D L^T.
  /// A by the composite-rigid-body algorithm: each body's subtree inertia I^c, its joint's
  /// block S^T I^c S, and the couplings S_j^T I^c S with every ancestor j (the subtree's
  /// momentum per unit rate, moved up the tree). C: each closure block G times the motion
  /// columns of the body's ancestors, moved to the body's centre.
  bool factorize_dense() {
    const Eigen::Index n = num_velocities();
    for (std::size_t i = tree_.size(); i-- > 0;)
      if (tree_[i].parent_node >= 0)
        Algebra::add_shifted_inertia(factor(i).articulated, nodes_[i].offset,
                                     factor(tree_[i].parent_node).articulated);
    kkt_.setZero();
    // Entries one motion-vector product at a time: at these sizes, Eigen's products of blocks of
    // run-time size cost more in their set-up than in their arithmetic.
    const auto fill = [&](const Motion* left, int rows, int row0, const MotionMatrix& right,
                          int columns, int column0) {
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < columns; ++c) kkt_(row0 + r, column0 + c) += left[r].dot(right.col(c));
    };
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const int dof = tree_[i].dof();
      if (dof == 0) continue;
      std::array<Motion, D> momentum;  // I^c S, carried up the tree
      for (int k = 0; k < dof; ++k)
        momentum[k].noalias() = factor(i).articulated * nodes_[i].motion.col(k);
      fill(momentum.data(), dof, tree_[i].v_offset, nodes_[i].motion, dof, tree_[i].v_offset);
      for (int j = static_cast<int>(i); tree_[j].parent_node >= 0;) {
        for (int k = 0; k < dof; ++k)
          angular(momentum[k]) += Algebra::moment(nodes_[j].offset, linear(momentum[k]));
        j = tree_[j].parent_node;
        fill(momentum.data(), dof, tree_[i].v_offset, nodes_[j].motion, tree_[j].dof(),
             tree_[j].v_offset);
      }
    }
    for (const ClosureBlock& block : closure_blocks_) {
      std::array<Motion, ClosureBlock::max_rows> rows;
      for (int r = 0; r < block.count; ++r) rows[r] = block.rows.row(r).transpose();
      for (int j = block.node; j >= 0; j = tree_[j].parent_node) {
        // G moved to node j's centre, so that it reads j's motion columns there: the rows act
        // on twists as G X with X = [1 0; -[r] 1], r = c_body - c_j.
        fill(rows.data(), block.count, static_cast<int>(n) + block.row, nodes_[j].motion,
             tree_[j].dof(), tree_[j].v_offset);
        for (int r = 0; r < block.count; ++r)
          angular(rows[r]) += Algebra::moment(nodes_[j].offset, linear(rows[r]));
      }
    }
    pin_closure_rows(kkt_, n, -1.0);  // a multiplier's pivot is negative
    return kkt_ldlts_[slot_].compute(kkt_);
  }

  /// ABA's force step for node i: u = -S^T p, and the force the subtree hands its parent,
  /// p + I^a c + U D^-1 u, moved to the parent's centre (torque plus r x force).
  template <int K>
  bool backward_node(std::size_t i, bool with_bias, const Eigen::VectorXd* joint_force) {
    NodeState& node = nodes_[i];
    const NodeFactor& own = factor(i);
    Motion handed = force_[i];
    if (with_bias) handed.noalias() += own.articulated * node.bias;
    if constexpr (K > 0) {
      auto u = node.pivot_force.template head<K>();
      u.noalias() = -(node.motion.template leftCols<K>().transpose() * force_[i]);
      if (joint_force) u += joint_force->segment<K>(tree_[i].v_offset);
      handed.noalias() += own.projected.template leftCols<K>() *
                          (own.inverse_pivot.template topLeftCorner<K, K>() * u);
    }
    const int parent = tree_[i].parent_node;
    if (parent >= 0) add_shifted_force(handed, node.offset, force_[parent]);
    return true;
  }

  /// ABA's acceleration step for node i: theta''_i = D^-1 (u - U^T a'), a = a' + S theta''_i,
  /// a' the parent's acceleration at this centre (plus c).
  template <int K>
  bool forward_node(std::size_t i, bool with_bias, Eigen::Ref<Eigen::VectorXd> x,
                    std::vector<Motion>& acceleration) {
    const NodeState& node = nodes_[i];
    const int parent = tree_[i].parent_node;
    Motion a = parent >= 0 ? shifted_motion(acceleration[parent], node.offset) : Motion::Zero();
    if (with_bias) a += node.bias;
    if constexpr (K > 0) {
      auto theta = x.segment<K>(tree_[i].v_offset);
      const NodeFactor& own = factor(i);
      theta.noalias() = own.inverse_pivot.template topLeftCorner<K, K>() *
                        (node.pivot_force.template head<K>() -
                         own.projected.template leftCols<K>().transpose() * a);
      a.noalias() += node.motion.template leftCols<K>() * theta;
    }
    acceleration[i] = a;
    return true;
  }

  /// x = A^-1 (J^T w + tau) with the factorization of the last factorize(), and every body's
  /// motion J x (+ c with_bias) into `acceleration`. force_ holds p = -w per body (plus the
  /// velocity terms with_bias) and is used up; tau (joint forces, per rate) may be absent.
  void tree_solve(bool with_bias, Eigen::Ref<Eigen::VectorXd> x, std::vector<Motion>& acceleration,
                  const Eigen::VectorXd* joint_force = nullptr) {
    for (std::size_t i = tree_.size(); i-- > 0;)
      with_dof(tree_[i].dof(),
               [&]<int K>() { return backward_node<K>(i, with_bias, joint_force); });
    for (std::size_t i = 0; i < tree_.size(); ++i)
      with_dof(tree_[i].dof(),
               [&]<int K>() { return forward_node<K>(i, with_bias, x, acceleration); });
  }

  /// [A C^T; C 0] [x; mu] = [J^T w; s], w from force_ (p = -w, with_force; else w = 0), by
  /// x0 = A^-1 J^T w, mu = (C A^-1 C^T)^-1 (C x0 - s), x = x0 - A^-1 C^T mu. With bias, C x0
  /// includes Phi_q c (s then stands for gamma in spatial form). motion_ ends with J x (+ c).
  void saddle_solve(bool with_force, bool with_bias, const Eigen::VectorXd& s,
                    Eigen::Ref<Eigen::VectorXd> x, Eigen::Ref<Eigen::VectorXd> mu,
                    const Eigen::VectorXd* joint_force = nullptr) {
    if (dense_) return saddle_solve_dense(with_force, with_bias, s, x, mu, joint_force);
    if (with_force || with_bias) {
      tree_solve(with_bias, x, motion_, joint_force);
    } else {
      x.setZero();
      clear(motion_);
    }
    if (num_equations() == 0) return;
    closure_rates(motion_, mu);
    mu -= s;
    for (const int row : pinned_rows_) mu[row] = 0.0;
    // By the triangular factors: LLT's own solveInPlace copies a Ref into a new vector.
    schur_llts_[slot_].matrixL().solveInPlace(mu);
    schur_llts_[slot_].matrixU().solveInPlace(mu);
    clear(force_);
    add_closure_wrenches(mu, 1.0, force_);  // p = -(-C^T mu)
    tree_solve(false, closure_step_, closure_motion_);
    x += closure_step_;
    for (std::size_t i = 0; i < tree_.size(); ++i) motion_[i] += closure_motion_[i];
  }

  /// saddle_solve with the factorized saddle-point matrix: [A C^T; C 0] [x; mu] =
  /// [-J^T (p + M c); s - Phi_q c], c the bodies' accelerations at zero theta'' (with_bias).
  void saddle_solve_dense(bool with_force, bool with_bias, const Eigen::VectorXd& s,
                          Eigen::Ref<Eigen::VectorXd> x, Eigen::Ref<Eigen::VectorXd> mu,
                          const Eigen::VectorXd* joint_force) {
    const Eigen::Index n = num_velocities();
    solution_.tail(num_equations()) = s;
    if (with_bias) {
      for (std::size_t i = 0; i < tree_.size(); ++i) {
        const int parent = tree_[i].parent_node;
        motion_[i] = nodes_[i].bias;
        if (parent >= 0) motion_[i] += shifted_motion(motion_[parent], nodes_[i].offset);
        // p + M c, M the body's own inertia at its centre (global axes).
        const auto& body = model_.body(BodyId{tree_[i].body});
        const auto& rotation = Algebra::axes(ws_.frames[tree_[i].body]);
        angular(force_[i]).noalias() += rotation * (Algebra::inertia(body.inertia) *
                                                    (rotation.transpose() * angular(motion_[i])));
        linear(force_[i]) += body.mass * linear(motion_[i]);
      }
      closure_rates(motion_, mu);
      solution_.tail(num_equations()) -= mu;
    }
    if (with_force || with_bias) {
      for (std::size_t i = tree_.size(); i-- > 0;) {
        const TreeBody& node = tree_[i];
        for (int k = 0; k < node.dof(); ++k)
          solution_[node.v_offset + k] = -nodes_[i].motion.col(k).dot(force_[i]) +
                                         (joint_force ? (*joint_force)[node.v_offset + k] : 0.0);
        if (node.parent_node >= 0)
          add_shifted_force(force_[i], nodes_[i].offset, force_[node.parent_node]);
      }
    } else {
      solution_.head(n).setZero();
    }
    for (const int row : pinned_rows_) solution_[n + row] = 0.0;
    kkt_ldlts_[slot_].solve_in_place(solution_);
    x = solution_.head(n);
    mu = solution_.tail(num_equations());
  }

  /// The closures' rates G V for the bodies' motions V (twists or accelerations), V of node i
  /// being motion(i).
  template <class Motion>
  void closure_rates_of(Motion&& motion, Eigen::Ref<Eigen::VectorXd> out) const {
    out.setZero();
    for (const ClosureBlock& block : closure_blocks_)
      for (int r = 0; r < block.count; ++r)
        out[block.row + r] += block.rows.row(r).dot(motion(block.node));
  }
  void closure_rates(const std::vector<Motion>& motion, Eigen::Ref<Eigen::VectorXd> out) const {
    closure_rates_of([&](int i) -> const Motion& { return motion[i]; }, out);
  }

  /// force += sign C^T lambda, as wrenches (global axes, at the centres).
  void add_closure_wrenches(const Eigen::Ref<const Eigen::VectorXd>& lambda, double sign,
                            std::vector<Motion>& force) const {
    for (const ClosureBlock& block : closure_blocks_)
      force[block.node].noalias() += sign * (block.rows.topRows(block.count).transpose() *
                                             lambda.segment(block.row, block.count));
  }

  static void clear(std::vector<Motion>& vectors) {
    for (Motion& v : vectors) v.setZero();
  }

  /// f(element, blocks, closure_row, model_row) for every loop-closing constraint element.
  template <class F>
  void for_each_closure(F&& f) {
    model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (Constraint<E>) {
        auto& blocks = std::get<type>(ws_.blocks);
        const auto& rows = model_.template rows<E>();
        const auto& closures = closures_[type];
        for (std::size_t c = 0; c < closures.size(); ++c) {
          const std::size_t i = closures[c].index;
          f(pool[i], std::as_const(std::get<type>(ws_.states)[i]), blocks[i], closures[c].row,
            rows[i]);
        }
      }
    });
  }

  struct Closure {
    std::size_t index;  // in its type's pool
    int row;            // first row in the closures' equations
  };
  struct Edge {
    std::size_t type, index;
    int a, b, equations;
  };

  using TreeFlags = std::array<std::vector<bool>, Model::num_types>;  // per pool: in the tree?

  /// The joints that carry bodies, most equations first, and which of them Kruskal's spanning
  /// tree takes (so that the loops close with the fewest equations).
  static TreeFlags spanning_tree(const Model& model, std::vector<Edge>& edges) {
    edges.clear();
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (Algebra::template carries_body<E>)
        for (std::size_t i = 0; i < pool.size(); ++i)
          edges.push_back(
              {type, i, pool[i].bodies()[0].index, pool[i].bodies()[1].index, E::num_equations});
    });
    std::stable_sort(edges.begin(), edges.end(),
                     [](const Edge& x, const Edge& y) { return x.equations > y.equations; });
    std::vector<int> group(model.num_bodies() + 1);
    std::iota(group.begin(), group.end(), 0);
    const auto root = [&](int x) {
      while (group[x] != x) x = group[x] = group[group[x]];
      return x;
    };
    TreeFlags in_tree;
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      in_tree[type].assign(pool.size(), false);
    });
    for (const Edge& edge : edges) {
      const int ra = root(edge.a), rb = root(edge.b);
      if (ra == rb) continue;
      group[ra] = rb;
      in_tree[edge.type][edge.index] = true;
    }
    return in_tree;
  }

  void build_tree() {
    const int nb = model_.num_bodies();
    std::vector<Edge> edges;
    const TreeFlags in_tree = spanning_tree(model_, edges);
    std::vector<std::vector<std::pair<int, int>>> neighbours(nb + 1);  // (body, edge)
    for (std::size_t e = 0; e < edges.size(); ++e) {
      if (!in_tree[edges[e].type][edges[e].index]) continue;
      neighbours[edges[e].a].push_back({edges[e].b, static_cast<int>(e)});
      neighbours[edges[e].b].push_back({edges[e].a, static_cast<int>(e)});
    }
    // Breadth first from the ground, then from a free root in each group left.
    std::vector<int> parent_edge(nb + 1, -1);
    std::vector<bool> reached(nb + 1, false);
    const auto grow = [&](int start) {
      reached[start] = true;
      if (start != 0) {
        TreeBody node;
        node.body = start;
        node.kind = Kind::free;
        tree_.push_back(node);
      }
      std::vector<int> queue{start};
      for (std::size_t head = 0; head < queue.size(); ++head)
        for (const auto& [to, e] : neighbours[queue[head]]) {
          if (reached[to]) continue;
          reached[to] = true;
          TreeBody node;
          node.body = to;
          node.parent = queue[head];
          parent_edge[to] = e;
          tree_.push_back(node);
          queue.push_back(to);
        }
    };
    grow(0);
    for (int b = 1; b <= nb; ++b)
      if (!reached[b]) grow(b);
    node_of_.assign(static_cast<std::size_t>(nb + 1), -1);
    for (std::size_t i = 0; i < tree_.size(); ++i) node_of_[tree_[i].body] = static_cast<int>(i);
    // Each tree joint's motions, seen from its parent, and the child's pose at the start.
    for (TreeBody& node : tree_) {
      if (node.kind == Kind::free) continue;
      node.parent_node = node.parent == 0 ? -1 : node_of_[node.parent];
      const Edge& edge = edges[parent_edge[node.body]];
      model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
        if constexpr (Algebra::template carries_body<E>) {
          if (type != edge.type) return;
          const E& joint = pool[edge.index];
          const int parent_side = joint.bodies()[0].index == node.parent ? 0 : 1;
          const auto in = detail::input_of(joint, ws_.frames, ws_.t);
          if constexpr (Algebra::template screw_joint<E>) {
            const auto screws = joint.tree_screws(in, parent_side);
            node.screws.assign(screws.begin(), screws.end());
          } else if constexpr (spatial_model) {
            node.kind = Kind::ball;
            node.pivot = joint.tree_pivot(in, parent_side);
          }
          node.joint_type = type;
          node.joint_index = edge.index;
          node.child_side = 1 - parent_side;
          node.joint = joint.name();
          tree_names_.push_back(joint.name());
        }
      });
      const Frame &parent = ws_.frames[node.parent], &child = ws_.frames[node.body];
      node.rotation0 = parent.rotation.transpose() * child.rotation;
      if constexpr (!spatial_model) node.angle0 = child.angle - parent.angle;
      node.position0 = parent.rotation.transpose() * (child.position - parent.position);
    }
    int q_offset = 0, v_offset = 0;
    for (TreeBody& node : tree_) {
      node.q_offset = q_offset;
      node.v_offset = v_offset;
      q_offset += node.num_positions();
      v_offset += node.dof();
    }
    q_.setZero(q_offset);
    v_.setZero(v_offset);
    // Every constraint element not in the tree closes a loop.
    int row = 0;
    model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (Constraint<E>)
        for (std::size_t i = 0; i < pool.size(); ++i)
          if (!in_tree[type][i]) {
            closures_[type].push_back({i, row});
            closure_names_.push_back(pool[i].name());
            for (int k = 0; k < E::num_bodies; ++k) {
              const int b = pool[i].bodies()[k].index;
              if (b != 0) closure_blocks_.push_back({node_of_[b], row, E::num_equations});
            }
            row += E::num_equations;
          }
    });
    phi_.setZero(row);
  }

  void size_buffers() {
    const Eigen::Index n = num_velocities(), m = num_equations();
    nodes_.assign(tree_.size(), NodeState{});
    for (int slot = 0; slot < slots_; ++slot) factors_[slot].assign(tree_.size(), NodeFactor{});
    own_blocks_.assign(static_cast<std::size_t>(model_.num_bodies() + 1), Space::MassBlock::Zero());
    force_.assign(tree_.size(), Motion::Zero());
    motion_ = force_;
    motion2_ = force_;
    closure_motion_ = force_;
    constraint_force_.setZero(Space::nv * model_.num_bodies());
    phi_t_.setZero(m);
    velocity_values_.setZero(m);
    acceleration_values_.setZero(m);
    lambda_.setZero(m);
    multiplier_.setZero(m);
    closure_rhs_.setZero(m);
    dense_ = n + m <= dense_limit;
    if (dense_) {
      kkt_.setZero(n + m, n + m);
      for (int slot = 0; slot < slots_; ++slot) kkt_ldlts_[slot].resize(n, m);
      solution_.setZero(n + m);
    } else {
      schur_.setZero(m, m);
      for (int slot = 0; slot < slots_; ++slot)  // sizes their storage once
        schur_llts_[slot].compute(Eigen::MatrixXd::Identity(m, m));
    }
    qdd_.setZero(n);
    increment_.setZero(n);
    increment2_.setZero(n);
    closure_step_.setZero(n);
    joint_rhs_.setZero(n);
    estimate_.setZero(n);
  }

  /// Joint coordinates 0 at the start (quaternions 1), free roots where they are; the rates
  /// nearest the bodies' velocities in the mass metric that satisfy the closures (the same
  /// rates, for a consistent state): [A C^T; C 0] [theta'; mu] = [J^T M v; -Phi_t].
  void initial_state() {
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free)
        q_.segment<Space::nq>(node.q_offset) =
            ws_.q.template segment<Space::nq>(Space::nq * (node.body - 1));
      if (node.kind == Kind::ball) q_.segment<4>(node.q_offset) << 1.0, 0.0, 0.0, 0.0;
    }
    const Eigen::VectorXd velocities = ws_.v;
    update_kinematics();
    evaluate_constraints();
    check_closures();
    if (num_velocities() == 0) return;
    if (!factorize())
      throw ModelError("joint coordinates",
                       "the mass matrix in joint coordinates is singular; every body of the tree "
                       "needs a positive mass and inertia");
    // The momenta M v as wrenches at the centres (global axes): p = -M v.
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const int b = tree_[i].body;
      const auto& body = model_.body(BodyId{b});
      angular(force_[i]).noalias() =
          -(Algebra::axes(ws_.frames[b]) *
            (Algebra::inertia(body.inertia) * velocities.segment<A>(Space::nv * (b - 1) + L)));
      linear(force_[i]) = -body.mass * velocities.segment<L>(Space::nv * (b - 1));
    }
    closure_rhs_ = -phi_t_;
    saddle_solve(true, false, closure_rhs_, v_, multiplier_);
    update_velocities();
  }

  /// Finds the closure equations that repeat others at the start (Bricard's linkage, two
  /// coaxial hinges closing one loop): a column-pivoted QR of C^T, whose columns
  /// C^T e_j = J^T (G^T e_j) are the closures' unit wrenches summed up the tree, pivots them
  /// last. They are pinned from then on (see pin_closure_rows): their multipliers stay zero and
  /// the others carry the loads, one valid choice of reactions among many (absolute
  /// coordinates give the minimum-norm one). An equation that stops repeating the others later
  /// is then not enforced, and the constraint residual, which every integrator checks over all
  /// of them, names it.
  void check_closures() {
    const Eigen::Index m = num_equations();
    if (m == 0) return;
    Eigen::MatrixXd jacobian(m, num_velocities());
    for (Eigen::Index j = 0; j < m; ++j) {
      multiplier_.setZero();
      multiplier_[j] = 1.0;
      clear(force_);
      add_closure_wrenches(multiplier_, 1.0, force_);
      for (std::size_t i = tree_.size(); i-- > 0;) {
        const TreeBody& node = tree_[i];
        jacobian.row(j).segment(node.v_offset, node.dof()) =
            (nodes_[i].motion.leftCols(node.dof()).transpose() * force_[i]).transpose();
        if (node.parent_node >= 0)
          add_shifted_force(force_[i], nodes_[i].offset, force_[node.parent_node]);
      }
    }
    const RankRevealingQr qr(jacobian.transpose(), rank_tolerance);
    const std::vector<int>& order = qr.column_order();
    pinned_rows_.assign(order.begin() + qr.rank(), order.end());
    std::sort(pinned_rows_.begin(), pinned_rows_.end());
  }

  /// Pins the redundant closure rows in a factorization's matrix, whose multipliers' block
  /// starts at row and column `offset` (lower triangle): their rows and columns cleared, the
  /// diagonal set to `diagonal`, so that a solve with zero right-hand side there leaves their
  /// multipliers at zero.
  void pin_closure_rows(Eigen::MatrixXd& matrix, Eigen::Index offset, double diagonal) const {
    for (const int row : pinned_rows_) {
      const Eigen::Index r = offset + row;
      matrix.row(r).head(r).setZero();
      matrix.col(r).tail(matrix.rows() - r - 1).setZero();
      matrix(r, r) = diagonal;
    }
  }

  /// A unit quaternion turned by exp(increment) on the right (in its own axes).
  static void turn(Eigen::Ref<Quaternion> q, const Eigen::Ref<const Eigen::Vector3d>& increment) {
    Eigen::Quaterniond turned =
        Eigen::Quaterniond(q[0], q[1], q[2], q[3]) * quaternion_exp(increment);
    turned.normalize();
    q << turned.w(), turned.x(), turned.y(), turned.z();
  }

  /// The turn (in the quaternion's own axes) whose rate at q is dq: 2 vec(q* dq).
  static Eigen::Vector3d turn_of(const Eigen::Ref<const Quaternion>& q,
                                 const Eigen::Ref<const Quaternion>& dq) {
    const Eigen::Quaterniond product = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).conjugate() *
                                       Eigen::Quaterniond(dq[0], dq[1], dq[2], dq[3]);
    return 2.0 * product.vec();
  }

  /// The change of the coordinates (the first entries of `change`) for rates w at positions q:
  /// a joint coordinate moves with its rate, a quaternion as q' = q (0, w) / 2.
  void configuration_change(const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& w,
                            Eigen::Ref<Eigen::VectorXd> change) const {
    for (const TreeBody& node : tree_) {
      if (node.kind == Kind::free) {
        change.segment<Space::nq>(node.q_offset) = Space::configuration_rate(
            q.segment<Space::nq>(node.q_offset), w.segment<Space::nv>(node.v_offset));
      } else if (node.kind == Kind::ball) {
        const auto at = q.segment<4>(node.q_offset);
        const auto rate = w.segment<3>(node.v_offset);
        const Eigen::Quaterniond turned = Eigen::Quaterniond(at[0], at[1], at[2], at[3]) *
                                          Eigen::Quaterniond(0.0, rate[0], rate[1], rate[2]);
        change.segment<4>(node.q_offset) << 0.5 * turned.w(), 0.5 * turned.x(), 0.5 * turned.y(),
            0.5 * turned.z();
      } else {
        change.segment(node.q_offset, node.dof()) = w.segment(node.v_offset, node.dof());
      }
    }
  }

  /// The bodies' twists (global axes, at their centres) for the joint rates x: J x.
  void motions_of_rates(const Eigen::Ref<const Eigen::VectorXd>& x, std::vector<Motion>& out) {
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const TreeBody& node = tree_[i];
      out[i] = node.parent_node >= 0 ? shifted_motion(out[node.parent_node], nodes_[i].offset)
                                     : Motion::Zero();
      out[i].noalias() +=
          nodes_[i].motion.leftCols(node.dof()) * x.segment(node.v_offset, node.dof());
    }
  }

  /// The closures' right-hand side in spatial form: gamma less Phi_linear (omega x v_centre),
  /// the part of the centre's acceleration that the spatial acceleration leaves out.
  void closure_gamma(Eigen::VectorXd& out) {
    for_each_closure(
        [&]<class E>(const E& element, const StateOf<E>& state, BlocksOf<E>& blocks, int row, int) {
          auto g = out.segment<E::num_equations>(row);
          g = constraint_gamma(element, detail::input_of(element, ws_.frames, ws_.t), state);
          for (int k = 0; k < E::num_bodies; ++k) {
            const int b = element.bodies()[k].index;
            if (b == 0) continue;
            const Motion& twist = nodes_[node_of_[b]].twist;
            g.noalias() -= blocks.jacobian[k].template leftCols<L>() *
                           Algebra::turn(angular(twist), linear(twist));
          }
        });
  }

  /// x - A^-1 C^T (C A^-1 C^T)^-1 C x, a rate-space vector with no component that C measures.
  void remove_normal_part(Eigen::Ref<Eigen::VectorXd> x) {
    motions_of_rates(x, motion2_);
    closure_rates(motion2_, closure_rhs_);
    closure_rhs_ = -closure_rhs_;
    saddle_solve(false, false, closure_rhs_, increment2_, multiplier_);
    x += increment2_;
  }

  /// Down the tree: every body's frame, its joint's motion columns S at its centre and its
  /// offset from its parent; then the velocities (update_velocities).
  void update_kinematics() {
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const TreeBody& node = tree_[i];
      NodeState& state = nodes_[i];
      Frame& frame = ws_.frames[node.body];
      const Frame& parent = ws_.frames[node.parent];
      if (node.kind == Kind::free) {
        Space::make_frame(q_.segment<Space::nq>(node.q_offset),
                          v_.segment<Space::nv>(node.v_offset), frame);
        // Rates (v_centre, omega in body axes): translations, then turns about the centre.
        state.motion.setZero();
        state.motion.template block<L, L>(A, 0).setIdentity();
        state.motion.template block<A, A>(0, L) = Algebra::axes(frame);
      } else if constexpr (spatial_model) {
        if (node.kind == Kind::ball)
          ball_kinematics(node, parent, frame, state);
        else
          screw_kinematics(node, parent, frame, state);
      } else {
        planar_kinematics(node, parent, frame, state);
      }
      state.offset = frame.position - parent.position;
    }
    update_velocities();
  }

  /// A ball joint's child: turned by its quaternion about the pivot.
  void ball_kinematics(const TreeBody& node, const Frame& parent, Frame& frame,
                       NodeState& state) const {
    const auto quaternion = q_.segment<4>(node.q_offset);
    const Eigen::Matrix3d axes = parent.rotation * Eigen::Quaterniond(quaternion[0], quaternion[1],
                                                                      quaternion[2], quaternion[3])
                                                       .toRotationMatrix();
    const Eigen::Vector3d pivot = parent.position + parent.rotation * node.pivot;
    frame.rotation = axes * node.rotation0;
    frame.position = pivot + axes * (node.position0 - node.pivot);
    // Turns about the pivot, about the axes the quaternion's rates are given in.
    const Eigen::Vector3d arm = frame.position - pivot;
    for (int k = 0; k < 3; ++k) {
      state.motion.col(k).template head<3>() = axes.col(k);
      state.motion.col(k).template tail<3>() = axes.col(k).cross(arm);
    }
  }

  /// A spatial screw joint's child: its product of exponentials.
  void screw_kinematics(const TreeBody& node, const Frame& parent, Frame& frame,
                        NodeState& state) const {
    // The frame the motions so far carry: its rotation and where the parent's origin went.
    Eigen::Matrix3d rotation = parent.rotation;
    Eigen::Vector3d origin = parent.position;
    std::array<Eigen::Vector3d, 6> axis, point;
    const int count = node.dof();
    for (int k = 0; k < count; ++k) {
      const Screw& screw = node.screws[k];
      const double angle = q_[node.q_offset + k];
      axis[k] = rotation * screw.axis;
      if (screw.kind == Screw::Kind::rotation) {
        point[k] = origin + rotation * screw.point;
        // Rodrigues on the right: R exp(angle [a]) = c R + s [R a] R + (1 - c) (R a) a^T.
        const double sine = std::sin(angle), cosine = std::cos(angle);
        for (int j = 0; j < 3; ++j) {
          const Eigen::Vector3d column = rotation.col(j);
          rotation.col(j) = cosine * column + sine * axis[k].cross(column) +
                            ((1.0 - cosine) * screw.axis[j]) * axis[k];
        }
        origin = point[k] - rotation * screw.point;
      } else {
        origin += angle * axis[k];
      }
    }
    frame.rotation = rotation * node.rotation0;
    frame.position = origin + rotation * node.position0;
    for (int k = 0; k < count; ++k) {
      const bool turns = node.screws[k].kind == Screw::Kind::rotation;
      state.motion.col(k).template head<3>() = turns ? axis[k] : Eigen::Vector3d::Zero();
      state.motion.col(k).template tail<3>() =
          turns ? Eigen::Vector3d(axis[k].cross(frame.position - point[k])) : axis[k];
    }
  }

  /// A planar joint's child: its turns about points and slides, in order. Turns in the plane
  /// commute, so the child's angle is its parent's plus the joint's angles (and the start's).
  void planar_kinematics(const TreeBody& node, const Frame& parent, Frame& frame,
                         NodeState& state) const {
    double angle = parent.angle;
    Eigen::Matrix2d rotation = parent.rotation;
    Eigen::Vector2d origin = parent.position;
    std::array<Eigen::Vector2d, D> axis, point;
    const int count = node.dof();
    for (int k = 0; k < count; ++k) {
      const Screw& screw = node.screws[k];
      const double coordinate = q_[node.q_offset + k];
      axis[k] = rotation * screw.axis;
      if (screw.kind == Screw::Kind::rotation) {
        point[k] = origin + rotation * screw.point;
        angle += coordinate;
        rotation = Space::rotation(angle);
        origin = point[k] - rotation * screw.point;
      } else {
        origin += coordinate * axis[k];
      }
    }
    frame.angle = angle + node.angle0;
    frame.rotation = rotation * node.rotation0;  // the angle's rotation, with no more sines
    frame.position = origin + rotation * node.position0;
    for (int k = 0; k < count; ++k) {
      const bool turns = node.screws[k].kind == Screw::Kind::rotation;
      state.motion(0, k) = turns ? 1.0 : 0.0;
      state.motion.col(k).template tail<2>() =
          turns ? Eigen::Vector2d(Space::perpendicular(frame.position - point[k])) : axis[k];
    }
  }

  /// Down the tree: twists V = V_parent (at this centre) + S theta', the joints' c and the
  /// frames' velocities, with the frames and columns of the last update_kinematics. c is
  /// sum_k (V_k-1 x S_k) theta'_k for a product of exponentials (S_k is carried by the motions
  /// before it), V_parent x S theta' for a ball joint (S is carried by the child), and
  /// (0, v_centre x omega) for a free root (its translations are the ground's).
  void update_velocities() {
    for (std::size_t i = 0; i < tree_.size(); ++i) {
      const TreeBody& node = tree_[i];
      NodeState& state = nodes_[i];
      Frame& frame = ws_.frames[node.body];
      Motion twist = node.parent_node >= 0
                         ? shifted_motion(nodes_[node.parent_node].twist, state.offset)
                         : Motion::Zero();
      state.bias.setZero();
      const auto rates = v_.segment(node.v_offset, node.dof());
      if (node.kind == Kind::free) {
        twist.noalias() = state.motion * rates;
        linear(state.bias) = -Algebra::turn(angular(twist), linear(twist));
      } else if (node.kind == Kind::ball) {
        const Motion relative = state.motion.template leftCols<3>() * rates;
        state.bias = Algebra::motion_cross(twist, relative);
        twist += relative;
      } else {
        for (int k = 0; k < node.dof(); ++k) {
          const Motion column = state.motion.col(k);
          state.bias += Algebra::motion_cross(twist, column) * rates[k];
          twist += column * rates[k];
        }
      }
      state.twist = twist;
      frame.angular_velocity.noalias() = Algebra::axes(frame).transpose() * angular(twist);
      frame.linear_velocity = linear(twist);
    }
  }

  const Model& model_;
  Workspace<Model>& ws_;
  std::vector<TreeBody> tree_;  // parents before children
  std::vector<int> node_of_;    // body index -> place in tree_ (-1: the ground)
  std::array<std::vector<Closure>, Model::num_types> closures_;
  std::vector<ClosureBlock> closure_blocks_;
  std::vector<std::string> tree_names_, closure_names_;

  std::vector<NodeState> nodes_;
  std::vector<typename Space::MassBlock> own_blocks_;  // per body: see add_own_force_blocks
  std::vector<Motion> force_;                          // per node: p in a solve (scratch)
  std::vector<Motion> motion_, motion2_;               // per node: J x (+ c) of a solve (scratch)
  std::vector<Motion> closure_motion_;                 // per node: saddle_solve's own scratch

  Eigen::VectorXd q_, v_;             // (nq), (n) joint coordinates and rates
  Eigen::VectorXd constraint_force_;  // (6 nb) Phi_q^T lambda, in complete_workspace()
  Eigen::VectorXd phi_, phi_t_;       // (m) of the closures
  Eigen::VectorXd velocity_values_;   // (m) C theta' + Phi_t
  Eigen::VectorXd acceleration_values_;  // (m) C theta'' - (gamma - Phi_q c)
  Eigen::VectorXd closure_rhs_;       // (m) a saddle-point solve's s
  Eigen::VectorXd multiplier_;        // (m) scratch
  std::vector<int> pinned_rows_;      // closure equations that repeat others (check_closures)
  Eigen::MatrixXd schur_;             // (m x m) C A^-1 C^T
  bool dense_ = false;                // small: the whole saddle-point matrix (dense_limit)
  Eigen::MatrixXd kkt_;               // (n + m) [A C^T; C 0], lower triangle (dense_)
  std::array<SaddlePointLdlt, max_slots> kkt_ldlts_;  // its factorization, per slot
  Eigen::VectorXd solution_;  // (n + m) right-hand side, then solution (dense_)
  std::array<Eigen::LLT<Eigen::MatrixXd>, max_slots> schur_llts_;  // the Schur's, per slot
  std::array<std::vector<NodeFactor>, max_slots> factors_;         // A's, per slot and node
  int slots_ = 1, slot_ = 0;  // the slots in use; the one factorized or solved with last
  Eigen::VectorXd increment_, increment2_;  // (n) scratch
  Eigen::VectorXd closure_step_;            // (n) saddle_solve's own scratch
  Eigen::VectorXd joint_rhs_, estimate_;    // (n) an implicit integrator's solves (scratch)
  Eigen::VectorXd qdd_, lambda_;            // (n), (m) of the last solve_accelerations
};

}  // namespace odyn
