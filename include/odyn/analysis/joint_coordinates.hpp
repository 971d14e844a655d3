#pragma once
// Joint coordinates: the bodies located through a spanning tree of the model's joints, so that
// only the joints that close loops stay constraint equations. The single-cylinder engine, for
// instance, becomes crank angle, piston travel and the two angles of the piston pin, closed by
// the crank pin's three equations: 4 coordinates and 3 equations instead of 18 and 17.
//
// The tree. Joints that can carry a body (TreeJoint: revolute, translational, cylindrical,
// universal, fixed) are taken greedily, most equations first (Kruskal), so that the joints left
// to close loops have the fewest equations; spherical joints, distances and drivers always
// close loops. A group of bodies that no tree joint ties to the ground gets a free root: one of
// its bodies keeps its own position and quaternion.
//
// The kinematics. Each tree joint moves its child by a product of exponentials (see
// spatial/screw.hpp), measured from the assembled start (every joint coordinate 0 there). Going
// down the tree gives every body's frame, the spatial Jacobian S_b (twists (omega, v_O) of the
// body, global, per unit coordinate rate) and the bias acceleration c_b (the acceleration at
// zero coordinate acceleration):
//     V_child = V_parent + sum_i xi_i theta_i',
//     A_child = A_parent + sum_i (xi_i theta_i'' + (V_i-1 x xi_i) theta_i').
// In the bodies' own velocity coordinates v = J theta' and v' = J theta'' + c.
//
// The equations. With the bodies' block-diagonal mass M and their forces Q (gyroscopic terms
// included), the closure equations' Jacobian C = Phi_q J and right-hand side gamma - Phi_q c:
//     [J^T M J  C^T] [theta'']   [J^T (Q - M c)]
//     [C        0  ] [lambda ] = [gamma - Phi_q c],
// one small dense saddle-point matrix, factorized L D L^T (linalg/saddle_point_ldlt.hpp) at
// every stage. The tree joints' equations hold exactly. At output points complete_workspace()
// fills in what an absolute-coordinate run leaves in the workspace: q, v, v' = J theta'' + c,
// every element's blocks and every lambda, the tree joints' from their bodies' own equations,
// leaves first (B B^T lambda = B (Q - M v' - the constraint forces already known), B the
// joint's block on its child; exact, since the equations are consistent).
//
// Limits: spatial models; loop closures must be independent (a redundant closure, as in
// Bricard's mechanism, is refused with its joints named: absolute coordinates handle it).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <numeric>
#include <string>
#include <type_traits>
#include <vector>

#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/spatial.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/linalg/all_finite.hpp"
#include "odyn/linalg/linear_solver.hpp"
#include "odyn/linalg/saddle_point_ldlt.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn {

template <class Model>
class JointCoordinates {
  static_assert(std::is_same_v<typename Model::Space, Spatial>,
                "joint coordinates are implemented for spatial models");
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Frame = Spatial::Frame;
  using Screw = spatial::Screw;

 public:
  static constexpr const char* name = "joint";

  /// Builds the tree at the workspace's (assembled) state and takes that state as the start.
  /// Throws ModelError if the loop closures are redundant there.
  /// (The closures' matrix is small and dense: `linear_solver` is not used.)
  JointCoordinates(const Model& model, Workspace<Model>& ws,
                   LinearSolver /*linear_solver*/ = LinearSolver::automatic)
      : model_(model), ws_(ws) {
    update_frames(model, ws);
    build_tree();
    size_buffers();
    initial_state();
  }

  Eigen::Index num_positions() const { return q_.size(); }
  Eigen::Index num_velocities() const { return v_.size(); }
  Eigen::Index num_equations() const { return phi_.size(); }

  /// Names of the joints that carry bodies (tree joints) and of those that close loops.
  const std::vector<std::string>& tree_joints() const { return tree_names_; }
  const std::vector<std::string>& loop_closures() const { return closure_names_; }

