#pragma once
// Linearization about any state, at rest or moving, as a state-space model for chosen inputs
// and outputs (ADAMS's LINEAR, Drake's first-order Taylor approximation):
//     x' = f0 + A x + B u,   y = y0 + C x + D u.
// The state x = (z, w) is a minimal set: z = T^T dq and w = T^T dv, T an orthonormal basis of
// Phi_q's null space at the state (as in analysis/modes.hpp), dq the change of the positions as
// the increment integrate() applies and dv the change of the velocity coordinates. Perturbed
// states keep the joints closed to first order: a change z moves the positions by T z and the
// velocities by -Phi_q^+ (d(Phi_q v + Phi_t)/dq) T z, which the velocity constraints ask.
// A's columns are differences of the dynamics themselves: the accelerations the constrained
// equations give (the same solve a run makes) and the positions' rate, read in the chart
// z = T^T increment_of(q0, q - q0), by fourth-order central differences along each column of
// that basis (steps of 1e-3 rad and 1e-3 of the model's size, as analysis/tangent.hpp's). So
// A is independent of the modes' M, C and K: at an equilibrium its eigenvalues are the damped
// modes' s, a check of both. f0 = (T^T v, T^T v') is zero at an equilibrium; about a moving
// state A depends on the chart (as any linearization away from an equilibrium does), and the
// chart is the one above.
// An input u_i is a load pattern (a force at a body point and a torque) scaled by u_i; B holds
// the accelerations it gives, T^T dv' = (T^T M T)^-1 T^T b_i with b_i the load as the
// coordinates' generalized force: exact, since the accelerations are linear in the loads. An
// output is a function of the workspace's positions and velocities (an element's output, a
// point's position or velocity); C by the same differences, and D = 0, since such outputs do
// not read the loads. O(n) solves of O(n^3) each: for models of up to a few hundred
// coordinates.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "odyn/analysis/absolute_coordinates.hpp"
#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/joint_coordinates.hpp"
#include "odyn/analysis/outputs.hpp"
#include "odyn/analysis/statics.hpp"
#include "odyn/analysis/tangent.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/forces/point_load.hpp"

