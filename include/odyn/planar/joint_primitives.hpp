#pragma once
// Planar joint primitives: the in-line primitive (a pin in a slot), the plane's twin of the
// spatial one. Its description is the spatial one's: the same parameters and meaning.
//   inline   b's point stays on the line through a's point along a's axis    1 equation

#include "odyn/planar/pair_joint.hpp"
#include "odyn/planar/primitives.hpp"

namespace odyn::planar {

/// b's point stays on a's line; b turns freely (a pin in a slot).
class InLine : public PairJoint {
 public:
  static constexpr int num_equations = 1;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "inline", "joint",
      "In-line primitive: b's point stays on the line through a's point along a's axis (a pin "
      "in a slot). 1 equation.",
      parameters::frame_pair};
  template <class Reader>
  static InLine from_parameters(Reader& r) {
    return parameters::from_frame_pair<InLine, JointFrame>(r);
  }

  void evaluate(const Input& in, BlocksOf<InLine>& out) const {
    primitive::on_line(in.body(0), normal(), on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi_t.setZero();
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    return Eigen::Matrix<double, 1, 1>(
        primitive::on_line_gamma(in.body(0), normal(), on_a_.point, in.body(1), on_b_.point));
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 1, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::on_line_stiffness(in.body(0), normal(), in.body(1), on_b_.point, lambda[0], out);
  }

 private:
  Eigen::Vector2d normal() const { return Space::perpendicular(on_a_.axis); }
};
static_assert(Constraint<InLine>);

}  // namespace odyn::planar
