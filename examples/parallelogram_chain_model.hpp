#pragma once
// A chain of parallelogram four-bars swinging freely under gravity: n + 1 equal cranks hinged
// to the ground at (i d, 0), i = 0..n, and n couplers, coupler j joining the tips of cranks j
// and j + 1. Each crank is a uniform bar of length r whose body x axis runs from its pivot to its
// tip; each coupler a uniform bar of length d, parallel to the ground.
//  - On the parallelogram branch every crank has the same angle theta and the couplers translate
//    along circles of radius r: a single-degree-of-freedom pendulum,
//      J theta'' = -G cos theta,  J = (n + 1) m_c r^2 / 3 + n m_p r^2,
//                                 G = g ((n + 1) m_c r / 2 + n m_p r).
//  - Whenever theta crosses 0 or pi (every link on the ground line) each four-bar is at a change
//    point: the constraint Jacobian loses n ranks for an instant, and the mobility jumps from 1 to
//    n + 1. Released above the horizontal it crosses four times a period.
//  - The planar model (2 equations per revolute) has no redundant equation away from the
//    crossings; the spatial one (revolutes about z, 5 equations each) has 3 per four-bar.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <odyn/odyn.hpp>

namespace parallelogram_chain {

struct Parameters {
  int four_bars = 10;                           // n
  double crank = 0.15, spacing = 0.40;          // r and d, m
  double crank_mass = 0.5, coupler_mass = 1.2;  // kg
  double angle = 0.5;                           // rad, initial crank angle (at rest)
  double g = 9.81;                              // m/s^2, along -y
};

/// "prefix" followed by i (written so that g++ 12 sees no overlapping copy in it).
inline std::string numbered(const char* prefix, int i) {
  std::string name = prefix;
  name += std::to_string(i);
  return name;
}

/// The minimal-coordinate pendulum's J and G (see above).
struct Pendulum {
  double inertia, moment;
};

inline Pendulum pendulum(const Parameters& p) {
  const double n = p.four_bars, r = p.crank;
  return {(n + 1) * p.crank_mass * r * r / 3.0 + n * p.coupler_mass * r * r,
          p.g * ((n + 1) * p.crank_mass * r / 2.0 + n * p.coupler_mass * r)};
}

/// A built chain: its model and its bodies in order.
template <class M>
struct Chain {
  M model;
  std::vector<odyn::BodyId> cranks, couplers;
};

namespace planar {

namespace pl = odyn::planar;
using Eigen::Vector2d;
using Model = pl::Model<pl::Revolute, pl::Gravity>;

/// Builds the chain at rest at the initial crank angle, in any planar model type that holds
/// revolute joints and gravity.
template <class M = Model>
Chain<M> build(const Parameters& p = {}) {
  Chain<M> chain;
  const double r = p.crank, d = p.spacing;
  const Vector2d tip = r * Vector2d(std::cos(p.angle), std::sin(p.angle));
  for (int i = 0; i <= p.four_bars; ++i) {
    const Vector2d pivot(i * d, 0.0);
    const odyn::BodyId crank = chain.model.add_body(pl::Body{.name = numbered("crank ", i),
                                                             .mass = p.crank_mass,
                                                             .inertia = p.crank_mass * r * r / 12.0,
                                                             .position = pivot + 0.5 * tip,
                                                             .angle = p.angle});
    chain.cranks.push_back(crank);
    chain.model.add(pl::Revolute(numbered("O", i), odyn::ground, {pivot}, crank, {{-r / 2, 0.0}}));
  }
  for (int j = 0; j < p.four_bars; ++j) {
    const odyn::BodyId coupler =
        chain.model.add_body(pl::Body{.name = numbered("coupler ", j),
                                      .mass = p.coupler_mass,
                                      .inertia = p.coupler_mass * d * d / 12.0,
                                      .position = Vector2d((j + 0.5) * d, 0.0) + tip,
                                      .angle = 0.0});
    chain.couplers.push_back(coupler);
    chain.model.add(
        pl::Revolute(numbered("A", j), chain.cranks[j], {{r / 2, 0.0}}, coupler, {{-d / 2, 0.0}}));
    chain.model.add(pl::Revolute(numbered("B", j), coupler, {{d / 2, 0.0}}, chain.cranks[j + 1],
                                 {{r / 2, 0.0}}));
  }
  chain.model.add(pl::Gravity("gravity", {0.0, -p.g}));
  return chain;
}

}  // namespace planar

namespace spatial {

namespace sp = odyn::spatial;
using Eigen::Vector3d;
using Model = sp::Model<sp::Revolute, sp::Gravity>;

/// The same chain in space, in the x-y plane, its hinges about z: the parallel axes of each
/// four-bar repeat 3 of its equations.
template <class M = Model>
Chain<M> build(const Parameters& p = {}) {
  Chain<M> chain;
  const double r = p.crank, d = p.spacing;
  const Vector3d tip = r * Vector3d(std::cos(p.angle), std::sin(p.angle), 0.0);
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(p.angle, Vector3d::UnitZ()));
  // A slender bar along its body x axis (its radius a tenth of its length).
  auto bar = [](double mass, double length) {
    const double transverse = mass * length * length / 12.0, axial = 0.05 * transverse;
    return sp::Body::principal(axial, transverse, transverse);
  };
  for (int i = 0; i <= p.four_bars; ++i) {
    const Vector3d pivot(i * d, 0.0, 0.0);
    const odyn::BodyId crank = chain.model.add_body({.name = numbered("crank ", i),
                                                     .mass = p.crank_mass,
                                                     .inertia = bar(p.crank_mass, r),
                                                     .position = pivot + 0.5 * tip,
                                                     .orientation = turned});
    chain.cranks.push_back(crank);
    chain.model.add(
        sp::Revolute(numbered("O", i), odyn::ground, {pivot}, crank, {Vector3d(-r / 2, 0.0, 0.0)}));
  }
  for (int j = 0; j < p.four_bars; ++j) {
    const odyn::BodyId coupler =
        chain.model.add_body({.name = numbered("coupler ", j),
                              .mass = p.coupler_mass,
                              .inertia = bar(p.coupler_mass, d),
                              .position = Vector3d((j + 0.5) * d, 0.0, 0.0) + tip});
    chain.couplers.push_back(coupler);
    chain.model.add(sp::Revolute(numbered("A", j), chain.cranks[j], {Vector3d(r / 2, 0.0, 0.0)},
                                 coupler, {Vector3d(-d / 2, 0.0, 0.0)}));
    chain.model.add(sp::Revolute(numbered("B", j), coupler, {Vector3d(d / 2, 0.0, 0.0)},
                                 chain.cranks[j + 1], {Vector3d(r / 2, 0.0, 0.0)}));
  }
  chain.model.add(sp::Gravity("gravity", {0.0, -p.g, 0.0}));
  return chain;
}

}  // namespace spatial

}  // namespace parallelogram_chain
