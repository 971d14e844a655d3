#pragma once
// Stiffness and damping blocks of a stateless force element by central differences of its own
// evaluate(), for elements that cannot write them (forces written in Python): an implicit
// integrator's Newton matrix then sees a gear's, a friction's or an impact's stiffness as it
// sees a spring's. Each column moves one body along one velocity coordinate (the centre of
// mass globally, the orientation about a body axis, as Space::integrate does) by a step h,
// and compares the forces at +h and -h: 2 NB nv evaluations for each set of blocks.

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "odyn/core/element.hpp"

namespace odyn {

/// A body's configuration coordinates from its frame (Space::make_frame's inverse).
template <class Space>
typename Space::Configuration configuration_of(const typename Space::Frame& frame) {
  typename Space::Configuration q;
  if constexpr (requires { frame.angle; }) {
    q << frame.position, frame.angle;
  } else {
    const Eigen::Quaterniond r(frame.rotation);
    q << frame.position, r.w(), r.x(), r.y(), r.z();
  }
  return q;
}

/// Fills out.stiffness (-dQ/dq) and out.damping (-dQ/dv) of `element` at `in` by central
/// differences; leaves out.force alone. Columns of the ground are zero (it does not move).
template <StatelessForce E>
void difference_jacobians(const E& element, const InputOf<E>& in, ForceBlocksOf<E>& out) {
  using Space = typename E::Space;
  using Frame = typename Space::Frame;
  constexpr int nb = E::num_bodies, nv = Space::nv;
  std::array<Frame, nb> frames;
  InputOf<E> moved = in;
  for (int k = 0; k < nb; ++k) {
    frames[static_cast<std::size_t>(k)] = in.body(k);
    moved.frames[static_cast<std::size_t>(k)] = &frames[static_cast<std::size_t>(k)];
  }
  ForceBlocksOf<E> plus, minus;
  Eigen::Matrix<double, nb * nv, 1> q_plus, q_minus;
  const auto stacked = [&](const ForceBlocksOf<E>& blocks, Eigen::Matrix<double, nb * nv, 1>& to) {
    for (int k = 0; k < nb; ++k)
      to.template segment<nv>(k * nv) = blocks.force[static_cast<std::size_t>(k)];
  };
  out.stiffness.setZero();
  out.damping.setZero();
  for (int k = 0; k < nb; ++k) {
    if (element.bodies()[static_cast<std::size_t>(k)].is_ground()) continue;
    const Frame& start = in.body(k);
    Frame& frame = frames[static_cast<std::size_t>(k)];
    const typename Space::Configuration q = configuration_of<Space>(start);
    typename Space::Velocity v;
    v << start.linear_velocity, start.angular_velocity;
    // Steps scaled to the body's own sizes: its distance from the origin and its speed.
    const double h_position = 1e-6 * std::max(1.0, start.position.norm());
    const double h_velocity = 1e-6 * std::max(1.0, v.norm());
    for (int j = 0; j < nv; ++j) {
      const bool turns = j >= Space::dim;
      const double hq = turns ? 1e-6 : h_position;
      for (const int sign : {1, -1}) {
        typename Space::Configuration moved_q;
        Space::integrate(q, sign * hq * Space::Velocity::Unit(j), moved_q);
        Space::make_frame(moved_q, v, frame);
        element.evaluate(moved, sign > 0 ? plus : minus);
      }
      stacked(plus, q_plus);
      stacked(minus, q_minus);
      out.stiffness.col(k * nv + j) = -(q_plus - q_minus) / (2.0 * hq);
      for (const int sign : {1, -1}) {
        Space::make_frame(q, v + sign * h_velocity * Space::Velocity::Unit(j), frame);
        element.evaluate(moved, sign > 0 ? plus : minus);
      }
      stacked(plus, q_plus);
      stacked(minus, q_minus);
      out.damping.col(k * nv + j) = -(q_plus - q_minus) / (2.0 * h_velocity);
    }
    frame = start;
  }
}

}  // namespace odyn
