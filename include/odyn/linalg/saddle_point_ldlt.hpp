#pragma once
// L D L^T factorization, without pivoting, of a small dense saddle-point matrix
//     K = [A  B^T]
//         [B  0  ]
// with A (n x n) symmetric positive definite and B (m x n) of full row rank. Eliminating A's
// rows first keeps the factorization stable without pivoting: the first n pivots are A's (all
// positive), the last m those of -B A^-1 B^T (all negative). A pivot of the wrong sign says
// that A is singular or that B's rows depend on each other.
//
// For the joint-coordinate equations (a few to tens of unknowns, factorized at every stage of
// an explicit integrator): one factorization and one solve of the whole system cost less than
// factorizing A and the Schur complement apart, with their m extra solves. Up to
// max_unrolled_size unknowns the loops run over a size fixed at compile time and unroll: at
// these sizes their bookkeeping costs more than the arithmetic (a 7 x 7 solve takes 93 ns with
// bounds known only at run time, 17 ns unrolled).

#include <Eigen/Core>
#include <array>
#include <cassert>
#include <cmath>
#include <utility>

namespace odyn {

namespace detail {

/// Factorizes the lower triangle of k (size x size, column-major) into `lower`: L below the
/// diagonal, D on it, 1 / D in inverse_diagonal. No pivoting: false unless the first n pivots
/// are positive and the others negative (all of them, for n = size, when k is positive
/// definite). N > 0 fixes size = N at compile time.
template <int N>
bool ldlt_factor(int size, int n, const double* __restrict k, double* __restrict lower,
                 double* __restrict inverse_diagonal) {
  if constexpr (N > 0) size = N;
#pragma GCC unroll 16
  for (int j = 0; j < size; ++j)
#pragma GCC unroll 16
    for (int i = j; i < size; ++i) lower[j * size + i] = k[j * size + i];
#pragma GCC unroll 16
  for (int p = 0; p < size; ++p) {
    double* column_p = lower + p * size;
    const double pivot = column_p[p];
    if (!std::isfinite(pivot) || !(p < n ? pivot > 0.0 : pivot < 0.0)) return false;
    const double inverse = 1.0 / pivot;
    inverse_diagonal[p] = inverse;
#pragma GCC unroll 16
    for (int j = p + 1; j < size; ++j) {
      double* column_j = lower + j * size;
      const double l_jp = column_p[j] * inverse;
#pragma GCC unroll 16
      for (int i = j; i < size; ++i) column_j[i] -= l_jp * column_p[i];
    }
#pragma GCC unroll 16
    for (int i = p + 1; i < size; ++i) column_p[i] *= inverse;
  }
  return true;
}

/// x <- (L D L^T)^-1 x with the factors above.
template <int N>
void ldlt_solve(int size, const double* __restrict lower, const double* __restrict inverse_diagonal,
                double* __restrict x) {
  if constexpr (N > 0) size = N;
#pragma GCC unroll 16
  for (int p = 0; p < size; ++p) {  // L z = x, by columns
    const double z_p = x[p];
#pragma GCC unroll 16
    for (int i = p + 1; i < size; ++i) x[i] -= lower[p * size + i] * z_p;
  }
  // D L^T y = z, by columns of L; each sum takes the newest y last, so that the rest of it
  // does not wait for that one.
#pragma GCC unroll 16
  for (int i = size - 1; i >= 0; --i) {
    double sum = 0.0;
#pragma GCC unroll 16
    for (int k = size - 1; k > i; --k) sum += lower[i * size + k] * x[k];
    x[i] = x[i] * inverse_diagonal[i] - sum;
  }
}

using SaddlePointLdltFactor = bool (*)(int, int, const double*, double*, double*);
using SaddlePointLdltSolve = void (*)(int, const double*, const double*, double*);

template <std::size_t... N>
constexpr std::array<SaddlePointLdltFactor, sizeof...(N)> ldlt_factors(std::index_sequence<N...>) {
  return {&ldlt_factor<static_cast<int>(N)>...};
}
template <std::size_t... N>
constexpr std::array<SaddlePointLdltSolve, sizeof...(N)> ldlt_solves(std::index_sequence<N...>) {
  return {&ldlt_solve<static_cast<int>(N)>...};
}

// Entry N: the kernels for N unknowns (entry 0 takes the size at run time).
inline constexpr int max_unrolled_ldlt_size = 12;
inline constexpr auto unrolled_ldlt_factors =
    ldlt_factors(std::make_index_sequence<max_unrolled_ldlt_size + 1>{});
inline constexpr auto unrolled_ldlt_solves =
    ldlt_solves(std::make_index_sequence<max_unrolled_ldlt_size + 1>{});

}  // namespace detail

class SaddlePointLdlt {
 public:
  static constexpr int max_unrolled_size = detail::max_unrolled_ldlt_size;

  /// Sizes the factors for n + m unknowns. Allocates; compute and solve then do not.
  void resize(Eigen::Index n, Eigen::Index m) {
    n_ = static_cast<int>(n);
    size_ = static_cast<int>(n + m);
    lower_ = Eigen::MatrixXd::Zero(size_, size_);
    inverse_diagonal_ = Eigen::VectorXd::Zero(size_);
    factor_ = &detail::ldlt_factor<0>;
    solve_ = &detail::ldlt_solve<0>;
    if (size_ <= max_unrolled_size) {
      factor_ = detail::unrolled_ldlt_factors[static_cast<std::size_t>(size_)];
      solve_ = detail::unrolled_ldlt_solves[static_cast<std::size_t>(size_)];
    }
  }

  /// Factorizes K (of the size given to resize), of which the lower triangle is read. False
  /// if a pivot has the wrong sign or is not finite.
  bool compute(const Eigen::MatrixXd& k) {
    assert(k.rows() == size_ && k.cols() == size_);
    return factor_(size_, n_, k.data(), lower_.data(), inverse_diagonal_.data());
  }

  /// x <- K^-1 x.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) const {
    assert(x.size() == size_);
    solve_(size_, lower_.data(), inverse_diagonal_.data(), x.data());
  }

  /// The i-th pivot (i < m) of the Schur complement S = B A^-1 B^T in its own L D L^T: minus
  /// constraint row i's pivot in the last factorization. A small one (relative to
  /// schur_diagonal) says that B's rows nearly depend on each other.
  double schur_pivot(int i) const { return -lower_(n_ + i, n_ + i); }

  /// S(i, i), from the factors: the i-th pivot of S plus what the rows before it took from it,
  /// sum over k < i of L(i, k)^2 D(k). O(i).
  double schur_diagonal(int i) const {
    const int row = n_ + i;
    double diagonal = lower_(row, row);
    for (int k = n_; k < row; ++k) diagonal += lower_(row, k) * lower_(row, k) * lower_(k, k);
    return -diagonal;
  }

 private:
  using Factor = detail::SaddlePointLdltFactor;
  using Solve = detail::SaddlePointLdltSolve;

  int n_ = 0, size_ = 0;
  Factor factor_ = &detail::ldlt_factor<0>;
  Solve solve_ = &detail::ldlt_solve<0>;
  Eigen::MatrixXd lower_;             // L below the diagonal, D on it
  Eigen::VectorXd inverse_diagonal_;  // 1 / D(i, i)
};

}  // namespace odyn
