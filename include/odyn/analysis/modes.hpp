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
// -Re(s) / |s|. Dense: for models of up to a few hundred coordinates.

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

/// The modes about the coordinates' held positions, at rest: the multipliers that balance the
/// loads there first (least squares), refused if they leave an imbalance.
template <class Coordinates>
Modes modes_here(Coordinates& c, double t, double length) {
  const Eigen::Index n = c.num_velocities();
  c.velocities().setZero();
  c.accelerations().setZero();
  c.multipliers().setZero();
  Eigen::VectorXd load(n), imbalance(n);
  residual_here(c, load);
  const Eigen::MatrixXd jacobian = constraint_jacobian(c);
  if (jacobian.rows() > 0)
    c.multipliers() = jacobian.transpose().completeOrthogonalDecomposition().solve(-load);
  residual_here(c, imbalance);
  Modes out;
  out.coordinates = c.velocity_coordinates();
  const Tangent tangent_here = tangent(c, length);
  // Forces against the loads, or the stiffness times the model's size where that is more (the
  // loads can cancel out at an equilibrium, body by body).
  const double scale =
      std::max({load.size() > 0 ? load.cwiseAbs().maxCoeff() : 0.0,
                n > 0 ? tangent_here.stiffness.cwiseAbs().maxCoeff() * length : 0.0, 1e-300});
  Eigen::Index worst = 0;
  if (n > 0 && imbalance.cwiseAbs().maxCoeff(&worst) > 1e-8 * scale)
    throw SolverError(t,
                      "modes are found about an equilibrium, and this pose is not one: a "
                      "force imbalance of " +
                          to_text(imbalance[worst]) + " on " +
                          out.coordinates[static_cast<std::size_t>(worst)].text() +
                          " (against forces of " + to_text(scale) +
                          "). Find the equilibrium first (find_equilibrium)");
  out.linearization = reduce(tangent_here);
  undamped_modes(out, t);
  damped_modes(out);
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
};

/// The natural modes about the static equilibrium near the workspace's pose (left in the
/// workspace; see static_equilibrium), or about the pose itself, its joints closed
/// (settings.find_equilibrium false). Throws SolverError when that pose is not at rest and
/// balanced.
template <class Model>
Modes natural_modes(const Model& model, Workspace<Model>& ws, const ModeSettings& s = {}) {
  if (s.coordinates != "absolute" && s.coordinates != "joint")
    throw ModelError("modal analysis",
                     "coordinates '" + s.coordinates + "' unknown; use 'absolute' or 'joint'");
  StaticSettings statics = s.statics;
  statics.coordinates = s.coordinates;
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
    out.body_shapes = detail::body_motions(c, model, ws, out.shapes);
    return out;
  }
  AbsoluteCoordinates<Model> c(model, ws, LinearSolver::dense);
  Modes out = detail::modes_here(c, ws.t, length);
  out.body_shapes = out.shapes;
  return out;
}

}  // namespace odyn
