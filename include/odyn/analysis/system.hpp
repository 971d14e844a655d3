#pragma once
// The stages that turn a model and a state into the blocks of the equations of motion
//   M v' + Phi_q^T lambda = Q,   Phi(q, t) = 0,   Phi_q v' = gamma.
// Each stage reads the workspace's state and writes the workspace's buffers; elements compute
// their own blocks and the stages scatter them, so no stage knows any element type.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "odyn/core/element.hpp"
#include "odyn/core/model.hpp"
#include "odyn/core/workspace.hpp"

namespace odyn {

namespace detail {
/// The input an element reads: its bodies' frames from the workspace, and the time.
template <class E, class Frame>
InputOf<E> input_of(const E& element, const std::vector<Frame>& frames, double t) {
  InputOf<E> in;
  for (int i = 0; i < E::num_bodies; ++i) in.frames[i] = &frames[element.bodies()[i].index];
  in.t = t;
  return in;
}
}  // namespace detail

/// Kinematics: each body's frame from q and v.
template <class Model>
void update_frames(const Model& model, Workspace<Model>& ws) {
  using Space = typename Model::Space;
  for (int b = 1; b <= model.num_bodies(); ++b)
    Space::make_frame(ws.q.template segment<Space::nq>((b - 1) * Space::nq),
                      ws.v.template segment<Space::nv>((b - 1) * Space::nv), ws.frames[b]);
}

/// Constraints: every element's Phi, Jacobian blocks and Phi_t at (frames, t).
template <class Model>
void evaluate_constraints(const Model& model, Workspace<Model>& ws) {
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (Constraint<E>) {
      auto& blocks = std::get<type>(ws.blocks);
      const auto& rows = model.template rows<E>();
      for (std::size_t i = 0; i < pool.size(); ++i) {
        evaluate_constraint(pool[i], detail::input_of(pool[i], ws.frames, ws.t),
                            std::get<type>(ws.states)[i], blocks[i]);
        ws.phi.template segment<E::num_equations>(rows[i]) = blocks[i].phi;
        ws.phi_t.template segment<E::num_equations>(rows[i]) = blocks[i].phi_t;
      }
    }
  });
}

/// Acceleration right-hand side gamma at (frames, t).
template <class Model>
void evaluate_gamma(const Model& model, Workspace<Model>& ws) {
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (Constraint<E>) {
      const auto& rows = model.template rows<E>();
      for (std::size_t i = 0; i < pool.size(); ++i)
        ws.gamma.template segment<E::num_equations>(rows[i]) = constraint_gamma(
            pool[i], detail::input_of(pool[i], ws.frames, ws.t), std::get<type>(ws.states)[i]);
    }
  });
}

/// The constraint force of the constraint at (type, index) in the model's lists on its second
/// body, -Phi_q,b^T lambda (generalized, at b's centre), from the workspace's last evaluated
/// blocks and its multipliers.
template <class Model>
typename Model::Space::Velocity constraint_force_on_b(const Model& model,
                                                      const Workspace<Model>& ws, std::size_t type,
                                                      std::size_t index) {
  typename Model::Space::Velocity force = Model::Space::Velocity::Zero();
  model.for_each_pool([&]<class E>(const std::vector<E>&, auto pool_type) {
    if constexpr (Constraint<E>) {
      if constexpr (E::num_bodies >= 2) {
        if (pool_type != type) return;
        const auto& blocks = std::get<pool_type>(ws.blocks)[index];
        const int row = model.template rows<E>()[index];
        force.noalias() =
            -blocks.jacobian[1].transpose() * ws.lambda.template segment<E::num_equations>(row);
      }
    }
  });
  return force;
}

/// True if some force element type of the model reads its joint's reaction (ReadsJointReaction).
template <class Model>
constexpr bool reads_joint_reactions() {
  return []<class B, class... E>(const odyn::Model<B, E...>*) {
    return (ReadsJointReaction<E> || ...);
  }(static_cast<const Model*>(nullptr));
}

/// The name of the model's first element that reads its joint's reaction; empty if none.
template <class Model>
std::string first_reaction_reader(const Model& model) {
  std::string found;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (ReadsJointReaction<E>)
      if (found.empty() && !pool.empty()) found = pool.front().name();
  });
  return found;
}

