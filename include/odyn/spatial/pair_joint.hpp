#pragma once
// What every two-body spatial joint shares: its name, its bodies and its frame on each body.

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/joint_coordinate.hpp"
#include "odyn/core/parameter_blocks.hpp"
#include "odyn/core/spatial.hpp"
#include "odyn/spatial/joint_frame.hpp"
#include "odyn/spatial/primitives.hpp"

namespace odyn::spatial {

class PairJoint {
 public:
  using Space = odyn::Spatial;
  static constexpr int num_bodies = 2;
  using Input = ElementInput<Space, 2>;
  /// The angle about a's axis counts whole turns only from a state (see angle_row).
  static constexpr bool angle_counts_turns_by_state = true;

  PairJoint(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
            const JointFrame& on_b)
      : name_(std::move(name)),
        bodies_{body_a, body_b},
        on_a_(Triad::from(on_a, name_, "a")),
        on_b_(Triad::from(on_b, name_, "b")) {}

  const std::string& name() const { return name_; }
  const std::array<BodyId, 2>& bodies() const { return bodies_; }
  /// The joint's frame on body a (side 0) or b (side 1), in body coordinates.
  const Triad& frame(int side) const { return side == 0 ? on_a_ : on_b_; }
  /// The joint's axes (u, v, w as columns, global) on the body at `side`, whose frame is given.
  Space::RotationMatrix axes(int side, const Space::Frame& body) const {
    const Triad& triad = frame(side);
    Space::RotationMatrix columns;
    columns << body.direction(triad.u), body.direction(triad.v), body.direction(triad.w);
    return columns;
  }

  /// The slide of b's point along a's axis w, (R_a w) . (P_b - P_a), as a translational driver
  /// prescribes it, with its rate and gradient.
  JointCoordinate<Space> slide(const Input& in) const {
    ConstraintBlocks<Space, 1, 2> row;
    primitive::dot2(in.body(0), on_a_.w, on_a_.point, in.body(1), on_b_.point, row, 0);
    JointCoordinate<Space> x;
    x.value = row.phi[0];
    x.direction << row.jacobian[0].transpose(), row.jacobian[1].transpose();
    x.set_rate(in);
    return x;
  }

  /// The slide as a constraint row.
  JointRow<Space> slide_row(const Input& in) const {
    const JointCoordinate<Space> slid = slide(in);
    return {slid.value,
            primitive::dot2_gamma(in.body(0), on_a_.w, on_a_.point, in.body(1), on_b_.point),
            slid.direction};
  }

  /// The angle of b's reference u about a's axis w, from a's reference u, as a constraint row:
  /// atan2(v_a . u_b, u_a . u_b), whole turns added to come nearest `near`. Its gradient and
  /// gamma are the exact derivatives of that atan2, so that Newton and the acceleration level
  /// agree with it even off the joint's own equations.
  JointRow<Space> angle_row(const Input& in, double near) const {
    const auto &a = in.body(0), &b = in.body(1);
    ConstraintBlocks<Space, 2, 2> rows;  // y = v_a . u_b, then x = u_a . u_b
    primitive::dot1(a, on_a_.v, b, on_b_.u, rows, 0);
    primitive::dot1(a, on_a_.u, b, on_b_.u, rows, 1);
    const double y = rows.phi[0], x = rows.phi[1], r2 = x * x + y * y;
    const double y_rate = primitive::dot1_rate(a, on_a_.v, b, on_b_.u);
    const double x_rate = primitive::dot1_rate(a, on_a_.u, b, on_b_.u);
    const double y_gamma = primitive::dot1_gamma(a, on_a_.v, b, on_b_.u);
    const double x_gamma = primitive::dot1_gamma(a, on_a_.u, b, on_b_.u);
    JointRow<Space> angle;
    const double turn = 2.0 * std::numbers::pi, raw = std::atan2(y, x);
    angle.value = raw + turn * std::round((near - raw) / turn);
    for (int k = 0; k < 2; ++k)
      angle.gradient.segment<Space::nv>(k * Space::nv) =
          ((x * rows.jacobian[k].row(0) - y * rows.jacobian[k].row(1)) / r2).transpose();
    const double cross = x * y_rate - y * x_rate, along = x * x_rate + y * y_rate;
    angle.gamma = (x * y_gamma - y * x_gamma) / r2 + 2.0 * cross * along / (r2 * r2);
    return angle;
  }

  /// Completes the reference directions from the initial pose (see JointFrame::reference).
  void bind(const Input& in) { bind_references(on_a_, on_b_, in.body(0), in.body(1)); }

 protected:
  std::string name_;
  std::array<BodyId, 2> bodies_;
  Triad on_a_;
  Triad on_b_;
};

}  // namespace odyn::spatial
