#pragma once
// Planar translational (prismatic) joint: b's point slides along the line through a's point
// with a's axis, and the bodies do not turn relative to each other. 2 equations. The axes
// stay parallel as at the initial pose (same or opposite sense: a slide has no direction).

#include <cmath>
#include <numbers>

#include "odyn/planar/pair_joint.hpp"
#include "odyn/planar/primitives.hpp"
#include "odyn/planar/screw.hpp"

namespace odyn::planar {

class Translational : public PairJoint {
 public:
  static constexpr int num_equations = 2;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "translational", "joint",
      "Translational (slider): b's point moves along the line through a's point with a's axis, "
      "without turning. 2 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Translational from_parameters(Reader& r) {
    return parameters::from_frame_pair<Translational, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 1;

  /// As a tree joint: the child slides along a's axis, which keeps its direction in the parent's
  /// coordinates (the bodies do not turn relative to each other).
  std::array<Screw, 1> tree_screws(const Input& in, int parent_side) const {
    const Eigen::Vector2d along =
        in.body(parent_side).rotation.transpose() * in.body(0).direction(on_a_.axis);
    return {Screw{Screw::Kind::translation, along, frame(parent_side).point}};
  }

  void bind(const Input& in) {
    PairJoint::bind(in);
    held_angle_ = std::numbers::pi * std::round(angle(in) / std::numbers::pi);
  }

  void evaluate(const Input& in, BlocksOf<Translational>& out) const {
    primitive::on_line(in.body(0), normal(), on_a_.point, in.body(1), on_b_.point, out, 0);
    out.phi[1] = angle(in) - held_angle_;
    angle_row(out, 1);
    out.phi_t.setZero();
  }

  Eigen::Vector2d gamma(const Input& in) const {
    return {primitive::on_line_gamma(in.body(0), normal(), on_a_.point, in.body(1), on_b_.point),
            0.0};
  }

  /// The angle row is linear in the coordinates: it adds nothing.
  void add_geometric_stiffness(const Input& in, const Eigen::Vector2d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::on_line_stiffness(in.body(0), normal(), in.body(1), on_b_.point, lambda[0], out);
  }

  /// The slide: displacement of b's point along a's axis, from a's point.
  double displacement(const Input& in) const {
    return in.body(0)
        .direction(on_a_.axis)
        .dot(in.body(1).point(on_b_.point) - in.body(0).point(on_a_.point));
  }

 private:
  Eigen::Vector2d normal() const { return Space::perpendicular(on_a_.axis); }
  double held_angle_ = 0.0;  // 0 or a multiple of pi
};
static_assert(Constraint<Translational>);
static_assert(TreeJoint<Translational>);

}  // namespace odyn::planar