/// Applied forces: Q from every force element, field forces and the bodies' gyroscopic terms.
/// An element that reads its joint's reaction gets it from the multipliers the workspace holds.
template <class Model>
void evaluate_forces(const Model& model, Workspace<Model>& ws) {
  using Space = typename Model::Space;
  constexpr int nv = Space::nv;
  // Forces are added into Q number by number. They come out of 3-vector products, stored a
  // number at a time, and a copy in pairs would read each pair before those stores reach the
  // cache (a store-forwarding stall, about 15 cycles a pair): this function took 106 ns on
  // the spatial engine with Eigen's packet copies, 61 ns without.
  const auto add = [&](int offset, const typename Space::Velocity& force) {
    for (int k = 0; k < nv; ++k) ws.force[offset + k] += force[k];
  };
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const auto gyroscopic = Space::gyroscopic_force(model.body(BodyId{b}).inertia, ws.frames[b]);
    for (int k = 0; k < nv; ++k) ws.force[(b - 1) * nv + k] = gyroscopic[k];
  }
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (FieldForce<E>) {
      for (const E& field : pool)
        for (int b = 1; b <= model.num_bodies(); ++b)
          add((b - 1) * nv, field.force_on(model.body(BodyId{b}).mass, ws.frames[b]));
    } else if constexpr (ForceElement<E>) {
      auto& blocks = std::get<type>(ws.blocks);
      for (std::size_t i = 0; i < pool.size(); ++i) {
        const auto in = detail::input_of(pool[i], ws.frames, ws.t);
        if constexpr (ReadsJointReaction<E>)
          std::get<type>(ws.states)[i].reaction =
              constraint_force_on_b(model, ws, pool[i].joint_type(), pool[i].joint_index());
        if constexpr (StatefulForce<E>)
          pool[i].evaluate(in, std::get<type>(ws.states)[i], blocks[i]);
        else
          pool[i].evaluate(in, blocks[i]);
        for (int k = 0; k < E::num_bodies; ++k) {
          const BodyId body = pool[i].bodies()[k];
          if (!body.is_ground()) add(Model::velocity_offset(body), blocks[i].force[k]);
        }
      }
    }
  });
}

namespace detail {
/// Calls f(first_row, first_column, block) for every Jacobian block of a moving body, from the
/// element blocks of the last evaluate_constraints; `block` has its element's fixed size.
template <class Model, class F>
void for_each_jacobian_block(const Model& model, const Workspace<Model>& ws, F&& f) {
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (Constraint<E>) {
      const auto& blocks = std::get<type>(ws.blocks);
      const auto& rows = model.template rows<E>();
      for (std::size_t i = 0; i < pool.size(); ++i)
        for (int k = 0; k < E::num_bodies; ++k) {
          const BodyId body = pool[i].bodies()[k];
          if (!body.is_ground()) f(rows[i], Model::velocity_offset(body), blocks[i].jacobian[k]);
        }
    }
  });
}
}  // namespace detail

/// out += Phi_q^T y.
template <class Model>
void add_jacobian_transpose_times(const Model& model, const Workspace<Model>& ws,
                                  const Eigen::Ref<const Eigen::VectorXd>& y,
                                  Eigen::Ref<Eigen::VectorXd> out) {
  detail::for_each_jacobian_block(model, ws, [&](int row, int column, const auto& block) {
    constexpr int m = std::decay_t<decltype(block)>::RowsAtCompileTime;
    out.template segment<Model::nv>(column).noalias() +=
        block.transpose() * y.template segment<m>(row);
  });
}

/// out = Phi_q x.
template <class Model>
void jacobian_times(const Model& model, const Workspace<Model>& ws,
                    const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> out) {
  out.setZero();
  detail::for_each_jacobian_block(model, ws, [&](int row, int column, const auto& block) {
    constexpr int m = std::decay_t<decltype(block)>::RowsAtCompileTime;
    out.template segment<m>(row).noalias() += block * x.template segment<Model::nv>(column);
  });
}