namespace odyn {

/// One input: the load u N (a force at `point`, body coordinates) and u N m (a torque) on a body.
template <class Space>
struct LinearInput {
  std::string name;
  BodyId body;
  typename Space::Vector force = Space::Vector::Zero();
  typename Space::Angular torque = Space::Angular::Zero();
  typename Space::Vector point = Space::Vector::Zero();
  Axes axes = Axes::global;  // the axes `force` and `torque` are given in
};

/// One output: a function of the workspace's positions and velocities (frames updated).
template <class Model>
struct LinearOutput {
  std::string name;
  std::function<double(const Workspace<Model>&)> value;
};

/// The state-space model about a state (see the file's comment). k degrees of freedom, n
/// velocity coordinates, p inputs, r outputs.
struct StateSpace {
  Eigen::MatrixXd a;        // (2k x 2k)
  Eigen::MatrixXd b;        // (2k x p)
  Eigen::MatrixXd c;        // (r x 2k)
  Eigen::MatrixXd d;        // (r x p), zero: outputs of positions and velocities
  Eigen::VectorXd drift;    // (2k) f0: x' at the state itself, zero at an equilibrium
  Eigen::VectorXd outputs;  // (r) y0, the outputs at the state
  Eigen::MatrixXd basis;    // (n x k) T: z's motions in the velocity coordinates
  std::vector<VelocityCoordinate> coordinates;  // what each row of `basis` is
  std::vector<std::string> input_names, output_names;
};

struct LinearizeSettings {
  std::string coordinates = "absolute";  // or "joint"
  /// Linearize about the static equilibrium near the pose (StaticSettings) rather than about
  /// the state as given (assembled: positions and velocities made consistent).
  bool find_equilibrium = false;
  StaticSettings statics = {};
  AssemblySettings assembly = {};
};

namespace detail {

/// The accelerations at positions q and velocities v (the coordinates' own solve); throws
/// where they have no unique value.
template <class Coordinates>
void accelerations_at(Coordinates& c, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                      double t) {
  c.positions() = q;
  c.velocities() = v;
  c.update_frames();
  c.evaluate_constraints();
  if (!c.factorize() || !c.solve_accelerations() || !all_finite(c.accelerations()))
    throw SolverError(t,
                      "the accelerations have no unique value at or near this state (a singular "
                      "configuration, or a motion that moves no mass): it cannot be linearized");
}

/// Throws unless `input` loads one of the model's moving bodies with finite numbers.
template <class Model>
void check_input(const Model& model, const LinearInput<typename Model::Space>& input) {
  if (input.body.index < 1 || input.body.index > model.num_bodies())
    throw ModelError(input.name, "body " + std::to_string(input.body.index) +
                                     " is not one of the model's moving bodies");
  if (!input.force.allFinite() || !input.torque.allFinite() || !input.point.allFinite())
    throw ModelError(input.name, "force, torque and point must be finite");
}

/// The generalized force, in the coordinates' velocity space, of `input` at the loaded state
/// with the accelerations and multipliers held: the change it makes to the residual.
template <class Coordinates, class Model>
Eigen::VectorXd input_load(Coordinates& c, Workspace<Model>& ws,
                           const LinearInput<typename Model::Space>& input) {
  using Space = typename Model::Space;
  const Eigen::Index n = c.num_velocities();
  Eigen::VectorXd before(n), after(n);
  residual_here(c, before);
  ForceBlocks<Space, 1> force, torque;
  const PointForceT<Space> push(input.name, input.body, input.point, input.force, input.axes);
  const PointTorqueT<Space> turn(input.name, input.body, input.torque, input.axes);
  push.evaluate(input_of(push, ws.frames, ws.t), force);
  turn.evaluate(input_of(turn, ws.frames, ws.t), torque);
  ws.force.template segment<Space::nv>(Space::nv * (input.body.index - 1)) +=
      force.force[0] + torque.force[0];
  c.dynamics_residual(after);
  c.evaluate_forces();    // the workspace's own loads again
  return before - after;  // r = M v' - Q + Phi_q^T lambda falls by the load
}

template <class Coordinates, class Model>
StateSpace linearize_here(Coordinates& c, const Model& model, Workspace<Model>& ws,
                          const std::vector<LinearInput<typename Model::Space>>& inputs,
                          const std::vector<LinearOutput<Model>>& outputs, double length) {
  const Eigen::Index n = c.num_velocities();
  const auto r = static_cast<Eigen::Index>(outputs.size());
  const auto p = static_cast<Eigen::Index>(inputs.size());
  const double t = ws.t;
  const Eigen::VectorXd q0 = c.positions(), v0 = c.velocities();
  StateSpace out;
  out.coordinates = c.velocity_coordinates();
  for (const auto& input : inputs) {
    check_input(model, input);
    out.input_names.push_back(input.name);
  }
  for (const auto& output : outputs) {
    if (!output.value) throw ModelError(output.name, "the output has no function");
    out.output_names.push_back(output.name);
  }

  accelerations_at(c, q0, v0, t);
  const Eigen::VectorXd a0 = c.accelerations(), lambda0 = c.multipliers();
  const Eigen::MatrixXd jacobian = constraint_jacobian(c);
  out.basis = null_space(jacobian, n);
  const Eigen::MatrixXd& basis = out.basis;
  const Eigen::Index k = basis.cols();

  // The positions and velocities along a direction (dq, dv) of the state, s far.
  Eigen::VectorXd q(q0.size()), increment(n), rate(q0.size()), chart_rate(n);
  const auto move = [&](const Eigen::VectorXd& dq, const Eigen::VectorXd& dv, double s) {
    increment = s * dq;
    c.integrate(q0, increment, q);
    return std::pair{q, Eigen::VectorXd(v0 + s * dv)};
  };
  const double position_step = 1e-3 * std::min(1.0, length);
  const double speed_step = 1e-3 * std::max(1.0, v0.size() > 0 ? v0.cwiseAbs().maxCoeff() : 0.0);
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(n);  // no change along a direction

  // The velocities' change that keeps Phi_q v + Phi_t = 0 as the positions move along T.
  Eigen::MatrixXd velocity_change = Eigen::MatrixXd::Zero(n, k);
  if (jacobian.rows() > 0) {
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> inverse(jacobian);
    inverse.setThreshold(1e-10);
    Eigen::VectorXd rates(jacobian.rows()), drift_of_rates(jacobian.rows());
    for (Eigen::Index j = 0; j < k; ++j) {
      fourth_order_difference(position_step, drift_of_rates, rates, [&](double s) {
        const auto [qs, vs] = move(basis.col(j), none, s);
        c.positions() = qs;
        c.velocities() = vs;
        c.update_frames();
        c.evaluate_constraints();
        rates = c.velocity_constraint_values();
      });
      velocity_change.col(j) = -inverse.solve(drift_of_rates);
    }
  }

  // The dynamics along each column of the state's basis: (chart rate, v', outputs).
  Eigen::VectorXd value(2 * n + r), slope(2 * n + r);
  const auto dynamics = [&](const Eigen::VectorXd& qs, const Eigen::VectorXd& vs) {
    accelerations_at(c, qs, vs, t);
    c.position_rate(qs, rate);
    c.increment_of(q0, rate, chart_rate);
    value.head(n) = chart_rate;
    value.segment(n, n) = c.accelerations();
    for (Eigen::Index i = 0; i < r; ++i)
      value[2 * n + i] = outputs[static_cast<std::size_t>(i)].value(ws);
  };
  out.a.resize(2 * k, 2 * k);
  out.c.resize(r, 2 * k);
  for (Eigen::Index j = 0; j < 2 * k; ++j) {
    const bool along_z = j < k;
    const Eigen::VectorXd dq = along_z ? Eigen::VectorXd(basis.col(j)) : none;
    const Eigen::VectorXd dv =
        along_z ? Eigen::VectorXd(velocity_change.col(j)) : Eigen::VectorXd(basis.col(j - k));
    fourth_order_difference(along_z ? position_step : speed_step, slope, value, [&](double s) {
      const auto [qs, vs] = move(dq, dv, s);
      dynamics(qs, vs);
    });
    out.a.col(j) << basis.transpose() * slope.head(n), basis.transpose() * slope.segment(n, n);
    out.c.col(j) = slope.tail(r);
  }

  // Back at the state: its drift and outputs, then the inputs' accelerations.
  dynamics(q0, v0);
  out.drift.resize(2 * k);
  out.drift << basis.transpose() * v0, basis.transpose() * c.accelerations();
  out.outputs = value.tail(r);
  c.accelerations() = a0;
  c.multipliers() = lambda0;
  out.b = Eigen::MatrixXd::Zero(2 * k, p);
  out.d = Eigen::MatrixXd::Zero(r, p);
  if (p > 0 && k > 0) {  // a mechanism that cannot move has no response to a load
    Eigen::VectorXd at_state(n), unit(n);
    residual_here(c, at_state);
    Eigen::MatrixXd mass(n, n);  // dr/dv', exact: r is linear in v'
    for (Eigen::Index j = 0; j < n; ++j) {
      c.accelerations()[j] += 1.0;
      residual_here(c, unit);
      mass.col(j) = unit - at_state;
      c.accelerations()[j] = a0[j];
    }
    Eigen::MatrixXd reduced = basis.transpose() * mass * basis;
    reduced = 0.5 * (reduced + reduced.transpose()).eval();
    const Eigen::LDLT<Eigen::MatrixXd> inertia(reduced);
    if (inertia.info() != Eigen::Success || !(inertia.vectorD().minCoeff() > 0.0))
      throw SolverError(t,
                        "the reduced mass matrix is not positive definite: a motion the joints "
                        "allow moves no mass (a body without mass or inertia)");
    for (Eigen::Index i = 0; i < p; ++i)
      out.b.col(i).tail(k) =
          inertia.solve(basis.transpose() * input_load(c, ws, inputs[static_cast<std::size_t>(i)]));
  }
  // The workspace as found: the state, its accelerations and multipliers.
  accelerations_at(c, q0, v0, t);
  c.evaluate_forces();
  return out;
}

}  // namespace detail

/// The state-space model about the workspace's state (assembled first), or about the static
/// equilibrium near its pose (settings.find_equilibrium), left in the workspace (see the file's
/// comment). Throws ModelError for an input or output that does not apply, SolverError where
/// the state has no unique accelerations.
template <class Model>
StateSpace linearize(const Model& model, Workspace<Model>& ws,
                     const std::vector<LinearInput<typename Model::Space>>& inputs = {},
                     const std::vector<LinearOutput<Model>>& outputs = {},
                     const LinearizeSettings& s = {}) {
  if (s.coordinates != "absolute" && s.coordinates != "joint")
    throw ModelError("linearization",
                     "coordinates '" + s.coordinates + "' unknown; use 'absolute' or 'joint'");
  if (s.find_equilibrium) {
    StaticSettings statics = s.statics;
    statics.coordinates = s.coordinates;
    static_equilibrium(model, ws, statics);
  } else {
    assemble(model, ws, s.assembly);
  }
  const double length = detail::model_size(model, ws);
  if (s.coordinates == "joint") {
    JointCoordinates<Model> c(model, ws);
    StateSpace out = detail::linearize_here(c, model, ws, inputs, outputs, length);
    c.complete_workspace();
    return out;
  }
  AbsoluteCoordinates<Model> c(model, ws, LinearSolver::dense);
  return detail::linearize_here(c, model, ws, inputs, outputs, length);
}

/// An output for linearize: one of the element `element`'s own outputs (core/outputs.hpp), by
/// its name. Refuses an output that reads the element's reactions.
template <class Model>
LinearOutput<Model> element_linear_output(const Model& model, const std::string& element,
                                          const std::string& output) {
  const auto where = model.locate(element);  // refuses an unknown element
  std::string known;
  bool found = false;
  model.for_each_pool([&]<class E>(const std::vector<E>&, auto type) {
    if (decltype(type)::value != where.type) return;
    if constexpr (HasOutputs<E>) {
      for (std::size_t i = 0; i < num_outputs<E>; ++i) {
        const char* listed = E::description.outputs[i].name;
        found = found || output == listed;
        known += (i > 0 ? ", " : "") + std::string(listed);
      }
      if (found && HasMultiplierOutputs<E>)
        throw ModelError(element,
                         "its outputs read its reactions, which the inputs change: a linear "
                         "model's outputs are functions of the positions and velocities");
    }
  });
  if (!found)
    throw ModelError(
        element, "no output '" + output + "'" +
                     (known.empty() ? "; the element reports none" : "; its outputs: " + known));
  const Model* m = &model;
  return {element + "." + output, [m, element, output](const Workspace<Model>& ws) {
            return element_output(*m, ws, element, output);
          }};
}

}  // namespace odyn
