#pragma once
// Planar revolute (pin): the joint points coincide. 2 equations. Its angle (PairJoint::angle)
// is what a RevoluteDriver prescribes and an Rsda resists.

#include "odyn/planar/pair_joint.hpp"
#include "odyn/planar/primitives.hpp"
#include "odyn/planar/screw.hpp"

namespace odyn::planar {

class Revolute : public PairJoint {
 public:
  static constexpr int num_equations = 2;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "revolute", "joint",
      "Revolute (pin): the joint points coincide; its angle is what a revolute driver prescribes. "
      "2 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Revolute from_parameters(Reader& r) {
    return parameters::from_frame_pair<Revolute, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 1;

  /// As a tree joint: the child turns about the parent's point.
  std::array<Screw, 1> tree_screws(const Input&, int parent_side) const {
    return {Screw{Screw::Kind::rotation, Eigen::Vector2d::UnitX(), frame(parent_side).point}};
  }

  void evaluate(const Input& in, BlocksOf<Revolute>& out) const {
    primitive::coincident(in.body(0), on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi_t.setZero();
  }

  Eigen::Vector2d gamma(const Input& in) const {
    return primitive::coincident_gamma(in.body(0), on_a_.point, in.body(1), on_b_.point);
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Vector2d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::coincident_stiffness(in.body(0), on_a_.point, in.body(1), on_b_.point, lambda, out);
  }
};
static_assert(Constraint<Revolute>);
static_assert(TreeJoint<Revolute>);

}  // namespace odyn::planar
