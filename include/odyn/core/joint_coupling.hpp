#pragma once
// A linear relation among the coordinates of pair joints: sum_i c_i (x_i - x_i0) = 0, x_i an
// angle or a slide of the i-th joint (its bodies and frames), x_i0 its value at the initial
// pose. Gears, a rack and pinion and a screw are such relations (core/gear_pairs.hpp). The
// coordinates are measured as the joints' drivers measure them; a spatial angle counts whole
// turns through the element's state (the last accepted angles), so the relation holds for any
// number of turns and any ratio.
//
// The element acts on the joints' bodies, each once: a body two joints share (a gearbox's
// carrier) takes one slot, and the slot it would have taken again holds the ground. A coupling
// may use fewer than N of its terms (a coupler of two joints where three fit): the terms past
// `count` take no part, and their slots hold the ground.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/joint_coordinate.hpp"

namespace odyn {

enum class JointCoordinateKind { angle, slide };

/// Pair: a space's two-body joint base (with angle_row and slide_row); N: the joints it holds.
template <class Pair, int N>
class JointCouplingT {
 public:
  using Space = typename Pair::Space;
  static constexpr int num_bodies = 2 * N;
  static constexpr int num_equations = 1;
  using Input = ElementInput<Space, num_bodies>;
  using PairInput = ElementInput<Space, 2>;

  /// One coordinate of the relation, and its coefficient.
  struct Term {
    Pair joint;
    JointCoordinateKind kind;
    double coefficient;
  };

  struct State {
    std::array<double, N> angle{};  // the angles, whole turns counted, at the last step
  };

  /// count: how many of the terms the relation uses, the first ones (2 to N).
  JointCouplingT(std::string name, std::array<Term, N> terms, int count = N)
      : name_(std::move(name)), terms_(std::move(terms)), count_(count) {
    for (int i = 0; i < count_; ++i) {
      for (int side = 0; side < 2; ++side) {
        const BodyId body = terms_[i].joint.bodies()[side];
        int slot = 2 * i + side;
        for (int earlier = 0; earlier < 2 * i + side && !body.is_ground(); ++earlier)
          if (bodies_[earlier].index == body.index) {
            slot = earlier;
            break;
          }
        slot_[i][side] = slot;
        bodies_[2 * i + side] = slot == 2 * i + side ? body : BodyId{0};
      }
    }
  }

  const std::string& name() const { return name_; }
  const std::array<BodyId, num_bodies>& bodies() const { return bodies_; }
  const Term& term(int i) const { return terms_[i]; }
  /// How many joints the relation couples.
  int count() const { return count_; }

  /// Completes each joint's frames, and takes each coordinate's value at the initial pose.
  void bind(const Input& in) {
    for (int i = 0; i < count_; ++i) {
      const PairInput pair = pair_input(in, i);
      terms_[i].joint.bind(pair);
      initial_[i] = row(pair, i, 0.0).value;
    }
  }

  State initial_state(const Input& in) const {
    State state;
    for (int i = 0; i < count_; ++i) state.angle[i] = row(pair_input(in, i), i, initial_[i]).value;
    return state;
  }
  void advance(const Input& in, State& state) const {
    for (int i = 0; i < count_; ++i) state.angle[i] = coordinate(in, state, i);
  }

  void evaluate(const Input& in, const State& state, BlocksOf<JointCouplingT>& out) const {
    out.phi[0] = 0.0;
    out.phi_t[0] = 0.0;
    for (auto& block : out.jacobian) block.setZero();
    for (int i = 0; i < count_; ++i) {
      const JointRow<Space> x = row(pair_input(in, i), i, state.angle[i]);
      const double c = terms_[i].coefficient;
      out.phi[0] += c * (x.value - initial_[i]);
      for (int side = 0; side < 2; ++side)
        out.jacobian[slot_[i][side]] +=
            c * x.gradient.template segment<Space::nv>(side * Space::nv).transpose();
    }
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in, const State& state) const {
    double value = 0.0;
    for (int i = 0; i < count_; ++i)
      value += terms_[i].coefficient * row(pair_input(in, i), i, state.angle[i]).gamma;
    return Eigen::Matrix<double, 1, 1>(value);
  }

  /// Each step must turn a spatial angle by less than half a turn (see turn_step_limit); a
  /// planar angle counts turns by itself.
  double step_limit(const Input& in, const State& state) const {
    double limit = std::numeric_limits<double>::infinity();
    if constexpr (Pair::angle_counts_turns_by_state)
      for (int i = 0; i < count_; ++i) {
        if (terms_[i].kind != JointCoordinateKind::angle) continue;
        const PairInput pair = pair_input(in, i);
        Eigen::Matrix<double, 2 * Space::nv, 1> v;
        v << pair.body(0).linear_velocity, pair.body(0).angular_velocity,
            pair.body(1).linear_velocity, pair.body(1).angular_velocity;
        limit = std::min(limit, turn_step_limit(row(pair, i, state.angle[i]).gradient.dot(v)));
      }
    return limit;
  }

  /// The i-th coordinate (an angle counting whole turns from the state's).
  double coordinate(const Input& in, const State& state, int i) const {
    return row(pair_input(in, i), i, state.angle[i]).value;
  }
  /// The coupling's effort on the i-th coordinate, -c_i lambda (a torque on an angle, a force on
  /// a slide, acting on the joint's body b, against body a): what -Phi_q^T lambda puts there.
  double effort(const Eigen::Matrix<double, 1, 1>& lambda, int i) const {
    return -terms_[i].coefficient * lambda[0];
  }

 protected:
  /// Refuses a zero or non-finite parameter (a ratio, a radius, a pitch), naming it.
  void require_nonzero(double value, const char* what, const char* advice) const {
    if (!std::isfinite(value) || value == 0.0)
      throw ModelError(name_, std::string(what) + " is " + to_text(value) + "; " + advice);
  }

 private:
  PairInput pair_input(const Input& in, int i) const {
    return PairInput{{in.frames[slot_[i][0]], in.frames[slot_[i][1]]}, in.t};
  }
  JointRow<Space> row(const PairInput& pair, int i, double near) const {
    return terms_[i].kind == JointCoordinateKind::angle ? terms_[i].joint.angle_row(pair, near)
                                                        : terms_[i].joint.slide_row(pair);
  }

  std::string name_;
  std::array<Term, N> terms_;
  std::array<BodyId, num_bodies> bodies_{};
  int count_;
  std::array<std::array<int, 2>, N> slot_{};
  std::array<double, N> initial_{};
};

}  // namespace odyn
