#pragma once
// Universal (Cardan, Hooke) joint: the joint points coincide and the cross's two axes, one on
// each body, stay perpendicular. 4 equations.

#include <cmath>

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

class Universal : public PairJoint {
 public:
  static constexpr int num_equations = 4;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "universal", "joint",
      "Universal (Cardan): the points coincide and the cross's two axes, one on each body, stay "
      "perpendicular. 4 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Universal from_parameters(Reader& r) {
    return parameters::from_frame_pair<Universal, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 2;

  /// As a tree joint: the child turns about the parent's axis, then about its own, both through
  /// the parent's point (the child's axis given where it is at the start, in parent coordinates).
  std::array<Screw, 2> tree_screws(const Input& in, int parent_side) const {
    const Triad &parent = frame(parent_side), &child = frame(1 - parent_side);
    const Spatial::Frame &p = in.body(parent_side), &c = in.body(1 - parent_side);
    const Eigen::Vector3d child_axis = p.rotation.transpose() * c.direction(child.w);
    return {Screw{Screw::Kind::rotation, parent.w, parent.point},
            Screw{Screw::Kind::rotation, child_axis.normalized(), parent.point}};
  }

  void bind(const Input& in) {
    PairJoint::bind(in);
    const double alignment = in.body(0).direction(on_a_.w).dot(in.body(1).direction(on_b_.w));
    if (std::abs(alignment) > 1.0 - 1e-9)
      throw ModelError(name_,
                       "the axes on body a and body b are parallel at the initial pose; "
                       "a universal joint needs two perpendicular axes");
  }

  void evaluate(const Input& in, BlocksOf<Universal>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident(a, on_a_.point, b, on_b_.point, out, 0);
    primitive::dot1(a, on_a_.w, b, on_b_.w, out, 3);
    out.phi_t.setZero();
  }

  Eigen::Vector4d gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Vector4d g;
    g << primitive::coincident_gamma(a, on_a_.point, b, on_b_.point),
        primitive::dot1_gamma(a, on_a_.w, b, on_b_.w);
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Vector4d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident_stiffness(a, on_a_.point, b, on_b_.point, lambda.head<3>(), out);
    primitive::dot1_stiffness(a, on_a_.w, b, on_b_.w, lambda[3], out);
  }
};
static_assert(Constraint<Universal>);
static_assert(TreeJoint<Universal>);

}  // namespace odyn::spatial
