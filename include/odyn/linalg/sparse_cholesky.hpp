#pragma once
// Sparse Cholesky factorization of a symmetric positive definite matrix given by the lower
// triangle of its compressed-column (CSC) structure, in Eigen's analyze / factorize / solve
// shape: the fill-reducing ordering and the symbolic factor are computed once per pattern
// (analyze), the numeric factor again whenever the values change (factorize), and solves
// reuse it. With SuiteSparse (ODYN_WITH_SUITESPARSE, target odyn::suitesparse) this is
// CHOLMOD, which orders by AMD (or METIS/nested dissection when it was built with it) and
// picks a simplicial or supernodal factorization by itself; without it, Eigen's simplicial
// L D L^T with AMD ordering, which is slower on large matrices but needs no library.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#ifdef ODYN_WITH_SUITESPARSE
#include <cholmod.h>

#include <utility>

#include "odyn/linalg/compressed_columns.hpp"
#else
#include <Eigen/SparseCholesky>
#endif

namespace odyn {

class SparseCholesky {
 public:
  SparseCholesky() = default;
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;
  SparseCholesky(SparseCholesky&&) noexcept = default;
  SparseCholesky& operator=(SparseCholesky&&) noexcept = default;

  /// Learns the pattern: n x n, the lower triangle in CSC arrays (which must outlive this
  /// object's use, and keep their values' positions). Allocates.
  void analyze(int n, const std::vector<int>& column_starts, const std::vector<int>& row_indices) {
    impl_ = std::make_unique<Impl>();
    impl_->analyze(n, column_starts, row_indices);
  }

  /// Factorizes the matrix with these values (in the analyzed pattern's order). False if the
  /// matrix is not positive definite to working precision, or holds non-finite values.
  bool factorize(const std::vector<double>& values) { return impl_->factorize(values); }

  /// An estimate of the reciprocal condition number from the factor's diagonal:
  /// (min L_ii / max L_ii)^2. Small values flag a nearly singular matrix.
  double reciprocal_condition() const { return impl_->reciprocal_condition(); }

  /// The smallest pivot relative to its own diagonal entry of A, min_j D_jj / A_jj (D_jj =
  /// L_jj^2 for an L L^T factor): the part of a row that elimination leaves. It is near
  /// rounding for a row that depends on the others, and it does not shrink with the spread of
  /// the rows' scales as the condition number does (a long chain of slender links is well
  /// posed with a condition number of 1e10 or more).
  double smallest_pivot_ratio() const { return impl_->smallest_pivot_ratio(); }

  /// x <- A^-1 x.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) { impl_->solve_in_place(x); }

  /// Whether the factor is supernodal (CHOLMOD's choice for matrices with much fill) rather
  /// than simplicial.
  bool supernodal() const { return impl_->supernodal(); }

 private:
#ifdef ODYN_WITH_SUITESPARSE
  // CHOLMOD copies and transposes a matrix that it must permute, at every factorization (two
  // allocations of the matrix's size). So the ordering that CHOLMOD's analysis chooses is
  // applied here, once, to the pattern: the permuted triangle that its factorization reads
  // without copying (the lower one for a supernodal L L^T, the upper one for a simplicial
  // L D L^T) is built by analyze, with a map from the caller's values, and CHOLMOD then
  // factorizes it in its natural order. Factorizations and solves then allocate nothing.
  struct Impl {
    cholmod_common common{};
    cholmod_sparse matrix{};  // the permuted triangle
    cholmod_factor* factor = nullptr;
    cholmod_dense *solution = nullptr, *work_y = nullptr, *work_e = nullptr;
    std::vector<int> permutation;   // (n) new position k holds old index permutation[k]
    std::vector<int> starts, rows;  // the permuted triangle's CSC structure
    std::vector<int> source;        // (entries) which caller value each entry takes
    std::vector<double> values;     // (entries)
    std::vector<int> diagonal;      // (n) where each column's diagonal entry is in values
    Eigen::VectorXd right_side;     // (n) permuted
    bool factorized = false;

    Impl() {
      cholmod_start(&common);
      common.print = 0;  // failures are reported by the return values, not on stdout
      common.quick_return_if_not_posdef = 1;
    }
    ~Impl() {
      cholmod_free_dense(&solution, &common);
      cholmod_free_dense(&work_y, &common);
      cholmod_free_dense(&work_e, &common);
      cholmod_free_factor(&factor, &common);
      cholmod_finish(&common);
    }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    static cholmod_sparse pattern(int n, const std::vector<int>& starts,
                                  const std::vector<int>& rows, int stype) {
      cholmod_sparse a{};
      a.nrow = a.ncol = static_cast<std::size_t>(n);
      a.nzmax = rows.size();
      a.p = const_cast<int*>(starts.data());
      a.i = const_cast<int*>(rows.data());
      a.stype = stype;
      a.itype = CHOLMOD_INT;
      a.xtype = CHOLMOD_PATTERN;
      a.dtype = CHOLMOD_DOUBLE;
      a.sorted = 1;
      a.packed = 1;
      return a;
    }

