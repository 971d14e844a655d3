#pragma once
// The heavy top of Brüls, Cardona & Arnold (Lie group generalized-alpha, 2012): a rigid body
// on a spherical joint at the origin, its centre of mass at (0, 1, 0) in the body frame,
// under gravity along -z; it spins fast about its body y axis (its axis of symmetry) and
// precesses and nutates. Started at the identity orientation.

#include <Eigen/Geometry>

#include <odyn/odyn.hpp>

namespace heavy_top {

namespace sp = odyn::spatial;
using Eigen::Vector3d;

struct Parameters {
  double mass = 15.0;                               // kg
  Vector3d inertia{0.234375, 0.46875, 0.234375};    // kg m^2, principal, about the centre
  Vector3d centre{0.0, 1.0, 0.0};                   // m, body frame, from the pivot
  Vector3d gravity{0.0, 0.0, -9.81};                // m/s^2
  Vector3d angular_velocity{0.0, 150.0, -4.61538};  // rad/s, body frame, initial
};

using Model = sp::Model<sp::Spherical, sp::Gravity>;

struct Top {
  Model model;
  odyn::BodyId body;
  odyn::Handle<sp::Spherical> pivot;
};

inline Top build(const Parameters& p = {}) {
  Top t;
  // At the identity orientation the centre of mass is at `centre` and moves with w x centre.
  t.body =
      t.model.add_body({.name = "top",
                        .mass = p.mass,
                        .inertia = sp::Body::principal(p.inertia.x(), p.inertia.y(), p.inertia.z()),
                        .position = p.centre,
                        .linear_velocity = p.angular_velocity.cross(p.centre),
                        .angular_velocity = p.angular_velocity});
  t.pivot = t.model.add(sp::Spherical("pivot", odyn::ground, Vector3d::Zero(), t.body, -p.centre));
  t.model.add(sp::Gravity("gravity", p.gravity));
  return t;
}

}  // namespace heavy_top
