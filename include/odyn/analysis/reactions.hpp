#pragma once
// Joint reactions from the Lagrange multipliers: the constraint's generalized force on body k
// is -Phi_q,k^T lambda. It is reported as a force and a torque at the joint point on that
// body, in global axes or in the joint frame on that body.

#include <Eigen/Core>
#include <concepts>

#include "odyn/analysis/system.hpp"

namespace odyn {

enum class ReactionAxes { global, joint };

/// Side of a joint: the reaction on body a (exerted by b) or on body b (exerted by a). A
/// constraint on one body has only side a; its side b reads zero.
enum class Side { a = 0, b = 1 };

/// A joint that says where it sits on each body (side 0 = a, 1 = b) and, in global
/// coordinates at a body frame, which axes it has there.
template <class E>
concept HasJointFrames = requires(const E& e, const typename E::Space::Frame& frame) {
  e.frame(0).point;
  { e.axes(0, frame) } -> std::convertible_to<typename E::Space::RotationMatrix>;
};

/// Reaction wrench of constraint `handle` on the body at `side`, from the workspace's last
/// evaluated blocks and its multipliers.
template <class Model, Constraint E>
typename Model::Space::Wrench reaction(const Model& model, const Workspace<Model>& ws,
                                       Handle<E> handle, Side side = Side::b,
                                       ReactionAxes axes = ReactionAxes::global) {
  using Space = typename Model::Space;
  const int k = static_cast<int>(side);
  // A constraint on one body (a point held on a fixed surface) has no side b: nothing acts there.
  if (k >= E::num_bodies) return {};
  const E& element = model.element(handle);
  const auto& blocks = std::get<Model::template type_index<E>>(ws.blocks)[handle.index];
  const auto lambda = ws.lambda.template segment<E::num_equations>(model.row(handle));
  const typename Space::Velocity generalized = -blocks.jacobian[k].transpose() * lambda;
  const auto& frame = ws.frames[element.bodies()[k].index];
  typename Space::Vector point = Space::Vector::Zero();
  if constexpr (HasJointFrames<E>) point = element.frame(k).point;
  const auto wrench = Space::wrench_at(frame, point, generalized);
  if (axes == ReactionAxes::global) return wrench;
  if constexpr (HasJointFrames<E>)
    return Space::in_axes(wrench, element.axes(k, frame));
  else
    return Space::in_axes(wrench, frame.rotation);
}

}  // namespace odyn
