#pragma once
// Every buffer an analysis writes: the state, the frames, each element's blocks and the
// assembled vectors. Sized once from the model, so that a time step allocates nothing.

#include <Eigen/Core>
#include <tuple>
#include <vector>

#include "odyn/core/element.hpp"
#include "odyn/core/model.hpp"

namespace odyn {

namespace detail {
struct NoBlocks {};
template <class E>
struct BlocksForImpl {
  using type = NoBlocks;
};
template <Constraint E>
struct BlocksForImpl<E> {
  using type = BlocksOf<E>;
};
template <ForceElement E>
struct BlocksForImpl<E> {
  using type = ForceBlocksOf<E>;
};
}  // namespace detail

/// What the workspace keeps for one element: constraint blocks, force blocks or nothing.
template <class E>
using BlocksFor = typename detail::BlocksForImpl<E>::type;

template <class Model>
struct Workspace;

template <class BodyT, class... Elements>
struct Workspace<Model<BodyT, Elements...>> {
  using ModelType = Model<BodyT, Elements...>;
  using Space = typename ModelType::Space;
  using Frame = typename Space::Frame;

  explicit Workspace(const ModelType& model)
      : q(model.initial_configuration()),
        v(model.initial_velocity()),
        vdot(Eigen::VectorXd::Zero(model.num_velocities())),
        lambda(Eigen::VectorXd::Zero(model.num_equations())),
        frames(model.num_bodies() + 1),
        phi(Eigen::VectorXd::Zero(model.num_equations())),
        phi_t(Eigen::VectorXd::Zero(model.num_equations())),
        gamma(Eigen::VectorXd::Zero(model.num_equations())),
        force(Eigen::VectorXd::Zero(model.num_velocities())) {
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      std::get<type>(blocks).resize(pool.size());
      std::get<type>(states).resize(pool.size());
    });
  }

  double t = 0.0;
  Eigen::VectorXd q;       // (nq * nb) configuration, body after body
  Eigen::VectorXd v;       // (nv * nb) velocity
  Eigen::VectorXd vdot;    // (nv * nb) acceleration
  Eigen::VectorXd lambda;  // (m) Lagrange multipliers

  std::vector<Frame> frames;  // (nb + 1) kinematic snapshot, ground first
  Eigen::VectorXd phi;        // (m) Phi(q, t)
  Eigen::VectorXd phi_t;      // (m) dPhi/dt
  Eigen::VectorXd gamma;      // (m) acceleration right-hand side
  Eigen::VectorXd force;      // (nv * nb) applied generalized force Q, gyroscopic included

  std::tuple<std::vector<BlocksFor<Elements>>...> blocks;  // per element type and instance
  std::tuple<std::vector<StateOf<Elements>>...> states;    // discrete states of force elements
};

}  // namespace odyn