    void analyze(int n, const std::vector<int>& lower_starts, const std::vector<int>& lower_rows) {
      // CHOLMOD's choice of ordering and of method, on the caller's lower triangle.
      cholmod_sparse original = pattern(n, lower_starts, lower_rows, -1);
      cholmod_factor* probe = cholmod_analyze(&original, &common);
      if (probe == nullptr) return;
      const bool supernodal = probe->is_super != 0;
      const int* perm = static_cast<const int*>(probe->Perm);
      permutation.assign(perm, perm + n);
      cholmod_free_factor(&probe, &common);
      std::vector<int> position(static_cast<std::size_t>(n));
      for (int k = 0; k < n; ++k) position[permutation[k]] = k;
      // The permuted entries, in the triangle the factorization reads.
      std::vector<SparseEntry> entries;
      entries.reserve(lower_rows.size());
      for (int j = 0; j < n; ++j)
        for (int k = lower_starts[j]; k < lower_starts[j + 1]; ++k) {
          const int a = position[lower_rows[k]], b = position[j];
          const int low = std::min(a, b), high = std::max(a, b);
          entries.push_back(supernodal ? SparseEntry{low, high, k} : SparseEntry{high, low, k});
        }
      CompressedColumns csc = compress_columns(std::move(entries), n);
      starts = std::move(csc.starts);
      rows = std::move(csc.rows);
      source = std::move(csc.sources);
      diagonal.assign(static_cast<std::size_t>(n), -1);
      for (int j = 0; j < n; ++j)
        for (int k = starts[j]; k < starts[j + 1]; ++k)
          if (rows[k] == j) diagonal[j] = k;
      values.assign(rows.size(), 0.0);
      matrix = pattern(n, starts, rows, supernodal ? -1 : 1);
      common.nmethods = 1;
      common.method[0].ordering = CHOLMOD_NATURAL;
      common.postorder = 0;  // the order is final
      common.supernodal = supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
      factor = cholmod_analyze(&matrix, &common);
      right_side = Eigen::VectorXd::Zero(n);
    }

    bool factorize(const std::vector<double>& caller_values) {
      for (std::size_t k = 0; k < values.size(); ++k) values[k] = caller_values[source[k]];
      matrix.x = values.data();
      matrix.xtype = CHOLMOD_REAL;
      factorized = factor != nullptr && cholmod_factorize(&matrix, factor, &common) != 0 &&
                   common.status == CHOLMOD_OK && factor->minor == factor->n;
      // A simplicial L D L^T goes through negative pivots: positive definiteness is checked on
      // D here. (A supernodal L L^T stops at the first non-positive pivot by itself.)
      if (factorized && !factor->is_super && !factor->is_ll)
        for_each_pivot([&](int, double pivot) { factorized = factorized && pivot > 0.0; });
      if (factorized) factorized = std::isfinite(reciprocal_condition());
      return factorized;
    }

    double reciprocal_condition() const {
      return cholmod_rcond(factor, const_cast<cholmod_common*>(&common));
    }

    /// D_jj of column j of the factor (L_jj^2 for L L^T), in the permuted order.
    template <class F>
    void for_each_pivot(F&& f) const {
      const auto* x = static_cast<const double*>(factor->x);
      if (factor->is_super) {
        const auto* super = static_cast<const int*>(factor->super);
        const auto* pi = static_cast<const int*>(factor->pi);
        const auto* px = static_cast<const int*>(factor->px);
        for (std::size_t s = 0; s < factor->nsuper; ++s) {
          const int rows_of_block = pi[s + 1] - pi[s];
          for (int j = super[s]; j < super[s + 1]; ++j) {
            const int c = j - super[s];
            const double l = x[px[s] + c * rows_of_block + c];
            f(j, l * l);
          }
        }
        return;
      }
      const auto* p = static_cast<const int*>(factor->p);
      for (int j = 0; j < static_cast<int>(factor->n); ++j)
        f(j, factor->is_ll ? x[p[j]] * x[p[j]] : x[p[j]]);
    }

