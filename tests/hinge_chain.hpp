#pragma once
// A hanging chain of `links` hinged links (1 m, 1 kg, uniform bars with a thin twist inertia)
// under gravity, its hinges about y: straight down at the equilibrium, or turned by `tilt` about
// y as a whole (a pose that statics must bring down). Its lowest modes are the swings of a
// hanging chain, which the tests find also in joint coordinates (a dense, different method)
// and the benchmarks time on the sparse path.

#include <string>

#include <odyn/odyn.hpp>

namespace hinge_chain {

namespace sp = odyn::spatial;
using Model = sp::DefaultModel;

inline Model build(int links, double tilt = 0.0) {
  using Eigen::Vector3d;
  const Eigen::AngleAxisd turn(tilt, Vector3d::UnitY());
  Model model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < links; ++i) {
    const odyn::BodyId body =
        model.add_body({.name = "link" + std::to_string(i),
                        .mass = 1.0,
                        .inertia = sp::Body::principal(1.0 / 12.0, 1.0 / 12.0, 1e-3),
                        .position = turn * Vector3d(0.0, 0.0, -0.5 - i),
                        .orientation = Eigen::Quaterniond(turn)});
    const Vector3d top = previous.is_ground() ? Vector3d::Zero() : Vector3d(0.0, 0.0, -0.5);
    model.add(sp::Revolute("hinge" + std::to_string(i), previous, {top, Vector3d::UnitY()}, body,
                           {Vector3d(0.0, 0.0, 0.5), Vector3d::UnitY()}));
    previous = body;
  }
  model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -9.81)));
  return model;
}

}  // namespace hinge_chain
