#pragma once
// The whole saddle-point matrix of a model,
//   [A  B^T]      A = mass_factor M + stiffness_factor K + damping_factor C,  B = Phi_q,
//   [B  0  ],
// kept sparse and factorized by a sparse LU (KLU with SuiteSparse; linalg/sparse_lu.hpp). For
// models whose force elements couple moving bodies in A (springs, dampers, bushings between
// bodies), where the Schur complement B A^-1 B^T would need A^-1 whole. The pattern is the
// model's: one nv x nv block per body and per pair of bodies that a force element's Newton
// blocks join, one block of B per constraint element and moving body, and its transpose. It is
// declared once (analyze); each factorization writes the blocks in place and gathers them into
// the compressed columns that KLU reads, so that a step builds no triplets and allocates
// nothing. The LU keeps its pivot order from one factorization to the next while it stays
// good (linalg/sparse_lu.hpp).
//
// A singular matrix from redundant constraints stays sparse: the rows of B that repeat earlier
// ones (sparse elimination in topological order, as the sparse assembly decides them) are pinned,
// their rows and columns cleared but for a unit diagonal (declared in the pattern, zero otherwise),
// so that their multipliers do not move and the other rows carry the constraint forces. That is one
// valid choice of multipliers, not the minimum-norm one of the dense solvers
// (analysis/saddle_point.hpp). A matrix singular for another reason (a dead point) falls back
// to a dense complete orthogonal decomposition, O((n + m)^3).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "odyn/analysis/sparse_assembly.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/linalg/block_sparse.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/sparse_lu.hpp"

namespace odyn {

/// Above this, relative to the size of its terms, a pinned row's equation left unsolved by a
/// solve says that the row no longer repeats others (see check_pinned_rows): at a Newton
/// iterate a repeated row holds to about the distance from the constraint manifold.
inline constexpr double pinned_consistency = 1e-6;

/// Multipliers of M, K = -dQ/dq and C = -dQ/dv in the top-left block, and whether the
/// stiffness term also holds the constraints' geometric stiffness G = d(Phi_q^T lambda)/dq
/// (see add_geometric_stiffness).
struct IterationFactors {
  double mass = 1.0;
  double stiffness = 0.0;
  double damping = 0.0;
  bool geometric = false;
};

template <class Model>
class SparseKktSaddlePoint {
 public:
  static constexpr int nv = Model::nv;

