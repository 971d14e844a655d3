#pragma once
// Linearization about a static equilibrium and the mechanism's natural modes. About a state at
// rest the equations of motion, to first order in a small motion dq (velocity coordinates),
//     M dq'' + C dq' + K dq + Phi_q^T dlambda = 0,   Phi_q dq = 0,
// hold with M, C and K the tangent's (analysis/tangent.hpp; K with the constraints' geometric
// stiffness, which is what makes a pendulum swing in absolute coordinates). The motions the
// joints allow are dq = T z, T an orthonormal basis of Phi_q's null space, and on them
//     M_r z'' + C_r z' + K_r z = 0,   M_r = T^T M T,  C_r = T^T C T,  K_r = T^T K T:
// a minimal set of coordinates z, as many as the degrees of freedom. The undamped modes solve
// K_r x = omega^2 M_r x (K_r's symmetric part); the damped ones are the eigenvalues s of the
// state matrix [0 I; -M_r^-1 K_r, -M_r^-1 C_r], natural frequency |s| and damping ratio
// -Re(s) / |s|. Dense, O(n^3); large models in absolute coordinates take the sparse path
// (analysis/sparse_linearization.hpp), which finds the lowest modes without forming T.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "odyn/analysis/sparse_linearization.hpp"
#include "odyn/analysis/statics.hpp"

namespace odyn {

/// The linearized equations on the constraint manifold (see the file's comment).
struct Linearization {
  Eigen::MatrixXd basis;      // (n x k) T: the minimal coordinates' motions, orthonormal
  Eigen::MatrixXd mass;       // (k x k) M_r
  Eigen::MatrixXd damping;    // (k x k) C_r
  Eigen::MatrixXd stiffness;  // (k x k) K_r
  /// (2k x 2k) A = [0 I; -M_r^-1 K_r, -M_r^-1 C_r], for x = (z, z').
  Eigen::MatrixXd state_matrix() const {
    const Eigen::Index k = mass.rows();
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * k, 2 * k);
    a.topRightCorner(k, k).setIdentity();
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(mass);
    a.bottomLeftCorner(k, k) = -lu.solve(stiffness);
    a.bottomRightCorner(k, k) = -lu.solve(damping);
    return a;
  }
};

/// A mechanism's natural modes about an equilibrium, lowest first.
struct Modes {
  /// Undamped: K_r x = omega^2 M_r x. Hz; a negative squared frequency (an unstable direction)
  /// gives a frequency of 0.
  Eigen::VectorXd squared_frequencies;  // (k) omega^2, 1/s^2, ascending
  Eigen::VectorXd frequencies;          // (k) omega / 2 pi, Hz
  Eigen::MatrixXd shapes;  // (n x k) each mode's motion in the velocity coordinates, M-unit
  /// Damped: one eigenvalue s of the state matrix for each conjugate pair (Im s >= 0), every
  /// real one (an overdamped or unstable motion), by |s|.
  Eigen::VectorXcd eigenvalues;                 // 1/s
  Eigen::VectorXd natural_frequencies;          // |s| / 2 pi, Hz
  Eigen::VectorXd damped_frequencies;           // Im(s) / 2 pi, Hz
  Eigen::VectorXd damping_ratios;               // -Re(s) / |s|
  std::vector<VelocityCoordinate> coordinates;  // what each row of `shapes` is
  /// (nv x k, the model's velocities) each undamped mode's motion as the bodies' velocities,
  /// as Workspace::v holds them (per body: travel in global axes, turn in the body's), whatever
  /// coordinates the analysis ran in: what a mode moves.
  Eigen::MatrixXd body_shapes;
  Linearization linearization;
};

