#pragma once
// Kinematic analysis: a mechanism whose joints and drivers leave it no degree of freedom moves
// as its drivers prescribe, whatever its masses. At each time:
//  1. positions: Newton on Phi(q, t) = 0 from a prediction off the last solution;
//  2. velocities from Phi_q v = -Phi_t and accelerations from Phi_q v' = gamma: the constraint
//     equations alone, since Phi_q has full column rank;
//  3. the multipliers from the equations of motion, Phi_q^T lambda = Q - M v': the drivers'
//     efforts and the joints' reactions (inverse dynamics).
// A mechanism with degrees of freedom left, a driver that repeats other equations, and a
// configuration where Phi_q loses rank (a lock-up: the drivers ask for a motion the joints
// cannot give) are refused by name.
// Small models use dense matrices (a rank-revealing QR of Phi_q). Large ones use sparse rows:
// the assembly's rank pass in the model's topological order keeps n independent rows of
// Phi_q, whose square matrix one sparse LU factorizes for the three solves of a time (the
// multipliers with its transpose), at a cost linear in the model's size.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/linalg/linear_solver.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/sparse_lu.hpp"

namespace odyn {

struct KinematicSettings {
  double tolerance = 1e-12;  // |Phi| in every entry
  int max_iterations = 25;   // Newton iterations per time
  /// A time whose Newton iteration fails is reached in halves of the step, down to this many.
  int max_halvings = 12;
  /// dense: rank-revealing QR of whole matrices; cholmod or klu (the same here): sparse rows
  /// and a sparse LU, linear in the model's size; auto: dense up to dense_assembly_limit
  /// velocities plus equations, sparse above.
  LinearSolver linear_solver = LinearSolver::automatic;
};

/// What the constraint Jacobian says of a mechanism's motion at its current configuration.
struct Mobility {
  int velocities = 0;                       // velocity coordinates
  int equations = 0;                        // constraint equations, drivers included
  int rank = 0;                             // independent equations
  std::vector<RedundantEquation> repeated;  // equations that depend on earlier ones
  std::vector<std::string> drivers;         // the drivers' names, in the model's order
  int degrees_of_freedom() const { return velocities - rank; }
};

namespace detail {
template <class E>
constexpr bool is_driver() {
  if constexpr (requires { E::description.category; })
    return std::string_view(E::description.category) == "driver";
  else
    return false;
}

inline std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "'" : ", '") + name + "'";
  return out.empty() ? "none" : out;
}

template <class Model>
bool sparse_kinematics(const Model& model, LinearSolver solver) {
  AssemblySettings s;
  s.linear_solver = solver;
  return sparse_assembly(model, s);
}

/// The rows of Phi_q at the last evaluate_constraints that depend on others (see
/// dependent_rows in analysis/assembly.hpp), by the chosen linear algebra.
template <class Model>
std::vector<int> dependent_rows(const Model& model, const Workspace<Model>& ws,
                                LinearSolver solver) {
  if (!sparse_kinematics(model, solver)) return dependent_rows(dense_jacobian(model, ws));
  const std::vector<char> independent =
      independent_rows(model, sparse_jacobian(model, ws), rank_tolerance);
  std::vector<int> rows;
  for (int r = 0; r < static_cast<int>(independent.size()); ++r)
    if (!independent[r]) rows.push_back(r);
  return rows;
}

template <class Model>
[[noreturn]] void throw_lock_up(const Model& model, double t, const std::vector<int>& dependent) {
  std::string rows;
  for (int row : dependent) rows += (rows.empty() ? "" : ", ") + locate_row(model, row).text();
  throw AssemblyError("model", "at t = " + to_text(t) +
                                   " s the mechanism locks up: its constraint Jacobian lost "
                                   "rank, so the drivers fix no unique velocity (dependent: " +
                                   (rows.empty() ? std::string("none listed") : rows) + ")");
}
}  // namespace detail

/// The mobility at the workspace's configuration (evaluates the constraints there), with the
/// rank found by the chosen linear algebra (see KinematicSettings::linear_solver).
template <class Model>
Mobility mobility(const Model& model, Workspace<Model>& ws,
                  LinearSolver solver = LinearSolver::automatic) {
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  Mobility out;
  out.velocities = model.num_velocities();
  out.equations = model.num_equations();
  const std::vector<int> dependent = detail::dependent_rows(model, ws, solver);
  out.rank = out.equations - static_cast<int>(dependent.size());
  for (int row : dependent) out.repeated.push_back(detail::locate_row(model, row));
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (detail::is_driver<E>())
      for (const E& element : pool) out.drivers.push_back(element.name());
  });
  return out;
}

