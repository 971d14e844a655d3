#pragma once
// Joint primitives (ADAMS's JPRIM): the elementary constraints between two joint frames from
// which any joint can be composed, and the planar joint built from two of them. Each is a list
// of rows, of two kinds (spatial/primitives.hpp):
//   perpendicular axes  (R_a x_a) . (R_b x_b) = 0         for axes x of the two frames
//   point in plane      (R_a x_a) . (P_b - P_a) = 0       for an axis x of a's frame
//
//   inline          b's point stays on a's axis (the line through a's point)     2 equations
//   inplane         b's point stays in a's plane (through a's point, normal a's axis)   1
//   orientation     the frames stay aligned (the references as given or as at the start) 3
//   parallel_axes   the axes stay parallel                                              2
//   perpendicular   the axes stay perpendicular                                         1
//   planar          b slides on a's plane and turns only about its normal                3
// Spherical (spatial/spherical.hpp) is the at-point primitive.

#include <array>

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::spatial {

/// One row of a primitive joint: which kind, and which axes of the two frames (0: u, 1: v,
/// 2: w, the joint axis).
struct PrimitiveRow {
  enum class Kind { perpendicular_axes, point_in_plane };
  Kind kind;
  int axis_a;
  int axis_b = 2;  // perpendicular_axes only
};

/// A joint whose equations are the rows Derived::rows (M of them), each written from the same
/// primitives as the catalogue's joints, with its gamma and geometric stiffness.
template <class Derived, int M>
class PrimitiveJoint : public PairJoint {
 public:
  static constexpr int num_equations = M;
  using PairJoint::PairJoint;
  using Row = PrimitiveRow;

  void evaluate(const Input& in, ConstraintBlocks<Space, M, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    for (int i = 0; i < M; ++i) {
      const Row& row = Derived::rows[static_cast<std::size_t>(i)];
      if (row.kind == Row::Kind::perpendicular_axes)
        primitive::dot1(a, axis(on_a_, row.axis_a), b, axis(on_b_, row.axis_b), out, i);
      else
        primitive::dot2(a, axis(on_a_, row.axis_a), on_a_.point, b, on_b_.point, out, i);
    }
    out.phi_t.setZero();
  }

  Eigen::Matrix<double, M, 1> gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Matrix<double, M, 1> g;
    for (int i = 0; i < M; ++i) {
      const Row& row = Derived::rows[static_cast<std::size_t>(i)];
      g[i] = row.kind == Row::Kind::perpendicular_axes
                 ? primitive::dot1_gamma(a, axis(on_a_, row.axis_a), b, axis(on_b_, row.axis_b))
                 : primitive::dot2_gamma(a, axis(on_a_, row.axis_a), on_a_.point, b, on_b_.point);
    }
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, M, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    for (int i = 0; i < M; ++i) {
      const Row& row = Derived::rows[static_cast<std::size_t>(i)];
      if (row.kind == Row::Kind::perpendicular_axes)
        primitive::dot1_stiffness(a, axis(on_a_, row.axis_a), b, axis(on_b_, row.axis_b), lambda[i],
                                  out);
      else
        primitive::dot2_stiffness(a, axis(on_a_, row.axis_a), b, on_b_.point, lambda[i], out);
    }
  }

 private:
  static const Eigen::Vector3d& axis(const Triad& frame, int which) {
    return which == 0 ? frame.u : which == 1 ? frame.v : frame.w;
  }
};

/// b's point stays on a's axis: a cylindrical joint without its parallel axes.
class InLine : public PrimitiveJoint<InLine, 2> {
 public:
  using PrimitiveJoint::PrimitiveJoint;
  static constexpr std::array<Row, 2> rows{
      {{Row::Kind::point_in_plane, 0}, {Row::Kind::point_in_plane, 1}}};
  static constexpr ElementDescription description{
      "inline", "joint",
      "In-line primitive: b's point stays on the line through a's point along a's axis. "
      "2 equations.",
      parameters::frame_pair};
  template <class Reader>
  static InLine from_parameters(Reader& r) {
    return parameters::from_frame_pair<InLine, JointFrame>(r);
  }
};

