#pragma once
// Solves with a saddle-point matrix [A G^T; G 0] built from a sparse A (n x n) and G (m x n, of
// full row rank), by the sparse LU of linalg/sparse_lu.hpp (KLU with SuiteSparse): the linear
// algebra of the analyses that linearize a large model (statics' Newton steps, shift-invert
// eigenvalues, least-squares multipliers with A = I). Each factorize() builds the pattern
// afresh: these analyses factorize a few times, not once a step.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "odyn/linalg/sparse_lu.hpp"

namespace odyn {

class SparseSaddleSolve {
 public:
  /// False if the matrix is singular (pivots' ratio at rounding level) or not finite.
  bool factorize(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& g) {
    n_ = a.rows();
    m_ = g.rows();
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<std::size_t>(a.nonZeros() + 2 * g.nonZeros() + m_));
    for (Eigen::Index j = 0; j < a.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, j); it; ++it)
        entries.emplace_back(it.row(), it.col(), it.value());
    for (Eigen::Index j = 0; j < g.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(g, j); it; ++it) {
        entries.emplace_back(n_ + it.row(), it.col(), it.value());
        entries.emplace_back(it.col(), n_ + it.row(), it.value());
      }
    // The multipliers' (zero) diagonal, so that the LU's ordering sees every column.
    for (Eigen::Index i = 0; i < m_; ++i) entries.emplace_back(n_ + i, n_ + i, 0.0);
    Eigen::SparseMatrix<double> matrix(n_ + m_, n_ + m_);
    matrix.setFromTriplets(entries.begin(), entries.end());
    matrix.makeCompressed();
    const auto size = static_cast<int>(n_ + m_);
    starts_.assign(matrix.outerIndexPtr(), matrix.outerIndexPtr() + size + 1);
    rows_.assign(matrix.innerIndexPtr(), matrix.innerIndexPtr() + matrix.nonZeros());
    values_.assign(matrix.valuePtr(), matrix.valuePtr() + matrix.nonZeros());
    lu_.analyze(size, starts_, rows_);
    return lu_.factorize(values_, SparseLu::independent_rows_ratio);
  }

  /// [x; y] for the right-hand side [f; g], in place.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> rhs) { lu_.solve_in_place(rhs); }

  /// x of the solution for [f; 0].
  void solve_free(const Eigen::Ref<const Eigen::VectorXd>& f, Eigen::Ref<Eigen::VectorXd> x) {
    work_.setZero(n_ + m_);
    work_.head(n_) = f;
    lu_.solve_in_place(work_);
    x = work_.head(n_);
  }

  Eigen::Index rows() const { return n_ + m_; }

 private:
  Eigen::Index n_ = 0, m_ = 0;
  std::vector<int> starts_, rows_;  // CSC, kept for the LU
  std::vector<double> values_;
  SparseLu lu_;
  Eigen::VectorXd work_;
};

}  // namespace odyn
