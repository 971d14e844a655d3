#pragma once
// A planar chain of `links` links (0.5 m, 1 + 0.01 i kg, uniform bars) hinged end to end from
// the ground under gravity, each hinge's angle driven: theta_i(t) = 0.1 (-1)^i +
// 0.2 sin(3 t + 0.5 i), the angle of link i relative to link i - 1. Fully driven, so a
// kinematic analysis moves it; forward kinematics (chain_at) gives every link's motion in
// closed form. The tests check the analysis against it, the benchmarks time it at sizes up
// to thousands of links.

#include <cmath>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

namespace driven_chain {

namespace pl = odyn::planar;
using Model = pl::Model<pl::Revolute, pl::RevoluteDriver, pl::Gravity>;
using Eigen::Vector2d;

inline constexpr double length = 0.5;
inline const Vector2d gravity(0.0, -9.81);

inline odyn::Motion theta(int i) {
  return odyn::Motion::harmonic(0.2, 3.0, 0.5 * i, i % 2 == 0 ? 0.1 : -0.1);
}
inline double mass(int i) {
  return 1.0 + 0.01 * i;
}

/// One link's motion: its hinge point and centre, its centre's velocity and acceleration, its
/// angle and their rates.
struct Link {
  Vector2d hinge, centre, velocity, acceleration;
  double angle = 0.0, rate = 0.0, angular_acceleration = 0.0;
};

/// Forward kinematics at time t: the angles add up along the chain, each link's far end is
/// the next one's hinge.
inline std::vector<Link> chain_at(int links, double t) {
  std::vector<Link> out(static_cast<std::size_t>(links));
  double angle = 0.0, rate = 0.0, angular_acceleration = 0.0;
  Vector2d point = Vector2d::Zero(), point_velocity = Vector2d::Zero(),
           point_acceleration = Vector2d::Zero();
  for (int i = 0; i < links; ++i) {
    const odyn::Motion motion = theta(i);
    angle += motion.position(t);
    rate += motion.velocity(t);
    angular_acceleration += motion.acceleration(t);
    const Vector2d along(std::cos(angle), std::sin(angle)), normal(-along.y(), along.x());
    const Vector2d turning = angular_acceleration * normal - rate * rate * along;
    Link& l = out[i];
    l.hinge = point;
    l.angle = angle;
    l.rate = rate;
    l.angular_acceleration = angular_acceleration;
    l.centre = point + 0.5 * length * along;
    l.velocity = point_velocity + 0.5 * length * rate * normal;
    l.acceleration = point_acceleration + 0.5 * length * turning;
    point += length * along;
    point_velocity += length * rate * normal;
    point_acceleration += length * turning;
  }
  return out;
}

struct Chain {
  Model model;
  std::vector<odyn::Handle<pl::Revolute>> hinges;
  std::vector<odyn::Handle<pl::RevoluteDriver>> motors;
};

/// The chain given slightly off its driven pose at t = 0, so that a first time assembles.
inline Chain build(int links) {
  Chain chain;
  const std::vector<Link> start = chain_at(links, 0.0);
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < links; ++i) {
    const odyn::BodyId body =
        chain.model.add_body({.name = "link" + std::to_string(i),
                              .mass = mass(i),
                              .inertia = mass(i) * length * length / 12.0,
                              .position = start[i].centre + Vector2d(1e-3, -2e-3),
                              .angle = start[i].angle + 0.01});
    const Vector2d top = previous.is_ground() ? Vector2d::Zero() : Vector2d(0.5 * length, 0.0);
    // Axes given: the joint angle is then the difference of the links' angles.
    const pl::Revolute hinge("hinge" + std::to_string(i), previous, {top, Vector2d::UnitX()}, body,
                             {Vector2d(-0.5 * length, 0.0), Vector2d::UnitX()});
    chain.hinges.push_back(chain.model.add(hinge));
    chain.motors.push_back(
        chain.model.add(pl::RevoluteDriver("motor" + std::to_string(i), hinge, theta(i))));
    previous = body;
  }
  chain.model.add(pl::Gravity("gravity", gravity));
  return chain;
}

}  // namespace driven_chain
