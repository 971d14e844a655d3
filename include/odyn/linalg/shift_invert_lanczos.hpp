#pragma once
// The few eigenpairs of a symmetric-definite pencil K x = mu M x nearest a shift sigma, from the
// operator Op = (K - sigma M)^-1 M, which is self-adjoint in the M inner product and whose
// largest eigenvalues theta = 1 / (mu - sigma) belong to the mu nearest sigma (shift and
// invert). The caller applies the inverse, so the pencil may live on a subspace: a saddle-point
// solve with the constraints' Jacobian keeps every vector among the motions the joints allow.
//
// The Lanczos process builds an M-orthonormal basis of the Krylov space of Op, each new vector
// orthogonalized against all earlier ones twice (classical Gram-Schmidt, repeated: the
// projected matrix stays symmetric to rounding and no spurious copies of an eigenvalue
// appear). When the basis is full before the wanted pairs converge, it restarts thick (Wu and
// Simon): the best Ritz vectors are kept with the next Lanczos vector, and the projected
// matrix becomes their Ritz values bordered by the residual's coefficients. A Ritz pair
// (theta, y) has the residual |Op y - theta y|_M = beta |s_last|, read from the projected
// matrix's eigenvector s: converged when that is below `tolerance` |theta|.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

namespace odyn {

struct LanczosResult {
  Eigen::VectorXd values;   // (k) theta, the operator's eigenvalues, largest |theta| first
  Eigen::MatrixXd vectors;  // (n x k) M-orthonormal
  int operator_applications = 0;
  bool converged = false;
};

/// The `count` eigenpairs of Op of largest |theta| (see the file's comment). apply(x, y):
/// y = Op x; mass(x, y): y = M x. `basis` bounds the Lanczos vectors kept (at least count + 2);
/// `max_applications` bounds the work. Returns fewer pairs when the Krylov space ends before
/// `count` (the subspace has fewer dimensions).
template <class Apply, class Mass>
LanczosResult shift_invert_lanczos(Eigen::Index n, int count, Apply&& apply, Mass&& mass, int basis,
                                   double tolerance, int max_applications) {
  LanczosResult out;
  if (n == 0 || count <= 0) return out;
  basis = std::max(basis, count + 2);
  Eigen::MatrixXd q(n, basis), mq(n, basis);                // the basis and M times it
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(basis, basis);  // the projected operator
  Eigen::VectorXd w(n), mw(n), next(n), m_next(n);
  // A start vector with a share of every mode (fixed, so runs repeat), mapped into the subspace.
  std::mt19937 random(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Eigen::Index i = 0; i < n; ++i) w[i] = uniform(random);
  apply(w, next);
  ++out.operator_applications;
  mass(next, m_next);
  double beta = std::sqrt(std::max(next.dot(m_next), 0.0));
  if (!(beta > 0.0)) return out;
  next /= beta;
  m_next /= beta;

  int columns = 0;  // basis vectors that Op has been applied to
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz;
  bool exhausted = false;  // the Krylov space is invariant: every pair in it is exact
  for (;;) {
    // Extend the basis with `next` and apply Op to it, until full.
    while (columns < basis && !exhausted) {
      const int j = columns;
      q.col(j) = next;
      mq.col(j) = m_next;
      apply(q.col(j), w);
      ++out.operator_applications;
      Eigen::VectorXd coefficients = mq.leftCols(j + 1).transpose() * w;
      w.noalias() -= q.leftCols(j + 1) * coefficients;
      const Eigen::VectorXd again = mq.leftCols(j + 1).transpose() * w;
      w.noalias() -= q.leftCols(j + 1) * again;
      coefficients += again;
      h.col(j).head(j + 1) = coefficients;
      mass(w, mw);
      beta = std::sqrt(std::max(w.dot(mw), 0.0));
      columns = j + 1;
      exhausted = !(beta > 1e-12 * coefficients.cwiseAbs().maxCoeff());
      if (!exhausted) {
        next = w / beta;
        m_next = mw / beta;
      } else {
        beta = 0.0;
      }
      if (columns < basis) h(columns, j) = beta;  // next's coefficient in Op q_j
      if (columns >= count && (columns % 4 == 0 || columns == basis || exhausted)) break;
    }
    const Eigen::MatrixXd projected =
        0.5 * (h.topLeftCorner(columns, columns) + h.topLeftCorner(columns, columns).transpose());
    ritz.compute(projected);
    // Ritz pairs by |theta|, largest first.
    std::vector<int> order(static_cast<std::size_t>(columns));
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return std::abs(ritz.eigenvalues()[a]) > std::abs(ritz.eigenvalues()[b]);
    });
    const int wanted = std::min(count, columns);
    bool converged = true;
    for (int i = 0; i < wanted; ++i) {
      const int k = order[static_cast<std::size_t>(i)];
      const double residual = beta * std::abs(ritz.eigenvectors()(columns - 1, k));
      converged = converged && residual <= tolerance * std::abs(ritz.eigenvalues()[k]);
    }
    const bool out_of_work = out.operator_applications >= max_applications;
    if (converged || exhausted || out_of_work) {
      out.converged = converged || exhausted;
      out.values.resize(wanted);
      out.vectors.resize(n, wanted);
      for (int i = 0; i < wanted; ++i) {
        const int k = order[static_cast<std::size_t>(i)];
        out.values[i] = ritz.eigenvalues()[k];
        out.vectors.col(i) = q.leftCols(columns) * ritz.eigenvectors().col(k);
      }
      return out;
    }
    if (columns < basis) continue;
    // Thick restart: keep the best Ritz vectors, then `next`, with the projected matrix their
    // Ritz values bordered by next's coefficients beta s_last.
    const int keep = std::min(columns - 1, count + (basis - count) / 2);
    Eigen::MatrixXd s(columns, keep);
    Eigen::VectorXd values(keep);
    for (int i = 0; i < keep; ++i) {
      const int k = order[static_cast<std::size_t>(i)];
      s.col(i) = ritz.eigenvectors().col(k);
      values[i] = ritz.eigenvalues()[k];
    }
    const Eigen::MatrixXd kept = q.leftCols(columns) * s, m_kept = mq.leftCols(columns) * s;
    q.leftCols(keep) = kept;
    mq.leftCols(keep) = m_kept;
    h.setZero();
    h.topLeftCorner(keep, keep).diagonal() = values;
    h.row(keep).head(keep) = beta * s.row(columns - 1);
    columns = keep;
  }
}

}  // namespace odyn