/// Refuses a mechanism that its drivers do not fully drive at the workspace's configuration:
/// degrees of freedom left (how many, and its drivers), or a driver whose equation repeats
/// others (over-driven). Repeated joint equations alone are allowed, as in dynamics (Bricard's
/// linkage): their multipliers are the minimum-norm ones (on sparse rows, those of the rows
/// kept, the repeated rows' being 0).
template <class Model>
void require_fully_driven(const Model& model, Workspace<Model>& ws,
                          LinearSolver solver = LinearSolver::automatic) {
  const Mobility m = mobility(model, ws, solver);
  for (const RedundantEquation& e : m.repeated)
    for (const std::string& driver : m.drivers)
      if (e.joint == driver)
        throw ModelError(driver, "the mechanism is over-driven: driver '" + driver + "' (" +
                                     e.text() +
                                     ") repeats what the joints and the other drivers already fix; "
                                     "remove it or drive another coordinate");
  if (m.degrees_of_freedom() > 0) {
    const int dof = m.degrees_of_freedom();
    throw ModelError(
        "model", "a kinematic analysis needs a fully driven mechanism, but " + std::to_string(dof) +
                     (dof == 1 ? " degree" : " degrees") + " of freedom remain (" +
                     std::to_string(m.velocities) + " velocities, " + std::to_string(m.rank) +
                     " independent equations); its drivers: " + detail::quoted_list(m.drivers) +
                     ". Add a driver for each, or run a " + "dynamic analysis");
  }
}

namespace detail {
/// solve_kinematics's velocities, accelerations and multipliers on sparse rows, at solved
/// positions. A constraint row that repeats others gets no multiplier (0): with redundant
/// joints the reactions are one valid choice, not the minimum-norm one of the dense path.
template <class Model>
void solve_kinematics_sparse(const Model& model, Workspace<Model>& ws) {
  const int n = model.num_velocities();
  const SparseRows rows = sparse_jacobian(model, ws);
  const std::vector<char> independent = independent_rows(model, rows, rank_tolerance);
  std::vector<int> kept, dependent;  // rows of Phi_q
  for (int r = 0; r < rows.num_rows(); ++r) (independent[r] ? kept : dependent).push_back(r);
  if (static_cast<int>(kept.size()) < n) throw_lock_up(model, ws.t, dependent);
  // The kept rows, a square matrix, by columns for the LU (row k of it is row kept[k]).
  std::vector<int> starts(static_cast<std::size_t>(n) + 1, 0);
  for (const int r : kept)
    for (int e = rows.starts[r]; e < rows.starts[r + 1]; ++e) ++starts[rows.columns[e] + 1];
  for (int j = 0; j < n; ++j) starts[j + 1] += starts[j];
  std::vector<int> row_indices(static_cast<std::size_t>(starts[n]));
  std::vector<double> values(row_indices.size());
  std::vector<int> next(starts.begin(), starts.end() - 1);
  for (int k = 0; k < n; ++k)
    for (int e = rows.starts[kept[k]]; e < rows.starts[kept[k] + 1]; ++e) {
      const int at = next[rows.columns[e]]++;
      row_indices[at] = k;
      values[at] = rows.values[e];
    }
  SparseLu lu;
  lu.analyze(n, starts, row_indices);
  if (!lu.factorize(values, SparseLu::independent_rows_ratio)) throw_lock_up(model, ws.t, {});
  Eigen::VectorXd v(n), vdot(n);
  for (int k = 0; k < n; ++k) v[k] = -ws.phi_t[kept[k]];
  lu.solve_in_place(v);
  ws.v = v;
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  initialize_states(model, ws);
  evaluate_forces(model, ws);
  evaluate_gamma(model, ws);
  for (int k = 0; k < n; ++k) vdot[k] = ws.gamma[kept[k]];
  lu.solve_in_place(vdot);  // Phi_q v' = gamma
  ws.vdot = vdot;
  Eigen::VectorXd multipliers(n);
  mass_times(model, ws.vdot, multipliers);
  multipliers = ws.force - multipliers;
  lu.solve_transposed_in_place(multipliers);  // Phi_q^T lambda = Q - M v'
  ws.lambda.setZero();
  for (int k = 0; k < n; ++k) ws.lambda[kept[k]] = multipliers[k];
  if (!v.allFinite() || !vdot.allFinite() || !multipliers.allFinite())
    throw_lock_up(model, ws.t, {});
}
}  // namespace detail

/// Solves positions, velocities, accelerations and multipliers at time ws.t, from a nearby
/// configuration in ws.q. Throws AssemblyError at a lock-up (Newton fails, or Phi_q loses
/// rank), naming the time and the equations that became dependent.
template <class Model>
void solve_kinematics(const Model& model, Workspace<Model>& ws, const KinematicSettings& s = {}) {
  AssemblySettings positions;
  positions.tolerance = s.tolerance;
  positions.max_iterations = s.max_iterations;
  positions.linear_solver =
      detail::sparse_kinematics(model, s.linear_solver) ? s.linear_solver : LinearSolver::dense;
  assemble_positions(model, ws, positions);
  if (positions.linear_solver != LinearSolver::dense)
    return detail::solve_kinematics_sparse(model, ws);
  const Eigen::MatrixXd jacobian = detail::dense_jacobian(model, ws);
  const RankRevealingQr qr(jacobian, rank_tolerance);
  if (qr.rank() < model.num_velocities())
    detail::throw_lock_up(model, ws.t, detail::dependent_rows(jacobian));
  ws.v = -qr.solve(ws.phi_t);
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  initialize_states(model, ws);
  evaluate_forces(model, ws);
  evaluate_gamma(model, ws);
  ws.vdot = qr.solve(ws.gamma);  // Phi_q v' = gamma, with Phi_q's factorization above
  // Phi_q^T lambda = Q - M v' (minimum-norm where joint equations repeat each other).
  Eigen::VectorXd inertial(model.num_velocities());
  mass_times(model, ws.vdot, inertial);
  ws.lambda = RankRevealingQr(jacobian.transpose(), rank_tolerance).solve(ws.force - inertial);
}

