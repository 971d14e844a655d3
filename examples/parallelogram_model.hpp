#pragma once
// A planar four-bar under gravity with one of its ground pivots driven at constant speed:
// ground pivots O2 = (0, 0) and O4 = (ground, 0), crank O2-A, coupler A-B, rocker O4-B, each a
// uniform bar whose body x axis runs from its first point to its second.
//  - The default lengths make a parallelogram (coupler = ground, rocker = crank). Twice a turn
//    all links line up (the change points), where the parallelogram branch (rocker angle =
//    crank angle, the coupler translating) crosses the anti-parallelogram branch. A driven run
//    must go straight through on its branch.
//  - With a crank-rocker's lengths and the rocker driven (`driven = Pivot::o4`), the driver asks
//    for a full turn the rocker cannot make: the linkage locks at a dead point (crank and
//    coupler in line).

#include <cmath>
#include <numbers>

#include <odyn/odyn.hpp>

namespace parallelogram {

namespace pl = odyn::planar;
using Eigen::Vector2d;

enum class Pivot { o2, o4 };

struct Parameters {
  double ground = 0.40, crank = 0.15, coupler = 0.40, rocker = 0.15;  // link lengths, m
  double crank_mass = 0.5, coupler_mass = 1.2, rocker_mass = 0.5;     // kg
  double crank_angle = 0.5;                                           // rad, initial
  double speed = 2.0 * std::numbers::pi;                              // rad/s, of the driven pivot
  Pivot driven = Pivot::o2;
  double g = 9.81;  // m/s^2, along -y
};

using Model = pl::Model<pl::Revolute, pl::RevoluteDriver, pl::Gravity>;

struct Linkage {
  Model model;
  odyn::BodyId crank, coupler, rocker;
  odyn::Handle<pl::Revolute> o2, a, b, o4;
  odyn::Handle<pl::RevoluteDriver> motor;
};

/// Point B for a crank angle: on the parallelogram branch for a parallelogram's lengths, else
/// the open (upper) assembly, where the circles about A (coupler) and O4 (rocker) meet.
inline Vector2d point_b(const Parameters& p, double crank_angle) {
  const Vector2d a = p.crank * Vector2d(std::cos(crank_angle), std::sin(crank_angle));
  const Vector2d o4(p.ground, 0.0);
  if (p.coupler == p.ground && p.rocker == p.crank) return o4 + a;
  const Vector2d d = o4 - a;
  const double distance = d.norm();
  const double along =
      (distance * distance + p.coupler * p.coupler - p.rocker * p.rocker) / (2.0 * distance);
  const double across = std::sqrt(p.coupler * p.coupler - along * along);
  const Vector2d unit = d / distance;
  return a + along * unit + across * Vector2d(-unit.y(), unit.x());
}

/// Builds the linkage at the initial crank angle, at rest; the motor then turns its pivot.
inline Linkage build(const Parameters& p = {}) {
  Linkage l;
  const Vector2d o2(0.0, 0.0), o4(p.ground, 0.0);
  const Vector2d a = p.crank * Vector2d(std::cos(p.crank_angle), std::sin(p.crank_angle));
  const Vector2d b = point_b(p, p.crank_angle);
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
  const pl::Revolute o2_pivot("O2", odyn::ground, {o2}, l.crank, {{-p.crank / 2, 0.0}});
  const pl::Revolute o4_pivot("O4", odyn::ground, {o4}, l.rocker, {{-p.rocker / 2, 0.0}});
  l.o2 = l.model.add(o2_pivot);
  l.a = l.model.add(
      pl::Revolute("A", l.crank, {{p.crank / 2, 0.0}}, l.coupler, {{-p.coupler / 2, 0.0}}));
  l.b = l.model.add(
      pl::Revolute("B", l.coupler, {{p.coupler / 2, 0.0}}, l.rocker, {{p.rocker / 2, 0.0}}));
  l.o4 = l.model.add(o4_pivot);
  l.motor = l.model.add(pl::RevoluteDriver(p.driven == Pivot::o2 ? "motor O2" : "motor O4",
                                           p.driven == Pivot::o2 ? o2_pivot : o4_pivot,
                                           odyn::Motion::constant_velocity(p.speed)));
  l.model.add(pl::Gravity("gravity", {0.0, -p.g}));
  return l;
}

}  // namespace parallelogram