  /// y = (joint coordinates, their rates).
  void read_state(Eigen::VectorXd& y) const { y << q_, v_; }

  /// The workspace at (t, y): every body's frame from the tree.
  void load(double t, const Eigen::VectorXd& y) {
    ws_.t = t;
    q_ = y.head(num_positions());
    for (const TreeBody& node : tree_)
      if (node.free) Spatial::normalize(q_.segment<Spatial::nq>(node.q_offset));
    v_ = y.tail(num_velocities());
    update_kinematics();
  }

  /// The coordinates' rate for the rates loaded last, at the positions held in y: a joint
  /// coordinate moves with its rate, a free root's quaternion as in Spatial.
  void position_rate(const Eigen::VectorXd& y, Eigen::Ref<Eigen::VectorXd> rate) const {
    configuration_change(y, v_, rate);
  }

  /// The closures' Phi and blocks, and C = Phi_q J (into the saddle-point matrix's rows n..).
  void evaluate_constraints() {
    const Eigen::Index n = num_velocities();
    kkt_.bottomLeftCorner(num_equations(), n).setZero();
    for_each_closure([&]<class E>(const E& element, BlocksOf<E>& blocks, int row, int model_row) {
      constexpr int m = E::num_equations;
      element.evaluate(detail::input_of(element, ws_.frames, ws_.t), blocks);
      phi_.segment<m>(row) = blocks.phi;
      phi_t_.segment<m>(row) = blocks.phi_t;
      ws_.phi.template segment<m>(model_row) = blocks.phi;
      ws_.phi_t.template segment<m>(model_row) = blocks.phi_t;
      for (int k = 0; k < E::num_bodies; ++k) {
        const int b = element.bodies()[k].index;
        if (b == 0) continue;
        for (int j = 0; j < num_columns(b); ++j)
          kkt_.col(columns_[b][j]).template segment<m>(n + row).noalias() +=
              blocks.jacobian[k] * body_column(b, j);
      }
    });
  }

  void evaluate_forces() { odyn::evaluate_forces(model_, ws_); }

