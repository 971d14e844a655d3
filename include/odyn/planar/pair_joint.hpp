#pragma once
// What every two-body planar joint shares: its name, its bodies, its point and axis on each
// body, and the joint angle.
//
// A joint's axis on a body is a direction in body coordinates (a slider's direction, the zero
// line of a hinge's angle). An axis the user leaves out (zero vector) is taken parallel to the
// other body's axis at the initial pose; with neither given, body a's x axis serves. The joint
// angle is the angle from a's axis to b's axis, counter-clockwise; it is a difference of body
// angles, so it keeps counting past a full turn, and it is read within (-pi, pi] at the initial
// pose.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/joint_coordinate.hpp"
#include "odyn/core/parameter_blocks.hpp"
#include "odyn/core/planar.hpp"
#include "odyn/planar/primitives.hpp"

namespace odyn::planar {

/// A joint's point and axis on one body, in body coordinates.
struct JointFrame {
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  /// Zero vector: parallel to the other body's axis at the initial pose. To leave it out,
  /// leave the member out ({point}): an Eigen vector written {} is not zero but uninitialized.
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();
};

class PairJoint {
 public:
  using Space = odyn::Planar;
  using Vector = Eigen::Vector2d;
  static constexpr int num_bodies = 2;
  using Input = ElementInput<Space, 2>;
  /// The joint angle counts whole turns by itself (a difference of body angles).
  static constexpr bool angle_counts_turns_by_state = false;

  /// A joint's frame on one body, normalized.
  struct Side {
    Vector point = Vector::Zero();
    Vector axis = Vector::UnitX();  // unit
    bool axis_given = false;
  };

  PairJoint(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
            const JointFrame& on_b)
      : name_(std::move(name)),
        bodies_{body_a, body_b},
        on_a_(side_from(on_a, "a")),
        on_b_(side_from(on_b, "b")) {}

  const std::string& name() const { return name_; }
  const std::array<BodyId, 2>& bodies() const { return bodies_; }
  /// The joint's frame on body a (side 0) or b (side 1), in body coordinates.
  const Side& frame(int side) const { return side == 0 ? on_a_ : on_b_; }
  /// The joint's axes (axis and its perpendicular as columns, global) on the body at `side`.
  Space::RotationMatrix axes(int side, const Space::Frame& body) const {
    const Vector axis = body.direction(frame(side).axis);
    Space::RotationMatrix columns;
    columns << axis, Space::perpendicular(axis);
    return columns;
  }

  /// Joint angle: from a's axis to b's axis, counting turns (see the file comment).
  double angle(const Input& in) const {
    return in.body(1).angle - in.body(0).angle + angle_offset_;
  }
  double angle_rate(const Input& in) const { return in.body(1).omega() - in.body(0).omega(); }

  /// The slide of b's point along a's axis, (R_a axis) . (P_b - P_a), as a translational driver
  /// prescribes it, with its rate and gradient.
  JointCoordinate<Space> slide(const Input& in) const {
    ConstraintBlocks<Space, 1, 2> row;
    primitive::on_line(in.body(0), on_a_.axis, on_a_.point, in.body(1), on_b_.point, row, 0);
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
            primitive::on_line_gamma(in.body(0), on_a_.axis, on_a_.point, in.body(1), on_b_.point),
            slid.direction};
  }

  /// The joint angle as a constraint row (it counts turns by itself: `near` is not needed).
  JointRow<Space> angle_row(const Input& in, double /*near*/) const {
    JointRow<Space> x;
    x.value = angle(in);
    x.gradient << 0.0, 0.0, -1.0, 0.0, 0.0, 1.0;
    return x;
  }

  /// Completes the axes and the angle's whole turns from the initial pose.
  void bind(const Input& in) {
    const double phi_a = in.body(0).angle, phi_b = in.body(1).angle;
    if (!on_b_.axis_given)
      on_b_.axis = Space::rotation(phi_a - phi_b) * on_a_.axis;
    else if (!on_a_.axis_given)
      on_a_.axis = Space::rotation(phi_b - phi_a) * on_b_.axis;
    const double from_axes =
        std::atan2(on_b_.axis.y(), on_b_.axis.x()) - std::atan2(on_a_.axis.y(), on_a_.axis.x());
    const double turn = 2.0 * std::numbers::pi;
    const double initial = phi_b - phi_a + from_axes;
    angle_offset_ = from_axes - turn * std::round(initial / turn);
  }

 protected:
  Side side_from(const JointFrame& frame, const char* side) const {
    if (!frame.point.allFinite())
      throw ModelError(name_, std::string("point on body ") + side + " is not finite");
    if (!frame.axis.allFinite())
      throw ModelError(name_, std::string("axis on body ") + side + " is not finite");
    Side out;
    out.point = frame.point;
    const double length = frame.axis.norm();
    out.axis_given = length > 0.0;
    if (out.axis_given) {
      if (!(length > 1e-12))
        throw ModelError(name_, std::string("axis on body ") + side + " is too short (" +
                                    to_text(length) + "); give a unit direction");
      out.axis = frame.axis / length;
    }
    return out;
  }

  /// Writes the row "joint angle = target" (target added by the caller) into a block set.
  template <class Blocks>
  static void angle_row(Blocks& out, int row) {
    out.jacobian[0].row(row) << 0.0, 0.0, -1.0;
    out.jacobian[1].row(row) << 0.0, 0.0, 1.0;
  }

  std::string name_;
  std::array<BodyId, 2> bodies_;
  Side on_a_;
  Side on_b_;
  double angle_offset_ = 0.0;  // joint angle minus (phi_b - phi_a)
};

}  // namespace odyn::planar
