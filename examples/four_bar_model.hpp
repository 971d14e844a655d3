#pragma once
// A planar crank-rocker four-bar linkage under gravity, its crank driven at constant speed.
// Ground pivots O2 = (0, 0) and O4 = (ground, 0); links crank O2-A, coupler A-B, rocker O4-B,
// each a uniform bar whose body x axis runs from its first point to its second.

#include <cmath>
#include <numbers>

#include <odyn/odyn.hpp>

namespace four_bar {

namespace pl = odyn::planar;
using Eigen::Vector2d;

struct Parameters {
  double ground = 0.40, crank = 0.10, coupler = 0.35, rocker = 0.30;  // link lengths, m
  double crank_mass = 0.5, coupler_mass = 1.2, rocker_mass = 1.0;     // kg
  double speed = 2.0 * std::numbers::pi;                              // crank, rad/s
  double g = 9.81;                                                    // m/s^2, along -y
};

using Model = pl::Model<pl::Revolute, pl::RevoluteDriver, pl::Gravity>;

struct Linkage {
  Model model;
  odyn::BodyId crank, coupler, rocker;
  odyn::Handle<pl::Revolute> o2, a, b, o4;
  odyn::Handle<pl::RevoluteDriver> motor;
};

/// Point B of the open (upper) assembly for a crank angle: the circles about A (coupler) and
/// about O4 (rocker) meet there.
inline Vector2d point_b(const Parameters& p, double crank_angle) {
  const Vector2d a = p.crank * Vector2d(std::cos(crank_angle), std::sin(crank_angle));
  const Vector2d o4(p.ground, 0.0);
  const Vector2d d = o4 - a;
  const double distance = d.norm();
  const double along =
      (distance * distance + p.coupler * p.coupler - p.rocker * p.rocker) / (2.0 * distance);
  const double across = std::sqrt(p.coupler * p.coupler - along * along);
  const Vector2d unit = d / distance;
  return a + along * unit + across * Vector2d(-unit.y(), unit.x());
}

/// Builds the linkage with the crank at angle 0, at rest; the motor then turns it.
inline Linkage build(const Parameters& p = {}) {
  Linkage l;
  const Vector2d o2(0.0, 0.0), o4(p.ground, 0.0), a(p.crank, 0.0), b = point_b(p, 0.0);
  auto bar = [](const char* name, double mass, const Vector2d& from, const Vector2d& to) {
    const Vector2d d = to - from;
    return pl::Body{.name = name,
                    .mass = mass,
                    .inertia = mass * d.squaredNorm() / 12.0,
                    .position = 0.5 * (from + to),
                    .angle = std::atan2(d.y(), d.x())};
  };
  l.crank = l.model.add_body(bar("crank", p.crank_mass, o2, a));
  l.coupler = l.model.add_body(bar("coupler", p.coupler_mass, a, b));
  l.rocker = l.model.add_body(bar("rocker", p.rocker_mass, o4, b));
  const double half_crank = p.crank / 2, half_coupler = p.coupler / 2, half_rocker = p.rocker / 2;
  const pl::Revolute pivot("O2", odyn::ground, {o2}, l.crank, {{-half_crank, 0.0}});
  l.o2 = l.model.add(pivot);
  l.a = l.model.add(
      pl::Revolute("A", l.crank, {{half_crank, 0.0}}, l.coupler, {{-half_coupler, 0.0}}));
  l.b = l.model.add(
      pl::Revolute("B", l.coupler, {{half_coupler, 0.0}}, l.rocker, {{half_rocker, 0.0}}));
  l.o4 = l.model.add(pl::Revolute("O4", odyn::ground, {o4}, l.rocker, {{-half_rocker, 0.0}}));
  l.motor =
      l.model.add(pl::RevoluteDriver("motor", pivot, odyn::Motion::constant_velocity(p.speed)));
  l.model.add(pl::Gravity("gravity", {0.0, -p.g}));
  return l;
}

}  // namespace four_bar
