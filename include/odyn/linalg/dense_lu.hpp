#pragma once
// Dense LU with partial pivoting behind the solver interface the analyses use
// (Eigen's: analyze_pattern once per structure, factorize per matrix values, solve).
// A sparse solver (KLU, CHOLMOD) slots in with the same four calls.

#include <Eigen/Core>
#include <Eigen/LU>

namespace odyn {

class DenseLu {
 public:
  using Matrix = Eigen::MatrixXd;

  /// Sizes the factorization once, so that later factorizations allocate nothing.
  void analyze_pattern(const Matrix& a) { lu_ = Eigen::PartialPivLU<Matrix>(a.rows()); }

  /// Factorizes; returns false if the matrix is numerically singular.
  bool factorize(const Matrix& a) {
    lu_.compute(a);
    // A zero or tiny pivot relative to the largest entry means a singular matrix.
    const double largest = lu_.matrixLU().cwiseAbs().maxCoeff();
    const double smallest_pivot = lu_.matrixLU().diagonal().cwiseAbs().minCoeff();
    return smallest_pivot > 1e-13 * largest;
  }

  /// x = A^-1 b (x and b must not alias).
  template <class Rhs, class Dst>
  void solve(const Rhs& b, Dst& x) const {
    x.noalias() = lu_.solve(b);
  }

 private:
  Eigen::PartialPivLU<Matrix> lu_;
};

}  // namespace odyn
