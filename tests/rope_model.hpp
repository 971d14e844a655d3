#pragma once
// The scaling report's rope, shared by the tests: `links` ball-jointed links of 1 m and 1 kg
// (thin about their own axis, x) along x from the origin, gravity along -z. With a `speed`, every
// link is given that velocity along y (the assembly keeps what the joints allow); with a
// `spring`, a spring-damper joins neighbours at points `offset` off their axes (along y).

#include <array>
#include <optional>
#include <string>

#include <odyn/odyn.hpp>

namespace rope_model {

namespace sp = odyn::spatial;
using Model = sp::DefaultModel;

inline Model rope(int links, double speed = 0.0,
                  std::optional<sp::Tsda::Parameters> spring = std::nullopt, double offset = 0.0) {
  using Eigen::Vector3d;
  Model model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < links; ++i) {
    sp::Body link{.name = "link" + std::to_string(i),
                  .mass = 1.0,
                  .inertia = sp::Body::principal(5e-5, 1.0 / 12.0, 1.0 / 12.0),
                  .position = {0.5 + i, 0.0, 0.0},
                  .linear_velocity = {0.0, speed, 0.0}};
    if (speed != 0.0) link.velocity_given = std::array<bool, 6>{true, true, true, true, true, true};
    const odyn::BodyId body = model.add_body(link);
    model.add(sp::Spherical("ball" + std::to_string(i), previous,
                            previous.is_ground() ? Vector3d::Zero() : Vector3d(0.5, 0, 0), body,
                            {-0.5, 0.0, 0.0}));
    if (spring && !previous.is_ground())
      model.add(sp::Tsda("spring" + std::to_string(i), previous, Vector3d(0, offset, 0), body,
                         Vector3d(0, offset, 0), *spring));
    previous = body;
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  return model;
}

}  // namespace rope_model
