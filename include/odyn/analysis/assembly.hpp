#pragma once
// Assembly: from the user's approximate initial pose and velocities to a consistent state.
//  1. positions: Newton on Phi(q, t) = 0 with minimum-norm steps dq = -Phi_q^+ Phi;
//  2. velocities: Phi_q v = -Phi_t, keeping each velocity component the user gave as long as
//     it is independent of the constraints and of the components kept before it; the rest
//     changes as little as possible in the kinetic-energy metric;
//  3. accelerations and multipliers from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma].
// Redundant constraint equations are reported by name (they make lambda non-unique).
// A mechanism whose redundant equations are consistent (Bricard's linkage, two coaxial hinges)
// assembles and runs: the solvers give the minimum-norm multipliers (analysis/saddle_point.hpp),
// and redundant_equations(model, ws) says which equations repeat others.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "odyn/analysis/sparse_assembly.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/linalg/linear_solver.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"

namespace odyn {

struct AssemblySettings {
  double tolerance = 1e-12;  // |Phi| in every entry
  int max_iterations = 50;
  /// dense: rank-revealing QR of whole matrices (small models); cholmod or klu: sparse rows and
  /// a sparse LU, linear in the model's size; auto: sparse above dense_assembly_limit unknowns.
  LinearSolver linear_solver = LinearSolver::automatic;
  /// A run warns when assembly moves a body farther than this from the pose it was given (m, rad):
  /// a joint whose points or axes do not fit the bodies' poses shows up that way.
  double warn_translation = 1e-5;
  double warn_rotation = 1e-5;
};

/// Velocities plus constraint equations up to which `auto` assembles with dense matrices.
inline constexpr int dense_assembly_limit = 100;

/// How far assembly moved one body from the pose it was given.
struct BodyDisplacement {
  std::string body;
  double translation = 0.0;  // of its origin, m
  double rotation = 0.0;     // angle of the rotation between the two orientations, rad
};

struct AssemblyReport {
  int iterations = 0;
  double position_residual = 0.0;                 // max |Phi|
  double velocity_residual = 0.0;                 // max |Phi_q v + Phi_t|
  std::vector<int> kept_velocity_components;      // indices into v the assembly kept
  std::vector<int> adjusted_velocity_components;  // given components it had to change
  /// The bodies the position stage moved beyond rounding (1e-12 m or rad), in body order.
  std::vector<BodyDisplacement> moved_bodies;
};

/// What a run should say about the assembly's moves: empty if no body moved beyond the
/// settings' thresholds, else the bodies that did (the farthest first) and what to check.
inline std::string assembly_motion_warning(const AssemblyReport& report,
                                           const AssemblySettings& s) {
  std::vector<BodyDisplacement> far;
  for (const BodyDisplacement& d : report.moved_bodies)
    if (d.translation > s.warn_translation || d.rotation > s.warn_rotation) far.push_back(d);
  if (far.empty()) return "";
  // Farthest first, by the larger of the two in units of its threshold.
  const auto size = [&s](const BodyDisplacement& d) {
    return std::max(d.translation / s.warn_translation, d.rotation / s.warn_rotation);
  };
  std::stable_sort(far.begin(), far.end(),
                   [&](const auto& a, const auto& b) { return size(a) > size(b); });
  constexpr std::size_t shown = 5;
  std::string list;
  for (std::size_t i = 0; i < std::min(far.size(), shown); ++i)
    list += (i == 0 ? "" : ", ") + ("'" + far[i].body + "' by " + to_text(far[i].translation) +
                                    " m and " + to_text(far[i].rotation) + " rad");
  if (far.size() > shown) list += " and " + std::to_string(far.size() - shown) + " more";
  return "assembly moved " + std::to_string(far.size()) + (far.size() == 1 ? " body" : " bodies") +
         " from the given pose beyond " + to_text(s.warn_translation) + " m or " +
         to_text(s.warn_rotation) + " rad: " + list +
         ". The given poses do not meet the constraints there: check the joints' points and "
         "axes against the bodies' poses (a rough pose on purpose is fine; raise "
         "warn_translation and warn_rotation of the assembly settings to silence this).";
}

/// A constraint equation that depends on the others at the current pose.
struct RedundantEquation {
  std::string joint;  // the element's name
  int equation = 0;   // index among the element's own equations (0-based)
  int row = 0;        // row of Phi
  /// "joint (equation k, row r)".
  std::string text() const {
    return joint + " (equation " + std::to_string(equation) + ", row " + std::to_string(row) + ")";
  }
};

namespace detail {
/// The element that owns a constraint row, and the row's index among its equations.
template <class Model>
RedundantEquation locate_row(const Model& model, int row) {
  RedundantEquation found;
  found.row = row;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (Constraint<E>) {
      const auto& offsets = model.template rows<E>();
      for (std::size_t i = 0; i < pool.size(); ++i)
        if (row >= offsets[i] && row < offsets[i] + E::num_equations) {
          found.joint = pool[i].name();
          found.equation = row - offsets[i];
        }
    }
  });
  return found;
}

