#pragma once
// Dense LU with partial pivoting behind the solver interface the analyses use
// (Eigen's: analyze_pattern once per structure, factorize per matrix values, solve).
// A sparse solver (KLU, CHOLMOD) slots in with the same four calls.
//
// A singular matrix (the saddle-point matrix of a mechanism with redundant constraints) can be
// factorized instead by a rank-revealing complete orthogonal decomposition, whose solve gives
// the minimum-norm least-squares solution; it is never used on the fast path.

#include <Eigen/Core>
#include <vector>

#include "odyn/linalg/pivoted_lu.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"

namespace odyn {

class DenseLu {
 public:
  using Matrix = Eigen::MatrixXd;

  /// Sizes the factorization once, so that later factorizations allocate nothing.
  void analyze_pattern(const Matrix& a) {
    lu_.resize(a.rows());
    rank_revealing_ = false;
  }

  /// Factorizes; returns false if the matrix is numerically singular.
  bool factorize(const Matrix& a) {
    rank_revealing_ = false;
    lu_.compute(a);
    // A zero or tiny pivot relative to the largest entry means a singular matrix.
    return lu_.smallest_pivot() > 1e-13 * lu_.largest_entry();
  }

  /// Factorizes a possibly singular matrix by a complete orthogonal decomposition (rank decided
  /// with `threshold` relative to the largest pivot); returns the rank deficiency. Later solves
  /// give the minimum-norm least-squares solution, until the next factorize.
  int factorize_rank_revealing(const Matrix& a, double threshold) {
    rank_revealing_ = true;
    cod_.compute(a, threshold);
    return static_cast<int>(a.rows() - cod_.rank());
  }

  /// After factorize_rank_revealing, the columns in pivot order: the last (rank deficiency)
  /// ones depend on the others.
  const std::vector<int>& rank_revealing_column_order() const { return cod_.column_order(); }

  /// x = A^-1 b (x and b must not alias); the minimum-norm solution after a rank-revealing
  /// factorization.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    if (rank_revealing_) {
      cod_.solve(b, x, work_);
    } else {
      x = b;
      lu_.solve_in_place(x);
    }
  }

 private:
  PivotedLu lu_;
  RankRevealingQr cod_;
  Eigen::VectorXd work_;  // scratch for the rank-revealing solve
  bool rank_revealing_ = false;
};

}  // namespace odyn
