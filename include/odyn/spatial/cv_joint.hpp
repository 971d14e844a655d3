#pragma once
// Constant-velocity (homokinetic) joint: the joint points coincide and b's joint frame is a's
// turned about an axis across a's shaft axis w, never about w itself: u_a . v_b = v_a . u_b.
// Two shafts held in bearings then turn at the same rate at any bend, where a universal joint's
// output speed fluctuates (tan psi = tan phi / cos beta). 4 equations.
//
// With (e0, e) the quaternion of b's frame in a's, u_a . v_b - v_a . u_b = -4 e0 e_w: the
// condition is e_w = 0 (no twist about the shaft), and also holds at e0 = 0 (a half turn), a
// branch that the joint keeps away from by refusing a start twisted by more than a quarter turn.

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"

namespace odyn::spatial {

inline constexpr std::array<Output, 1> cv_joint_outputs{{
    {"bend", "rad", "the angle between the two shafts' axes"},
}};

class CvJoint : public PairJoint {
 public:
  static constexpr int num_equations = 4;
  using PairJoint::PairJoint;
  static constexpr ElementDescription description{
      "cv_joint", "joint",
      "Constant-velocity (homokinetic): the points coincide and b's frame is a's turned about "
      "an axis across the shafts, so both turn at the same rate at any bend. 4 equations.",
      parameters::frame_pair, cv_joint_outputs};
  template <class Reader>
  static CvJoint from_parameters(Reader& r) {
    return parameters::from_frame_pair<CvJoint, JointFrame>(r);
  }

  /// Completes a reference left out so that b's frame is a's turned by the shortest rotation
  /// from a's shaft axis to b's (no twist), and refuses a start on the wrong branch.
  void bind(const Input& in) {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Vector3d w_a = a.direction(on_a_.w), w_b = b.direction(on_b_.w);
    if (w_a.dot(w_b) < -1.0 + 1e-6)
      throw ModelError(name_,
                       "the shafts' axes on body a and body b point in opposite directions at "
                       "the initial pose; a constant-velocity joint bends by less than a half "
                       "turn (reverse one axis)");
    if (on_a_.reference_given || !on_b_.reference_given)
      on_b_.adopt_reference(Eigen::Quaterniond::FromTwoVectors(w_a, w_b) * a.direction(on_a_.u),
                            b.rotation);
    else
      on_a_.adopt_reference(Eigen::Quaterniond::FromTwoVectors(w_b, w_a) * b.direction(on_b_.u),
                            a.rotation);
    const double twist = twist_angle(a, b);
    if (std::abs(twist) > 0.5 * std::numbers::pi)
      throw ModelError(name_, "the references on body a and body b are twisted by " +
                                  to_text(twist * 180.0 / std::numbers::pi) +
                                  " degrees about the shafts at the initial pose; a "
                                  "constant-velocity joint allows no twist: give references "
                                  "that agree, or leave one out to have it chosen");
  }

  void evaluate(const Input& in, BlocksOf<CvJoint>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident(a, on_a_.point, b, on_b_.point, out, 0);
    ConstraintBlocks<Space, 2, 2> terms;  // u_a . v_b, then v_a . u_b
    primitive::dot1(a, on_a_.u, b, on_b_.v, terms, 0);
    primitive::dot1(a, on_a_.v, b, on_b_.u, terms, 1);
    out.phi[3] = terms.phi[0] - terms.phi[1];
    for (int k = 0; k < 2; ++k)
      out.jacobian[k].row(3) = terms.jacobian[k].row(0) - terms.jacobian[k].row(1);
    out.phi_t.setZero();
  }

  Eigen::Vector4d gamma(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Eigen::Vector4d g;
    g << primitive::coincident_gamma(a, on_a_.point, b, on_b_.point),
        primitive::dot1_gamma(a, on_a_.u, b, on_b_.v) -
            primitive::dot1_gamma(a, on_a_.v, b, on_b_.u);
    return g;
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Vector4d& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    const auto &a = in.body(0), &b = in.body(1);
    primitive::coincident_stiffness(a, on_a_.point, b, on_b_.point, lambda.head<3>(), out);
    primitive::dot1_stiffness(a, on_a_.u, b, on_b_.v, lambda[3], out);
    primitive::dot1_stiffness(a, on_a_.v, b, on_b_.u, -lambda[3], out);
  }

  std::array<double, 1> outputs(const Input& in) const {
    const Eigen::Vector3d w_a = in.body(0).direction(on_a_.w), w_b = in.body(1).direction(on_b_.w);
    return {std::atan2(w_a.cross(w_b).norm(), w_a.dot(w_b))};
  }

  /// The twist of b's frame about the shafts relative to a's: 2 atan2(e_w, e0), from the
  /// quaternion (e0, e) of b's joint axes in a's.
  double twist_angle(const Space::Frame& a, const Space::Frame& b) const {
    const Eigen::Quaterniond relative(Space::RotationMatrix(axes(0, a).transpose() * axes(1, b)));
    const double sign = relative.w() < 0.0 ? -1.0 : 1.0;  // q and -q are the same rotation
    return 2.0 * std::atan2(sign * relative.z(), sign * relative.w());
  }
};
static_assert(Constraint<CvJoint>);

}  // namespace odyn::spatial