/// Rows of Phi_q that depend on earlier ones, in the pivot order of a rank-revealing QR of
/// Phi_q^T (threshold relative to the largest pivot), sorted.
inline std::vector<int> dependent_rows(const Eigen::MatrixXd& jacobian) {
  std::vector<int> rows;
  if (jacobian.rows() == 0) return rows;
  const RankRevealingQr qr(jacobian.transpose(), rank_tolerance);
  for (Eigen::Index k = qr.rank(); k < jacobian.rows(); ++k)
    rows.push_back(qr.column_order()[static_cast<std::size_t>(k)]);
  std::sort(rows.begin(), rows.end());
  return rows;
}

template <class Model>
Eigen::MatrixXd dense_jacobian(const Model& model, const Workspace<Model>& ws) {
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(model.num_equations(), model.num_velocities());
  write_jacobian(model, ws, jacobian, 0, 0, false);
  return jacobian;
}

template <class Model>
Eigen::MatrixXd dense_mass(const Model& model) {
  constexpr int nv = Model::nv;
  Eigen::MatrixXd mass = Eigen::MatrixXd::Zero(model.num_velocities(), model.num_velocities());
  for (int b = 1; b <= model.num_bodies(); ++b)
    mass.block<nv, nv>((b - 1) * nv, (b - 1) * nv) = model.body(BodyId{b}).mass_block();
  return mass;
}

/// Whether the assembly runs on sparse rows (see AssemblySettings::linear_solver).
template <class Model>
bool sparse_assembly(const Model& model, const AssemblySettings& s) {
  if (s.linear_solver == LinearSolver::automatic)
    return model.num_velocities() + model.num_equations() > dense_assembly_limit;
  return s.linear_solver != LinearSolver::dense;
}

/// The rows of Phi_q (at the blocks of the last evaluate_constraints) that depend on others:
/// by a rank-revealing QR of the dense matrix for small models, and for large ones (past
/// dense_assembly_limit, or as `solver` says) by sparse elimination in the model's
/// topological order (see independent_rows), which names rows of the joints that close loops.
template <class Model>
std::vector<int> dependent_rows(const Model& model, const Workspace<Model>& ws,
                                LinearSolver solver = LinearSolver::automatic) {
  AssemblySettings s;
  s.linear_solver = solver;
  if (!sparse_assembly(model, s)) return dependent_rows(dense_jacobian(model, ws));
  const std::vector<char> independent =
      independent_rows(model, sparse_jacobian(model, ws), rank_tolerance);
  std::vector<int> rows;
  for (int r = 0; r < static_cast<int>(independent.size()); ++r)
    if (!independent[r]) rows.push_back(r);
  return rows;
}

/// The mass matrix's block of body b (from 0), for the sparse solves.
template <class Model>
auto mass_blocks(const Model& model) {
  return [&model](int b) { return model.body(BodyId{b + 1}).mass_block(); };
}

/// The minimum-norm Newton step of the positions, -Phi_q^+ Phi, on sparse rows: the rows that
/// repeat earlier ones are left out (their residual follows from the others'), the rest solve
/// [I Phi_q^T; Phi_q 0] [dq; y] = [0; -Phi]. Empty if that system is singular.
template <class Model>
Eigen::VectorXd sparse_position_step(const Model& model, const Workspace<Model>& ws) {
  constexpr int nv = Model::nv;
  const SparseRows rows = sparse_jacobian(model, ws);
  const std::vector<char> use = independent_rows(model, rows, rank_tolerance);
  Eigen::VectorXd g(std::count(use.begin(), use.end(), 1));
  for (int r = 0, k = 0; r < rows.num_rows(); ++r)
    if (use[r]) g[k++] = -ws.phi[r];
  const auto identity = [](int) { return Eigen::Matrix<double, nv, nv>::Identity(); };
  Eigen::VectorXd step, multipliers;
  if (!solve_sparse_saddle_point<nv>(identity, rows, use, {},
                                     Eigen::VectorXd::Zero(rows.num_columns), g, step, multipliers))
    return {};
  return step;
}

