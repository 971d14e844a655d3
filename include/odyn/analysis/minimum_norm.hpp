#pragma once
// Minimum-norm multipliers under redundant constraints. When Phi_q has dependent rows, every
// lambda + n with Phi_q^T n = 0 gives the same constraint forces Phi_q^T lambda. A direct
// solve returns the minimum-norm lambda, but Newton corrections cannot see the null-space part,
// and an integrator that carries lambda from step to step lets it grow as the null space turns
// with the pose. This removes it: lambda becomes the minimum-norm solution of
// Phi_q^T lambda = (the same constraint forces).

#include <Eigen/Core>

#include "odyn/analysis/system.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"

namespace odyn {

/// Replaces ws.lambda by the minimum-norm multipliers with the same constraint forces, from the
/// Jacobian blocks of the last evaluate_constraints. Allocates: call it only for a model whose
/// saddle-point solver reports a rank deficiency.
template <class Model>
void make_multipliers_minimum_norm(const Model& model, Workspace<Model>& ws) {
  const Eigen::Index n = model.num_velocities(), m = model.num_equations();
  if (m == 0) return;
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(m, n);
  write_jacobian(model, ws, jacobian, 0, 0, false);
  const Eigen::VectorXd forces = jacobian.transpose() * ws.lambda;
  ws.lambda = RankRevealingQr(jacobian.transpose(), rank_tolerance).solve(forces);
}

}  // namespace odyn
