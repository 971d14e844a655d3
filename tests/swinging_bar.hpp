#pragma once
// A test model shared by the explicit integrators' tests: a 1 m, 1 kg uniform bar swinging
// about one end under gravity, released at rest from theta0 = 2 rad. Its period is exact,
// T = 4 sqrt(I_O / (m g d)) K(sin(theta0 / 2)) (tests/reference/elliptic.hpp); after T it is back
// at theta0, at rest.

#include <cmath>

#include <odyn/odyn.hpp>

#include "reference/elliptic.hpp"

namespace swinging_bar {

constexpr double theta0 = 2.0, g = 9.81, inertia_o = 1.0 / 3.0, d = 0.5;

inline double period() {
  return 4.0 * std::sqrt(inertia_o / (d * g)) * reference::elliptic_k(std::sin(theta0 / 2.0));
}

/// The bar at its release pose on a pivot at the origin: its angle is q[2], its rate v[2].
inline odyn::planar::DefaultModel build() {
  namespace pl = odyn::planar;
  pl::DefaultModel model;
  const auto bar = model.add_body({.name = "bar",
                                   .mass = 1.0,
                                   .inertia = 1.0 / 12.0,
                                   .position = {d * std::sin(theta0), -d * std::cos(theta0)},
                                   .angle = theta0});
  model.add(pl::Revolute("pivot", odyn::ground, {}, bar, {{0.0, d}}));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  return model;
}

}  // namespace swinging_bar
