#pragma once
// Sparse LU factorization of a square unsymmetric matrix in compressed-column (CSC) form, in
// Eigen's analyze / factorize / solve shape. With SuiteSparse (ODYN_WITH_SUITESPARSE) this is
// KLU, made for the matrices of circuit and multibody simulation: a block triangular form and
// an AMD ordering found once (analyze); the first factorization chooses its pivots, later
// ones reuse them (klu_refactor, several times faster) and choose afresh only when the reused
// pivots have degraded, that is when the estimate min |U_ii| / max |U_ii| falls a thousand
// times below the one of the last pivoting factorization. Without SuiteSparse, Eigen's
// SparseLU (supernodal, COLAMD ordering) stands in.

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <vector>

#ifdef ODYN_WITH_SUITESPARSE
#include <klu.h>
#else
#include <Eigen/OrderingMethods>
#include <Eigen/SparseLU>
#endif

namespace odyn {

class SparseLu {
 public:
  SparseLu() = default;
  SparseLu(const SparseLu&) = delete;
  SparseLu& operator=(const SparseLu&) = delete;
  SparseLu(SparseLu&&) noexcept = default;
  SparseLu& operator=(SparseLu&&) noexcept = default;

  /// Learns the pattern of an n x n matrix from its CSC arrays (which must outlive this
  /// object's use). Allocates.
  void analyze(int n, const std::vector<int>& column_starts, const std::vector<int>& row_indices) {
    impl_ = std::make_unique<Impl>();
    impl_->analyze(n, column_starts, row_indices);
  }

  /// Below this, min |U_ii| / max |U_ii| counts as singular.
  static constexpr double singular_ratio = 1e-14;
  /// The same for a matrix whose constraint rows a rank pass has found independent: then only
  /// a pivot at the level of rounding counts. A long chain of slender hinged links is well
  /// posed with a ratio that falls as N^-3 (4e-14 at 4096 links, 7e-16 at 16384).
  static constexpr double independent_rows_ratio = 1e-20;

  /// Factorizes the matrix with these values. False if it is singular (its pivots' ratio at or
  /// below `singular`) or holds non-finite values.
  bool factorize(const std::vector<double>& values, double singular = singular_ratio) {
    return impl_->factorize(values, singular);
  }

  /// x <- A^-1 x.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) { impl_->solve_in_place(x); }

  /// x <- A^-T x, with the same factors (a kinematic analysis's multipliers).
  void solve_transposed_in_place(Eigen::Ref<Eigen::VectorXd> x) {
    impl_->solve_transposed_in_place(x);
  }

  /// Factorizations that chose their pivots afresh (the others reused them).
  long pivoting_factorizations() const { return impl_->pivoting; }

 private:
#ifdef ODYN_WITH_SUITESPARSE
  struct Impl {
    klu_common common{};
    klu_symbolic* symbolic = nullptr;
    klu_numeric* numeric = nullptr;
    int* starts = nullptr;
    int* rows = nullptr;
    int n = 0;
    double pivoting_rcond = 0.0;  // of the last factorization that chose its pivots
    long pivoting = 0;

    Impl() {
      klu_defaults(&common);
      common.halt_if_singular = 1;
      common.btf =
          0;  // saddle-point matrices of connected models are irreducible: BTF finds nothing
    }
    ~Impl() {
      if (numeric != nullptr) klu_free_numeric(&numeric, &common);
      if (symbolic != nullptr) klu_free_symbolic(&symbolic, &common);
    }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    void analyze(int size, const std::vector<int>& column_starts,
                 const std::vector<int>& row_indices) {
      n = size;
      starts = const_cast<int*>(column_starts.data());
      rows = const_cast<int*>(row_indices.data());
      symbolic = klu_analyze(n, starts, rows, &common);
    }

    double rcond() {
      if (klu_rcond(symbolic, numeric, &common) == 0) return 0.0;
      return std::isfinite(common.rcond) ? common.rcond : 0.0;
    }

    bool factorize(const std::vector<double>& values, double singular_ratio) {
      if (symbolic == nullptr) return false;
      double* x = const_cast<double*>(values.data());
      if (numeric != nullptr) {
        // Reuse the pivots while they stay good.
        if (klu_refactor(starts, rows, x, symbolic, numeric, &common) != 0) {
          const double estimate = rcond();
          if (estimate > singular_ratio && estimate >= 1e-3 * pivoting_rcond) return true;
        }
        klu_free_numeric(&numeric, &common);
      }
      ++pivoting;
      numeric = klu_factor(starts, rows, x, symbolic, &common);
      if (numeric == nullptr) return false;
      pivoting_rcond = rcond();
      if (pivoting_rcond > singular_ratio) return true;
      klu_free_numeric(&numeric, &common);
      return false;
    }

    void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) {
      klu_solve(symbolic, numeric, static_cast<int>(x.size()), 1, x.data(), &common);
    }

    void solve_transposed_in_place(Eigen::Ref<Eigen::VectorXd> x) {
      klu_tsolve(symbolic, numeric, static_cast<int>(x.size()), 1, x.data(), &common);
    }
  };
#else
  struct Impl {
    using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
    Eigen::SparseLU<Matrix, Eigen::COLAMDOrdering<int>> lu;
    int n = 0;
    const std::vector<int>* starts = nullptr;
    const std::vector<int>* rows = nullptr;
    long pivoting = 0;

    Eigen::Map<const Matrix> map(const double* values) const {
      return Eigen::Map<const Matrix>(n, n, static_cast<int>(rows->size()), starts->data(),
                                      rows->data(), values);
    }

    void analyze(int size, const std::vector<int>& column_starts,
                 const std::vector<int>& row_indices) {
      n = size;
      starts = &column_starts;
      rows = &row_indices;
      const std::vector<double> ones(row_indices.size(), 1.0);
      lu.analyzePattern(map(ones.data()));
    }

    bool factorize(const std::vector<double>& values, double /*singular_ratio*/) {
      ++pivoting;
      lu.factorize(map(values.data()));
      if (lu.info() != Eigen::Success) return false;
      // A zero pivot makes the determinant vanish, a non-finite value makes it non-finite.
      return std::isfinite(lu.logAbsDeterminant());
    }

    void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) { x = lu.solve(Eigen::VectorXd(x)); }

    void solve_transposed_in_place(Eigen::Ref<Eigen::VectorXd> x) {
      x = lu.transpose().solve(Eigen::VectorXd(x));
    }
  };
#endif
  std::unique_ptr<Impl> impl_;
};

}  // namespace odyn