/// Accelerations and multipliers from [M Phi_q^T; Phi_q 0] [v'; lambda] = [Q; gamma] on sparse
/// rows (`use`: the independent ones), with the workspace's forces and gamma evaluated. A
/// constraint row that repeats earlier ones gets no multiplier (0).
template <class Model>
void solve_accelerations_sparse(const Model& model, Workspace<Model>& ws, const SparseRows& rows,
                                const std::vector<char>& use) {
  constexpr int nv = Model::nv;
  const int m = model.num_equations();
  Eigen::VectorXd g(std::count(use.begin(), use.end(), 1));
  for (int r = 0, k = 0; r < m; ++r)
    if (use[r]) g[k++] = ws.gamma[r];
  Eigen::VectorXd vdot, multipliers;
  if (!solve_sparse_saddle_point<nv>(mass_blocks(model), rows, use, {}, ws.force, g, vdot,
                                     multipliers))
    throw AssemblyError("assembly", "the mass-constraint matrix is singular (sparse assembly)");
  ws.vdot = vdot;
  ws.lambda.setZero();
  for (int r = 0, k = 0; r < m; ++r)
    if (use[r]) ws.lambda[r] = multipliers[k++];
}

/// Velocities (keeping the given components that the constraints leave free, the rest
/// changed as little as possible in the kinetic-energy metric), then accelerations and
/// multipliers, on sparse rows. A constraint row that repeats earlier ones gets no multiplier
/// (0): with redundant constraints the reactions are one valid choice, not the minimum-norm one
/// of the dense assembly.
template <class Model>
void assemble_velocities_and_accelerations_sparse(const Model& model, Workspace<Model>& ws,
                                                  const Eigen::VectorXd& user_velocity,
                                                  AssemblyReport& report) {
  constexpr int nv = Model::nv;
  const int m = model.num_equations(), n = model.num_velocities();
  const SparseRows rows = sparse_jacobian(model, ws);
  const std::vector<char> use = independent_rows(model, rows, rank_tolerance);
  const int independent = static_cast<int>(std::count(use.begin(), use.end(), 1));
  std::vector<int> given;
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const auto components = model.body(BodyId{b}).given_components();
    for (int k = 0; k < nv; ++k)
      if (components[k]) given.push_back((b - 1) * nv + k);
  }
  const std::vector<char> keep = keepable_components(rows, use, given);
  for (std::size_t k = 0; k < given.size(); ++k)
    (keep[k] ? report.kept_velocity_components : report.adjusted_velocity_components)
        .push_back(given[k]);
  const std::vector<int>& kept = report.kept_velocity_components;
  // min (v - v_user)^T M (v - v_user) subject to Phi_q v = -Phi_t and the kept components.
  Eigen::VectorXd velocity_residual(m);
  jacobian_times(model, ws, user_velocity, velocity_residual);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(independent + static_cast<int>(kept.size()));
  for (int r = 0, k = 0; r < m; ++r)
    if (use[r]) g[k++] = -ws.phi_t[r] - velocity_residual[r];
  Eigen::VectorXd correction, multipliers;
  if (!solve_sparse_saddle_point<nv>(mass_blocks(model), rows, use, kept, Eigen::VectorXd::Zero(n),
                                     g, correction, multipliers))
    throw AssemblyError("assembly", "the velocity equations are singular (sparse assembly)");
  ws.v = user_velocity + correction;
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  jacobian_times(model, ws, ws.v, velocity_residual);
  report.velocity_residual = m > 0 ? (velocity_residual + ws.phi_t).cwiseAbs().maxCoeff() : 0.0;

  // Accelerations and multipliers, with the same Phi_q (the positions have not moved).
  initialize_states(model, ws);
  evaluate_forces(model, ws);
  evaluate_gamma(model, ws);
  solve_accelerations_sparse(model, ws, rows, use);
}

/// Minimum-norm solution of the saddle-point system [A C^T; C 0] [x; y] = [f; g].
inline void solve_saddle_point(const Eigen::MatrixXd& a, const Eigen::MatrixXd& c,
                               const Eigen::VectorXd& f, const Eigen::VectorXd& g,
                               Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const Eigen::Index n = a.rows(), m = c.rows();
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(n + m, n + m);
  kkt.topLeftCorner(n, n) = a;
  kkt.bottomLeftCorner(m, n) = c;
  kkt.topRightCorner(n, m) = c.transpose();
  Eigen::VectorXd rhs(n + m);
  rhs << f, g;
  const Eigen::VectorXd solution = RankRevealingQr(kkt, 1e-12).solve(rhs);
  x = solution.head(n);
  y = solution.tail(m);
}