/// b's point stays in the plane through a's point whose normal is a's axis.
class InPlane : public PrimitiveJoint<InPlane, 1> {
 public:
  using PrimitiveJoint::PrimitiveJoint;
  static constexpr std::array<Row, 1> rows{{{Row::Kind::point_in_plane, 2}}};
  static constexpr ElementDescription description{
      "inplane", "joint",
      "In-plane primitive: b's point stays in the plane through a's point normal to a's axis. "
      "1 equation.",
      parameters::frame_pair};
  template <class Reader>
  static InPlane from_parameters(Reader& r) {
    return parameters::from_frame_pair<InPlane, JointFrame>(r);
  }
};

/// The two frames stay aligned (about the axis, as their references give or as at the start):
/// a fixed joint without its coincident points.
class Orientation : public PrimitiveJoint<Orientation, 3> {
 public:
  using PrimitiveJoint::PrimitiveJoint;
  static constexpr std::array<Row, 3> rows{{{Row::Kind::perpendicular_axes, 0, 2},
                                            {Row::Kind::perpendicular_axes, 1, 2},
                                            {Row::Kind::perpendicular_axes, 0, 1}}};
  static constexpr ElementDescription description{
      "orientation", "joint",
      "Orientation primitive: b's frame keeps a's orientation (axes aligned, references as "
      "given or as at the start); b translates freely. 3 equations.",
      parameters::frame_pair};
  template <class Reader>
  static Orientation from_parameters(Reader& r) {
    return parameters::from_frame_pair<Orientation, JointFrame>(r);
  }
};

/// The two axes stay parallel.
class ParallelAxes : public PrimitiveJoint<ParallelAxes, 2> {
 public:
  using PrimitiveJoint::PrimitiveJoint;
  static constexpr std::array<Row, 2> rows{
      {{Row::Kind::perpendicular_axes, 0, 2}, {Row::Kind::perpendicular_axes, 1, 2}}};
  static constexpr ElementDescription description{
      "parallel_axes", "joint",
      "Parallel-axes primitive: b's axis stays parallel to a's. 2 equations.",
      parameters::frame_pair};
  template <class Reader>
  static ParallelAxes from_parameters(Reader& r) {
    return parameters::from_frame_pair<ParallelAxes, JointFrame>(r);
  }
};

/// The two axes stay perpendicular.
class Perpendicular : public PrimitiveJoint<Perpendicular, 1> {
 public:
  using PrimitiveJoint::PrimitiveJoint;
  static constexpr std::array<Row, 1> rows{{{Row::Kind::perpendicular_axes, 2, 2}}};
  static constexpr ElementDescription description{
      "perpendicular", "joint",
      "Perpendicular primitive: b's axis stays perpendicular to a's. 1 equation.",
      parameters::frame_pair};
  template <class Reader>
  static Perpendicular from_parameters(Reader& r) {
    return parameters::from_frame_pair<Perpendicular, JointFrame>(r);
  }
};

/// Planar joint: b's point stays in a's plane (normal a's axis) and the axes stay parallel, so
/// that b slides in the plane and turns about its normal.
class PlanarJoint : public PrimitiveJoint<PlanarJoint, 3> {
 public:
  using PrimitiveJoint::PrimitiveJoint;
  static constexpr std::array<Row, 3> rows{{{Row::Kind::point_in_plane, 2},
                                            {Row::Kind::perpendicular_axes, 0, 2},
                                            {Row::Kind::perpendicular_axes, 1, 2}}};
  static constexpr ElementDescription description{
      "planar", "joint",
      "Planar joint: b's point stays in a's plane (normal a's axis) and the axes stay parallel; "
      "b slides in the plane and turns about its normal. 3 equations.",
      parameters::frame_pair};
  template <class Reader>
  static PlanarJoint from_parameters(Reader& r) {
    return parameters::from_frame_pair<PlanarJoint, JointFrame>(r);
  }
  static constexpr int degrees_of_freedom = 3;

  /// As a tree joint: the child slides along the parent's u and v and turns about its w.
  std::array<Screw, 3> tree_screws(const Input&, int parent_side) const {
    const Triad& parent = frame(parent_side);
    return {Screw{Screw::Kind::translation, parent.u, parent.point},
            Screw{Screw::Kind::translation, parent.v, parent.point},
            Screw{Screw::Kind::rotation, parent.w, parent.point}};
  }
};

static_assert(Constraint<InLine> && Constraint<InPlane> && Constraint<Orientation> &&
              Constraint<ParallelAxes> && Constraint<Perpendicular>);
static_assert(TreeJoint<PlanarJoint>);

}  // namespace odyn::spatial