/// Writes Phi_q into `target` at (row_offset, col_offset); `with_transpose` also writes Phi_q^T
/// at (col_offset, row_offset): the two off-diagonal blocks of a saddle-point matrix.
template <class Model, class Matrix>
void write_jacobian(const Model& model, const Workspace<Model>& ws, Matrix& target, int row_offset,
                    int col_offset, bool with_transpose) {
  detail::for_each_jacobian_block(model, ws, [&](int row, int column, const auto& block) {
    constexpr int m = std::decay_t<decltype(block)>::RowsAtCompileTime;
    const int r = row_offset + row, c = col_offset + column;
    target.template block<m, Model::nv>(r, c) = block;
    if (with_transpose) target.template block<Model::nv, m>(c, r) = block.transpose();
  });
}

/// True if some constraint type of the model provides its geometric stiffness.
template <class Model>
constexpr bool has_geometric_stiffness() {
  return []<class B, class... E>(const odyn::Model<B, E...>*) {
    return (HasGeometricStiffness<E> || ...);
  }(static_cast<const Model*>(nullptr));
}

/// target's body blocks += factor G, G = d(Phi_q^T lambda)/dq at ws.lambda, from the
/// constraints that provide it (the geometric stiffness; see GeometricStiffness).
template <class Model, class Matrix>
void add_geometric_stiffness(const Model& model, const Workspace<Model>& ws, Matrix& target,
                             double factor) {
  using Space = typename Model::Space;
  constexpr int nv = Space::nv;
  if (factor == 0.0) return;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (HasGeometricStiffness<E>) {
      constexpr int m = E::num_equations;
      const auto& rows = model.template rows<E>();
      GeometricStiffness<Space, E::num_bodies> blocks;
      for (std::size_t i = 0; i < pool.size(); ++i) {
        for (auto& block : blocks) block.setZero();
        const Eigen::Matrix<double, m, 1> lambda = ws.lambda.template segment<m>(rows[i]);
        pool[i].add_geometric_stiffness(detail::input_of(pool[i], ws.frames, ws.t), lambda, blocks);
        for (int k = 0; k < E::num_bodies; ++k) {
          const BodyId body = pool[i].bodies()[k];
          if (body.is_ground()) continue;
          const int offset = Model::velocity_offset(body);
          target.template block<nv, nv>(offset, offset) += factor * blocks[k];
        }
      }
    }
  });
}

/// target(0:n, 0:n) += mass_factor M + stiffness_factor (K + G) + damping_factor C, where
/// K = -dQ/dq and C = -dQ/dv come from the force elements that provide them and the
/// gyroscopic terms, and G = d(Phi_q^T lambda)/dq from the constraints if `geometric`
/// (add_geometric_stiffness).
template <class Model, class Matrix>
void add_iteration_blocks(const Model& model, const Workspace<Model>& ws, Matrix& target,
                          double mass_factor, double stiffness_factor, double damping_factor,
                          bool geometric = false) {
  using Space = typename Model::Space;
  constexpr int nv = Space::nv;
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const auto& body = model.body(BodyId{b});
    target.template block<nv, nv>((b - 1) * nv, (b - 1) * nv) +=
        mass_factor * body.mass_block() +
        damping_factor * Space::gyroscopic_damping(body.inertia, ws.frames[b]);
  }
  if (stiffness_factor == 0.0 && damping_factor == 0.0) return;
  if (geometric) add_geometric_stiffness(model, ws, target, stiffness_factor);
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (HasForceJacobians<E>) {
      ForceBlocksOf<E> blocks;
      for (std::size_t k = 0; k < pool.size(); ++k) {
        const E& element = pool[k];
        force_jacobians(element, detail::input_of(element, ws.frames, ws.t),
                        std::get<type>(ws.states)[k], blocks);
        for (int i = 0; i < E::num_bodies; ++i)
          for (int j = 0; j < E::num_bodies; ++j) {
            const BodyId bi = element.bodies()[i], bj = element.bodies()[j];
            if (bi.is_ground() || bj.is_ground()) continue;
            target.template block<nv, nv>(Model::velocity_offset(bi), Model::velocity_offset(bj)) +=
                stiffness_factor * blocks.stiffness.template block<nv, nv>(i * nv, j * nv) +
                damping_factor * blocks.damping.template block<nv, nv>(i * nv, j * nv);
          }
      }
    }
  });
}