/// Accelerations and multipliers, minimum-norm, from the dense mass matrix and Jacobian, with
/// the workspace's forces and gamma evaluated.
template <class Model>
void solve_accelerations_dense(const Eigen::MatrixXd& mass, const Eigen::MatrixXd& jacobian,
                               Workspace<Model>& ws) {
  Eigen::VectorXd vdot, lambda;
  solve_saddle_point(mass, jacobian, ws.force, ws.gamma, vdot, lambda);
  ws.vdot = vdot;
  ws.lambda = lambda;
}

/// A damped Newton step: the largest of the fractions 1, 1/2, ..., 2^-29 of the step whose
/// residual falls below `norm` (the smallest if none does). move(fraction) puts the positions
/// that fraction of the step from the iteration's start; residual() is max |Phi| there, which
/// it returns.
template <class Move, class Residual>
double damped_newton_step(double norm, Move&& move, Residual&& residual) {
  double fraction = 1.0, trial = norm;
  for (int halving = 0; halving < 30; ++halving, fraction *= 0.5) {
    move(fraction);
    trial = residual();
    if (trial < norm) break;
  }
  return trial;
}
}  // namespace detail

/// Positions only: Newton with minimum-norm steps. Throws AssemblyError naming the joint with
/// the largest residual if it cannot converge.
template <class Model>
int assemble_positions(const Model& model, Workspace<Model>& ws, const AssemblySettings& s = {}) {
  using Space = typename Model::Space;
  constexpr int nq = Model::nq, nv = Model::nv;
  const int m = model.num_equations();
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const std::string& name = model.body(BodyId{b}).name;
    if (!ws.q.template segment<nq>((b - 1) * nq).allFinite())
      throw AssemblyError(
          name, "the initial state contains NaN or infinity: the pose of body '" + name + "'");
    if (!ws.v.template segment<nv>((b - 1) * nv).allFinite())
      throw AssemblyError(name,
                          "the initial state contains NaN or infinity: the velocity of "
                          "body '" +
                              name + "'");
  }
  auto residual_norm = [&] {
    update_frames(model, ws);
    evaluate_constraints(model, ws);
    return m > 0 ? ws.phi.cwiseAbs().maxCoeff() : 0.0;
  };
  double norm = residual_norm();
  const bool sparse = detail::sparse_assembly(model, s);
  int iteration = 0;
  for (; iteration < s.max_iterations && norm > s.tolerance && std::isfinite(norm); ++iteration) {
    Eigen::VectorXd step;
    if (sparse) step = detail::sparse_position_step(model, ws);
    if (step.size() == 0) {
      const Eigen::MatrixXd jacobian = detail::dense_jacobian(model, ws);
      // Rank to rounding: a step along nearly dependent rows is still a step toward Phi = 0.
      const double threshold = std::numeric_limits<double>::epsilon() * static_cast<double>(m);
      step = -RankRevealingQr(jacobian, threshold).solve(ws.phi);
    }
    const Eigen::VectorXd start = ws.q;
    norm = detail::damped_newton_step(
        norm,
        [&](double fraction) {
          for (int b = 0; b < model.num_bodies(); ++b)
            Space::integrate(start.template segment<nq>(b * nq),
                             fraction * step.template segment<nv>(b * nv),
                             ws.q.template segment<nq>(b * nq));
        },
        residual_norm);
  }
  if (!(norm <= s.tolerance)) {
    Eigen::Index row = 0;
    const double worst = m > 0 ? ws.phi.cwiseAbs().maxCoeff(&row) : 0.0;
    const std::string joint = m > 0 ? model.constraint_name(static_cast<int>(row)) : "";
    // The least-squares compromise spreads the violation: list every joint left unsatisfied.
    std::string others;
    for (int r = 0; r < m; ++r) {
      const std::string name = model.constraint_name(r);
      if (std::abs(ws.phi[r]) > s.tolerance && name != joint &&
          others.find("'" + name + "'") == std::string::npos)
        others += (others.empty() ? "" : ", ") + ("'" + name + "'");
    }
    throw AssemblyError(
        joint, "constraints could not be satisfied after " + std::to_string(iteration) +
                   " Newton iterations; largest residual " + to_text(worst) + " at joint '" +
                   joint + "'" + (others.empty() ? "" : "; also unsatisfied: " + others) +
                   ". Check their points, axes and lengths, or start from a "
                   "pose closer to an assembled one.");
  }
  return iteration;
}

