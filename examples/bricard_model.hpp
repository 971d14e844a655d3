#pragma once
// Bricard's orthogonal linkage: a closed loop of six equal links (one of them the ground) and
// six revolute joints, each joint axis perpendicular to both links it connects, each link
// turning the axis by 90 degrees. Its initial pose runs along six edges of a unit cube,
//   V1 = (0,0,0), V2 = (1,0,0), V3 = (1,1,0), V4 = (1,1,1), V5 = (0,1,1), V6 = (0,0,1),
// with the ground link V6-V1 and five uniform bars V1-V2, ..., V5-V6 (lengths scaled by
// `length`). Grubler's count gives 6 x 5 - 5 x 6 = 0 degrees of freedom, yet the linkage moves
// with one: Phi_q (30 equations) has rank 29 at every pose, one equation is always redundant.
// Released at rest under gravity along -z it folds and swings back (no friction).
// With `cylinder`, joint J6 is a cylindrical joint instead: its fifth equation (no sliding
// along the axis) is the one the other joints already impose, so the linkage moves the same
// way with 29 independent equations: the same mechanism without its redundancy.

#include <array>
#include <string>

#include <odyn/odyn.hpp>

namespace bricard {

namespace sp = odyn::spatial;
using Eigen::Vector3d;

struct Parameters {
  double length = 1.0;                // m, every link
  double mass = 1.0;                  // kg, every moving bar
  double radius = 0.01;               // m, of the bars (their inertia about their own axis)
  Vector3d gravity{0.0, 0.0, -9.81};  // m/s^2
  bool cylinder = false;              // J6 cylindrical (no redundant equation)
};

using Model = sp::Model<sp::Revolute, sp::Cylindrical, sp::RevoluteDriver, sp::Gravity>;

struct Linkage {
  Model model;
  std::array<odyn::BodyId, 5> bars;
  std::array<odyn::Handle<sp::Revolute>, 6> joints;  // J1 (ground-bar 1) ... J6 (bar 5-ground)
  odyn::Handle<sp::Cylindrical> cylinder;            // J6 instead, with Parameters::cylinder
};

/// The corners V1..V6 of the initial pose, and the joint axes there.
inline std::array<Vector3d, 6> corners(double length) {
  return {Vector3d(0, 0, 0) * length, Vector3d(1, 0, 0) * length, Vector3d(1, 1, 0) * length,
          Vector3d(1, 1, 1) * length, Vector3d(0, 1, 1) * length, Vector3d(0, 0, 1) * length};
}
inline std::array<Vector3d, 6> axes() {
  return {Vector3d::UnitY(), Vector3d::UnitZ(), Vector3d::UnitX(),
          Vector3d::UnitY(), Vector3d::UnitZ(), Vector3d::UnitX()};
}

/// Builds the linkage at its cube pose, at rest, with gravity.
inline Linkage build(const Parameters& p = {}) {
  Linkage l;
  const auto v = corners(p.length);
  const auto w = axes();
  const double transverse = p.mass * (p.length * p.length / 12.0 + p.radius * p.radius / 4.0);
  const double axial = 0.5 * p.mass * p.radius * p.radius;
  for (int i = 0; i < 5; ++i) {
    const Vector3d e = (v[i + 1] - v[i]) / p.length;  // the bar's direction (body = global axes)
    const Eigen::Matrix3d inertia =
        transverse * (Eigen::Matrix3d::Identity() - e * e.transpose()) + axial * e * e.transpose();
    l.bars[i] = l.model.add_body({.name = "bar " + std::to_string(i + 1),
                                  .mass = p.mass,
                                  .inertia = inertia,
                                  .position = 0.5 * (v[i] + v[i + 1])});
  }
  // Joint i sits at V_i, between bar i-1 (or the ground) and bar i (or the ground).
  for (int i = 0; i < 6; ++i) {
    const odyn::BodyId a = i == 0 ? odyn::ground : l.bars[i - 1];
    const odyn::BodyId b = i == 5 ? odyn::ground : l.bars[i];
    const Vector3d on_a = i == 0 ? v[0] : Vector3d(0.5 * (v[i] - v[i - 1]));
    const Vector3d on_b = i == 5 ? v[5] : Vector3d(0.5 * (v[i] - v[i + 1]));
    const std::string name = "J" + std::to_string(i + 1);
    if (i == 5 && p.cylinder)
      l.cylinder = l.model.add(sp::Cylindrical(name, a, {on_a, w[i]}, b, {on_b, w[i]}));
    else
      l.joints[i] = l.model.add(sp::Revolute(name, a, {on_a, w[i]}, b, {on_b, w[i]}));
  }
  l.model.add(sp::Gravity("gravity", p.gravity));
  return l;
}

}  // namespace bricard