    double smallest_pivot_ratio() const {
      double smallest = std::numeric_limits<double>::infinity();
      for_each_pivot([&](int j, double pivot) {
        const double a = diagonal[j] >= 0 ? values[diagonal[j]] : 0.0;
        smallest = std::min(smallest, a > 0.0 ? pivot / a : 0.0);
      });
      return smallest;
    }

    void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) {
      const Eigen::Index n = x.size();
      for (Eigen::Index k = 0; k < n; ++k) right_side[k] = x[permutation[k]];
      if (!factor->is_super && !factor->is_ll) {
        solve_simplicial();
        for (Eigen::Index k = 0; k < n; ++k) x[permutation[k]] = right_side[k];
        return;
      }
      cholmod_dense b{};
      b.nrow = b.d = b.nzmax = static_cast<std::size_t>(n);
      b.ncol = 1;
      b.x = right_side.data();
      b.xtype = CHOLMOD_REAL;
      b.dtype = CHOLMOD_DOUBLE;
      // solve2 keeps its result and workspaces from call to call: no allocation after the first.
      cholmod_solve2(CHOLMOD_A, factor, &b, nullptr, &solution, nullptr, &work_y, &work_e, &common);
      const auto* solved = static_cast<const double*>(solution->x);
      for (Eigen::Index k = 0; k < n; ++k) x[permutation[k]] = solved[k];
    }

    /// right_side <- (L D L^T)^-1 right_side with the simplicial factor: column j of L holds
    /// D_jj first, then L_ij below the (unit) diagonal. (cholmod_solve2 reallocates its
    /// workspaces at every call in this case.)
    void solve_simplicial() {
      const auto* column_starts = static_cast<const int*>(factor->p);
      const auto* counts = static_cast<const int*>(factor->nz);
      const auto* row = static_cast<const int*>(factor->i);
      const auto* entry = static_cast<const double*>(factor->x);
      const auto n = static_cast<int>(factor->n);
      double* y = right_side.data();
      for (int j = 0; j < n; ++j) {
        const double yj = y[j];
        for (int k = column_starts[j] + 1; k < column_starts[j] + counts[j]; ++k)
          y[row[k]] -= entry[k] * yj;
      }
      for (int j = 0; j < n; ++j) y[j] /= entry[column_starts[j]];
      for (int j = n - 1; j >= 0; --j) {
        double yj = y[j];
        for (int k = column_starts[j] + 1; k < column_starts[j] + counts[j]; ++k)
          yj -= entry[k] * y[row[k]];
        y[j] = yj;
      }
    }

    bool supernodal() const { return factor != nullptr && factor->is_super; }
  };
#else
  struct Impl {
    using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
    Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
    int n = 0;
    const std::vector<int>* starts = nullptr;
    const std::vector<int>* rows = nullptr;
    const std::vector<double>* values = nullptr;  // of the last factorize

    Eigen::Map<const Matrix> map(const double* x) const {
      return Eigen::Map<const Matrix>(n, n, static_cast<int>(rows->size()), starts->data(),
                                      rows->data(), x);
    }

    void analyze(int size, const std::vector<int>& column_starts,
                 const std::vector<int>& row_indices) {
      n = size;
      starts = &column_starts;
      rows = &row_indices;
      const std::vector<double> ones(row_indices.size(), 1.0);
      ldlt.analyzePattern(map(ones.data()));
    }

    bool factorize(const std::vector<double>& new_values) {
      values = &new_values;
      ldlt.factorize(map(new_values.data()));
      if (ldlt.info() != Eigen::Success) return false;
      const auto d = ldlt.vectorD();
      return n == 0 || (d.minCoeff() > 0.0 && std::isfinite(d.sum()));
    }

    double reciprocal_condition() const {
      const auto d = ldlt.vectorD();
      return n == 0 ? 1.0 : d.minCoeff() / d.maxCoeff();
    }

    double smallest_pivot_ratio() const {
      // Eigen's D is in its own permuted order: compare with the permuted diagonal of A.
      const auto d = ldlt.vectorD();
      const auto& order = ldlt.permutationP().indices();
      double smallest = std::numeric_limits<double>::infinity();
      for (int j = 0; j < n; ++j) {
        double a = 0.0;
        for (int k = (*starts)[j]; k < (*starts)[j + 1]; ++k)
          if ((*rows)[k] == j) a = (*values)[k];
        smallest = std::min(smallest, a > 0.0 ? d[order[j]] / a : 0.0);
      }
      return smallest;
    }

    void solve_in_place(Eigen::Ref<Eigen::VectorXd> x) { x = ldlt.solve(Eigen::VectorXd(x)); }

    bool supernodal() const { return false; }
  };
#endif
  std::unique_ptr<Impl> impl_;
};

}  // namespace odyn