namespace detail {
/// The constraint equation nearest to depending on the others at the workspace's (solved)
/// configuration: the last pivot of a column-pivoted QR of Phi_q^T; on sparse rows, the
/// independent row that the rank pass found nearest to the rows before it.
template <class Model>
RedundantEquation weakest_equation(const Model& model, const Workspace<Model>& ws,
                                   LinearSolver solver) {
  if (sparse_kinematics(model, solver)) {
    const SparseRows rows = sparse_jacobian(model, ws);
    std::vector<double> margins;
    const std::vector<char> independent =
        independent_rows(row_order(model), rows, rank_tolerance, nullptr, &margins);
    int weakest = 0;
    for (int r = 0; r < rows.num_rows(); ++r)
      if (independent[r] && (!independent[weakest] || margins[r] < margins[weakest])) weakest = r;
    return locate_row(model, weakest);
  }
  const Eigen::MatrixXd jacobian = dense_jacobian(model, ws);
  const RankRevealingQr qr(jacobian.transpose(), 0.0);
  return locate_row(model, qr.column_order().back());
}
}  // namespace detail

/// Runs a kinematic analysis from ws.t to t_end, calling record(ws) at ws.t, every `interval`
/// after it, and at t_end. The first time assembles from the given pose. Between outputs the
/// configuration is predicted from the last solution (Taylor to second order) and corrected by
/// Newton; a step that fails is taken in halves, and a lock-up is named with its time.
template <class Model, class Record>
void kinematic_analysis(const Model& model, Workspace<Model>& ws, double t_end, double interval,
                        Record&& record, const KinematicSettings& s = {}) {
  constexpr int nq = Model::nq, nv = Model::nv;
  if (!(interval > 0.0) || !std::isfinite(interval))
    throw ModelError("kinematic analysis",
                     "expected an output interval > 0, got " + to_text(interval));
  if (!(t_end >= ws.t) || !std::isfinite(t_end))
    throw ModelError("kinematic analysis", "expected an end time >= the start time " +
                                               to_text(ws.t) + ", got " + to_text(t_end));
  AssemblySettings start;
  start.tolerance = s.tolerance;
  start.linear_solver = s.linear_solver;
  assemble_positions(model, ws, start);
  require_fully_driven(model, ws, s.linear_solver);
  solve_kinematics(model, ws, s);
  record(static_cast<const Workspace<Model>&>(ws));

  // One step from the solved state in ws to time `to`; false (ws unchanged) if it fails.
  auto step = [&](double to) {
    const Eigen::VectorXd q = ws.q;
    const double from = ws.t, h = to - from;
    const Eigen::VectorXd move = h * ws.v + 0.5 * h * h * ws.vdot;
    for (int b = 0; b < model.num_bodies(); ++b)
      Model::Space::integrate(q.template segment<nq>(b * nq), move.template segment<nv>(b * nv),
                              ws.q.template segment<nq>(b * nq));
    ws.t = to;
    try {
      solve_kinematics(model, ws, s);
      return true;
    } catch (const AssemblyError&) {
      ws.t = from;
      ws.q = q;
      solve_kinematics(model, ws, s);  // restores the solved state's v, v' and lambda
      return false;
    }
  };
  auto advance = [&](double to) {
    double h = to - ws.t;
    int halvings = 0;
    while (ws.t < to) {
      const double next = to - ws.t <= h * (1.0 + 1e-9) ? to : ws.t + h;
      if (step(next)) continue;
      if (++halvings > s.max_halvings) {
        const RedundantEquation weakest = detail::weakest_equation(model, ws, s.linear_solver);
        throw AssemblyError(weakest.joint,
                            "the mechanism locks up after t = " + to_text(ws.t) +
                                " s: no configuration meets the constraints and drivers a " +
                                to_text(h) +
                                " s step later; the equation nearest to depending "
                                "on the others there is " +
                                weakest.text());
      }
      h *= 0.5;
    }
  };
  const double t0 = ws.t;
  const auto outputs = static_cast<long>(std::floor((t_end - t0) / interval * (1.0 + 1e-12)));
  for (long k = 1; k <= outputs; ++k) {
    advance(t0 + static_cast<double>(k) * interval);
    record(static_cast<const Workspace<Model>&>(ws));
  }
  if (t_end - ws.t > 1e-12 * std::max(1.0, std::abs(t_end))) {
    advance(t_end);
    record(static_cast<const Workspace<Model>&>(ws));
  }
}

}  // namespace odyn
