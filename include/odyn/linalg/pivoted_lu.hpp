#pragma once
// LU factorization with partial pivoting, P A = L U, of a small dense square matrix.
//
// Written as plain loops over the column-major storage rather than with Eigen's PartialPivLU:
// the matrices here are tens of rows, where both run at the same speed, but every translation
// unit that includes this library compiles it, and Eigen's expression machinery for a dynamic
// decomposition costs about two seconds of g++ time per unit against a tenth of one here.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace odyn {

class PivotedLu {
 public:
  /// Sizes the factors for n x n matrices, so that later factorizations allocate nothing.
  void resize(Eigen::Index n) {
    lu_.resize(n, n);
    pivots_.resize(static_cast<std::size_t>(n));
  }

  /// Factorizes a. The factors are kept whatever the outcome; see smallest_pivot().
  void compute(const Eigen::MatrixXd& a) {
    const Eigen::Index n = a.rows();
    lu_ = a;  // no allocation when the size is unchanged
    pivots_.resize(static_cast<std::size_t>(n));
    double* m = lu_.data();
    for (Eigen::Index k = 0; k < n; ++k) {
      double* column_k = m + k * n;
      Eigen::Index pivot = k;
      for (Eigen::Index i = k + 1; i < n; ++i)
        if (std::abs(column_k[i]) > std::abs(column_k[pivot])) pivot = i;
      pivots_[static_cast<std::size_t>(k)] = static_cast<int>(pivot);
      if (pivot != k)
        for (Eigen::Index j = 0; j < n; ++j) std::swap(m[k + j * n], m[pivot + j * n]);
      const double diagonal = column_k[k];
      if (diagonal != 0.0)
        for (Eigen::Index i = k + 1; i < n; ++i) column_k[i] /= diagonal;
      // Rank-one update of the trailing block, column by column (contiguous inner loop).
      for (Eigen::Index j = k + 1; j < n; ++j) {
        double* column_j = m + j * n;
        const double factor = column_j[k];
        if (factor == 0.0) continue;
        for (Eigen::Index i = k + 1; i < n; ++i) column_j[i] -= column_k[i] * factor;
      }
    }
    largest_entry_ = 0.0;
    for (Eigen::Index k = 0; k < n * n; ++k)
      largest_entry_ = std::max(largest_entry_, std::abs(m[k]));
  }

  /// Smallest |U_kk|: zero or tiny against largest_entry() for a (numerically) singular matrix.
  double smallest_pivot() const {
    double smallest = std::numeric_limits<double>::infinity();
    for (Eigen::Index k = 0; k < lu_.rows(); ++k)
      smallest = std::min(smallest, std::abs(lu_(k, k)));
    return smallest;
  }

  /// Largest |entry| of the factors L and U.
  double largest_entry() const { return largest_entry_; }

  /// x <- A^-1 x, for any vector expression with coefficient access (a VectorXd, a segment).
  template <class Vector>
  void solve_in_place(Vector&& x) const {
    const Eigen::Index n = lu_.rows();
    const double* m = lu_.data();
    for (Eigen::Index k = 0; k < n; ++k) {
      const auto pivot = static_cast<Eigen::Index>(pivots_[static_cast<std::size_t>(k)]);
      if (pivot != k) std::swap(x[k], x[pivot]);
    }
    for (Eigen::Index j = 0; j < n; ++j) {  // L y = P b, L unit lower triangular
      const double xj = x[j];
      if (xj == 0.0) continue;
      for (Eigen::Index i = j + 1; i < n; ++i) x[i] -= m[i + j * n] * xj;
    }
    for (Eigen::Index j = n - 1; j >= 0; --j) {  // U x = y
      x[j] /= m[j + j * n];
      const double xj = x[j];
      for (Eigen::Index i = 0; i < j; ++i) x[i] -= m[i + j * n] * xj;
    }
  }

 private:
  Eigen::MatrixXd lu_;       // L below the diagonal (unit diagonal implied), U on and above
  std::vector<int> pivots_;  // row k was swapped with row pivots_[k] at step k
  double largest_entry_ = 0.0;
};

/// x = A^-1 b for a small fixed-size A, by Gaussian elimination with partial pivoting.
template <int N>
Eigen::Matrix<double, N, 1> solve_small(Eigen::Matrix<double, N, N> a,
                                        Eigen::Matrix<double, N, 1> b) {
  for (int k = 0; k < N; ++k) {
    int pivot = k;
    for (int i = k + 1; i < N; ++i)
      if (std::abs(a(i, k)) > std::abs(a(pivot, k))) pivot = i;
    if (pivot != k) {
      for (int j = k; j < N; ++j) std::swap(a(k, j), a(pivot, j));
      std::swap(b[k], b[pivot]);
    }
    for (int i = k + 1; i < N; ++i) {
      const double factor = a(i, k) / a(k, k);
      for (int j = k + 1; j < N; ++j) a(i, j) -= factor * a(k, j);
      b[i] -= factor * b[k];
    }
  }
  for (int k = N - 1; k >= 0; --k) {
    for (int j = k + 1; j < N; ++j) b[k] -= a(k, j) * b[j];
    b[k] /= a(k, k);
  }
  return b;
}

}  // namespace odyn