/// out = M x (block diagonal, constant in body coordinates).
template <class Model>
void mass_times(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& x,
                Eigen::Ref<Eigen::VectorXd> out) {
  using Space = typename Model::Space;
  constexpr int nv = Model::nv;
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const auto& body = model.body(BodyId{b});
    out.template segment<nv>((b - 1) * nv) =
        Space::mass_times(body.mass, body.inertia, x.template segment<nv>((b - 1) * nv));
  }
}

/// Stateful elements take their step: called once per accepted step.
template <class Model>
void advance_states(const Model& model, Workspace<Model>& ws) {
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (Stateful<E>) {
      auto& states = std::get<type>(ws.states);
      for (std::size_t i = 0; i < pool.size(); ++i)
        pool[i].advance(detail::input_of(pool[i], ws.frames, ws.t), states[i]);
    }
  });
}

/// The longest next step the elements allow from the workspace's state (LimitsSteps);
/// infinity when none limits it.
template <class Model>
double element_step_limit(const Model& model, const Workspace<Model>& ws) {
  double limit = std::numeric_limits<double>::infinity();
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (LimitsSteps<E>) {
      const auto& states = std::get<type>(ws.states);
      for (std::size_t i = 0; i < pool.size(); ++i)
        limit = std::min(limit,
                         pool[i].step_limit(detail::input_of(pool[i], ws.frames, ws.t), states[i]));
    }
  });
  return limit;
}

/// Stateful elements start from the current frames.
template <class Model>
void initialize_states(const Model& model, Workspace<Model>& ws) {
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (Stateful<E>) {
      auto& states = std::get<type>(ws.states);
      for (std::size_t i = 0; i < pool.size(); ++i)
        states[i] = pool[i].initial_state(detail::input_of(pool[i], ws.frames, ws.t));
    }
  });
}

/// True if some element type of the model declares events (known at compile time).
template <class Model>
constexpr bool has_events() {
  return []<class B, class... E>(const odyn::Model<B, E...>*) {
    return (HasEvents<E> || ...);
  }(static_cast<const Model*>(nullptr));
}

/// Largest event function of all elements at the workspace's frames: it reaches zero when the
/// first element switches its law. -infinity if there are none.
template <class Model>
double event_function(const Model& model, const Workspace<Model>& ws) {
  double largest = -std::numeric_limits<double>::infinity();
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (HasEvents<E>) {
      const auto& states = std::get<type>(ws.states);
      for (std::size_t i = 0; i < pool.size(); ++i)
        largest = std::max(largest, static_cast<double>(pool[i].event_function(
                                        detail::input_of(pool[i], ws.frames, ws.t), states[i])));
    }
  });
  return largest;
}

template <class Model>
double kinetic_energy(const Model& model, const Workspace<Model>& ws) {
  constexpr int nv = Model::nv;
  double energy = 0.0;
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const auto v = ws.v.template segment<nv>((b - 1) * nv);
    energy += 0.5 * v.dot(model.body(BodyId{b}).mass_block() * v);
  }
  return energy;
}

/// Potential energy of the gravity fields and of the force elements that have one.
template <class Model>
double potential_energy(const Model& model, const Workspace<Model>& ws) {
  double energy = 0.0;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (FieldForce<E>) {
      for (const E& field : pool)
        for (int b = 1; b <= model.num_bodies(); ++b)
          energy += field.potential_energy(model.body(BodyId{b}).mass, ws.frames[b]);
    } else if constexpr (HasStatefulPotential<E>) {
      const auto& states = std::get<type>(ws.states);
      for (std::size_t i = 0; i < pool.size(); ++i)
        energy += pool[i].potential_energy(detail::input_of(pool[i], ws.frames, ws.t), states[i]);
    } else if constexpr (HasPotential<E>) {
      for (const E& element : pool)
        energy += element.potential_energy(detail::input_of(element, ws.frames, ws.t));
    }
  });
  return energy;
}

}  // namespace odyn
