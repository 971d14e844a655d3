#pragma once
// A stiff spring-mass chain: two planar blocks sliding along the x axis (translational guides
// to the ground), the first tied to the ground by a soft spring, the second to the first by a
// spring whose stiffness/mass ratio is 1e8 (1/s^2). Its two modes are far apart: the blocks
// swinging together on the soft spring (omega ~ 7 rad/s) and beating against each other on
// the stiff one (omega ~ 1.4e4 rad/s, explicit stability limit h < 2/omega = 1.4e-4 s).
// The springs' free lengths put the rest positions at x = spacing and x = 2 spacing.

#include <odyn/odyn.hpp>

namespace stiff_chain {

namespace pl = odyn::planar;
using Eigen::Vector2d;

struct Parameters {
  double mass = 1.0;                        // kg, each block
  double soft = 100.0;                      // N/m, ground - block 1
  double stiff = 1e8;                       // N/m, block 1 - block 2
  double stiff_damping = 0.0;               // N s/m, beside the stiff spring
  double spacing = 1.0;                     // m, free length of each spring
  double displacement1 = 0.0;               // m, initial, from rest
  double displacement2 = 0.0;               // m
  double velocity1 = 0.0, velocity2 = 0.0;  // m/s, initial
};

using Model = pl::Model<pl::Translational, pl::Tsda>;

struct Chain {
  Model model;
  odyn::BodyId first, second;
};

inline Chain build(const Parameters& p = {}) {
  Chain c;
  auto block = [&](const char* name, double x, double v) {
    return pl::Body{.name = name,
                    .mass = p.mass,
                    .inertia = p.mass * 0.01,
                    .position = {x, 0.0},
                    .linear_velocity = {v, 0.0}};
  };
  c.first = c.model.add_body(block("block 1", p.spacing + p.displacement1, p.velocity1));
  c.second = c.model.add_body(block("block 2", 2.0 * p.spacing + p.displacement2, p.velocity2));
  const Vector2d x_axis(1.0, 0.0);
  c.model.add(pl::Translational("guide 1", odyn::ground, {{0.0, 0.0}, x_axis}, c.first,
                                {{0.0, 0.0}, x_axis}));
  c.model.add(pl::Translational("guide 2", odyn::ground, {{0.0, 0.0}, x_axis}, c.second,
                                {{0.0, 0.0}, x_axis}));
  c.model.add(pl::Tsda("soft spring", odyn::ground, {0.0, 0.0}, c.first, {0.0, 0.0},
                       {.stiffness = p.soft, .free_length = p.spacing}));
  c.model.add(
      pl::Tsda("stiff spring", c.first, {0.0, 0.0}, c.second, {0.0, 0.0},
               {.stiffness = p.stiff, .damping = p.stiff_damping, .free_length = p.spacing}));
  return c;
}

}  // namespace stiff_chain