namespace detail {
template <class Model>
void record_moves(const Model& model, const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                  AssemblyReport& report) {
  constexpr int nq = Model::nq;
  constexpr double rounding = 1e-12;
  for (int b = 0; b < model.num_bodies(); ++b) {
    const auto [translation, rotation] = Model::Space::displacement(
        from.template segment<nq>(b * nq), to.template segment<nq>(b * nq));
    if (translation > rounding || rotation > rounding)
      report.moved_bodies.push_back({model.body(BodyId{b + 1}).name, translation, rotation});
  }
}
}  // namespace detail

/// Assembles positions, velocities, accelerations and multipliers at time ws.t.
template <class Model>
AssemblyReport assemble(const Model& model, Workspace<Model>& ws, const AssemblySettings& s = {}) {
  constexpr int nv = Model::nv;
  AssemblyReport report;
  const Eigen::VectorXd user_velocity = ws.v;
  const Eigen::VectorXd given_pose = ws.q;
  report.iterations = assemble_positions(model, ws, s);
  detail::record_moves(model, given_pose, ws.q, report);
  report.position_residual = model.num_equations() > 0 ? ws.phi.cwiseAbs().maxCoeff() : 0.0;

  if (detail::sparse_assembly(model, s)) {
    detail::assemble_velocities_and_accelerations_sparse(model, ws, user_velocity, report);
    return report;
  }
  const Eigen::MatrixXd jacobian = detail::dense_jacobian(model, ws);
  const Eigen::MatrixXd mass = detail::dense_mass(model);
  const int m = model.num_equations(), n = model.num_velocities();
  // Keep given velocity components one by one while they stay independent of the rest.
  Eigen::MatrixXd rows = jacobian;
  Eigen::VectorXd rhs = -ws.phi_t;
  auto rank_of = [](const Eigen::MatrixXd& a) {
    return a.rows() == 0 ? Eigen::Index{0} : RankRevealingQr(a.transpose(), rank_tolerance).rank();
  };
  Eigen::Index rank = rank_of(rows);
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const auto given = model.body(BodyId{b}).given_components();
    for (int k = 0; k < nv; ++k) {
      if (!given[k]) continue;
      const int index = (b - 1) * nv + k;
      Eigen::MatrixXd extended(rows.rows() + 1, n);
      extended << rows, Eigen::RowVectorXd::Unit(n, index);
      const Eigen::Index extended_rank = rank_of(extended);
      if (extended_rank > rank) {
        rows = std::move(extended);
        rhs.conservativeResize(rhs.size() + 1);
        rhs[rhs.size() - 1] = user_velocity[index];
        rank = extended_rank;
        report.kept_velocity_components.push_back(index);
      } else {
        report.adjusted_velocity_components.push_back(index);
      }
    }
  }
  // min (v - v_user)^T M (v - v_user)  subject to  rows v = rhs.
  Eigen::VectorXd correction, multipliers;
  detail::solve_saddle_point(mass, rows, Eigen::VectorXd::Zero(n), rhs - rows * user_velocity,
                             correction, multipliers);
  ws.v = user_velocity + correction;
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  report.velocity_residual = m > 0 ? (jacobian * ws.v + ws.phi_t).cwiseAbs().maxCoeff() : 0.0;

  // Accelerations and multipliers.
  initialize_states(model, ws);
  evaluate_forces(model, ws);
  evaluate_gamma(model, ws);
  detail::solve_accelerations_dense(mass, jacobian, ws);
  return report;
}

/// Accelerations and multipliers at the workspace's positions and velocities (the last stage of
/// assemble), for a state whose forces changed since it was assembled. Stateful force elements
/// keep their states.
template <class Model>
void assemble_accelerations(const Model& model, Workspace<Model>& ws,
                            const AssemblySettings& s = {}) {
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  evaluate_forces(model, ws);
  evaluate_gamma(model, ws);
  if (detail::sparse_assembly(model, s)) {
    const detail::SparseRows rows = detail::sparse_jacobian(model, ws);
    detail::solve_accelerations_sparse(model, ws, rows,
                                       detail::independent_rows(model, rows, rank_tolerance));
  } else {
    detail::solve_accelerations_dense(detail::dense_mass(model), detail::dense_jacobian(model, ws),
                                      ws);
  }
}