namespace detail {

inline Linearization reduce(const Tangent& t) {
  Linearization out;
  out.basis = null_space(t.jacobian, t.stiffness.cols());
  const Eigen::MatrixXd& basis = out.basis;
  out.mass = basis.transpose() * t.mass * basis;
  out.mass = 0.5 * (out.mass + out.mass.transpose()).eval();
  out.damping = basis.transpose() * t.damping * basis;
  out.stiffness = basis.transpose() * t.stiffness * basis;
  return out;
}

inline void undamped_modes(Modes& out, double t) {
  const Linearization& l = out.linearization;
  const Eigen::MatrixXd stiffness = 0.5 * (l.stiffness + l.stiffness.transpose());
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(stiffness, l.mass);
  if (solver.info() != Eigen::Success)
    throw SolverError(t,
                      "the reduced mass matrix is not positive definite: a motion the "
                      "joints allow moves no mass (a body without mass or inertia)");
  out.squared_frequencies = solver.eigenvalues();
  out.frequencies = out.squared_frequencies.unaryExpr(
      [](double w2) { return std::sqrt(std::max(w2, 0.0)) / (2.0 * std::numbers::pi); });
  out.shapes = l.basis * solver.eigenvectors();
}

/// The damped modes' fields from their eigenvalues s (one of each conjugate pair).
inline void set_damped(Modes& out, const std::vector<std::complex<double>>& kept) {
  const auto count = static_cast<Eigen::Index>(kept.size());
  out.eigenvalues.resize(count);
  out.natural_frequencies.resize(count);
  out.damped_frequencies.resize(count);
  out.damping_ratios.resize(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const std::complex<double> s = kept[static_cast<std::size_t>(i)];
    const double size = std::abs(s);
    out.eigenvalues[i] = s;
    out.natural_frequencies[i] = size / (2.0 * std::numbers::pi);
    out.damped_frequencies[i] = s.imag() / (2.0 * std::numbers::pi);
    out.damping_ratios[i] = size > 0.0 ? -s.real() / size : 0.0;
  }
}

inline void damped_modes(Modes& out) {
  const Eigen::Index k = out.linearization.mass.rows();
  if (k == 0) return;
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(out.linearization.state_matrix(), false);
  const Eigen::VectorXcd& all = solver.eigenvalues();
  std::vector<std::complex<double>> kept;
  // One of each conjugate pair; a real eigenvalue stands alone.
  for (Eigen::Index i = 0; i < all.size(); ++i)
    if (all[i].imag() >= 0.0) kept.push_back(all[i]);
  std::sort(kept.begin(), kept.end(),
            [](const auto& a, const auto& b) { return std::abs(a) < std::abs(b); });
  set_damped(out, kept);
}

/// Throws unless the force imbalance at a pose is negligible against its forces: the loads, or
/// the stiffness times the model's size where that is more (the loads can cancel out at an
/// equilibrium, body by body).
inline void refuse_imbalance(const Eigen::VectorXd& imbalance, const Eigen::VectorXd& load,
                             double largest_stiffness, double length,
                             const std::vector<VelocityCoordinate>& coordinates, double t) {
  const Eigen::Index n = imbalance.size();
  const double scale = std::max({load.size() > 0 ? load.cwiseAbs().maxCoeff() : 0.0,
                                 n > 0 ? largest_stiffness * length : 0.0, 1e-300});
  Eigen::Index worst = 0;
  if (n > 0 && imbalance.cwiseAbs().maxCoeff(&worst) > 1e-8 * scale)
    throw SolverError(t,
                      "modes are found about an equilibrium, and this pose is not one: a "
                      "force imbalance of " +
                          to_text(imbalance[worst]) + " on " +
                          coordinates[static_cast<std::size_t>(worst)].text() +
                          " (against forces of " + to_text(scale) +
                          "). Find the equilibrium first (find_equilibrium)");
}

/// The coordinates at rest with the multipliers that best balance the loads there (least
/// squares); `load` the residual without them.
template <class Coordinates, class Algebra>
void balanced_at_rest(Coordinates& c, Algebra algebra, Eigen::VectorXd& load) {
  c.velocities().setZero();
  c.accelerations().setZero();
  c.multipliers().setZero();
  load.resize(c.num_velocities());
  residual_here(c, load);
  if (c.num_equations() > 0) algebra.balance(c, load);
}

/// The modes about the coordinates' held positions, at rest: the multipliers that balance the
/// loads there first (least squares), refused if they leave an imbalance.
template <class Coordinates>
Modes modes_here(Coordinates& c, double t, double length) {
  const Eigen::Index n = c.num_velocities();
  Eigen::VectorXd load, imbalance(n);
  balanced_at_rest(c, DenseStaticAlgebra{}, load);
  residual_here(c, imbalance);
  Modes out;
  out.coordinates = c.velocity_coordinates();
  const Tangent tangent_here = tangent(c, length);
  refuse_imbalance(imbalance, load, n > 0 ? tangent_here.stiffness.cwiseAbs().maxCoeff() : 0.0,
                   length, out.coordinates, t);
  out.linearization = reduce(tangent_here);
  undamped_modes(out, t);
  damped_modes(out);
  return out;
}

/// The lowest `count` undamped modes about the workspace's pose at rest, in absolute
/// coordinates, by the sparse path (analysis/sparse_linearization.hpp). Damped ones too when
/// no force damps (then s = +-i omega); with dampers they are left empty.
template <class Model, class Solver>
Modes sparse_modes_here(AbsoluteCoordinates<Model, Solver>& c, const Model& model,
                        Workspace<Model>& ws, double length, int count) {
  const Eigen::Index n = c.num_velocities();
  Eigen::VectorXd load, imbalance(n);
  balanced_at_rest(c, SparseStaticAlgebra<Model>(model, ws), load);
  residual_here(c, imbalance);
  const std::vector<int> rows = kept_rows(model, ws);
  const Eigen::SparseMatrix<double> jacobian =
      selected_rows(sparse_constraint_jacobian(model, ws), rows);
  Modes out;
  out.coordinates = c.velocity_coordinates();
  const SparseTangent tangent_here = sparse_tangent(c, model, ws, length);
  const double largest_stiffness = SparseStaticAlgebra<Model>::largest(tangent_here.stiffness);
  refuse_imbalance(imbalance, load, largest_stiffness, length, out.coordinates, ws.t);
  const LowestModes lowest =
      lowest_modes(tangent_here.stiffness, tangent_here.mass, jacobian, count);
  if (lowest.values.size() == 0 && count > 0 && n > static_cast<Eigen::Index>(rows.size()))
    throw SolverError(ws.t,
                      "the modes could not be found: the reduced mass matrix is not positive "
                      "definite (a body without mass or inertia), or the stiffness is singular");
  if (!lowest.converged)
    throw SolverError(ws.t, "the lowest " + std::to_string(count) +
                                " modes did not converge (Lanczos); ask for fewer, or use the "
                                "dense method");
  out.squared_frequencies = lowest.values;
  out.frequencies = lowest.values.unaryExpr(
      [](double w2) { return std::sqrt(std::max(w2, 0.0)) / (2.0 * std::numbers::pi); });
  out.shapes = lowest.vectors;
  // Nothing damps where C is rounding against sqrt(K M) (a damping ratio of 1e-12).
  const auto largest = SparseStaticAlgebra<Model>::largest;
  const bool damped = largest(tangent_here.damping) >
                      1e-12 * std::sqrt(largest_stiffness * largest(tangent_here.mass));
  if (!damped) {
    // s = +-i omega, or +-sqrt(-omega^2) along an unstable direction (both kept, as the dense
    // path keeps every real eigenvalue).
    std::vector<std::complex<double>> kept;
    for (const double w2 : lowest.values) {
      if (w2 >= 0.0) {
        kept.emplace_back(0.0, std::sqrt(w2));
      } else {
        kept.emplace_back(std::sqrt(-w2), 0.0);
        kept.emplace_back(-std::sqrt(-w2), 0.0);
      }
    }
    std::stable_sort(kept.begin(), kept.end(),
                     [](const auto& a, const auto& b) { return std::abs(a) < std::abs(b); });
    set_damped(out, kept);
  }
  return out;
}

/// Each column of `shapes` (motions in the coordinates' velocities) as the bodies' velocities,
/// read from the frames the coordinates update; leaves the coordinates at rest.
template <class Coordinates, class Model>
Eigen::MatrixXd body_motions(Coordinates& c, const Model& model, const Workspace<Model>& ws,
                             const Eigen::MatrixXd& shapes) {
  using Space = typename Model::Space;
  Eigen::MatrixXd out(model.num_velocities(), shapes.cols());
  for (Eigen::Index k = 0; k < shapes.cols(); ++k) {
    c.velocities() = shapes.col(k);
    c.update_frames();
    for (int b = 1; b <= model.num_bodies(); ++b) {
      const auto& frame = ws.frames[static_cast<std::size_t>(b)];
      const Eigen::Index row = Space::nv * (b - 1);
      out.col(k).template segment<Space::dim>(row) = frame.linear_velocity;
      out.col(k).template segment<Space::nw>(row + Space::dim) = frame.angular_velocity;
    }
  }
  c.velocities().setZero();
  c.update_frames();
  return out;
}

}  // namespace detail

