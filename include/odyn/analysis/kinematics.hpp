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
// Phi_q, whose square matrix a sparse LU factorizes for the Newton steps and for the three
// solves of a time (the multipliers with its transpose), at a cost linear in the model's size
// (see SparseKinematics). In joint coordinates (KinematicSettings::coordinates "joint") the
// spanning tree's joints hold by construction and Newton runs on the loops' closures and the
// drivers alone (see JointKinematics).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/joint_coordinates.hpp"
#include "odyn/analysis/output_times.hpp"
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
  /// "absolute": every body's position and orientation, every joint an equation; "joint": a
  /// spanning tree's joint coordinates, the joints that close loops and the drivers as the
  /// equations (see analysis/joint_coordinates.hpp). The same motion and reactions either way;
  /// the start's checks (fully driven, not over-driven) use linear_solver.
  std::string coordinates = "absolute";
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

/// The error of a time whose Newton iteration did not meet the constraints: the joint with the
/// largest residual in ws.phi.
template <class Model>
[[noreturn]] void throw_unmet(const Model& model, const Workspace<Model>& ws, int iterations,
                              const std::string& note) {
  Eigen::Index row = 0;
  const double worst = ws.phi.size() > 0 ? ws.phi.cwiseAbs().maxCoeff(&row) : 0.0;
  const std::string joint = ws.phi.size() > 0 ? model.constraint_name(static_cast<int>(row)) : "";
  throw AssemblyError(
      joint, "at t = " + to_text(ws.t) + " s the constraints and drivers could not be met after " +
                 std::to_string(iterations) + " Newton iterations" + note + "; largest residual " +
                 to_text(worst) + " at joint '" + joint + "'");
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
/// The dense path of solve_kinematics: a rank-revealing QR of the whole Jacobian.
template <class Model>
void solve_kinematics_dense(const Model& model, Workspace<Model>& ws, const KinematicSettings& s) {
  AssemblySettings positions;
  positions.tolerance = s.tolerance;
  positions.max_iterations = s.max_iterations;
  positions.linear_solver = LinearSolver::dense;
  assemble_positions(model, ws, positions);
  const Eigen::MatrixXd jacobian = dense_jacobian(model, ws);
  const RankRevealingQr qr(jacobian, rank_tolerance);
  if (qr.rank() < model.num_velocities()) throw_lock_up(model, ws.t, dependent_rows(jacobian));
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

/// The sparse path of solve_kinematics, kept across the times of an analysis. The rank pass
/// (in the model's topological order, found once) chooses n independent rows of Phi_q. Their
/// square matrix keeps its pattern while the same rows stay chosen, so the LU's ordering, and
/// its pivots while they stay good, carry over from one Newton iteration and one time to the
/// next. A Newton step solves that square system: the one step that zeroes the chosen rows'
/// linear residual, the others' following from them. A constraint row that repeats others gets
/// no multiplier (0): with redundant joints the reactions are one valid choice, not the
/// minimum-norm one of the dense path.
template <class Model>
class SparseKinematics {
 public:
  explicit SparseKinematics(const Model& model)
      : model_(model), order_(row_order(model)), n_(model.num_velocities()) {}

  /// Positions (Newton from ws.q), velocities, accelerations and multipliers at time ws.t.
  void solve(Workspace<Model>& ws, const KinematicSettings& s) {
    solve_positions(ws, s);
    solve_rates(ws);
  }

 private:
  const Model& model_;
  RowOrder order_;
  int n_;
  SparseRows rows_;             // Phi_q at the last evaluate_constraints
  std::vector<int> kept_;       // the chosen rows (row k of the square matrix is row kept_[k])
  std::vector<int> dependent_;  // the others, from the last rank pass
  std::vector<int> slot_;       // for each entry of rows_, its place in values_ (-1: not kept)
  std::vector<int> starts_, row_indices_;  // the square matrix's pattern, by columns
  std::vector<double> values_;
  SparseLu lu_;
  bool analyzed_ = false;

  /// The rank pass on rows_: false if fewer than n rows are independent. A new choice of rows
  /// builds the square matrix's pattern and the LU's ordering afresh.
  bool choose_rows() {
    const std::vector<char> independent = independent_rows(order_, rows_, rank_tolerance);
    std::vector<int> kept;
    dependent_.clear();
    for (int r = 0; r < rows_.num_rows(); ++r) (independent[r] ? kept : dependent_).push_back(r);
    if (static_cast<int>(kept.size()) < n_) return false;
    if (analyzed_ && kept == kept_) return true;
    kept_ = std::move(kept);
    starts_.assign(static_cast<std::size_t>(n_) + 1, 0);
    for (const int r : kept_)
      for (int e = rows_.starts[r]; e < rows_.starts[r + 1]; ++e) ++starts_[rows_.columns[e] + 1];
    for (int j = 0; j < n_; ++j) starts_[j + 1] += starts_[j];
    row_indices_.resize(static_cast<std::size_t>(starts_[n_]));
    values_.resize(row_indices_.size());
    slot_.assign(rows_.columns.size(), -1);
    std::vector<int> next(starts_.begin(), starts_.end() - 1);
    for (int k = 0; k < n_; ++k)
      for (int e = rows_.starts[kept_[k]]; e < rows_.starts[kept_[k] + 1]; ++e) {
        slot_[e] = next[rows_.columns[e]]++;
        row_indices_[slot_[e]] = k;
      }
    if (n_ > 0) lu_.analyze(n_, starts_, row_indices_);
    analyzed_ = true;
    return true;
  }

  /// Factorizes the chosen rows of rows_; false if they are singular.
  bool factorize() {
    if (n_ == 0) return true;
    for (std::size_t e = 0; e < slot_.size(); ++e)
      if (slot_[e] >= 0) values_[slot_[e]] = rows_.values[e];
    return lu_.factorize(values_, SparseLu::independent_rows_ratio);
  }

  /// Factors of Phi_q at the last evaluate_constraints: the rows chosen before while they stay
  /// regular, else a new choice. False if Phi_q has fewer than n independent rows.
  bool factorize_here(const Workspace<Model>& ws) {
    sparse_jacobian(model_, ws, rows_);
    if (analyzed_ && factorize()) return true;
    return choose_rows() && factorize();
  }

  void solve_positions(Workspace<Model>& ws, const KinematicSettings& s) {
    using Space = typename Model::Space;
    constexpr int nq = Model::nq, nv = Model::nv;
    const int m = model_.num_equations();
    auto residual_norm = [&] {
      update_frames(model_, ws);
      evaluate_constraints(model_, ws);
      return m > 0 ? ws.phi.cwiseAbs().maxCoeff() : 0.0;
    };
    double norm = residual_norm();
    int iteration = 0;
    for (; iteration < s.max_iterations && norm > s.tolerance && std::isfinite(norm); ++iteration) {
      if (!factorize_here(ws)) throw_lock_up(model_, ws.t, dependent_);
      Eigen::VectorXd step(n_);
      for (int k = 0; k < n_; ++k) step[k] = -ws.phi[kept_[k]];
      lu_.solve_in_place(step);
      const Eigen::VectorXd start = ws.q;
      norm = damped_newton_step(
          norm,
          [&](double fraction) {
            for (int b = 0; b < model_.num_bodies(); ++b)
              Space::integrate(start.template segment<nq>(b * nq),
                               fraction * step.template segment<nv>(b * nv),
                               ws.q.template segment<nq>(b * nq));
          },
          residual_norm);
    }
    if (!(norm <= s.tolerance)) throw_unmet(model_, ws, iteration, "");
  }

  /// Velocities, accelerations and multipliers at solved positions (constraints evaluated).
  void solve_rates(Workspace<Model>& ws) {
    sparse_jacobian(model_, ws, rows_);
    if (!choose_rows()) throw_lock_up(model_, ws.t, dependent_);  // rank checked at every time
    if (!factorize()) throw_lock_up(model_, ws.t, {});
    Eigen::VectorXd v(n_), vdot(n_), multipliers(n_);
    for (int k = 0; k < n_; ++k) v[k] = -ws.phi_t[kept_[k]];
    if (n_ > 0) lu_.solve_in_place(v);  // Phi_q v = -Phi_t
    ws.v = v;
    update_frames(model_, ws);
    evaluate_constraints(model_, ws);
    initialize_states(model_, ws);
    evaluate_forces(model_, ws);
    evaluate_gamma(model_, ws);
    for (int k = 0; k < n_; ++k) vdot[k] = ws.gamma[kept_[k]];
    if (n_ > 0) lu_.solve_in_place(vdot);  // Phi_q v' = gamma
    ws.vdot = vdot;
    mass_times(model_, ws.vdot, multipliers);
    multipliers = ws.force - multipliers;
    if (n_ > 0) lu_.solve_transposed_in_place(multipliers);  // Phi_q^T lambda = Q - M v'
    ws.lambda.setZero();
    for (int k = 0; k < n_; ++k) ws.lambda[kept_[k]] = multipliers[k];
    if (!v.allFinite() || !vdot.allFinite() || !multipliers.allFinite())
      throw_lock_up(model_, ws.t, {});
  }
};

/// The joint-coordinate path of a kinematic analysis (see analysis/joint_coordinates.hpp): the
/// spanning tree's coordinates theta, with the joints that close loops and the drivers as the
/// equations, C their Jacobian in the joint rates. A fully driven mechanism's C has full
/// column rank (square unless closures repeat each other), so the constraints alone give the
/// motion, as in absolute coordinates: Newton on the closures' Phi(theta, t) = 0, then
/// C theta' = -Phi_t and C theta'' = gamma - Phi_q c (c the bodies' accelerations at zero
/// theta''), with a rank-revealing QR of C; then C^T lambda = J^T (Q - the velocity terms) -
/// A theta'', whose right side is the residual of the equations of motion at lambda = 0, by the
/// recursive Newton-Euler algorithm. A itself is never factorized: its conditioning, which
/// grows as a chain's length to the fourth, has no part in the answer. complete_workspace()
/// then leaves q, v, v' and every joint's lambda as the absolute path does.
template <class Model>
class JointKinematics {
 public:
  /// Builds the tree at the workspace's assembled pose (every joint coordinate 0 there).
  JointKinematics(const Model& model, Workspace<Model>& ws)
      : model_(model), ws_(ws), coordinates_(model, ws) {}

  /// Positions (Newton from the held coordinates), velocities, accelerations and multipliers
  /// at time ws.t, left in the workspace.
  void solve(const KinematicSettings& s) {
    JointCoordinates<Model>& c = coordinates_;
    const auto residual_norm = [&] {
      c.update_frames();
      c.evaluate_constraints();
      return c.position_residual();
    };
    double norm = residual_norm();
    int iteration = 0;
    for (; iteration < s.max_iterations && norm > s.tolerance && std::isfinite(norm); ++iteration) {
      factorize();
      const Eigen::VectorXd start = c.positions();
      const Eigen::VectorXd step = -qr_.solve(c.constraint_values());
      norm = damped_newton_step(
          norm, [&](double fraction) { c.integrate(start, fraction * step, c.positions()); },
          residual_norm);
    }
    // The closures' rows of ws.phi are current, the tree joints' hold to rounding.
    if (!(norm <= s.tolerance)) throw_unmet(model_, ws_, iteration, " (joint coordinates)");
    factorize();  // at the solution, checking its rank
    // C theta' = -Phi_t, one correction from the last rates (exact: the system is linear).
    c.velocities() -= qr_.solve(c.velocity_constraint_values());
    c.update_frames();  // the twists, and the accelerations they leave at zero theta''
    initialize_states(model_, ws_);
    c.accelerations().setZero();
    c.accelerations() = -qr_.solve(c.acceleration_constraint_values());
    c.evaluate_forces();
    c.multipliers().setZero();
    residual_.resize(c.num_velocities());
    c.dynamics_residual(residual_);
    c.multipliers() = -RankRevealingQr(jacobian_.transpose(), rank_tolerance).solve(residual_);
    if (!c.velocities().allFinite() || !c.accelerations().allFinite() ||
        !c.multipliers().allFinite())
      throw_lock_up(model_, ws_.t, {});
    c.complete_workspace();
  }

  /// Moves the held coordinates from the last solution by h theta' + h^2 / 2 theta''.
  void predict(double h) {
    JointCoordinates<Model>& c = coordinates_;
    solved_positions_ = c.positions();
    solved_velocities_ = c.velocities();
    const Eigen::VectorXd move = h * c.velocities() + 0.5 * h * h * c.accelerations();
    c.integrate(solved_positions_, move, c.positions());
  }

  /// Back to the last solution's coordinates and rates (before predict), to be solved again.
  void restore() {
    coordinates_.positions() = solved_positions_;
    coordinates_.velocities() = solved_velocities_;
  }

 private:
  /// C at the loaded positions and its rank-revealing QR; a lock-up where C's rank falls below
  /// the number of joint coordinates (as the absolute path's test of Phi_q).
  void factorize() {
    coordinates_.closure_jacobian(jacobian_);
    qr_.compute(jacobian_, rank_tolerance);
    if (qr_.rank() < coordinates_.num_velocities()) throw_lock_up(model_, ws_.t, {});
  }

  const Model& model_;
  Workspace<Model>& ws_;
  JointCoordinates<Model> coordinates_;
  Eigen::MatrixXd jacobian_;  // C
  RankRevealingQr qr_;        // of C
  Eigen::VectorXd residual_;
  Eigen::VectorXd solved_positions_, solved_velocities_;
};

/// Refuses coordinates other than "absolute" and "joint"; true for "joint".
inline bool joint_kinematics(const KinematicSettings& s) {
  if (s.coordinates != "absolute" && s.coordinates != "joint")
    throw ModelError("kinematic analysis",
                     "coordinates '" + s.coordinates + "' unknown; use 'absolute' or 'joint'");
  return s.coordinates == "joint";
}
}  // namespace detail

/// Solves positions, velocities, accelerations and multipliers at time ws.t, from a nearby
/// configuration in ws.q. Throws AssemblyError at a lock-up (Newton fails, or Phi_q loses
/// rank), naming the time and the equations that became dependent. (In joint coordinates the
/// positions are assembled in absolute ones, then the rest solved in joint coordinates.)
template <class Model>
void solve_kinematics(const Model& model, Workspace<Model>& ws, const KinematicSettings& s = {}) {
  if (detail::joint_kinematics(s)) {
    AssemblySettings positions;
    positions.tolerance = s.tolerance;
    positions.max_iterations = s.max_iterations;
    positions.linear_solver = s.linear_solver;
    assemble_positions(model, ws, positions);
    detail::JointKinematics<Model>(model, ws).solve(s);
  } else if (detail::sparse_kinematics(model, s.linear_solver))
    detail::SparseKinematics<Model>(model).solve(ws, s);
  else
    detail::solve_kinematics_dense(model, ws, s);
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
  detail::output_count("kinematic analysis", ws.t, t_end, interval);  // refuses a tiny interval
  const bool in_joint_coordinates = detail::joint_kinematics(s);
  AssemblySettings start;
  start.tolerance = s.tolerance;
  start.linear_solver = s.linear_solver;
  assemble_positions(model, ws, start);
  require_fully_driven(model, ws, s.linear_solver);
  std::optional<detail::JointKinematics<Model>> joint;
  std::optional<detail::SparseKinematics<Model>> sparse;
  if (in_joint_coordinates)
    joint.emplace(model, ws);
  else if (detail::sparse_kinematics(model, s.linear_solver))
    sparse.emplace(model);
  const auto solve = [&] {
    if (joint)
      joint->solve(s);
    else if (sparse)
      sparse->solve(ws, s);
    else
      detail::solve_kinematics_dense(model, ws, s);
  };
  solve();
  record(static_cast<const Workspace<Model>&>(ws));

  // One step from the solved state in ws to time `to`; false (ws unchanged) if it fails.
  auto step = [&](double to) {
    const Eigen::VectorXd q = ws.q;
    const double from = ws.t, h = to - from;
    if (joint) {
      joint->predict(h);
    } else {
      const Eigen::VectorXd move = h * ws.v + 0.5 * h * h * ws.vdot;
      for (int b = 0; b < model.num_bodies(); ++b)
        Model::Space::integrate(q.template segment<nq>(b * nq), move.template segment<nv>(b * nv),
                                ws.q.template segment<nq>(b * nq));
    }
    ws.t = to;
    try {
      solve();
      return true;
    } catch (const AssemblyError&) {
      ws.t = from;
      if (joint)
        joint->restore();
      else
        ws.q = q;
      solve();  // restores the solved state's v, v' and lambda
      return false;
    }
  };
  detail::step_through_outputs(
      "kinematic analysis", ws.t, t_end, interval, s.max_halvings, step,
      [&](double h, double) {
        const RedundantEquation weakest = detail::weakest_equation(model, ws, s.linear_solver);
        throw AssemblyError(weakest.joint,
                            "the mechanism locks up after t = " + to_text(ws.t) +
                                " s: no configuration meets the constraints and drivers a " +
                                to_text(h) +
                                " s step later; the equation nearest to depending "
                                "on the others there is " +
                                weakest.text());
      },
      [&] { record(static_cast<const Workspace<Model>&>(ws)); });
}

}  // namespace odyn