  /// Factorizes [J^T M J  C^T; C  0] at the loaded positions (C from evaluate_constraints).
  /// J^T M J: each body adds m J_v^T J_v + J_w^T I J_w over the coordinates that move it.
  bool factorize() {
    kkt_.topLeftCorner(num_velocities(), num_velocities()).setZero();
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      const auto& body = model_.body(BodyId{b});
      for (int j = 0; j < num_columns(b); ++j) {
        const Vector6& column_j = body_column(b, j);
        const Eigen::Vector3d linear = body.mass * column_j.head<3>();
        const Eigen::Vector3d angular = body.inertia * column_j.tail<3>();
        for (int i = j; i < num_columns(b); ++i)
          kkt_(columns_[b][i], columns_[b][j]) += body_column(b, i).template head<3>().dot(linear) +
                                                  body_column(b, i).template tail<3>().dot(angular);
      }
    }
    return kkt_ldlt_.compute(kkt_);
  }

  /// theta'' and the closures' lambda at the loaded state, with the matrix factorized last:
  /// the right-hand side J^T (Q - M c), gamma - Phi_q c.
  bool solve_accelerations() {
    odyn::evaluate_forces(model_, ws_);
    const Eigen::Index n = num_velocities();
    auto force = solution_.head(n);
    force.setZero();
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      const auto& body = model_.body(BodyId{b});
      // Q - M c, by 3-vectors (see evaluate_forces).
      const Eigen::Vector3d linear =
          ws_.force.template segment<3>(6 * (b - 1)) - body.mass * bias_.segment<3>(6 * (b - 1));
      const Eigen::Vector3d angular = ws_.force.template segment<3>(6 * (b - 1) + 3) -
                                      body.inertia * bias_.segment<3>(6 * (b - 1) + 3);
      for (int j = 0; j < num_columns(b); ++j)
        force[columns_[b][j]] += body_column(b, j).template head<3>().dot(linear) +
                                 body_column(b, j).template tail<3>().dot(angular);
    }
    for_each_closure([&]<class E>(const E& element, BlocksOf<E>& blocks, int row, int) {
      auto g = solution_.segment<E::num_equations>(n + row);
      g = element.gamma(detail::input_of(element, ws_.frames, ws_.t));
      for (int k = 0; k < E::num_bodies; ++k) {
        const int b = element.bodies()[k].index;
        if (b != 0) g.noalias() -= blocks.jacobian[k] * bias_.segment<6>(6 * (b - 1));
      }
    });
    kkt_ldlt_.solve_in_place(solution_);
    qdd_ = solution_.head(n);
    lambda_ = solution_.tail(num_equations());
    return all_finite(solution_);
  }

  const Eigen::VectorXd& accelerations() const { return qdd_; }
  const Eigen::VectorXd& multipliers() const { return lambda_; }
  void restore_solution(const Eigen::VectorXd& qdd, const Eigen::VectorXd& lambda) {
    qdd_ = qdd;
    lambda_ = lambda;
  }
  bool state_finite() const { return all_finite(q_) && all_finite(v_); }

  double position_residual() const {
    return num_equations() > 0 ? phi_.cwiseAbs().maxCoeff() : 0.0;
  }

  /// One (chord) correction towards the closures' Phi = 0, least distance in J^T M J.
  void correct_positions() {
    solution_.head(num_velocities()).setZero();
    solution_.tail(num_equations()) = -phi_;
    kkt_ldlt_.solve_in_place(solution_);
    for (const TreeBody& node : tree_) {
      if (node.free) {
        const Eigen::Matrix<double, Spatial::nq, 1> from = q_.segment<Spatial::nq>(node.q_offset);
        Spatial::integrate(from, solution_.segment<Spatial::nv>(node.v_offset),
                           q_.segment<Spatial::nq>(node.q_offset));
      } else {
        q_.segment(node.q_offset, node.dof()) += solution_.segment(node.v_offset, node.dof());
      }
    }
    update_kinematics();
    evaluate_constraints();
  }

  /// The part of a local error estimate e = (e_q, e_v) that outlives the projection ending the
  /// step. correct_positions and correct_velocities move along A^-1 C^T (A = J^T M J) and remove
  /// what C measures, so to first order only e - A^-1 C^T (C A^-1 C^T)^-1 C e is kept, for each
  /// part; the matrix is the one factorized last (at a stage within the step, near its end). A
  /// free root's quaternion error is taken as a turn, its change of length dropped (load()
  /// normalizes).
  void keep_tangential(Eigen::Ref<Eigen::VectorXd> error) {
    if (num_equations() == 0) return;
    for (const TreeBody& node : tree_) {
      if (node.free)
        increment_.segment<Spatial::nv>(node.v_offset) = Spatial::increment_of(
            q_.segment<Spatial::nq>(node.q_offset), error.segment<Spatial::nq>(node.q_offset));
      else
        increment_.segment(node.v_offset, node.dof()) = error.segment(node.q_offset, node.dof());
    }
    remove_normal_part(increment_);
    configuration_change(q_, increment_, error);
    remove_normal_part(error.tail(num_velocities()));
  }

  /// Removes C theta' + Phi_t, least change in J^T M J.
  void correct_velocities() {
    const Eigen::Index n = num_velocities();
    solution_.head(n).setZero();
    auto residual = solution_.tail(num_equations());  // -(C theta' + Phi_t), in place
    residual.noalias() = kkt_.bottomLeftCorner(num_equations(), n) * v_;
    residual = -(residual + phi_t_);
    kkt_ldlt_.solve_in_place(solution_);
    v_ += solution_.head(n);
    update_velocities();
  }

  /// Brings the whole workspace to the loaded state as an absolute-coordinate run leaves it:
  /// q and v, every element's blocks, v' and lambda of every joint (tree joints included, for
  /// their reactions). Reads the forces and theta'' of the last solve_accelerations, which
  /// the integrator has made at this state.
  void complete_workspace() {
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      const Frame& frame = ws_.frames[b];
      const Eigen::Quaterniond turn(frame.rotation);
      ws_.q.template segment<3>(7 * (b - 1)) = frame.position;
      ws_.q.template segment<4>(7 * (b - 1) + 3) << turn.w(), turn.x(), turn.y(), turn.z();
    }
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      ws_.v.template segment<3>(6 * (b - 1)) = ws_.frames[b].linear_velocity;
      ws_.v.template segment<3>(6 * (b - 1) + 3) = ws_.frames[b].angular_velocity;
    }
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      auto vdot = ws_.vdot.template segment<6>(6 * (b - 1));
      vdot = bias_.segment<6>(6 * (b - 1));
      for (int j = 0; j < num_columns(b); ++j) vdot += body_column(b, j) * qdd_[columns_[b][j]];
    }
    // Each body's constraint forces Phi_q^T lambda, from the closures first.
    constraint_force_.setZero();
    for_each_closure([&]<class E>(const E& element, BlocksOf<E>& blocks, int row, int model_row) {
      const auto lambda = lambda_.segment<E::num_equations>(row);
      ws_.lambda.template segment<E::num_equations>(model_row) = lambda;
      for (int k = 0; k < E::num_bodies; ++k) {
        const int b = element.bodies()[k].index;
        if (b != 0)
          constraint_force_.segment<6>(6 * (b - 1)).noalias() +=
              blocks.jacobian[k].transpose() * lambda;
      }
    });
    // Then up the tree: what the body's own equation leaves, Q - M v' - (the forces known so
    // far), is its tree joint's force B^T lambda; lambda follows from B B^T lambda = B (that),
    // exact as the equations are consistent, and its force on the parent joins the parent's.
    // The tree joints' blocks are evaluated here (the closures' are current from
    // evaluate_constraints(), which every state the integrator loads goes through).
    for (auto node = tree_.rbegin(); node != tree_.rend(); ++node) {
      if (node->free) continue;
      const int b = node->body;
      const auto& body = model_.body(BodyId{b});
      const Vector6 left =
          ws_.force.template segment<6>(6 * (b - 1)) -
          Spatial::mass_times(body.mass, body.inertia, ws_.vdot.template segment<6>(6 * (b - 1))) -
          constraint_force_.segment<6>(6 * (b - 1));
      model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
        if constexpr (spatial::TreeJoint<E>) {
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
            constraint_force_.segment<6>(6 * (node->parent - 1)).noalias() +=
                blocks.jacobian[1 - node->child_side].transpose() * lambda;
        }
      });
    }
  }

 private:
  struct TreeBody {
    int body = 0;       // the model's body index
    int parent = 0;     // the parent's body index (0: the ground)
    bool free = false;  // a root with its own position and quaternion
    int q_offset = 0, v_offset = 0;
    std::size_t joint_type = 0, joint_index = 0;  // the tree joint: type in the model, index
    int child_side = 1;                           // which of its bodies this one is
    std::vector<Screw> screws;                    // the tree joint's motions
    Eigen::Matrix3d rotation0 = Eigen::Matrix3d::Identity();  // in the parent's frame at start
    Eigen::Vector3d position0 = Eigen::Vector3d::Zero();
    int dof() const { return free ? Spatial::nv : static_cast<int>(screws.size()); }
  };

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
          f(pool[i], blocks[i], closures[c].row, rows[i]);
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

  void build_tree() {
    const int nb = model_.num_bodies();
    std::vector<Edge> edges;
    model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (spatial::TreeJoint<E>)
        for (std::size_t i = 0; i < pool.size(); ++i)
          edges.push_back(
              {type, i, pool[i].bodies()[0].index, pool[i].bodies()[1].index, E::num_equations});
    });
    // Kruskal: most equations first, so the loops close with the fewest.
    std::stable_sort(edges.begin(), edges.end(),
                     [](const Edge& x, const Edge& y) { return x.equations > y.equations; });
    std::vector<int> group(nb + 1);
    std::iota(group.begin(), group.end(), 0);
    const auto root = [&](int x) {
      while (group[x] != x) x = group[x] = group[group[x]];
      return x;
    };
    std::vector<std::vector<std::pair<int, int>>> neighbours(nb + 1);  // (body, edge)
    std::array<std::vector<bool>, Model::num_types> in_tree;
    model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      in_tree[type].assign(pool.size(), false);
    });
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const int ra = root(edges[e].a), rb = root(edges[e].b);
      if (ra == rb) continue;
      group[ra] = rb;
      in_tree[edges[e].type][edges[e].index] = true;
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
        node.free = true;
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
    // Each tree joint's motions, seen from its parent, and the child's pose at the start.
    for (TreeBody& node : tree_) {
      if (node.free) continue;
      const Edge& edge = edges[parent_edge[node.body]];
      model_.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
        if constexpr (spatial::TreeJoint<E>) {
          if (type != edge.type) return;
          const E& joint = pool[edge.index];
          const int parent_side = joint.bodies()[0].index == node.parent ? 0 : 1;
          const auto screws =
              joint.tree_screws(detail::input_of(joint, ws_.frames, ws_.t), parent_side);
          node.screws.assign(screws.begin(), screws.end());
          node.joint_type = type;
          node.joint_index = edge.index;
          node.child_side = 1 - parent_side;
          tree_names_.push_back(joint.name());
        }
      });
      const Frame &parent = ws_.frames[node.parent], &child = ws_.frames[node.body];
      node.rotation0 = parent.rotation.transpose() * child.rotation;
      node.position0 = parent.rotation.transpose() * (child.position - parent.position);
    }
    int q_offset = 0, v_offset = 0;
    for (TreeBody& node : tree_) {
      node.q_offset = q_offset;
      node.v_offset = v_offset;
      q_offset += node.free ? Spatial::nq : node.dof();
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
            row += E::num_equations;
          }
    });
    phi_.setZero(row);
  }

  void size_buffers() {
    const int nb = model_.num_bodies();
    const Eigen::Index n = num_velocities(), m = num_equations();
    // The coordinates that move each body: its ancestors' and its own, in increasing order
    // (offsets follow the breadth-first order, so a parent's come first).
    columns_.assign(static_cast<std::size_t>(nb + 1), {});
    first_column_.assign(static_cast<std::size_t>(nb + 2), 0);
    for (const TreeBody& node : tree_) {
      auto& columns = columns_[node.body];
      if (!node.free) columns = columns_[node.parent];
      for (int i = 0; i < node.dof(); ++i) columns.push_back(node.v_offset + i);
    }
    for (int b = 0; b <= nb; ++b)
      first_column_[b + 1] = first_column_[b] + static_cast<int>(columns_[b].size());
    spatial_columns_.assign(static_cast<std::size_t>(first_column_[nb + 1]), Vector6::Zero());
    body_columns_ = spatial_columns_;
    twist_.assign(static_cast<std::size_t>(nb + 1), Vector6::Zero());
    spatial_bias_.assign(static_cast<std::size_t>(nb + 1), Vector6::Zero());
    bias_.setZero(6 * nb);
    constraint_force_.setZero(6 * nb);
    phi_t_.setZero(m);
    lambda_.setZero(m);
    qdd_.setZero(n);
    kkt_.setZero(n + m, n + m);
    solution_.setZero(n + m);
    increment_.setZero(n);
    kkt_ldlt_.resize(n, m);
  }

  /// Joint coordinates 0 at the start, free roots where they are; the rates nearest the
  /// bodies' velocities in the mass metric that satisfy the closures (the same rates, for a
  /// consistent state): [J^T M J  C^T; C  0] [theta'; mu] = [J^T M v; -Phi_t].
  void initial_state() {
    for (const TreeBody& node : tree_)
      if (node.free)
        q_.segment<Spatial::nq>(node.q_offset) =
            ws_.q.template segment<Spatial::nq>(7 * (node.body - 1));
    const Eigen::VectorXd velocities = ws_.v;
    update_kinematics();
    evaluate_constraints();
    check_closures();
    if (num_velocities() == 0) return;
    if (!factorize())
      throw ModelError("joint coordinates",
                       "the mass matrix in joint coordinates is singular; every body of the tree "
                       "needs a positive mass and inertia");
    solution_.setZero();
    for (int b = 1; b <= model_.num_bodies(); ++b) {
      const auto& body = model_.body(BodyId{b});
      const Vector6 momentum =
          Spatial::mass_times(body.mass, body.inertia, velocities.segment<6>(6 * (b - 1)));
      for (int j = 0; j < num_columns(b); ++j)
        solution_[columns_[b][j]] += body_column(b, j).dot(momentum);
    }
    solution_.tail(num_equations()) = -phi_t_;
    kkt_ldlt_.solve_in_place(solution_);
    v_ = solution_.head(num_velocities());
    update_kinematics();
  }

  /// Refuses closures whose equations repeat each other at the start.
  void check_closures() {
    if (num_equations() == 0) return;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(kkt_.bottomLeftCorner(num_equations(), num_velocities()));
    lu.setThreshold(1e-10);
    if (lu.rank() < num_equations()) {
      std::string names;
      for (const auto& name : closure_names_) names += (names.empty() ? "'" : ", '") + name + "'";
      throw ModelError("joint coordinates",
                       "the loop-closure equations of " + names + " are redundant (rank " +
                           std::to_string(lu.rank()) + " of " + std::to_string(num_equations()) +
                           "); use absolute coordinates, which run with redundant constraints");
    }
  }

  /// The change of the coordinates (the first entries of `change`) for rates w at positions q:
  /// a joint coordinate moves with its rate, a free root's quaternion as in Spatial.
  void configuration_change(const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& w,
                            Eigen::Ref<Eigen::VectorXd> change) const {
    for (const TreeBody& node : tree_) {
      if (node.free)
        change.segment<Spatial::nq>(node.q_offset) = Spatial::configuration_rate(
            q.segment<Spatial::nq>(node.q_offset), w.segment<Spatial::nv>(node.v_offset));
      else
        change.segment(node.q_offset, node.dof()) = w.segment(node.v_offset, node.dof());
    }
  }

  /// x - A^-1 C^T (C A^-1 C^T)^-1 C x, a rate-space vector with no component that C measures.
  void remove_normal_part(Eigen::Ref<Eigen::VectorXd> x) {
    const Eigen::Index n = num_velocities();
    solution_.head(n).setZero();
    auto measured = solution_.tail(num_equations());  // -C x, in place (no temporary)
    measured.noalias() = kkt_.bottomLeftCorner(num_equations(), n) * x;
    measured = -measured;
    kkt_ldlt_.solve_in_place(solution_);
    x += solution_.head(n);
  }

  int num_columns(int body) const { return first_column_[body + 1] - first_column_[body]; }
  /// Column j of body b's spatial Jacobian S_b and of its Jacobian J_b.
  Vector6& spatial_column(int b, int j) { return spatial_columns_[first_column_[b] + j]; }
  const Vector6& body_column(int b, int j) const { return body_columns_[first_column_[b] + j]; }

  /// to = from, by 3-vectors: from's halves were just stored a number at a time, and a copy
  /// in pairs would wait on them (see evaluate_forces).
  static void copy_halves(const Vector6& from, Vector6& to) {
    to.head<3>() = from.head<3>();
    to.tail<3>() = from.tail<3>();
  }

  /// A joint's motion xi at its rate, added to the twist carried so far, and the bias that the
  /// carrying adds: (twist x xi) rate, with (omega, v) x (omega', v') = (omega x omega',
  /// omega x v' + v x omega'). By 3-vectors: the cross products are stored a number at a time,
  /// and 6-vector arithmetic on them would read pairs (see evaluate_forces).
  static void add_motion(const Vector6& xi, double rate, Vector6& twist, Vector6& bias) {
    const Eigen::Vector3d omega = twist.head<3>(), velocity = twist.tail<3>();
    bias.head<3>() += omega.cross(xi.head<3>()) * rate;
    bias.tail<3>() += (omega.cross(xi.tail<3>()) + velocity.cross(xi.head<3>())) * rate;
    twist.head<3>() += xi.head<3>() * rate;
    twist.tail<3>() += xi.tail<3>() * rate;
  }

  /// Down the tree: frames, spatial Jacobians, twists and bias accelerations; then J and c in
  /// the bodies' velocity coordinates (linear velocity of the centre, body-frame omega).
  void update_kinematics() {
    for (const TreeBody& node : tree_) {
      const int b = node.body;
      Frame& frame = ws_.frames[b];
      Vector6 twist, bias;  // (omega, velocity of the point at the origin), global
      if (node.free) {
        Spatial::make_frame(q_.segment<Spatial::nq>(node.q_offset),
                            v_.segment<Spatial::nv>(node.v_offset), frame);
        const Eigen::Vector3d omega = frame.rotation * frame.angular_velocity;
        for (int k = 0; k < 3; ++k) {
          spatial_column(b, k) << Eigen::Vector3d::Zero(), Eigen::Vector3d::Unit(k);
          spatial_column(b, 3 + k) << frame.rotation.col(k),
              frame.position.cross(frame.rotation.col(k));
        }
        twist << omega, frame.linear_velocity + frame.position.cross(omega);
        bias << Eigen::Vector3d::Zero(), frame.linear_velocity.cross(omega);
      } else {
        const Frame& parent = ws_.frames[node.parent];
        const int inherited = num_columns(node.parent);
        for (int j = 0; j < inherited; ++j) spatial_column(b, j) = spatial_column(node.parent, j);
        copy_halves(twist_[node.parent], twist);
        copy_halves(spatial_bias_[node.parent], bias);
        // The frame the motions so far carry: its rotation and where the parent's origin went.
        Eigen::Matrix3d rotation = parent.rotation;
        Eigen::Vector3d origin = parent.position;
        for (int i = 0; i < static_cast<int>(node.screws.size()); ++i) {
          const Screw& screw = node.screws[i];
          const double angle = q_[node.q_offset + i];
          const double rate = v_[node.v_offset + i];
          const Eigen::Vector3d axis = rotation * screw.axis;
          Vector6 xi;
          if (screw.kind == Screw::Kind::rotation) {
            const Eigen::Vector3d point = origin + rotation * screw.point;
            xi << axis, point.cross(axis);
            // Rodrigues on the right: R exp(angle [a]) = c R + s [R a] R + (1 - c) (R a) a^T.
            const double sine = std::sin(angle), cosine = std::cos(angle);
            for (int k = 0; k < 3; ++k) {
              const Eigen::Vector3d column = rotation.col(k);
              rotation.col(k) = cosine * column + sine * axis.cross(column) +
                                ((1.0 - cosine) * screw.axis[k]) * axis;
            }
            origin = point - rotation * screw.point;
          } else {
            xi << Eigen::Vector3d::Zero(), axis;
            origin += angle * axis;
          }
          add_motion(xi, rate, twist, bias);
          copy_halves(xi, spatial_column(b, inherited + i));
        }
        frame.rotation = rotation * node.rotation0;
        frame.position = origin + rotation * node.position0;
        frame.angular_velocity = frame.rotation.transpose() * twist.head<3>();
        frame.linear_velocity = twist.tail<3>() + twist.head<3>().cross(frame.position);
      }
      // v_centre = v_O + omega x x and omega_body = R^T omega, column by column.
      for (int j = 0; j < num_columns(b); ++j) {
        const Vector6& xi = spatial_column(b, j);
        Vector6& column = body_columns_[first_column_[b] + j];
        column.head<3>() = xi.tail<3>() + xi.head<3>().cross(frame.position);
        column.tail<3>().noalias() = frame.rotation.transpose() * xi.head<3>();
      }
      store_motion(b, frame, twist, bias);
    }
  }

  /// After a change of the rates alone (correct_velocities): twists, bias accelerations and
  /// the frames' velocities again, with the frames and screws of the last update_kinematics.
  /// The same operations in the same order as there, so the same numbers.
  void update_velocities() {
    for (const TreeBody& node : tree_) {
      const int b = node.body;
      Frame& frame = ws_.frames[b];
      Vector6 twist, bias;
      if (node.free) {
        frame.linear_velocity = v_.segment<3>(node.v_offset);
        frame.angular_velocity = v_.segment<3>(node.v_offset + 3);
        const Eigen::Vector3d omega = frame.rotation * frame.angular_velocity;
        twist << omega, frame.linear_velocity + frame.position.cross(omega);
        bias << Eigen::Vector3d::Zero(), frame.linear_velocity.cross(omega);
      } else {
        copy_halves(twist_[node.parent], twist);
        copy_halves(spatial_bias_[node.parent], bias);
        const int inherited = num_columns(node.parent);
        for (int i = 0; i < static_cast<int>(node.screws.size()); ++i) {
          const Vector6& xi = spatial_column(b, inherited + i);
          const double rate = v_[node.v_offset + i];
          add_motion(xi, rate, twist, bias);
        }
        frame.angular_velocity = frame.rotation.transpose() * twist.head<3>();
        frame.linear_velocity = twist.tail<3>() + twist.head<3>().cross(frame.position);
      }
      store_motion(b, frame, twist, bias);
    }
  }

  /// Keeps body b's twist and bias acceleration (global, at the origin), and its bias c in its
  /// own velocity coordinates: the centre's acceleration v_O' + omega' x x + omega x v_centre,
  /// and R^T omega'.
  void store_motion(int b, const Frame& frame, const Vector6& twist, const Vector6& bias) {
    copy_halves(twist, twist_[b]);
    copy_halves(bias, spatial_bias_[b]);
    bias_.segment<3>(6 * (b - 1)) = bias.tail<3>() + bias.head<3>().cross(frame.position) +
                                    twist.head<3>().cross(frame.linear_velocity);
    bias_.segment<3>(6 * (b - 1) + 3) = frame.rotation.transpose() * bias.head<3>();
  }

  const Model& model_;
  Workspace<Model>& ws_;
  std::vector<TreeBody> tree_;  // parents before children
  std::array<std::vector<Closure>, Model::num_types> closures_;
  std::vector<std::string> tree_names_, closure_names_;

  // Per body (index 0: the ground): the coordinates that move it, where its columns start in
  // the flat arrays of columns, its twist V_b and its spatial acceleration at rest.
  std::vector<std::vector<Eigen::Index>> columns_;
  std::vector<int> first_column_;
  std::vector<Vector6> spatial_columns_, body_columns_;  // of S_b (twists), of J_b
  std::vector<Vector6> twist_, spatial_bias_;

  Eigen::VectorXd q_, v_;             // (nq), (n) joint coordinates and rates
  Eigen::VectorXd bias_;              // (6 nb) c
  Eigen::VectorXd constraint_force_;  // (6 nb) Phi_q^T lambda, in complete_workspace()
  Eigen::VectorXd phi_, phi_t_;       // (m) of the closures
  Eigen::MatrixXd kkt_;               // (n + m) [J^T M J  C^T; C  0], lower triangle
  SaddlePointLdlt kkt_ldlt_;
  Eigen::VectorXd solution_;      // (n + m) right-hand side, then solution
  Eigen::VectorXd increment_;     // (n) a position error in rate coordinates
  Eigen::VectorXd qdd_, lambda_;  // (n), (m) of the last solve_accelerations
};

}  // namespace odyn
