#pragma once
// Planar bushing: a three-component spring-damper between a joint frame on body a and one on
// body b (forces/bushing.hpp, forces/bushing_law.hpp), the spatial bushing's twin. Its
// displacement x = (d, theta) is frame b's origin in a's axes, d = R_a^T (p_b - p_a), and the
// joint angle from a's axis to b's (PairJoint::angle, counting turns); it rests where the frames
// coincide. An axis left out is the body's x axis (not, as for a joint, the other body's at the
// initial pose), so that a body started away from rest starts loaded. The law's generalized
// force g = (g_d, g_theta) acts on b at its frame's origin, the force R_a g_d and the torque
// g_theta, with the opposite on a at the same point.

#include <Eigen/Core>

#include "odyn/forces/bushing.hpp"
#include "odyn/planar/pair_joint.hpp"

namespace odyn::planar {

struct BushingGeometry {
  using Pair = PairJoint;
  using JointFrame = planar::JointFrame;
  using Displacement = BushingLaw<3>::Displacement;
  static constexpr int components = 3;
  static constexpr const char* summary =
      "Three-component spring-damper between frame a and frame b: force and torque on b -K x - C "
      "x' + preload + law(t, x, x'), x = (b's origin in a's axes, joint angle).";
  static constexpr std::array<Output, 9> outputs{{
      {"x", "m", "b's frame origin in a's axes, x"},
      {"y", "m", "b's frame origin in a's axes, y"},
      {"rz", "rad", "the joint angle from a's axis to b's, counting turns"},
      {"vx", "m/s", "the rate of x"},
      {"vy", "m/s", "the rate of y"},
      {"wz", "rad/s", "the rate of rz"},
      {"fx", "N", "the law's force on b, x (a's axes)"},
      {"fy", "N", "the law's force on b, y (a's axes)"},
      {"tz", "N m", "the law's torque on b"},
  }};

  static JointFrame with_defaults(JointFrame frame) {
    if (frame.axis.squaredNorm() == 0.0) frame.axis = Eigen::Vector2d::UnitX();
    return frame;
  }

  static Displacement displacement(const Pair& pair, const Pair::Input& in) {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Matrix2d axes_a = pair.axes(0, a);
    const Eigen::Vector2d point_a = pair.frame(0).point, point_b = pair.frame(1).point;
    const Eigen::Vector2d d = axes_a.transpose() * (b.point(point_b) - a.point(point_a));
    // d' = R_a^T (p_b' - p_a') - phi_a' perpendicular(d).
    const Eigen::Vector2d d_rate =
        axes_a.transpose() * (b.point_velocity(point_b) - a.point_velocity(point_a)) -
        a.omega() * Planar::perpendicular(d);
    Displacement out;
    out.x << d, pair.angle(in);
    out.rate << d_rate, pair.angle_rate(in);
    return out;
  }

  static void apply(const Pair& pair, const Pair::Input& in, const Displacement&,
                    const BushingLaw<3>::Vector& g, ForceBlocks<Planar, 2>& out) {
    const auto &a = in.body(0), &b = in.body(1);
    const Eigen::Vector2d force = pair.axes(0, a) * g.head<2>();
    const Eigen::Vector2d origin_b = b.point(pair.frame(1).point);
    out.force[0] << -force, -g[2] - Planar::cross(origin_b - a.position, force);
    out.force[1] << force, g[2] + Planar::cross(origin_b - b.position, force);
  }
};

using Bushing = BushingT<BushingGeometry>;
static_assert(StatelessForce<Bushing> && HasForceJacobians<Bushing> && HasPotential<Bushing>);

}  // namespace odyn::planar
