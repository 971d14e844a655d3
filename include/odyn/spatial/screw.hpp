#pragma once
// What a joint offers a joint-coordinate tree (analysis/joint_coordinates.hpp): the motions it
// allows, as a product of exponentials. Relative to its parent, the child body of a tree joint
// sits at
//     g(theta) = exp(xi_1 theta_1) exp(xi_2 theta_2) ... g(0),
// each xi a rotation about an axis through a point, or a translation along an axis, all given in
// the parent body's coordinates at the pose where every theta is 0 (the assembled start). The
// joint's own equations then hold for every theta by construction. A ball joint (BallTreeJoint)
// turns its child freely about a point instead: a quaternion, not a product of exponentials.

#include <Eigen/Core>
#include <array>
#include <concepts>

#include "odyn/core/element.hpp"

namespace odyn::spatial {

/// One elementary motion of a joint, in the parent body's coordinates at theta = 0.
struct Screw {
  enum class Kind { rotation, translation };
  Kind kind = Kind::rotation;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // on the axis (rotations)
};

/// A joint with degrees_of_freedom elementary motions; `parent_side` (0 or 1) says which of its
/// bodies is the parent in the tree, `in` holds both bodies' frames at theta = 0.
template <class E>
concept TreeJoint = Constraint<E> && requires(const E& e, const InputOf<E>& in) {
  { E::degrees_of_freedom } -> std::convertible_to<int>;
  { e.tree_screws(in, 0) } -> std::same_as<std::array<Screw, E::degrees_of_freedom>>;
};

/// A joint that lets its child turn freely about one point, given (by `tree_pivot`) in the
/// coordinates of the body at `parent_side`: a spherical joint as a tree joint.
template <class E>
concept BallTreeJoint = Constraint<E> && requires(const E& e, const InputOf<E>& in) {
  { e.tree_pivot(in, 0) } -> std::convertible_to<Eigen::Vector3d>;
};

/// A joint that can carry a body in a joint-coordinate tree.
template <class E>
concept CarriesBody = TreeJoint<E> || BallTreeJoint<E>;

}  // namespace odyn::spatial
