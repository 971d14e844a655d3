#pragma once
// What every two-body spatial joint shares: its name, its bodies and its frame on each body.

#include <array>
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

  /// Completes the reference directions from the initial pose (see JointFrame::reference).
  void bind(const Input& in) { bind_references(on_a_, on_b_, in.body(0), in.body(1)); }

 protected:
  std::string name_;
  std::array<BodyId, 2> bodies_;
  Triad on_a_;
  Triad on_b_;
};

}  // namespace odyn::spatial
