#pragma once
// An undamped planar double pendulum: two uniform bars of length l hanging from a pin at the
// origin and pinned to each other, under gravity along -y, released at rest at angles theta1
// (upper bar) and theta2 (lower bar) from the downward vertical. Chaotic for large angles;
// nothing dissipates energy but the integrator.

#include <cmath>

#include <odyn/odyn.hpp>

namespace double_pendulum {

namespace pl = odyn::planar;
using Eigen::Vector2d;

struct Parameters {
  double mass = 1.0, length = 1.0;    // each bar; kg, m
  double theta1 = 1.0, theta2 = 2.0;  // rad, from the downward vertical
  double g = 9.81;                    // m/s^2
};

using Model = pl::Model<pl::Revolute, pl::Gravity>;

struct Pendulum {
  Model model;
  odyn::BodyId upper, lower;
  odyn::Handle<pl::Revolute> shoulder, elbow;
};

inline Pendulum build(const Parameters& p = {}) {
  Pendulum d;
  // A bar's body x axis runs from its top to its bottom.
  const Vector2d down1(std::sin(p.theta1), -std::cos(p.theta1));
  const Vector2d down2(std::sin(p.theta2), -std::cos(p.theta2));
  auto bar = [&](const char* name, const Vector2d& top, const Vector2d& down) {
    return pl::Body{.name = name,
                    .mass = p.mass,
                    .inertia = p.mass * p.length * p.length / 12.0,
                    .position = top + 0.5 * p.length * down,
                    .angle = std::atan2(down.y(), down.x())};
  };
  d.upper = d.model.add_body(bar("upper", Vector2d::Zero(), down1));
  d.lower = d.model.add_body(bar("lower", p.length * down1, down2));
  const double half = 0.5 * p.length;
  d.shoulder =
      d.model.add(pl::Revolute("shoulder", odyn::ground, {{0.0, 0.0}}, d.upper, {{-half, 0.0}}));
  d.elbow = d.model.add(pl::Revolute("elbow", d.upper, {{half, 0.0}}, d.lower, {{-half, 0.0}}));
  d.model.add(pl::Gravity("gravity", {0.0, -p.g}));
  return d;
}

}  // namespace double_pendulum
