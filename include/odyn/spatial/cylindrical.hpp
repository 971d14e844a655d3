#pragma once
// Cylindrical joint: the axes stay parallel and body b's point stays on body a's axis; b may
// slide along and turn about it. 4 equations.

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

class Cylindrical : public PairJoint {
 public:
  static constexpr int num_equations = 4;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "cylindrical", "joint",
      "Cylindrical: the axes stay parallel and b's point stays on a's axis; b slides along and "
      "turns about it. 4 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Cylindrical from_parameters(Reader& r) {
    return parameters::from_frame_pair<Cylindrical, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 2;

  /// As a tree joint: the child slides along the parent's axis and turns about it.
  std::array<Screw, 2> tree_screws(const Input&, int parent_side) const {
    const Triad& parent = frame(parent_side);
    return {Screw{Screw::Kind::translation, parent.w, parent.point},
            Screw{Screw::Kind::rotation, parent.w, parent.point}};
  }

  void evaluate(const Input& in, BlocksOf<Cylindrical>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::dot1(a, on_a_.u, b, on_b_.w, out, 0);
    primitive::dot1(a, on_a_.v, b, on_b_.w, out, 1);
    primitive::dot2(a, on_a_.u, on_a_.point, b, on_b_.point, out, 2);
    primitive::dot2(a, on_a_.v, on_a_.point, b, on_b_.point, out, 3);
    out.phi_t.setZero();
  }

  Eigen::Vector4d gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Vector4d g;
    g << primitive::dot1_gamma(a, on_a_.u, b, on_b_.w),
        primitive::dot1_gamma(a, on_a_.v, b, on_b_.w),
        primitive::dot2_gamma(a, on_a_.u, on_a_.point, b, on_b_.point),
        primitive::dot2_gamma(a, on_a_.v, on_a_.point, b, on_b_.point);
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Vector4d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.w, lambda[0], out);
    primitive::dot1_stiffness(a, on_a_.v, b, on_b_.w, lambda[1], out);
    primitive::dot2_stiffness(a, on_a_.u, b, on_b_.point, lambda[2], out);
    primitive::dot2_stiffness(a, on_a_.v, b, on_b_.point, lambda[3], out);
  }
};
static_assert(Constraint<Cylindrical>);
static_assert(TreeJoint<Cylindrical>);

}  // namespace odyn::spatial