/// What check_assembled finds in a workspace that an assembly filled earlier.
enum class AssembledCheck {
  assembled,       // as an assembly leaves it
  forces_changed,  // positions and velocities are, accelerations and multipliers no longer fit
  not_assembled,   // positions or velocities off the constraints (a driver changed, say)
};

/// Whether the workspace holds an assembled state at its time: positions and velocities on the
/// constraints (|Phi| within the tolerance, the velocity residual no larger than `report`
/// found, up to rounding), and accelerations and multipliers that solve the equations of motion
/// there to rounding. Leaves the constraints, forces and gamma evaluated at that state.
template <class Model>
AssembledCheck check_assembled(const Model& model, Workspace<Model>& ws, const AssemblySettings& s,
                               const AssemblyReport& report) {
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  const auto largest = [](const Eigen::VectorXd& x) {
    return x.size() > 0 ? x.cwiseAbs().maxCoeff() : 0.0;
  };
  if (!(largest(ws.phi) <= s.tolerance)) return AssembledCheck::not_assembled;
  const int n = model.num_velocities(), m = model.num_equations();
  Eigen::VectorXd constraint_rate(m);
  jacobian_times(model, ws, ws.v, constraint_rate);
  // (2x: the report's residual may have been summed in another order.)
  if (!(largest(constraint_rate + ws.phi_t) <= 2.0 * report.velocity_residual + s.tolerance))
    return AssembledCheck::not_assembled;
  evaluate_forces(model, ws);
  evaluate_gamma(model, ws);
  // M v' + Phi_q^T lambda = Q and Phi_q v' = gamma, to rounding relative to their terms (the
  // terms of Phi_q v' summed in absolute value: it is zero on a chain falling freely).
  constexpr double relative = 1e-9;
  Eigen::VectorXd inertia(n), reaction = Eigen::VectorXd::Zero(n), constraint_acceleration(m);
  mass_times(model, ws.vdot, inertia);
  add_jacobian_transpose_times(model, ws, ws.lambda, reaction);
  jacobian_times(model, ws, ws.vdot, constraint_acceleration);
  Eigen::VectorXd acceleration_terms = Eigen::VectorXd::Zero(m);
  detail::for_each_jacobian_block(model, ws, [&](int row, int column, const auto& block) {
    constexpr int rows = std::decay_t<decltype(block)>::RowsAtCompileTime;
    acceleration_terms.template segment<rows>(row).noalias() +=
        block.cwiseAbs() * ws.vdot.template segment<Model::nv>(column).cwiseAbs();
  });
  const double force_scale =
      std::max({largest(inertia), largest(reaction), largest(ws.force), 1e-300});
  const double rate_scale = std::max({largest(acceleration_terms), largest(ws.gamma), 1e-300});
  const bool balanced = largest(inertia + reaction - ws.force) <= relative * force_scale &&
                        largest(constraint_acceleration - ws.gamma) <= relative * rate_scale;
  return balanced ? AssembledCheck::assembled : AssembledCheck::forces_changed;
}

/// The constraint equations that repeat what others impose at the workspace's pose (empty when
/// Phi_q has full row rank). Their number is the rank deficiency of Phi_q; which ones are named
/// is a choice (any equation of a dependent set could be), made by a pivoted QR.
template <class Model>
std::vector<RedundantEquation> redundant_equations(const Model& model, Workspace<Model>& ws) {
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  std::vector<RedundantEquation> redundant;
  for (const int row : detail::dependent_rows(model, ws))
    redundant.push_back(detail::locate_row(model, row));
  return redundant;
}

/// Throws ModelError listing redundant constraint equations at the current pose, if any.
template <class Model>
void require_independent_constraints(const Model& model, Workspace<Model>& ws) {
  update_frames(model, ws);
  evaluate_constraints(model, ws);
  std::vector<std::string> redundant;
  for (const int row : detail::dependent_rows(model, ws))
    redundant.push_back(model.constraint_name(row) + " (equation " + std::to_string(row) + ")");
  if (redundant.empty()) return;
  std::string list;
  for (const auto& name : redundant) list += (list.empty() ? "" : ", ") + name;
  throw ModelError(redundant.front(),
                   "constraint equations are redundant (they repeat what other joints already "
                   "impose): " +
                       list +
                       ". Replace a joint by one with fewer equations (for example a spherical "
                       "joint instead of a revolute one) so that the mechanism is not "
                       "over-constrained.");
}

}  // namespace odyn
