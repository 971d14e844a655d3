#pragma once
// Planar fixed (weld) joint: the joint points coincide and the joint angle stays zero (the
// axes as at the initial pose unless both are given). 3 equations.

#include "odyn/planar/pair_joint.hpp"
#include "odyn/planar/primitives.hpp"
#include "odyn/planar/screw.hpp"

namespace odyn::planar {

class Fixed : public PairJoint {
 public:
  static constexpr int num_equations = 3;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{"fixed", "joint",
                                                  "Fixed (weld): the joint points coincide and the "
                                                  "joint angle stays as it starts. 3 equations.",
                                                  parameters::frame_pair};
  template <class Reader>
  static Fixed from_parameters(Reader& r) {
    return parameters::from_frame_pair<Fixed, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 0;

  /// As a tree joint: the child moves with its parent.
  std::array<Screw, 0> tree_screws(const Input&, int) const { return {}; }

  void evaluate(const Input& in, BlocksOf<Fixed>& out) const {
    primitive::coincident(in.body(0), on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi[2] = angle(in);
    angle_row(out, 2);
    out.phi_t.setZero();
  }

  Eigen::Vector3d gamma(const Input& in) const {
    Eigen::Vector3d g;
    g << primitive::coincident_gamma(in.body(0), on_a_.point, in.body(1), on_b_.point), 0.0;
    return g;
  }

  /// The angle row is linear in the coordinates: it adds nothing.
  void add_geometric_stiffness(const Input& in, const Eigen::Vector3d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::coincident_stiffness(in.body(0), on_a_.point, in.body(1), on_b_.point,
                                    lambda.head<2>(), out);
  }
};
static_assert(Constraint<Fixed>);
static_assert(TreeJoint<Fixed>);

}  // namespace odyn::planar
