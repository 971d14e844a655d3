#pragma once
// Translational (prismatic) joint: a cylindrical joint that also keeps the bodies from turning
// about the axis; body b slides along body a's axis. 5 equations.

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

class Translational : public PairJoint {
 public:
  static constexpr int num_equations = 5;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "translational", "joint",
      "Translational (prismatic): b slides along a's axis without turning. 5 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Translational from_parameters(Reader& r) {
    return parameters::from_frame_pair<Translational, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 1;

  /// As a tree joint: the child slides along the parent's axis.
  std::array<Screw, 1> tree_screws(const Input&, int parent_side) const {
    const Triad& parent = frame(parent_side);
    return {Screw{Screw::Kind::translation, parent.w, parent.point}};
  }

  void evaluate(const Input& in, BlocksOf<Translational>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::dot1(a, on_a_.u, b, on_b_.w, out, 0);
    primitive::dot1(a, on_a_.v, b, on_b_.w, out, 1);
    primitive::dot2(a, on_a_.u, on_a_.point, b, on_b_.point, out, 2);
    primitive::dot2(a, on_a_.v, on_a_.point, b, on_b_.point, out, 3);
    primitive::dot1(a, on_a_.u, b, on_b_.v, out, 4);
    out.phi_t.setZero();
  }

  Eigen::Matrix<double, 5, 1> gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Matrix<double, 5, 1> g;
    g << primitive::dot1_gamma(a, on_a_.u, b, on_b_.w),
        primitive::dot1_gamma(a, on_a_.v, b, on_b_.w),
        primitive::dot2_gamma(a, on_a_.u, on_a_.point, b, on_b_.point),
        primitive::dot2_gamma(a, on_a_.v, on_a_.point, b, on_b_.point),
        primitive::dot1_gamma(a, on_a_.u, b, on_b_.v);
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 5, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.w, lambda[0], out);
    primitive::dot1_stiffness(a, on_a_.v, b, on_b_.w, lambda[1], out);
    primitive::dot2_stiffness(a, on_a_.u, b, on_b_.point, lambda[2], out);
    primitive::dot2_stiffness(a, on_a_.v, b, on_b_.point, lambda[3], out);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.v, lambda[4], out);
  }
};
static_assert(Constraint<Translational>);
static_assert(TreeJoint<Translational>);

}  // namespace odyn::spatial
