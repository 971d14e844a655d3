#pragma once
// What a planar joint offers a joint-coordinate tree (analysis/joint_coordinates.hpp): the
// motions it allows, as in spatial/screw.hpp but in the plane. Relative to its parent, the child
// body of a tree joint moves by a turn about a point or a slide along a direction, each given in
// the parent body's coordinates at the pose where every joint coordinate is 0 (the assembled
// start), so that the joint's own equations hold for every coordinate by construction.

#include <Eigen/Core>
#include <array>
#include <concepts>

#include "odyn/core/element.hpp"

namespace odyn::planar {

/// One elementary motion of a joint, in the parent body's coordinates at theta = 0.
struct Screw {
  enum class Kind { rotation, translation };
  Kind kind = Kind::rotation;
  Eigen::Vector2d axis = Eigen::Vector2d::UnitX();  // unit; the direction of a slide
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  // the centre of a turn
};

/// A joint with degrees_of_freedom elementary motions; `parent_side` (0 or 1) says which of its
/// bodies is the parent in the tree, `in` holds both bodies' frames at theta = 0.
template <class E>
concept TreeJoint = Constraint<E> && requires(const E& e, const InputOf<E>& in) {
  { E::degrees_of_freedom } -> std::convertible_to<int>;
  { e.tree_screws(in, 0) } -> std::same_as<std::array<Screw, E::degrees_of_freedom>>;
};

/// A joint that can carry a body in a joint-coordinate tree (the plane has no ball joint).
template <class E>
concept CarriesBody = TreeJoint<E>;

}  // namespace odyn::planar
