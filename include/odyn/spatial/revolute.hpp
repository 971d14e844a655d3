#pragma once
// Revolute (hinge): the joint points coincide and the axes stay parallel. 5 equations.

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

class Revolute : public PairJoint {
 public:
  static constexpr int num_equations = 5;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "revolute", "joint",
      "Revolute (hinge): the joint points coincide and the axes stay parallel. 5 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Revolute from_parameters(Reader& r) {
    return parameters::from_frame_pair<Revolute, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 1;

  /// As a tree joint: the child turns about the parent's axis, through the parent's point.
  std::array<Screw, 1> tree_screws(const Input&, int parent_side) const {
    const Triad& parent = frame(parent_side);
    return {Screw{Screw::Kind::rotation, parent.w, parent.point}};
  }

  void evaluate(const Input& in, BlocksOf<Revolute>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident(a, on_a_.point, b, on_b_.point, out, 0);
    primitive::dot1(a, on_a_.u, b, on_b_.w, out, 3);
    primitive::dot1(a, on_a_.v, b, on_b_.w, out, 4);
    out.phi_t.setZero();
  }

  Eigen::Matrix<double, 5, 1> gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Matrix<double, 5, 1> g;
    g << primitive::coincident_gamma(a, on_a_.point, b, on_b_.point),
        primitive::dot1_gamma(a, on_a_.u, b, on_b_.w),
        primitive::dot1_gamma(a, on_a_.v, b, on_b_.w);
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 5, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident_stiffness(a, on_a_.point, b, on_b_.point, lambda.head<3>(), out);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.w, lambda[3], out);
    primitive::dot1_stiffness(a, on_a_.v, b, on_b_.w, lambda[4], out);
  }
};
static_assert(Constraint<Revolute>);
static_assert(TreeJoint<Revolute>);

}  // namespace odyn::spatial
