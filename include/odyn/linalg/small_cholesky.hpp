#pragma once
// Cholesky factorization S = L D L^T (square-root free, L unit lower triangular) of a small
// symmetric positive definite matrix with an envelope, for the Schur complements of the
// saddle-point solver (tens of rows, factorized and solved at every stage of an explicit
// integrator).
//
// Why not Eigen's LLT: it is built for large dense matrices, and at this size its blocked
// triangular solves spend more time in bookkeeping than in arithmetic. What helps here:
//  - the envelope. Column j of S has no entries below row end(j) - 1. In a Schur complement,
//    rows couple only when their joints share a body, so a chain of joints listed in order
//    (the engine: revolute, spherical, universal, translational) gives a band: the
//    factorization keeps its factor inside the envelope and does a third of the dense work;
//  - the chain of dependent operations, which sets the time at this size: each pivot waits on
//    the previous one. L D L^T has one division per pivot on it, where L L^T has a square root
//    and a division (about 15 % faster on the engine's 17 x 17 matrix). The next pivot is
//    computed first and kept in a register, so the chain from pivot to pivot is a division, a
//    product and a difference;
//  - solves by dot products (rows of L from a copy of L^T for L z = x, columns of L for
//    L^T y = z) whose last term, the unknown just found, is held in a register: each row then
//    waits on one product and one difference, not on a store and a load as well (a third
//    faster than column updates on the engine's matrix, half on the planar one's).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace odyn {

class SmallCholesky {
 public:
  /// Sizes the factors for n x n matrices whose column j has no entry below row end[j] - 1
  /// (end[j] > j; empty: dense). Allocates; compute and solve then do not.
  void resize(Eigen::Index n, std::vector<Eigen::Index> end = {}) {
    lower_ = Eigen::MatrixXd::Zero(n, n);
    upper_ = Eigen::MatrixXd::Zero(n, n);
    inverse_diagonal_ = Eigen::VectorXd::Zero(n);
    if (end.empty()) end.assign(static_cast<std::size_t>(n), n);
    // The factor fills the envelope of the monotone ends; the first row of column i of L^T is
    // the first column k whose envelope reaches row i.
    end_.assign(static_cast<std::size_t>(n), 0);
    begin_.assign(static_cast<std::size_t>(n), 0);
    Eigen::Index reach = 0;
    for (Eigen::Index j = 0; j < n; ++j) {
      reach = std::clamp(std::max(reach, end[j]), j + 1, n);
      end_[j] = reach;
    }
    Eigen::Index k = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      while (end_[k] <= i) ++k;
      begin_[i] = k;
    }
  }

  /// Factorizes the symmetric matrix s (its lower triangle within the envelope is read). False
  /// if a pivot is not positive (s is not positive definite) or not finite.
  bool compute(const Eigen::MatrixXd& s) {
    const Eigen::Index n = s.rows();
    for (Eigen::Index j = 0; j < n; ++j)
      lower_.col(j).segment(j, end_[j] - j) = s.col(j).segment(j, end_[j] - j);
    double pivot = n > 0 ? lower_(0, 0) : 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      double* __restrict column_k = &lower_(0, k);
      if (!(pivot > 0.0) || !std::isfinite(pivot)) return false;
      column_k[k] = pivot;
      smallest_pivot_ = k == 0 ? pivot : std::min(smallest_pivot_, pivot);
      const double inverse = 1.0 / pivot;
      inverse_diagonal_[k] = inverse;
      const Eigen::Index end = end_[k];
      if (k + 1 == n) break;
      // The next pivot first, kept in a register: the chain from pivot to pivot is a division,
      // a product and a difference.
      pivot = k + 1 < end ? lower_(k + 1, k + 1) - (column_k[k + 1] * column_k[k + 1]) * inverse
                          : lower_(k + 1, k + 1);
      for (Eigen::Index j = k + 1; j < end; ++j) {
        double* __restrict column_j = &lower_(0, j);
        const double l_jk = column_k[j] * inverse;
        // Column k + 1's diagonal is the pivot above.
        for (Eigen::Index i = j == k + 1 ? j + 1 : j; i < end; ++i)
          column_j[i] -= l_jk * column_k[i];
      }
      for (Eigen::Index i = k + 1; i < end; ++i) column_k[i] *= inverse;
    }
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = j + 1; i < end_[j]; ++i) upper_(j, i) = lower_(i, j);
    return true;
  }

  /// The smallest pivot D(j, j) of the last successful compute: it bounds the smallest
  /// eigenvalue of S from above, so a tiny one flags a (nearly) singular matrix.
  double smallest_pivot() const { return smallest_pivot_; }

  /// x <- S^-1 x.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) const {
    const Eigen::Index n = x.size();
    if (n == 0) return;
    double* __restrict z = x.data();
    // L z = x, by rows of L (columns of the copy L^T); `previous` holds the last unknown found.
    double previous = z[0];
    for (Eigen::Index i = 1; i < n; ++i) {
      const double* __restrict row_i = &upper_(0, i);
      double sum = z[i];
      for (Eigen::Index k = begin_[i]; k < i - 1; ++k) sum -= row_i[k] * z[k];
      if (begin_[i] < i) sum -= row_i[i - 1] * previous;
      z[i] = sum;
      previous = sum;
    }
    // D L^T y = z, by columns of L, from the last row.
    previous = z[n - 1] * inverse_diagonal_[n - 1];
    z[n - 1] = previous;
    for (Eigen::Index i = n - 2; i >= 0; --i) {
      const double* __restrict column_i = &lower_(0, i);
      double sum = z[i] * inverse_diagonal_[i];
      for (Eigen::Index k = end_[i] - 1; k > i + 1; --k) sum -= column_i[k] * z[k];
      if (end_[i] > i + 1) sum -= column_i[i + 1] * previous;
      z[i] = sum;
      previous = sum;
    }
  }

 private:
  Eigen::MatrixXd lower_;                  // L below the diagonal, the pivots D on it
  Eigen::MatrixXd upper_;                  // L^T above the diagonal
  Eigen::VectorXd inverse_diagonal_;       // 1 / D(i, i)
  std::vector<Eigen::Index> end_, begin_;  // envelope: rows [j, end_j) of L's column j, and
                                           // rows [begin_i, i] of L^T's column i
  double smallest_pivot_ = 0.0;
};

}  // namespace odyn
