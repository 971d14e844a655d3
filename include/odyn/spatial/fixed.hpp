#pragma once
// Fixed (weld) joint: the joint frames of the two bodies stay together. 6 equations.

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

class Fixed : public PairJoint {
 public:
  static constexpr int num_equations = 6;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "fixed", "joint",
      "Fixed (weld): the joint frames of the two bodies stay together. 6 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Fixed from_parameters(Reader& r) {
    return parameters::from_frame_pair<Fixed, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 0;

  /// As a tree joint: the child is carried rigidly.
  std::array<Screw, 0> tree_screws(const Input&, int) const { return {}; }

  void evaluate(const Input& in, BlocksOf<Fixed>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident(a, on_a_.point, b, on_b_.point, out, 0);
    primitive::dot1(a, on_a_.u, b, on_b_.w, out, 3);
    primitive::dot1(a, on_a_.v, b, on_b_.w, out, 4);
    primitive::dot1(a, on_a_.u, b, on_b_.v, out, 5);
    out.phi_t.setZero();
  }

  Eigen::Matrix<double, 6, 1> gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Matrix<double, 6, 1> g;
    g << primitive::coincident_gamma(a, on_a_.point, b, on_b_.point),
        primitive::dot1_gamma(a, on_a_.u, b, on_b_.w),
        primitive::dot1_gamma(a, on_a_.v, b, on_b_.w),
        primitive::dot1_gamma(a, on_a_.u, b, on_b_.v);
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 6, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident_stiffness(a, on_a_.point, b, on_b_.point, lambda.head<3>(), out);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.w, lambda[3], out);
    primitive::dot1_stiffness(a, on_a_.v, b, on_b_.w, lambda[4], out);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.v, lambda[5], out);
  }
};
static_assert(Constraint<Fixed>);
static_assert(TreeJoint<Fixed>);

}  // namespace odyn::spatial