struct ModeSettings {
  std::string coordinates = "absolute";  // or "joint"
  /// Find the static equilibrium first (StaticSettings) and linearize there; false linearizes
  /// about the workspace's pose as it is, which must be an equilibrium at rest.
  bool find_equilibrium = true;
  StaticSettings statics = {};
  /// How many of the lowest modes: 0 gives all of them by the dense method, the lowest
  /// `sparse_default_count` by the sparse one.
  int count = 0;
  /// "dense": every mode and the damped ones, O(n^3); "sparse": the lowest `count` undamped
  /// ones (analysis/sparse_linearization.hpp), in absolute coordinates, about linear in the
  /// model's size; "automatic": sparse in absolute coordinates above `sparse_above` velocity
  /// coordinates, else dense.
  std::string method = "automatic";
  static constexpr int sparse_default_count = 20;
  static constexpr int sparse_above = 600;
};

namespace detail {
/// Whether the modes take the sparse path; refuses a method that does not apply.
template <class Model>
bool sparse_modes(const Model& model, const ModeSettings& s) {
  if (s.method != "automatic" && s.method != "dense" && s.method != "sparse")
    throw ModelError("modal analysis",
                     "method '" + s.method + "' unknown; use 'automatic', 'dense' or 'sparse'");
  if (s.count < 0)
    throw ModelError("modal analysis",
                     "count must be 0 (all) or positive, got " + std::to_string(s.count));
  if (s.method == "sparse" && s.coordinates != "absolute")
    throw ModelError("modal analysis",
                     "the sparse method runs in absolute coordinates; use coordinates "
                     "'absolute' or the dense method");
  return s.method == "sparse" || (s.method == "automatic" && s.coordinates == "absolute" &&
                                  model.num_velocities() > ModeSettings::sparse_above);
}

/// The lowest `count` of the modes (all if 0 or more than there are).
inline void keep_lowest(Modes& out, int count) {
  if (count <= 0) return;
  const auto undamped = std::min<Eigen::Index>(count, out.squared_frequencies.size());
  out.squared_frequencies.conservativeResize(undamped);
  out.frequencies.conservativeResize(undamped);
  out.shapes.conservativeResize(Eigen::NoChange, undamped);
  const auto damped = std::min<Eigen::Index>(count, out.eigenvalues.size());
  out.eigenvalues.conservativeResize(damped);
  out.natural_frequencies.conservativeResize(damped);
  out.damped_frequencies.conservativeResize(damped);
  out.damping_ratios.conservativeResize(damped);
}
}  // namespace detail

