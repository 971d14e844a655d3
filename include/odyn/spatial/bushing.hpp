#pragma once
// Bushing: a six-component spring-damper between a joint frame on body a and one on body b
// (forces/bushing.hpp, forces/bushing_law.hpp). Its displacement x = (d, theta) is frame b's
// origin in a's axes, d = R_a^T (p_b - p_a), and the rotation vector of b's axes relative to
// a's, theta = log(R_a^T R_b), in a's axes; it rests where the two frames coincide. A frame's
// axes are its body's unless given (the reference left out is the body's x axis, or y if the
// frame's axis is along x): unlike a joint's, they are not taken from the initial pose, so that
// a body started away from rest starts loaded. The law's generalized force g = (g_d, g_theta)
// acts on b at its frame's origin, with the opposite on a at the same point:
//     force  R_a g_d,   torque  R_a J_l^{-T}(theta) g_theta,
// J_l being SO(3)'s left Jacobian. That torque is the one whose power is g_theta . theta', so the
// spring stays conservative and the damper dissipative at any angle below a half turn (for small
// angles J_l = I and the bushing is ADAMS's); beyond pi the rotation vector flips to the other
// side.

#include <Eigen/Core>

#include "odyn/core/rotation.hpp"
#include "odyn/forces/bushing.hpp"
#include "odyn/spatial/pair_joint.hpp"

namespace odyn::spatial {

struct BushingGeometry {
  using Pair = PairJoint;
  using JointFrame = spatial::JointFrame;
  using Displacement = BushingLaw<6>::Displacement;
  static constexpr int components = 6;
  static constexpr const char* summary =
      "Six-component spring-damper between frame a and frame b: force and torque on b -K x - C "
      "x' + preload + law(t, x, x'), x = (b's origin in a's axes, rotation vector).";
  static constexpr std::array<Output, 18> outputs{{
      {"x", "m", "b's frame origin in a's axes, x"},
      {"y", "m", "b's frame origin in a's axes, y"},
      {"z", "m", "b's frame origin in a's axes, z"},
      {"rx", "rad", "the rotation vector from a's axes to b's, x (a's axes)"},
      {"ry", "rad", "the rotation vector from a's axes to b's, y (a's axes)"},
      {"rz", "rad", "the rotation vector from a's axes to b's, z (a's axes)"},
      {"vx", "m/s", "the rate of x"},
      {"vy", "m/s", "the rate of y"},
      {"vz", "m/s", "the rate of z"},
      {"wx", "rad/s", "the rate of rx"},
      {"wy", "rad/s", "the rate of ry"},
      {"wz", "rad/s", "the rate of rz"},
      {"fx", "N", "the law's force on b, x (a's axes)"},
      {"fy", "N", "the law's force on b, y (a's axes)"},
      {"fz", "N", "the law's force on b, z (a's axes)"},
      {"tx", "N m", "the law's torque component x (on b, a's axes, at small angles)"},
      {"ty", "N m", "the law's torque component y (on b, a's axes, at small angles)"},
      {"tz", "N m", "the law's torque component z (on b, a's axes, at small angles)"},
  }};

  /// The frame with its reference filled in from the body's axes (see the file comment).
  static JointFrame with_defaults(JointFrame frame) {
    if (frame.reference.squaredNorm() == 0.0 && frame.axis.allFinite())
      frame.reference = frame.axis.cross(Eigen::Vector3d::UnitX()).norm() > 1e-6 * frame.axis.norm()
                            ? Eigen::Vector3d::UnitX()
                            : Eigen::Vector3d::UnitY();
    return frame;
  }

  static Displacement displacement(const Pair& pair, const Pair::Input& in) {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Matrix3d axes_a = pair.axes(0, a);
    const Eigen::Vector3d point_a = pair.frame(0).point, point_b = pair.frame(1).point;
    const Eigen::Vector3d d = axes_a.transpose() * (b.point(point_b) - a.point(point_a));
    const Eigen::Vector3d theta = rotation_log(axes_a.transpose() * pair.axes(1, b));
    // d' = R_a^T (p_b' - p_a') - omega_a x d and theta' = J_l^{-1} omega, with the angular
    // velocities in a's axes (omega: b's relative to a's).
    const Eigen::Vector3d omega_a = axes_a.transpose() * a.global_angular_velocity();
    const Eigen::Vector3d omega = axes_a.transpose() * b.global_angular_velocity() - omega_a;
    const Eigen::Vector3d d_rate =
        axes_a.transpose() * (b.point_velocity(point_b) - a.point_velocity(point_a)) -
        omega_a.cross(d);
    Displacement out;
    out.x << d, theta;
    out.rate << d_rate, left_jacobian_inverse(theta) * omega;
    return out;
  }

  static void apply(const Pair& pair, const Pair::Input& in, const Displacement& x,
                    const BushingLaw<6>::Vector& g, ForceBlocks<Spatial, 2>& out) {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Matrix3d axes_a = pair.axes(0, a);
    const Eigen::Vector3d origin_b = b.point(pair.frame(1).point);
    const Eigen::Vector3d force = axes_a * g.head<3>();
    const Eigen::Vector3d torque =
        axes_a * (left_jacobian_inverse(x.x.tail<3>()).transpose() * g.tail<3>());
    out.force[0] << -force,
        a.rotation.transpose() * (-torque - (origin_b - a.position).cross(force));
    out.force[1] << force, b.rotation.transpose() * (torque + (origin_b - b.position).cross(force));
  }
};

using Bushing = BushingT<BushingGeometry>;
static_assert(StatelessForce<Bushing> && HasForceJacobians<Bushing> && HasPotential<Bushing>);

}  // namespace odyn::spatial
