#pragma once
// The linear algebra of statics and modes on large models in absolute coordinates, at a cost
// about linear in the model's size where the dense path (analysis/statics.hpp, modes.hpp) spends
// O(n^3) on null spaces and complete orthogonal decompositions:
//  - the constraint rows kept: those that repeat no others (analysis/sparse_assembly.hpp
//    decides them in the model's topological order), so that every saddle-point matrix below
//    is regular and the motions the joints allow are those the kept rows allow;
//  - least-squares multipliers, min |r + G^T lambda|, from [I G^T; G 0];
//  - the lowest squared frequencies of K against M along those motions by shift-invert Lanczos
//    (linalg/shift_invert_lanczos.hpp) on [K - sigma M, G^T; G 0], which keeps every vector
//    among them without forming a basis of the null space.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <vector>

#include "odyn/analysis/sparse_assembly.hpp"
#include "odyn/analysis/sparse_tangent.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/shift_invert_lanczos.hpp"
#include "odyn/linalg/sparse_saddle_solve.hpp"

namespace odyn::detail {

/// Phi_q's rows that repeat no others (see the file's comment), at the last
/// evaluate_constraints: their indices.
template <class Model>
std::vector<int> kept_rows(const Model& model, const Workspace<Model>& ws) {
  const std::vector<char> independent =
      independent_rows(row_order(model), sparse_jacobian(model, ws), rank_tolerance);
  std::vector<int> out;
  for (int row = 0; row < static_cast<int>(independent.size()); ++row)
    if (independent[static_cast<std::size_t>(row)]) out.push_back(row);
  return out;
}

/// The rows `rows` of a sparse matrix.
inline Eigen::SparseMatrix<double> selected_rows(const Eigen::SparseMatrix<double>& matrix,
                                                 const std::vector<int>& rows) {
  std::vector<int> place(static_cast<std::size_t>(matrix.rows()), -1);
  for (std::size_t i = 0; i < rows.size(); ++i)
    place[static_cast<std::size_t>(rows[i])] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j = 0; j < matrix.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix, j); it; ++it)
      if (const int i = place[static_cast<std::size_t>(it.row())]; i >= 0)
        entries.emplace_back(i, it.col(), it.value());
  Eigen::SparseMatrix<double> out(static_cast<Eigen::Index>(rows.size()), matrix.cols());
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

inline Eigen::SparseMatrix<double> sparse_identity(Eigen::Index n) {
  Eigen::SparseMatrix<double> out(n, n);
  out.setIdentity();
  return out;
}

/// lambda (one per row of `jacobian`) minimizing |r + jacobian^T lambda|; false if the
/// jacobian's rows are dependent (the matrix is singular).
inline bool least_squares_multipliers(const Eigen::SparseMatrix<double>& jacobian,
                                      const Eigen::VectorXd& r, Eigen::VectorXd& lambda) {
  const Eigen::Index n = jacobian.cols(), m = jacobian.rows();
  lambda.setZero(m);
  if (m == 0) return true;
  SparseSaddleSolve solver;
  if (!solver.factorize(sparse_identity(n), jacobian)) return false;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + m);
  rhs.head(n) = -r;
  solver.solve_in_place(rhs);
  lambda = rhs.tail(m);
  return true;
}

/// The lowest squared frequencies and their M-unit directions.
struct LowestModes {
  Eigen::VectorXd values;   // (k) ascending, 1/s^2
  Eigen::MatrixXd vectors;  // (n x k)
  bool converged = false;
  /// The largest ratio of K's diagonal to M's: an estimate of the largest squared frequency.
  double largest_ratio = 0.0;
};

/// The `count` squared frequencies of K's symmetric part against M nearest zero along the
/// motions `jacobian` allows (see the file's comment), refined as Rayleigh quotients. Empty
/// values if the shifted matrix is singular or M is not positive along a motion.
inline LowestModes lowest_modes(const Eigen::SparseMatrix<double>& stiffness,
                                const Eigen::SparseMatrix<double>& mass,
                                const Eigen::SparseMatrix<double>& jacobian, int count) {
  const Eigen::SparseMatrix<double> k =
      0.5 * (stiffness + Eigen::SparseMatrix<double>(stiffness.transpose()));
  const Eigen::SparseMatrix<double> m =
      0.5 * (mass + Eigen::SparseMatrix<double>(mass.transpose()));
  const Eigen::Index n = k.rows();
  LowestModes out;
  // A shift just below zero, so that a motion without stiffness (a free wheel) leaves the
  // matrix regular, small against the stiffness-to-mass ratios so that the lowest stay apart.
  double ratio = 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
    if (m.coeff(i, i) > 0.0) ratio = std::max(ratio, std::abs(k.coeff(i, i)) / m.coeff(i, i));
  out.largest_ratio = ratio;
  const double sigma = -1e-9 * std::max(ratio, 1e-300);
  SparseSaddleSolve solver;
  if (!solver.factorize(k - sigma * m, jacobian)) return out;
  const auto apply = [&](const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::Ref<Eigen::VectorXd> y) { solver.solve_free(m * x, y); };
  const auto mass_times = [&](const Eigen::Ref<const Eigen::VectorXd>& x,
                              Eigen::Ref<Eigen::VectorXd> y) { y = m * x; };
  const int basis = std::max(2 * count + 20, count + 40);
  const LanczosResult found =
      shift_invert_lanczos(n, count, apply, mass_times, basis, 1e-10, 40 * basis);
  out.converged = found.converged;
  const auto size = found.values.size();
  Eigen::VectorXd values(size);
  for (Eigen::Index i = 0; i < size; ++i) {
    const Eigen::VectorXd x = found.vectors.col(i);
    const double xmx = x.dot(m * x);
    if (!(xmx > 0.0)) {
      out.converged = false;
      return out;
    }
    values[i] = x.dot(k * x) / xmx;
  }
  std::vector<Eigen::Index> order(static_cast<std::size_t>(size));
  for (Eigen::Index i = 0; i < size; ++i) order[static_cast<std::size_t>(i)] = i;
  std::sort(order.begin(), order.end(),
            [&](Eigen::Index a, Eigen::Index b) { return values[a] < values[b]; });
  out.values.resize(size);
  out.vectors.resize(n, size);
  for (Eigen::Index i = 0; i < size; ++i) {
    const Eigen::Index j = order[static_cast<std::size_t>(i)];
    out.values[i] = values[j];
    const Eigen::VectorXd x = found.vectors.col(j);
    out.vectors.col(i) = x / std::sqrt(x.dot(m * x));
  }
  return out;
}

}  // namespace odyn::detail