/// The natural modes about the static equilibrium near the workspace's pose (left in the
/// workspace; see static_equilibrium), or about the pose itself, its joints closed
/// (settings.find_equilibrium false). Throws SolverError when that pose is not at rest and
/// balanced.
template <class Model>
Modes natural_modes(const Model& model, Workspace<Model>& ws, const ModeSettings& s = {}) {
  if (s.coordinates != "absolute" && s.coordinates != "joint")
    throw ModelError("modal analysis",
                     "coordinates '" + s.coordinates + "' unknown; use 'absolute' or 'joint'");
  const bool sparse = detail::sparse_modes(model, s);
  StaticSettings statics = s.statics;
  statics.coordinates = s.coordinates;
  statics.method = s.method;
  if (s.find_equilibrium) {
    static_equilibrium(model, ws, statics);
  } else {
    // The pose as given, its joints closed (assembly moves it only where they are open).
    AssemblySettings closed;
    closed.tolerance = std::min(statics.tolerance, 1e-10);
    assemble_positions(model, ws, closed);
    update_frames(model, ws);
    if (ws.v.size() > 0 && ws.v.cwiseAbs().maxCoeff() > 0.0)
      throw SolverError(ws.t, "modes are found about a state at rest; this one moves (|v| = " +
                                  to_text(ws.v.cwiseAbs().maxCoeff()) +
                                  "). Find the equilibrium first (find_equilibrium)");
  }
  const double length = detail::model_size(model, ws);
  if (s.coordinates == "joint") {
    JointCoordinates<Model> c(model, ws);
    Modes out = detail::modes_here(c, ws.t, length);
    detail::keep_lowest(out, s.count);
    out.body_shapes = detail::body_motions(c, model, ws, out.shapes);
    return out;
  }
  AbsoluteCoordinates<Model> c(model, ws, sparse ? LinearSolver::automatic : LinearSolver::dense);
  Modes out =
      sparse ? detail::sparse_modes_here(c, model, ws, length,
                                         s.count > 0 ? s.count : ModeSettings::sparse_default_count)
             : detail::modes_here(c, ws.t, length);
  detail::keep_lowest(out, s.count);
  out.body_shapes = out.shapes;
  return out;
}

}  // namespace odyn