  void analyze(const Model& model) {
    n_ = model.num_velocities();
    m_ = model.num_equations();
    matrix_.reset(n_ + m_);
    for (int b = 0; b < model.num_bodies(); ++b) matrix_.declare(b * nv, b * nv, nv, nv);
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
      if constexpr (HasForceJacobians<E>) {
        for (const E& element : pool)
          for (const BodyId bi : element.bodies())
            for (const BodyId bj : element.bodies())
              if (!bi.is_ground() && !bj.is_ground())
                matrix_.declare(Model::velocity_offset(bi), Model::velocity_offset(bj), nv, nv);
      }
      if constexpr (Constraint<E>) {
        for (std::size_t i = 0; i < pool.size(); ++i)
          for (const BodyId body : pool[i].bodies()) {
            if (body.is_ground()) continue;
            const int row = n_ + model.template rows<E>()[i];
            const int column = Model::velocity_offset(body);
            matrix_.declare(row, column, E::num_equations, nv);
            matrix_.declare(column, row, nv, E::num_equations);
          }
      }
    });
    // The multipliers' diagonal, zero but where a redundant row is pinned (AMD, which orders
    // the pattern, ignores diagonal entries).
    for (int row = n_; row < n_ + m_; ++row) matrix_.declare(row, row, 1, 1);
    matrix_.finalize(BlockSparseMatrix::Triangle::full);
    lu_.analyze(n_ + m_, matrix_.column_starts(), matrix_.row_indices());
    rank_deficiency_ = 0;
    minimum_norm_ = false;
    pinned_rows_.clear();
    kept_pinned_rows_.clear();
    pins_doubted_ = false;
    rows_independent_ = false;
    pinned_products_.assign(static_cast<std::size_t>(n_ + m_), 0.0);
    pinned_sizes_.assign(static_cast<std::size_t>(n_ + m_), 0.0);
    row_order_ = {};
  }

  /// Factorizes by sparse LU; if the matrix is singular (redundant constraints), by a dense
  /// complete orthogonal decomposition. False only if the matrix holds non-finite values.
  bool factorize(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    matrix_.set_zero();
    add_iteration_blocks(model, ws, matrix_, f.mass, f.stiffness, f.damping, f.geometric);
    write_jacobian(model, ws, matrix_, n_, 0, true);
    const std::vector<double>& values = matrix_.gather();
    rank_deficiency_ = 0;
    minimum_norm_ = false;
    // Rows pinned last time are kept while the rest factorizes regularly and the solves find
    // them consistent, as BlockSchurSaddlePoint::factorize_sparse_schur keeps them.
    const bool pinned_before = !pinned_rows_.empty();
    const bool doubted = pins_doubted_;
    if (pinned_before && !doubted && factorize_pinned(values)) return true;
    bool decided = false;  // a rank pass ran in this call
    const auto decide = [&] {
      decided = true;
      if (pin_dependent_rows(model, ws, values)) return true;
      rows_independent_ = pinned_rows_.empty();
      return false;
    };
    if (pinned_before &&
        (decide() || (doubted && restore_pinned_rows() && factorize_pinned(values))))
      return true;
    pinned_rows_.clear();
    if (lu_.factorize(values, singular_ratio())) return true;
    for (const double x : values)
      if (!std::isfinite(x)) return false;
    if (!decided && decide()) return true;
    pinned_rows_.clear();
    // No row repeats others, by the rank pass: only rounding counts as singular now (a long
    // chain of slender links is well posed with pivots that shrink as N^-3).
    if (rows_independent_ && lu_.factorize(values, singular_ratio())) return true;
    rows_independent_ = false;
    if (n_ + m_ > dense_fallback_limit) return false;  // O(n^2) memory: refused, not attempted
    minimum_norm_ = true;
    dense_.compute(matrix_.to_dense(), rank_tolerance);
    rank_deficiency_ = static_cast<int>(n_ + m_ - dense_.rank());
    return true;
  }

  /// rhs = [f; g] -> solution = [x; y] (minimum-norm y after a singular factorization that
  /// could not pin its redundant rows).
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
    if (minimum_norm_) {
      dense_.solve(rhs, solution, work_);
      return;
    }
    solution = rhs;
    for (const int row : pinned_rows_) solution[n_ + row] = 0.0;  // their multipliers stay
    lu_.solve_in_place(solution);
    if (!pinned_rows_.empty()) check_pinned_rows(rhs, solution);
  }

  int rank_deficiency() const { return rank_deficiency_; }
  /// True if the last factorization pinned redundant rows (no minimum-norm projection then).
  bool multipliers_pinned() const { return !pinned_rows_.empty(); }
  /// How many times a rank pass decided which rows to pin.
  long pin_decisions() const { return pin_decisions_; }
  /// Factorizations that chose their pivots afresh.
  long pivoting_factorizations() const { return lu_.pivoting_factorizations(); }

 private:
  /// Beyond this size a singular matrix is not copied to a dense one (20000: 3.2 GB).
  static constexpr int dense_fallback_limit = 20000;

  /// The singular pivots' ratio for the plain factorization: rounding only once a rank pass
  /// has found the rows independent.
  double singular_ratio() const {
    return rows_independent_ ? SparseLu::independent_rows_ratio : SparseLu::singular_ratio;
  }

  /// Pins the rows of B that repeat earlier ones (see the top of this file) and factorizes
  /// again. False if none repeats others or the matrix is still singular.
  bool pin_dependent_rows(const Model& model, const Workspace<Model>& ws,
                          const std::vector<double>& values) {
    if (row_order_.elements.empty()) row_order_ = detail::row_order(model);  // once a model
    const std::vector<char> independent =
        detail::independent_rows(row_order_, detail::sparse_jacobian(model, ws), rank_tolerance);
    kept_pinned_rows_.swap(pinned_rows_);
    pinned_rows_.clear();
    for (int row = 0; row < m_; ++row)
      if (!independent[row]) pinned_rows_.push_back(row);
    pins_doubted_ = false;
    ++pin_decisions_;
    return !pinned_rows_.empty() && factorize_pinned(values);
  }

  /// Back to the rows pinned before the last decision.
  bool restore_pinned_rows() {
    if (kept_pinned_rows_.empty()) return false;
    pinned_rows_.swap(kept_pinned_rows_);
    kept_pinned_rows_.clear();
    return true;
  }

  /// Whether the pinned rows still repeat the others: their equations, which the solve left
  /// out, must hold with the solution it found (see BlockSchurSaddlePoint::check_pinned_rows).
  void check_pinned_rows(const Eigen::VectorXd& rhs, const Eigen::VectorXd& solution) {
    const std::vector<double>& values = matrix_.values();
    const std::vector<int>& starts = matrix_.column_starts();
    const std::vector<int>& rows = matrix_.row_indices();
    for (const int row : pinned_rows_) pinned_products_[n_ + row] = pinned_sizes_[n_ + row] = 0.0;
    for (int column = 0; column < n_ + m_; ++column)
      for (int k = starts[column]; k < starts[column + 1]; ++k)
        if (pinned_mark_[rows[k]]) {
          pinned_products_[rows[k]] += values[k] * solution[column];
          pinned_sizes_[rows[k]] += std::abs(values[k] * solution[column]);
        }
    double mismatch = 0.0, scale = rhs.tail(m_).cwiseAbs().maxCoeff();
    for (const int row : pinned_rows_) {
      mismatch = std::max(mismatch, std::abs(pinned_products_[n_ + row] - rhs[n_ + row]));
      scale = std::max({scale, pinned_sizes_[n_ + row], std::abs(rhs[n_ + row])});
    }
    if (mismatch > pinned_consistency * scale) pins_doubted_ = true;
  }

  /// Factorizes the matrix with the rows pinned_rows_ pinned. False if it is still singular.
  bool factorize_pinned(const std::vector<double>& values) {
    std::vector<char>& pinned = pinned_mark_;
    pinned.assign(static_cast<std::size_t>(n_ + m_), 0);
    for (const int row : pinned_rows_) pinned[n_ + row] = 1;
    pinned_values_ = values;
    const std::vector<int>& starts = matrix_.column_starts();
    const std::vector<int>& rows = matrix_.row_indices();
    for (int column = 0; column < n_ + m_; ++column)
      for (int k = starts[column]; k < starts[column + 1]; ++k)
        if (pinned[rows[k]] || pinned[column]) pinned_values_[k] = rows[k] == column ? 1.0 : 0.0;
    // Its rows were decided by a rank pass: only rounding counts as singular.
    if (!lu_.factorize(pinned_values_, SparseLu::independent_rows_ratio)) return false;
    rank_deficiency_ = static_cast<int>(pinned_rows_.size());
    return true;
  }

  int n_ = 0, m_ = 0;
  int rank_deficiency_ = 0;
  bool minimum_norm_ = false;
  BlockSparseMatrix matrix_;  // (n + m) x (n + m)
  SparseLu lu_;
  RankRevealingQr dense_;  // only after a singular factorization that pinning did not cure
  Eigen::VectorXd work_;
  std::vector<int> pinned_rows_;       // rows of B that repeat others (after a singular LU)
  std::vector<double> pinned_values_;  // the matrix's values with them cleared
  std::vector<char> pinned_mark_;      // 1 on the pinned rows
  std::vector<int> kept_pinned_rows_;  // those pinned before the last decision
  bool pins_doubted_ = false;          // a solve found a pinned row inconsistent
  std::vector<double> pinned_products_, pinned_sizes_;  // (scratch) their rows times a solution
  long pin_decisions_ = 0;                              // rank passes that decided them
  bool rows_independent_ = false;  // the last rank pass found no row repeating others
  detail::RowOrder row_order_;     // how to find them (built on the first need)
};

}  // namespace odyn
