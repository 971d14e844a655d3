#pragma once
// Spherical (ball) joint: the joint points coincide. 3 equations.

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

class Spherical : public PairJoint {
 public:
  static constexpr int num_equations = 3;
  static constexpr ElementDescription description{
      "spherical", "joint", "Spherical (ball): the two points coincide. 3 equations.",
      parameters::point_pair};
  template <class Reader>
  static Spherical from_parameters(Reader& r) {
    return parameters::from_point_pair<Spherical, Eigen::Vector3d>(r);
  }

  Spherical(std::string name, BodyId body_a, const Eigen::Vector3d& point_a, BodyId body_b,
            const Eigen::Vector3d& point_b)
      : PairJoint(std::move(name), body_a, JointFrame{point_a}, body_b, JointFrame{point_b}) {}

  /// As a tree joint: the child turns freely about the parent's joint point.
  Eigen::Vector3d tree_pivot(const Input&, int parent_side) const {
    return frame(parent_side).point;
  }

  void evaluate(const Input& in, BlocksOf<Spherical>& out) const {
    primitive::coincident(in.body(0), on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi_t.setZero();
  }

  Eigen::Vector3d gamma(const Input& in) const {
    return primitive::coincident_gamma(in.body(0), on_a_.point, in.body(1), on_b_.point);
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Vector3d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::coincident_stiffness(in.body(0), on_a_.point, in.body(1), on_b_.point, lambda, out);
  }
};
static_assert(Constraint<Spherical>);
static_assert(BallTreeJoint<Spherical>);

}  // namespace odyn::spatial
