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
// factorizing A and the Schur complement apart, with their m extra solves.

#include <Eigen/Core>
#include <cmath>

namespace odyn {

class SaddlePointLdlt {
 public:
  /// Sizes the factors for n + m unknowns. Allocates; compute and solve then do not.
  void resize(Eigen::Index n, Eigen::Index m) {
    n_ = n;
    lower_ = Eigen::MatrixXd::Zero(n + m, n + m);
    inverse_diagonal_ = Eigen::VectorXd::Zero(n + m);
  }

  /// Factorizes K, of which the lower triangle is read. False if a pivot has the wrong sign
  /// or is not finite.
  bool compute(const Eigen::MatrixXd& k) {
    const Eigen::Index size = k.rows();
    lower_.triangularView<Eigen::Lower>() = k.triangularView<Eigen::Lower>();
    for (Eigen::Index p = 0; p < size; ++p) {
      double* __restrict column_p = &lower_(0, p);
      const double pivot = column_p[p];
      if (!std::isfinite(pivot) || !(p < n_ ? pivot > 0.0 : pivot < 0.0)) return false;
      const double inverse = 1.0 / pivot;
      inverse_diagonal_[p] = inverse;
      for (Eigen::Index j = p + 1; j < size; ++j) {
        double* __restrict column_j = &lower_(0, j);
        const double l_jp = column_p[j] * inverse;
        for (Eigen::Index i = j; i < size; ++i) column_j[i] -= l_jp * column_p[i];
      }
      for (Eigen::Index i = p + 1; i < size; ++i) column_p[i] *= inverse;
    }
    return true;
  }

  /// x <- K^-1 x.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) const {
    const Eigen::Index size = x.size();
    double* __restrict z = x.data();
    for (Eigen::Index p = 0; p < size; ++p) {  // L z = x, by columns
      const double* __restrict column_p = &lower_(0, p);
      for (Eigen::Index i = p + 1; i < size; ++i) z[i] -= column_p[i] * z[p];
    }
    for (Eigen::Index i = size - 1; i >= 0; --i) {  // D L^T y = z, by columns of L
      const double* __restrict column_i = &lower_(0, i);
      double sum = z[i] * inverse_diagonal_[i];
      for (Eigen::Index k = i + 1; k < size; ++k) sum -= column_i[k] * z[k];
      z[i] = sum;
    }
  }

 private:
  Eigen::Index n_ = 0;
  Eigen::MatrixXd lower_;             // L below the diagonal, D on it
  Eigen::VectorXd inverse_diagonal_;  // 1 / D(i, i)
};

}  // namespace odyn
