#pragma once
// Solvers for the saddle-point systems of the analyses,
//   [A  B^T] [x]   [f]
//   [B  0  ] [y] = [g],   A = mass_factor M + stiffness_factor K + damping_factor C,  B = Phi_q,
// behind one interface: analyze(model) once per model, factorize(model, ws, factors) per
// matrix values, solve(rhs, solution). The integrators hold a BlockSchurSaddlePoint, which
// chooses among four factorizations at analyze (choose(LinearSolver), see
// linalg/linear_solver.hpp; by size and pattern when automatic):
//  - the Schur complement, when A is block diagonal (no force element couples two moving
//    bodies in the Newton matrix), or when the blocks that couple them weigh little against
//    its diagonal blocks (large models; see max_dropped_coupling): A is inverted body by body
//    and only the m x m complement
//    S = B A^-1 B^T is factorized, dense by an envelope Cholesky (small models: several times
//    cheaper than a whole-matrix LU) or sparse by CHOLMOD (large ones: linear cost on chains
//    and trees). S is assembled from the elements' own Jacobian blocks in the workspace, one
//    fixed-size product per pair of blocks on a body (the pairs are listed once, by analyze,
//    under their two element types), so no loop in factorize or solve runs over a row count
//    known only at run time;
//  - the whole matrix, when A is not block diagonal: DenseSaddlePoint's dense LU for small
//    models, SparseKktSaddlePoint's KLU (analysis/sparse_kkt.hpp) for large ones.
//
// Redundant constraints. When B = Phi_q is rank-deficient (a mechanism whose joints repeat one
// another's equations, such as Bricard's linkage, or two coaxial hinges), the matrix is singular
// but the system is still solvable for a consistent right-hand side: x is unique, y is not (any
// vector of the null space of B^T may be added to it). Both solvers then return the
// minimum-norm y, the one orthogonal to that null space. For the multipliers this means that
// the joint reactions of an over-constrained mechanism are not unique: the physics fixes only
// B^T lambda, the sum of the constraint forces on each body, and odyn reports the least-squares
// distribution of it over the joints. Caveat: within a Newton iteration the solvers return
// minimum-norm *corrections*, which cannot see the null-space part of the multipliers the
// iteration started from. The multipliers are minimum-norm where they are solved outright (at
// assembly and at every restart of an integrator); between restarts, an integrator that
// extrapolates lambda from step to step carries a null-space part along, which grows as the
// null space turns with the pose, unless it projects lambda after each step (rank_deficiency()
// says when that is needed). B^T lambda, and so the motion, is unaffected.
// Large models (the sparse paths) keep their linear cost instead: the rows of B that repeat
// earlier ones are pinned (their multipliers stay at zero, as the sparse assembly leaves them)
// and the rest is factorized, still sparse; see pin_dependent_rows. Their reactions are then
// the other valid choice, all of a repeated joint's load on the joint that came first.
// An inconsistent right-hand side (constraints that cannot all hold, or a driver at a dead
// point) gets the least-squares y: the constraint residual then does not vanish and the
// caller's convergence test fails, so it never hides.
// The rank is decided by a column-pivoted QR of S (or of the dense matrix): a pivot counts if it
// exceeds rank_tolerance times the first. A full-rank system keeps the fast path:
// Cholesky of S (the block Schur solver) or LU (the dense one); the rank-revealing
// factorizations run only when that path finds a singular matrix.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>  // inverse() of the small fixed-size body blocks
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "odyn/analysis/sparse_assembly.hpp"
#include "odyn/analysis/sparse_kkt.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/linalg/block_sparse.hpp"
#include "odyn/linalg/dense_lu.hpp"
#include "odyn/linalg/linear_solver.hpp"
#include "odyn/linalg/pivoted_lu.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/small_cholesky.hpp"
#include "odyn/linalg/sparse_cholesky.hpp"

namespace odyn {

namespace detail {
/// Largest Schur complement of a pinned row, relative to the largest diagonal entry of
/// B A^-1 B^T, for which the row still counts as repeating the others (see
/// DenseSaddlePoint::factorize_pinned). A row that repeats others at every pose leaves rounding
/// there, or the distance of a Newton iterate from the constraints: 1e-22 to 1e-12 on
/// Bricard's linkage, nearly all below 1e-14. A row that repeats others only for an instant,
/// near a singular configuration, leaves 1e-12 to 1e-10 on the chain of parallelograms, and
/// goes to the rank-revealing path, whose least-squares solutions carry Newton through the
/// crossing (pinned there, it stalls at h = 1e-4).
inline constexpr double repeated_row_tolerance = 1e-13;

/// y - N (N^T N)^-1 N^T y: y without its part in the span of N's columns (work: scratch).
inline void remove_null_space_part(const Eigen::MatrixXd& null_basis,
                                   const Eigen::LLT<Eigen::MatrixXd>& gram, Eigen::VectorXd& work,
                                   Eigen::Ref<Eigen::VectorXd> y) {
  work.noalias() = null_basis.transpose() * y;
  gram.solveInPlace(work);
  y.noalias() -= null_basis * work;
}
}  // namespace detail

template <class Model>
class DenseSaddlePoint {
 public:
  /// This solver was chosen at compile time (an integrator's Solver parameter): the run-time
  /// setting does not apply to it.
  void choose(LinearSolver) {}

  void analyze(const Model& model) {
    n_ = model.num_velocities();
    const int size = n_ + model.num_equations();
    matrix_ = Eigen::MatrixXd::Zero(size, size);
    lu_.analyze_pattern(matrix_);
    rank_deficiency_ = 0;
    pinned_.clear();
    pinned_solve_ = false;
  }

  /// Factorizes by LU; if the matrix is singular (redundant constraints), by LU with the
  /// multipliers of the equations that repeat others pinned (see factorize_pinned), else by a
  /// complete orthogonal decomposition whose solve gives the minimum-norm solution. False only
  /// if the matrix holds non-finite values.
  bool factorize(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    matrix_.setZero();
    add_iteration_blocks(model, ws, matrix_, f.mass, f.stiffness, f.damping, f.geometric);
    write_jacobian(model, ws, matrix_, n_, 0, true);
    rank_deficiency_ = 0;
    // A redundant mechanism stays singular at every pose: its rows are tried pinned first.
    if (!pinned_.empty()) {
      if (factorize_pinned()) return true;
      pinned_.clear();
    }
    pinned_solve_ = false;
    if (lu_.factorize(matrix_)) return true;
    if (!matrix_.allFinite()) return false;
    rank_deficiency_ = lu_.factorize_rank_revealing(matrix_, rank_tolerance);
    // The columns the rank-revealing QR pivoted last repeat the others; they must be
    // multipliers' columns (the velocity ones are independent while A is regular on the null
    // space of B), else the decomposition stays.
    const std::vector<int>& order = lu_.rank_revealing_column_order();
    pinned_.clear();
    for (auto k = order.size() - static_cast<std::size_t>(rank_deficiency_); k < order.size(); ++k)
      pinned_.push_back(order[k] - n_);
    std::sort(pinned_.begin(), pinned_.end());
    if (pinned_.empty() || pinned_.front() < 0 || !factorize_pinned()) {
      pinned_.clear();
      lu_.factorize_rank_revealing(matrix_, rank_tolerance);  // factorize_pinned overwrote it
    }
    return true;
  }

  /// `minimum_norm` false: see solve_correction.
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution, bool minimum_norm = true) {
    if (!pinned_solve_) return lu_.solve(rhs, solution);
    work_ = rhs;
    for (const int row : pinned_) work_[n_ + row] = 0.0;
    lu_.solve(work_, solution);
    // The minimum-norm multipliers (see factorize_pinned); x is unchanged.
    if (minimum_norm)
      detail::remove_null_space_part(null_basis_, null_gram_, null_work_,
                                     solution.tail(work_.size() - n_));
  }

  /// The weight of the geometric stiffness in A is not measured here (see
  /// BlockSchurSaddlePoint::geometric_share): infinity, so an integrator that asked for it keeps
  /// it.
  double geometric_share() const { return std::numeric_limits<double>::infinity(); }

  /// Number of dependent rows of the last factorized matrix (0: full rank).
  int rank_deficiency() const { return rank_deficiency_; }

  /// True if the last factorization pinned redundant equations (see factorize_pinned).
  bool corrections_pinned() const { return pinned_solve_; }

  /// solve() for a Newton correction: after a factorization that pinned redundant equations,
  /// their multipliers' corrections stay zero (y_P = 0) instead of taking the minimum-norm y,
  /// so that an iteration never moves the multipliers along the null space of B^T, which turns
  /// with the pose (they would drift along it from step to step).
  void solve_correction(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
    solve(rhs, solution, false);
  }

 private:
  /// Redundant constraints at the cost of a regular matrix. With P the equations in pinned_
  /// and K the rest, the matrix with the multipliers y_P pinned (their rows and columns cleared
  /// but for the diagonal) is factorized by LU. The rows P repeat K if B_P = C B_K: then
  /// [x; y_K] = [0; C^T e_i] solves it for the right-hand side [B_P^T e_i; 0], and the Schur
  /// complement of the pinned block, -B_P x, vanishes. That is checked here (against
  /// detail::repeated_row_tolerance times an estimate of the largest diagonal entry of
  /// B A^-1 B^T, by A's diagonal), so that a
  /// row that stops repeating the others (a mechanism leaving a singular configuration) falls
  /// back to the regular factorization at once. The columns of N = [-C^T; I] span the null
  /// space of B^T, and a solve's y is made the minimum-norm one by removing its part in that
  /// space. False if the pinned rows do not all repeat the others or the rest is singular.
  bool factorize_pinned() {
    const auto m = matrix_.rows() - n_, k = static_cast<Eigen::Index>(pinned_.size());
    double largest_diagonal = 0.0, scale = 0.0;  // of A; of B A^-1 B^T (estimated)
    for (Eigen::Index c = 0; c < n_; ++c)
      largest_diagonal = std::max(largest_diagonal, std::abs(matrix_(c, c)));
    for (Eigen::Index row = 0; row < m; ++row) {
      double diagonal = 0.0;
      for (Eigen::Index c = 0; c < n_; ++c)
        if (matrix_(n_ + row, c) != 0.0)
          diagonal += matrix_(n_ + row, c) * matrix_(n_ + row, c) / std::abs(matrix_(c, c));
      scale = std::max(scale, diagonal);
    }
    pinned_matrix_ = matrix_;
    for (const int row : pinned_) {
      pinned_matrix_.row(n_ + row).setZero();
      pinned_matrix_.col(n_ + row).setZero();
      pinned_matrix_(n_ + row, n_ + row) = largest_diagonal;
    }
    if (!(scale > 0.0) || !std::isfinite(scale) || !lu_.factorize(pinned_matrix_)) return false;
    null_basis_.resize(m, k);
    for (Eigen::Index i = 0; i < k; ++i) {
      const int p = pinned_[i];
      work_.setZero(n_ + m);
      work_.head(n_) = matrix_.col(n_ + p).head(n_);  // B_p^T
      lu_.solve(work_, solution_);
      const double complement = matrix_.row(n_ + p).head(n_).dot(solution_.head(n_));
      if (!(std::abs(complement) <= detail::repeated_row_tolerance * scale)) return false;
      null_basis_.col(i) = -solution_.tail(m);
      null_basis_(p, i) = 1.0;
    }
    null_gram_matrix_.noalias() = null_basis_.transpose() * null_basis_;
    null_gram_.compute(null_gram_matrix_);
    null_work_.resize(k);
    rank_deficiency_ = static_cast<int>(k);
    pinned_solve_ = true;
    return true;
  }

  int n_ = 0;
  int rank_deficiency_ = 0;
  Eigen::MatrixXd matrix_;  // (n + m) x (n + m)
  DenseLu lu_;
  std::vector<int> pinned_;                // equations that repeat others (see factorize_pinned)
  bool pinned_solve_ = false;              // the last factorization pinned them
  Eigen::MatrixXd pinned_matrix_;          // matrix_ with their multipliers pinned
  Eigen::MatrixXd null_basis_;             // (m x k) N, a basis of the null space of B^T
  Eigen::MatrixXd null_gram_matrix_;       // N^T N
  Eigen::LLT<Eigen::MatrixXd> null_gram_;  // its factorization
  Eigen::VectorXd null_work_, work_, solution_;  // scratch
};

namespace detail {
/// Which moving bodies a force element's Newton blocks couple; true if two different ones.
template <class Model>
bool couples_bodies(const Model& model) {
  bool coupled = false;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (HasForceJacobians<E>) {
      for (const E& element : pool) {
        int moving = 0;
        for (const BodyId body : element.bodies()) moving += body.is_ground() ? 0 : 1;
        if (moving > 1 && element.bodies()[0] != element.bodies()[1]) coupled = true;
      }
    }
  });
  return coupled;
}

/// True if the symmetric 3 x 3 matrix a is positive definite (its leading minors).
inline bool positive_definite(const Eigen::Matrix3d& a) {
  return a(0, 0) > 0.0 && a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0) > 0.0 && a.determinant() > 0.0;
}

/// Inverse of a symmetric body block. Eigen inverts up to 4 x 4 in closed form; a 6 x 6 block
/// goes through its 3 x 3 blocks, several times faster than a 6 x 6 LU. With `positive`, also
/// says whether a is positive definite (for 6 x 6, whether both 3 x 3 pivots are).
template <int N>
Eigen::Matrix<double, N, N> invert_symmetric(const Eigen::Matrix<double, N, N>& a,
                                             bool* positive = nullptr) {
  if constexpr (N == 6) {
    const Eigen::Matrix3d p = a.template topLeftCorner<3, 3>();
    const Eigen::Matrix3d p_inverse = p.inverse();
    const Eigen::Matrix3d q = a.template topRightCorner<3, 3>();
    const Eigen::Matrix3d p_inverse_q = p_inverse * q;
    const Eigen::Matrix3d schur =
        a.template bottomRightCorner<3, 3>() - q.transpose() * p_inverse_q;
    if (positive) *positive = positive_definite(p) && positive_definite(schur);
    const Eigen::Matrix3d schur_inverse = schur.inverse();
    Eigen::Matrix<double, 6, 6> inverse;
    inverse.template topRightCorner<3, 3>() = -p_inverse_q * schur_inverse;
    inverse.template topLeftCorner<3, 3>() =
        p_inverse - inverse.template topRightCorner<3, 3>() * p_inverse_q.transpose();
    inverse.template bottomLeftCorner<3, 3>() = inverse.template topRightCorner<3, 3>().transpose();
    inverse.template bottomRightCorner<3, 3>() = schur_inverse;
    return inverse;
  } else {
    if (positive) {
      if constexpr (N == 3)
        *positive = positive_definite(a);
      else
        *positive = Eigen::LLT<Eigen::Matrix<double, N, N>>(a).info() == Eigen::Success;
    }
    return a.inverse();
  }
}

/// Lets add_iteration_blocks write into per-body diagonal blocks, and the blocks that join two
/// bodies (force elements between moving bodies) into a per-body sum, if `couplings` is given.
template <int nv>
struct BlockDiagonalView {
  std::vector<Eigen::Matrix<double, nv, nv>>* blocks;
  std::vector<Eigen::Matrix<double, nv, nv>>* couplings = nullptr;
  template <int R, int C>
  Eigen::Matrix<double, nv, nv>& block(Eigen::Index row, Eigen::Index column) {
    static_assert(R == nv && C == nv);
    return row == column || couplings == nullptr ? (*blocks)[row / nv] : (*couplings)[row / nv];
  }
};
}  // namespace detail

template <class Model>
class BlockSchurSaddlePoint {
 public:
  static constexpr int nv = Model::nv;
  using Block = Eigen::Matrix<double, nv, nv>;

  /// The factorization to use from the next analyze on (default: automatic).
  void choose(LinearSolver solver) { choice_ = solver; }

  /// Sizes below which `automatic` keeps the dense factorizations: constraint equations for the
  /// Schur complement, unknowns for the whole matrix. Chosen, not measured as crossovers: the
  /// engine-sized models keep the dense kernels they were tuned for, and on the scaling chains
  /// (bench/scaling.cpp) the sparse paths run in about linear time from some 40 bodies on.
  static constexpr int dense_schur_limit = 120;
  static constexpr int dense_kkt_limit = 60;

  /// Largest Newton contraction, estimated body by body as |A_sym^-1 A_skew|, that the Schur
  /// complement may cost by using the symmetric part of A. Beyond it (slender bodies spinning
  /// about their thin axis, whose gyroscopic terms outweigh their inertia at the step size)
  /// Newton would crawl or fail, and that factorization takes the whole matrix instead.
  static constexpr double max_dropped_skew = 0.25;

  /// Largest Newton contraction, estimated body by body as |A_b^-1 sum_j A_bj|, that the Schur
  /// complement of a large model may cost by leaving out the blocks by which force elements
  /// couple two bodies. Springs and dampers soft against mass over the step squared (the
  /// scaling report's rope: about 1e-3, mostly its dampers') keep the Schur path; stiffer ones
  /// take the whole matrix for that factorization.
  static constexpr double max_dropped_coupling = 0.01;

  void analyze(const Model& model) {
    coupled_ = detail::couples_bodies(model);
    path_ = choose_path(model);
    whole_ = Whole::none;
    whole_dense_analyzed_ = whole_sparse_analyzed_ = false;
    if (path_ == Path::dense_kkt) {
      dense_.analyze(model);
      return;
    }
    if (path_ == Path::sparse_kkt) {
      sparse_kkt_.analyze(model);
      return;
    }
    bodies_ = model.num_bodies();
    n_ = model.num_velocities();
    m_ = model.num_equations();
    blocks_.assign(bodies_, Block::Zero());
    if (coupled_) body_couplings_.assign(bodies_, Block::Zero());
    if (has_geometric_stiffness<Model>()) geometric_.assign(bodies_, Block::Zero());
    inverses_.assign(bodies_, Block::Zero());
    diagonal_inverse_.assign(bodies_, false);
    cached_mass_factor_ = std::numeric_limits<double>::quiet_NaN();
    // Every block of B (a constraint element's rows on one of its moving bodies), by type.
    std::vector<std::vector<std::pair<std::size_t, BlockRef>>> on_body(bodies_);
    std::vector<Eigen::Index> envelope_end(static_cast<std::size_t>(m_), 0);
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      block_refs_[type].clear();
      if constexpr (Constraint<E>) {
        std::get<type>(weighted_).resize(pool.size());
        for (std::size_t i = 0; i < pool.size(); ++i) {
          const int row = model.template rows<E>()[i];
          for (int r = row; r < row + E::num_equations; ++r)  // one element's block is full
            envelope_end[r] = std::max<Eigen::Index>(envelope_end[r], row + E::num_equations);
          for (int k = 0; k < E::num_bodies; ++k) {
            const BodyId body = pool[i].bodies()[k];
            if (body.is_ground()) continue;
            const BlockRef ref{static_cast<int>(i), k, body.index - 1, row, E::num_equations};
            block_refs_[type].push_back(ref);
            on_body[body.index - 1].emplace_back(type, ref);
          }
        }
      }
    });
    // Two blocks on one body couple their rows in S (which bounds the envelope of its
    // columns). Each pair is kept once, under the types of its lower and upper element, so
    // that factorize multiplies blocks of fixed sizes.
    for (auto& list : couplings_) list.clear();
    for (const auto& blocks : on_body)
      for (const auto& [lower_type, lower] : blocks)
        for (const auto& [upper_type, upper] : blocks) {
          if (lower.row <= upper.row) continue;
          couplings_[lower_type * Model::num_types + upper_type].push_back(Coupling{lower, upper});
          for (int column = upper.row; column < upper.row + upper.equations; ++column)
            envelope_end[column] =
                std::max<Eigen::Index>(envelope_end[column], lower.row + lower.equations);
        }
    if (path_ == Path::sparse_schur) {
      // The blocks of S: one per constraint element on the diagonal, one per coupling below it.
      schur_ = Eigen::MatrixXd();
      sparse_schur_.reset(m_);
      model.for_each_pool([&]<class E>(const std::vector<E>&, auto) {
        if constexpr (Constraint<E>)
          for (const int row : model.template rows<E>())
            sparse_schur_.declare(row, row, E::num_equations, E::num_equations);
      });
      for (const auto& list : couplings_)
        for (const auto& [lower, upper] : list)
          sparse_schur_.declare(lower.row, upper.row, lower.equations, upper.equations);
      sparse_schur_.finalize(BlockSparseMatrix::Triangle::lower);
      sparse_cholesky_.analyze(m_, sparse_schur_.column_starts(), sparse_schur_.row_indices());
    } else {
      schur_ = Eigen::MatrixXd::Zero(m_, m_);
      schur_cholesky_.resize(m_, envelope_end);
      schur_lu_.resize(m_);
      // Sized by a first computation, so that a singular S later allocates nothing.
      schur_minimum_norm_.compute(Eigen::MatrixXd::Identity(m_, m_), rank_tolerance);
    }
    work_m_ = Eigen::VectorXd::Zero(m_);
    work_y_ = Eigen::VectorXd::Zero(m_);
    work_qr_ = Eigen::VectorXd::Zero(m_);
    method_ = Method::cholesky;
    rank_deficiency_ = 0;
    row_order_ = {};
    kept_pinned_rows_.clear();
    dense_pinned_.clear();
    pins_doubted_ = false;
    trusted_pivot_ratio_ = singular_pivot_ratio;
  }

  bool factorize(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    if (path_ == Path::dense_kkt) return dense_.factorize(model, ws, f);
    if (path_ == Path::sparse_kkt) return sparse_kkt_.factorize(model, ws, f);
    if (!invert_blocks(model, ws, f)) return false;
    whole_ = Whole::none;
    if (dropped_skew_ + dropped_coupling_ > max_dropped_skew ||
        dropped_coupling_ > max_dropped_coupling)
      return factorize_whole(model, ws, f);
    if (path_ == Path::sparse_schur) {
      sparse_schur_.set_zero();
      assemble_schur(ws, sparse_schur_);
    } else {
      schur_.setZero();
      assemble_schur(ws, schur_);
    }
    if (m_ == 0) {
      rank_deficiency_ = 0;
      return true;
    }
    return path_ == Path::sparse_schur ? factorize_sparse_schur(model, ws) : factorize_schur();
  }

  /// The smallest pivot of the last Cholesky factorization of S relative to S's diagonal (the
  /// dense path: to its largest entry; the sparse one: each to its own). Near a singular
  /// configuration it falls as sigma^2, sigma the smallest singular value of Phi_q relative to
  /// its scale. 1 where the last factorization was another (rows pinned, the whole matrix, no
  /// equations), 0 where S was found singular and solved by minimum norm.
  double pivot_ratio() const {
    if (path_ == Path::dense_kkt || path_ == Path::sparse_kkt || whole_ != Whole::none || m_ == 0)
      return 1.0;
    switch (method_) {
      case Method::cholesky:
        return pivot_ratio_;
      case Method::sparse_cholesky:
        return sparse_cholesky_.smallest_pivot_ratio();
      case Method::minimum_norm:
        return 0.0;
      default:
        return 1.0;
    }
  }

  /// Number of dependent constraint equations in the last factorized matrix (0: full rank).
  int rank_deficiency() const {
    if (path_ == Path::dense_kkt || whole_ == Whole::dense) return dense_.rank_deficiency();
    if (path_ == Path::sparse_kkt || whole_ == Whole::sparse) return sparse_kkt_.rank_deficiency();
    return rank_deficiency_;
  }

  /// True if the last factorization was a dense one that pinned redundant equations (see
  /// factorize_dense_pinned, DenseSaddlePoint::factorize_pinned): solve_correction then leaves
  /// their multipliers where they are.
  bool corrections_pinned() const {
    if (path_ == Path::dense_kkt || whole_ == Whole::dense) return dense_.corrections_pinned();
    return path_ == Path::dense_schur && whole_ == Whole::none &&
           method_ == Method::cholesky_pinned;
  }

  /// solve() for a Newton correction (see DenseSaddlePoint::solve_correction).
  void solve_correction(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
    solve(rhs, solution, false);
  }

  /// True if the last factorization pinned the multipliers of redundant equations (see
  /// pin_dependent_rows): they then need no minimum-norm projection.
  bool multipliers_pinned() const {
    if (path_ == Path::sparse_kkt || whole_ == Whole::sparse)
      return sparse_kkt_.multipliers_pinned();
    return path_ == Path::sparse_schur && whole_ == Whole::none && method_ == Method::sparse_pinned;
  }

  /// How many times the sparse paths decided which rows to pin by a rank pass (see
  /// factorize_sparse_schur: once while the same rows keep repeating others).
  long pin_decisions() const { return pin_decisions_ + sparse_kkt_.pin_decisions(); }

  /// |A_sym^-1 A_skew| of the last factorization (largest over the bodies): what the Schur
  /// paths compare with max_dropped_skew.
  double dropped_skew() const { return dropped_skew_; }

  /// |A_b^-1 sum_j A_bj| of the last factorization (largest over the bodies): the weight of the
  /// blocks that couple bodies, which the Schur paths compare with max_dropped_coupling.
  double dropped_coupling() const { return dropped_coupling_; }

  /// True if the last factorization took the whole matrix (a Schur path's fallback, or a
  /// whole-matrix path).
  bool whole_matrix() const {
    return path_ == Path::dense_kkt || path_ == Path::sparse_kkt || whole_ != Whole::none;
  }

  /// How much the geometric stiffness weighed in the last factorization that was asked for
  /// it: |A^-1 G| largest over the bodies (infinity where it could not be used, or where a
  /// whole-matrix path took it without measuring).
  double geometric_share() const {
    return path_ == Path::dense_kkt || path_ == Path::sparse_kkt
               ? std::numeric_limits<double>::infinity()
               : geometric_share_;
  }

  /// The factorization the last analyze chose: "dense-schur", "cholmod-schur", "dense-lu" or
  /// "klu".
  const char* path_name() const {
    switch (path_) {
      case Path::sparse_schur:
        return "cholmod-schur";
      case Path::dense_kkt:
        return "dense-lu";
      case Path::sparse_kkt:
        return "klu";
      default:
        return "dense-schur";
    }
  }

  /// rhs = [f; g] -> solution = [x; y]: y = S^-1 (B A^-1 f - g), x = A^-1 (f - B^T y).
  /// `minimum_norm` false: see solve_correction.
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution, bool minimum_norm = true) {
    if (path_ == Path::dense_kkt || whole_ == Whole::dense)
      return dense_.solve(rhs, solution, minimum_norm);
    if (path_ == Path::sparse_kkt || whole_ == Whole::sparse)
      return sparse_kkt_.solve(rhs, solution);
    // B A^-1 f = sum over the blocks of W_e f_b.
    work_m_ = -rhs.tail(m_);
    for_each_weighted([&](const BlockRef& ref, const auto& w) {
      constexpr int m = std::decay_t<decltype(w)>::RowsAtCompileTime;
      work_m_.template segment<m>(ref.row).noalias() += w * rhs.template segment<nv>(ref.body * nv);
    });
    switch (method_) {
      case Method::cholesky:
        solution.tail(m_) = work_m_;
        schur_cholesky_.solve_in_place(solution.tail(m_));
        break;
      case Method::sparse_cholesky:
        solution.tail(m_) = work_m_;
        sparse_cholesky_.solve_in_place(solution.tail(m_));
        break;
      case Method::sparse_pinned: {  // the pinned rows' multipliers do not move
        pinned_rhs_.resize(pinned_rows_.size());
        for (std::size_t i = 0; i < pinned_rows_.size(); ++i) {
          pinned_rhs_[i] = work_m_[pinned_rows_[i]];
          work_m_[pinned_rows_[i]] = 0.0;
        }
        solution.tail(m_) = work_m_;
        sparse_cholesky_.solve_in_place(solution.tail(m_));
        check_pinned_rows(rhs.tail(m_).cwiseAbs().maxCoeff(), solution.tail(m_));
        break;
      }
      case Method::lu:
        solution.tail(m_) = work_m_;
        schur_lu_.solve_in_place(solution.tail(m_));
        break;
      case Method::cholesky_pinned:  // the minimum-norm y (see factorize_dense_pinned)
        for (const int row : dense_pinned_) work_m_[row] = 0.0;
        solution.tail(m_) = work_m_;
        schur_cholesky_.solve_in_place(solution.tail(m_));
        if (minimum_norm)
          detail::remove_null_space_part(null_basis_, null_gram_, null_work_, solution.tail(m_));
        break;
      case Method::minimum_norm:
        schur_minimum_norm_.solve(work_m_, work_y_, work_qr_);
        solution.tail(m_) = work_y_;
        break;
    }
    // x_b = A_b^-1 f_b - sum over the blocks on body b of W_e^T y_e.
    for (int b = 0; b < bodies_; ++b) {
      const Eigen::Matrix<double, nv, 1> f = rhs.template segment<nv>(b * nv);
      if (diagonal_inverse_[b])
        solution.template segment<nv>(b * nv) = inverses_[b].diagonal().cwiseProduct(f);
      else
        solution.template segment<nv>(b * nv).noalias() = inverses_[b] * f;
    }
    for_each_weighted([&](const BlockRef& ref, const auto& w) {
      constexpr int m = std::decay_t<decltype(w)>::RowsAtCompileTime;
      solution.template segment<nv>(ref.body * nv).noalias() -=
          w.transpose() * solution.template segment<m>(n_ + ref.row);
    });
  }

 private:
  enum class Method { cholesky, cholesky_pinned, sparse_cholesky, sparse_pinned, lu, minimum_norm };
  enum class Path { dense_schur, sparse_schur, dense_kkt, sparse_kkt };
  /// Which whole-matrix factorization stands in for a Schur path's, if any.
  enum class Whole { none, dense, sparse };

  /// The whole matrix, for a factorization whose A is too unsymmetric for the Schur
  /// complement: dense for small models, KLU for large ones, analyzed on first use.
  bool factorize_whole(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    if (n_ + m_ <= dense_kkt_limit && choice_ != LinearSolver::klu) {
      if (!whole_dense_analyzed_) dense_.analyze(model);
      whole_dense_analyzed_ = true;
      whole_ = Whole::dense;
      return dense_.factorize(model, ws, f);
    }
    if (!whole_sparse_analyzed_) sparse_kkt_.analyze(model);
    whole_sparse_analyzed_ = true;
    whole_ = Whole::sparse;
    return sparse_kkt_.factorize(model, ws, f);
  }

  /// What to factorize: the Schur complement needs A block diagonal, or nearly (force elements
  /// that join two moving bodies: small models take the whole matrix, large ones the Schur
  /// complement while the couplings weigh little; see max_dropped_coupling).
  Path choose_path(const Model& model) const {
    switch (choice_) {
      case LinearSolver::dense:
        return coupled_ ? Path::dense_kkt : Path::dense_schur;
      case LinearSolver::klu:
        return Path::sparse_kkt;
      case LinearSolver::cholmod:
        if (coupled_)
          throw ModelError("linear_solver",
                           "cholmod factorizes the Schur complement B A^-1 B^T, which needs the "
                           "bodies uncoupled in A, but a force element here joins two moving "
                           "bodies; choose klu (or auto) for this model");
        return Path::sparse_schur;
      default:
        if (coupled_ && model.num_velocities() + model.num_equations() <= dense_kkt_limit)
          return Path::dense_kkt;
        return model.num_equations() <= dense_schur_limit ? Path::dense_schur : Path::sparse_schur;
    }
  }

  /// Adds S = B A^-1 B^T into `target` (a dense matrix or the sparse one), block by block:
  /// each block B_e of B (element e's rows on body b) is weighted, W_e = B_e A_b^-1, and gives
  /// S_ee += W_e B_e^T; each pair of blocks on one body gives the off-diagonal block W_e B_f^T.
  /// All sizes are fixed at compile time.
  template <class Target>
  void assemble_schur(const Workspace<Model>& ws, Target& target) {
    for_each_type([&]<class E, std::size_t T>() {
      constexpr int m = E::num_equations;
      const auto& blocks = std::get<T>(ws.blocks);
      auto& weighted = std::get<T>(weighted_);
      for (const BlockRef& ref : block_refs_[T]) {
        const auto& jacobian = blocks[ref.element].jacobian[ref.side];
        auto& w = weighted[ref.element][ref.side];
        const Block& inverse = inverses_[ref.body];
        if (diagonal_inverse_[ref.body])  // principal axes at the centre of mass
          w = jacobian * inverse.diagonal().asDiagonal();
        else
          w.noalias() = jacobian * inverse;  // A_b^-1 is symmetric
        target.template block<m, m>(ref.row, ref.row).noalias() += w * jacobian.transpose();
      }
    });
    for_each_type([&]<class E, std::size_t T>() {
      for_each_type([&]<class F, std::size_t U>() {
        const auto& weighted = std::get<T>(weighted_);
        const auto& blocks = std::get<U>(ws.blocks);
        for (const auto& [lower, upper] : couplings_[T * Model::num_types + U])
          target.template block<E::num_equations, F::num_equations>(lower.row, upper.row)
              .noalias() += weighted[lower.element][lower.side] *
                            blocks[upper.element].jacobian[upper.side].transpose();
      });
    });
  }

  /// One block of B: element `element` of its type, its body number `side`, that body's index
  /// from 0, the element's first row and its number of rows.
  struct BlockRef {
    int element, side, body, row, equations;
  };
  /// Two blocks of B on one body, the lower one's rows below the upper one's.
  struct Coupling {
    BlockRef lower, upper;
  };

  template <class E>
  struct WeightedOf {
    using type = char;  // not a constraint: nothing to keep
  };
  template <Constraint E>
  struct WeightedOf<E> {
    using type = std::array<Eigen::Matrix<double, E::num_equations, nv>, E::num_bodies>;
  };
  template <class>
  struct WeightedPools;
  template <class BodyT, class... Elements>
  struct WeightedPools<odyn::Model<BodyT, Elements...>> {
    using type = std::tuple<std::vector<typename WeightedOf<Elements>::type>...>;
  };

  /// f.template operator()<E, T>() for every constraint type E, T its position in the model.
  template <class F>
  static void for_each_type(F&& f) {
    [&]<std::size_t... T>(std::index_sequence<T...>) {
      (
          [&] {
            using E = std::variant_alternative_t<T, typename Model::Variant>;
            if constexpr (Constraint<E>) f.template operator()<E, T>();
          }(),
          ...);
    }
    (std::make_index_sequence<Model::num_types>{});
  }

  /// f(block, W_e) for every block of B, with the weights of the last factorize.
  template <class F>
  void for_each_weighted(F&& f) const {
    for_each_type([&]<class E, std::size_t T>() {
      for (const BlockRef& ref : block_refs_[T])
        f(ref, std::get<T>(weighted_)[ref.element][ref.side]);
    });
  }

  /// A_b^-1 for every body. With mass terms only (explicit integrators, projections,
  /// assembly) A is a multiple of the constant mass matrix: its inverses are kept and reused.
  bool invert_blocks(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    const bool mass_only = f.stiffness == 0.0 && f.damping == 0.0;
    dropped_skew_ = dropped_coupling_ = 0.0;  // M is symmetric and block diagonal
    if (mass_only && f.mass == cached_mass_factor_) return true;
    cached_mass_factor_ = std::numeric_limits<double>::quiet_NaN();
    std::fill(diagonal_inverse_.begin(), diagonal_inverse_.end(), false);
    for (Block& block : blocks_) block.setZero();
    for (Block& block : body_couplings_) block.setZero();
    detail::BlockDiagonalView<nv> view{&blocks_, coupled_ ? &body_couplings_ : nullptr};
    add_iteration_blocks(model, ws, view, f.mass, f.stiffness, f.damping, false);
    const bool geometric = has_geometric_stiffness<Model>() && f.geometric && f.stiffness != 0.0;
    geometric_share_ = 0.0;
    if (geometric) {
      for (Block& block : geometric_) block.setZero();
      detail::BlockDiagonalView<nv> geometric_view{&geometric_};
      add_geometric_stiffness(model, ws, geometric_view, f.stiffness);
    }
    for (int b = 0; b < bodies_; ++b) {
      // Gyroscopic damping makes A unsymmetric; Cholesky needs its symmetric part, which
      // slows Newton's convergence (never its result) by about |A_sym^-1 A_skew| a step.
      // The constraints' geometric stiffness joins it where it keeps that part positive
      // definite (large compressive forces against mass over the step squared would not).
      const Block symmetric = 0.5 * (blocks_[b] + blocks_[b].transpose());
      if (geometric) {
        const Block with_geometric = symmetric + 0.5 * (geometric_[b] + geometric_[b].transpose());
        bool positive = false;
        inverses_[b] = detail::invert_symmetric<nv>(with_geometric, &positive);
        if (positive) {
          blocks_[b] += geometric_[b];
          geometric_share_ =
              std::max(geometric_share_,
                       (inverses_[b] * geometric_[b]).cwiseAbs().rowwise().sum().maxCoeff());
        } else {
          inverses_[b] = detail::invert_symmetric<nv>(symmetric);
          geometric_share_ = std::numeric_limits<double>::infinity();
        }
      } else {
        inverses_[b] = detail::invert_symmetric<nv>(symmetric);
      }
      if (!inverses_[b].allFinite()) return false;
      if (!mass_only) {
        const Block skew = 0.5 * (blocks_[b] - blocks_[b].transpose());
        dropped_skew_ =
            std::max(dropped_skew_, (inverses_[b] * skew).cwiseAbs().rowwise().sum().maxCoeff());
        if (coupled_)
          dropped_coupling_ =
              std::max(dropped_coupling_,
                       (inverses_[b] * body_couplings_[b]).cwiseAbs().rowwise().sum().maxCoeff());
      }
    }
    if (mass_only) {
      cached_mass_factor_ = f.mass;
      for (int b = 0; b < bodies_; ++b) diagonal_inverse_[b] = inverses_[b].isDiagonal(0.0);
    }
    return true;
  }

  /// Below this, a pivot of the sparse factorization relative to its diagonal entry of S
  /// calls for the rank pass on Phi_q: a row that repeats others leaves rounding (1e-16 or
  /// so). Not rank_tolerance: on a chain of slender hinged links the smallest ratio falls as
  /// N^-3 in a well-posed model (7.5e-9 at 256 links, 1.2e-10 at 1024, 3e-14 on a ladder of
  /// 5461 hinged parallelograms), and the rank pass then decides (see trust_pivots).
  static constexpr double singular_pivot_ratio = 1e-13;
  /// What rounding leaves of a pivot for a row that repeats others.
  static constexpr double rounding_pivot_ratio = 1e-16;
  /// Beyond this many equations a singular S is not copied to a dense matrix (8000: 0.5 GB).
  static constexpr int dense_fallback_limit = 8000;

  /// Factorizes the sparse S by CHOLMOD. When S is singular because rows of Phi_q repeat
  /// others (redundant constraints), those rows are pinned (see pin_dependent_rows) and the
  /// rest is factorized, still sparse. When S is not positive definite (A indefinite) or
  /// singular for another reason (a dead point), it goes the dense way below: correct, but
  /// O(m^3).
  bool factorize_sparse_schur(const Model& model, const Workspace<Model>& ws) {
    rank_deficiency_ = 0;
    const std::vector<double>& values = sparse_schur_.gather();
    // The rows pinned last time repeat the others again as the model moves on (parallel
    // hinges stay parallel): they are kept, without a new rank pass, while the rest factorizes
    // regularly and the solves find them consistent (see check_pinned_rows). A rank pass at a
    // Newton iterate, where loops close only to the tolerance, would also lose the
    // cancellation that keeps its elimination local. Decided afresh otherwise; the rows kept
    // are the fallback if the new decision leaves S singular.
    const bool pinned_before = method_ == Method::sparse_pinned;
    const bool doubted = pins_doubted_;
    if (pinned_before && !doubted && factorize_pinned(values, false)) return true;
    bool decided = false, none_repeat = false;  // a rank pass ran in this call; its verdict
    const auto decide = [&] {
      decided = true;
      if (pin_dependent_rows(model, ws, values)) return true;
      none_repeat = pinned_rows_.empty();
      return false;
    };
    if (pinned_before &&
        (decide() || (doubted && restore_pinned_rows() && factorize_pinned(values, false))))
      return true;
    const bool positive_definite = sparse_cholesky_.factorize(values);
    if (positive_definite && sparse_cholesky_.smallest_pivot_ratio() > trusted_pivot_ratio_) {
      method_ = Method::sparse_cholesky;
      return true;
    }
    for (const double x : values)
      if (!std::isfinite(x)) return false;
    if (!decided && decide()) return true;
    // No row repeats others, by the rank pass: a small pivot is the conditioning of a long
    // chain of slender links, not a redundancy (see singular_pivot_ratio).
    if (positive_definite && none_repeat && trust_pivots()) {
      method_ = Method::sparse_cholesky;
      return true;
    }
    if (m_ > dense_fallback_limit) return false;  // O(m^2) memory: refused, not attempted
    schur_ = sparse_schur_.to_dense();
    schur_cholesky_.resize(m_);
    schur_lu_.resize(m_);
    return factorize_schur();
  }

  /// After a rank pass has decided which rows repeat others, the pivots of the factorization
  /// of the rest are trusted down to rounding (rounding_pivot_ratio), and those of the
  /// factorizations that follow without a rank pass down to a hundredth of the smallest one
  /// (or singular_pivot_ratio, if higher). False if rounding explains the smallest pivot.
  bool trust_pivots() {
    const double ratio = sparse_cholesky_.smallest_pivot_ratio();
    if (!(ratio > rounding_pivot_ratio)) return false;
    trusted_pivot_ratio_ =
        std::max(rounding_pivot_ratio, std::min(singular_pivot_ratio, 1e-2 * ratio));
    return true;
  }

  /// Redundant constraints on the sparse path. The rows of Phi_q that repeat earlier ones
  /// (sparse elimination in topological order, as the sparse assembly decides them: linear cost)
  /// are pinned: their rows and columns of S are cleared but for the diagonal, so that a solve
  /// leaves their multipliers where they are (zero, from the sparse assembly) and the other
  /// rows' multipliers carry the constraint forces. For consistent redundant equations that is
  /// one valid solution, not the minimum-norm one of the dense solvers (the reactions are not
  /// unique either way; see the top of this file). False if no row repeats others, or if the
  /// rest is still singular.
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
    return !pinned_rows_.empty() && factorize_pinned(values, true);
  }

  /// Back to the rows pinned before the last decision (see factorize_sparse_schur).
  bool restore_pinned_rows() {
    if (kept_pinned_rows_.empty()) return false;
    pinned_rows_.swap(kept_pinned_rows_);
    kept_pinned_rows_.clear();
    return true;
  }

  /// Factorizes S with the rows pinned_rows_ pinned, just `decided` by a rank pass or kept
  /// from before (see trust_pivots). False if the rest is singular.
  bool factorize_pinned(const std::vector<double>& values, bool decided) {
    std::vector<char>& pinned = pinned_mark_;
    pinned.assign(static_cast<std::size_t>(m_), 0);
    for (const int row : pinned_rows_) pinned[row] = 1;
    pinned_values_ = values;
    const std::vector<int>& starts = sparse_schur_.column_starts();
    const std::vector<int>& rows = sparse_schur_.row_indices();
    for (int column = 0; column < m_; ++column)
      for (int k = starts[column]; k < starts[column + 1]; ++k)
        if ((pinned[rows[k]] || pinned[column]) && rows[k] != column) pinned_values_[k] = 0.0;
    if (!sparse_cholesky_.factorize(pinned_values_)) return false;
    if (decided ? !trust_pivots()
                : !(sparse_cholesky_.smallest_pivot_ratio() > trusted_pivot_ratio_))
      return false;
    method_ = Method::sparse_pinned;
    rank_deficiency_ = static_cast<int>(pinned_rows_.size());
    return true;
  }

  /// Whether the pinned rows still repeat the others: their equations of S y = rhs, which the
  /// pinned solve left out, must hold with the y it found (to O(distance from the constraint
  /// manifold), as a dependent row's consistency does at a Newton iterate). A row that
  /// stopped repeating others (a mechanism leaving a singular configuration) fails this, and
  /// the next factorization decides the pinned rows afresh. One pass over S's lower triangle.
  template <class Multipliers>
  void check_pinned_rows(double rhs_scale, const Multipliers& y) {
    const std::vector<double>& values = sparse_schur_.values();
    const std::vector<int>& starts = sparse_schur_.column_starts();
    const std::vector<int>& rows = sparse_schur_.row_indices();
    for (const int row : pinned_rows_) work_qr_[row] = work_y_[row] = 0.0;
    const auto add = [&](int row, double term) {
      work_qr_[row] += term;
      work_y_[row] += std::abs(term);
    };
    for (int column = 0; column < m_; ++column)
      for (int k = starts[column]; k < starts[column + 1]; ++k) {
        const int row = rows[k];
        if (pinned_mark_[row]) add(row, values[k] * y[column]);
        if (pinned_mark_[column] && row != column) add(column, values[k] * y[row]);
      }
    double mismatch = 0.0, scale = rhs_scale;
    for (std::size_t i = 0; i < pinned_rows_.size(); ++i) {
      mismatch = std::max(mismatch, std::abs(work_qr_[pinned_rows_[i]] - pinned_rhs_[i]));
      scale = std::max({scale, work_y_[pinned_rows_[i]], std::abs(pinned_rhs_[i])});
    }
    if (mismatch > pinned_consistency * scale) pins_doubted_ = true;
  }

  /// Factorizes the assembled S: Cholesky, else LU, else (singular) Cholesky with the rows that
  /// repeat others pinned, else a complete orthogonal decomposition.
  bool factorize_schur() {
    rank_deficiency_ = 0;
    const double largest_diagonal = schur_.diagonal().cwiseAbs().maxCoeff();
    // Rows that repeated others in the last factorization are tried first: a redundant
    // mechanism (Bricard's) stays singular at every pose, and trying the regular Cholesky first
    // would cost a failed factorization each time.
    if (!dense_pinned_.empty()) {
      if (factorize_dense_pinned(largest_diagonal)) return true;
      dense_pinned_.clear();
    }
    // The fast path: Cholesky on the lower triangle. Its pivots are the diagonal of L squared,
    // and the smallest one bounds the smallest eigenvalue of S from above, so a tiny pivot flags
    // a singular S. A non-finite entry reaches a pivot and fails it.
    const bool positive_definite = schur_cholesky_.compute(schur_);
    if (positive_definite && schur_cholesky_.smallest_pivot() > rank_tolerance * largest_diagonal) {
      method_ = Method::cholesky;
      pivot_ratio_ = schur_cholesky_.smallest_pivot() / largest_diagonal;
      return true;
    }
    if (!schur_.allFinite()) return false;
    schur_.triangularView<Eigen::StrictlyUpper>() = schur_.transpose();
    if (!positive_definite) {
      // Not positive definite (A itself is not): LU on the same matrix, if it is regular.
      schur_lu_.compute(schur_);
      if (schur_lu_.smallest_pivot() > rank_tolerance * schur_lu_.largest_entry()) {
        method_ = Method::lu;
        return true;
      }
    }
    // Singular: redundant (or, at a dead point, locked) constraints. A rank-revealing QR of S
    // decides its rank; the rows it pivots last repeat the others. Those are pinned (Cholesky of
    // the rest, as fast as a regular S), or, if the rest is not regular either, its complete
    // orthogonal decomposition gives the minimum-norm y.
    method_ = Method::minimum_norm;
    schur_minimum_norm_.compute(schur_, rank_tolerance);
    rank_deficiency_ = static_cast<int>(m_ - schur_minimum_norm_.rank());
    const std::vector<int>& order = schur_minimum_norm_.column_order();
    dense_pinned_.assign(order.begin() + schur_minimum_norm_.rank(), order.end());
    std::sort(dense_pinned_.begin(), dense_pinned_.end());
    if (!dense_pinned_.empty() && factorize_dense_pinned(largest_diagonal)) return true;
    dense_pinned_.clear();
    return true;
  }

  /// Redundant constraints on the dense Schur path, at the cost of a regular S. With P the rows
  /// in dense_pinned_ and K the rest, S_KK is factorized by Cholesky (the pinned rows and
  /// columns of S cleared but for the diagonal). The rows P repeat K if B_P = C B_K; then
  /// S_KP = S_KK C^T, and the Schur complement E = S_PP - S_PK C^T vanishes: that is checked
  /// here (E below detail::repeated_row_tolerance times S's largest diagonal entry), so that a
  /// row that repeats the others only near a singular configuration goes to the rank-revealing
  /// path, and one that stops repeating them falls back to the regular paths at once. The columns
  /// of N = [-C^T; I] span the null space of B^T; a solve's y (y_P = 0) is made the minimum-norm
  /// one by removing its part in that space, y - N (N^T N)^-1 N^T y, which leaves x unchanged.
  /// False if the pinned rows do not all repeat the others or the rest is singular.
  bool factorize_dense_pinned(double largest_diagonal) {
    const auto k = static_cast<Eigen::Index>(dense_pinned_.size());
    pinned_schur_ = schur_;
    pinned_mark_.assign(static_cast<std::size_t>(m_), 0);
    for (const int row : dense_pinned_) {
      pinned_mark_[row] = 1;
      pinned_schur_.row(row).setZero();
      pinned_schur_.col(row).setZero();
      pinned_schur_(row, row) = largest_diagonal;
    }
    if (!schur_cholesky_.compute(pinned_schur_) ||
        !(schur_cholesky_.smallest_pivot() > rank_tolerance * largest_diagonal))
      return false;
    null_basis_.resize(m_, k);
    for (Eigen::Index i = 0; i < k; ++i) {
      const int p = dense_pinned_[i];
      for (int row = 0; row < m_; ++row)  // S_KP's column, from the lower triangle of S
        null_basis_(row, i) = pinned_mark_[row] ? 0.0 : row > p ? schur_(row, p) : schur_(p, row);
      schur_cholesky_.solve_in_place(null_basis_.col(i));  // C^T's column
      double complement = schur_(p, p);                    // E_ii = S_pp - S_pK C^T_i
      for (int row = 0; row < m_; ++row)
        if (!pinned_mark_[row])
          complement -= (row > p ? schur_(row, p) : schur_(p, row)) * null_basis_(row, i);
      if (!(std::abs(complement) <= detail::repeated_row_tolerance * largest_diagonal))
        return false;
      null_basis_.col(i) *= -1.0;
      null_basis_(p, i) = 1.0;
    }
    null_gram_matrix_.noalias() = null_basis_.transpose() * null_basis_;
    null_gram_.compute(null_gram_matrix_);
    null_work_.resize(k);
    method_ = Method::cholesky_pinned;
    rank_deficiency_ = static_cast<int>(k);
    return true;
  }

  LinearSolver choice_ = LinearSolver::automatic;
  Path path_ = Path::dense_schur;
  Whole whole_ = Whole::none;  // the last factorization took the whole matrix
  bool whole_dense_analyzed_ = false, whole_sparse_analyzed_ = false;
  std::vector<Block> geometric_;       // the stiffness factor times G, per body (scratch)
  double geometric_share_ = 0.0;       // see geometric_share()
  double dropped_skew_ = 0.0;          // max over the bodies of |A_sym^-1 A_skew| (infinity norm)
  bool coupled_ = false;               // force elements join moving bodies in A
  std::vector<Block> body_couplings_;  // (nb) sum of A's off-diagonal blocks in each body's rows
  double dropped_coupling_ = 0.0;      // max over the bodies of |A_b^-1 body_couplings_[b]|
  DenseSaddlePoint<Model> dense_;      // path dense_kkt
  SparseKktSaddlePoint<Model> sparse_kkt_;  // path sparse_kkt
  int bodies_ = 0, n_ = 0, m_ = 0;
  Method method_ = Method::cholesky;
  int rank_deficiency_ = 0;
  double cached_mass_factor_ = 0.0;     // NaN unless inverses_ hold (factor M)^-1
  std::vector<Block> blocks_;           // (nb) diagonal blocks of A
  std::vector<Block> inverses_;         // (nb) inverses of their symmetric parts
  std::vector<bool> diagonal_inverse_;  // (nb) inverses_[b] is diagonal (kept mass-only ones)
  std::array<std::vector<BlockRef>, Model::num_types> block_refs_;  // blocks of B, by type
  std::array<std::vector<Coupling>, Model::num_types * Model::num_types> couplings_;
  typename WeightedPools<Model>::type weighted_;  // W_e = B_e A_b^-1, laid out like ws.blocks
  Eigen::MatrixXd schur_;                         // (m x m) S = B A^-1 B^T (path dense_schur)
  BlockSparseMatrix sparse_schur_;                // its lower triangle (path sparse_schur)
  SparseCholesky sparse_cholesky_;
  SmallCholesky schur_cholesky_;
  PivotedLu schur_lu_;                  // S not positive definite
  RankRevealingQr schur_minimum_norm_;  // S singular
  std::vector<int> dense_pinned_;       // rows of S that repeat others (cholesky_pinned)
  Eigen::MatrixXd pinned_schur_;        // S with those rows and columns cleared
  Eigen::MatrixXd null_basis_;          // (m x k) N, a basis of the null space of B^T
  Eigen::MatrixXd null_gram_matrix_;    // N^T N
  Eigen::LLT<Eigen::MatrixXd> null_gram_;  // its factorization
  Eigen::VectorXd null_work_;              // (k) scratch
  std::vector<int> pinned_rows_;        // rows of Phi_q that repeat others (sparse_pinned)
  std::vector<double> pinned_values_;   // S's values with those rows and columns cleared
  std::vector<char> pinned_mark_;       // 1 on the pinned rows
  std::vector<int> kept_pinned_rows_;   // those pinned before the last decision
  std::vector<double> pinned_rhs_;      // (scratch) their right-hand side in a solve
  bool pins_doubted_ = false;           // a solve found a pinned row inconsistent
  long pin_decisions_ = 0;              // rank passes that decided them
  double trusted_pivot_ratio_ = singular_pivot_ratio;  // see trust_pivots
  double pivot_ratio_ = 1.0;  // of the last dense Cholesky of S (see pivot_ratio)
  detail::RowOrder row_order_;                         // how to find them (built on the first need)
  Eigen::VectorXd work_m_, work_y_, work_qr_;
};

/// Whether the multipliers need the minimum-norm projection (make_multipliers_minimum_norm)
/// after the solver's last factorization: it found redundant equations and did not pin them.
template <class Solver>
bool needs_minimum_norm_multipliers(const Solver& solver) {
  if constexpr (requires { solver.multipliers_pinned(); })
    if (solver.multipliers_pinned()) return false;
  return solver.rank_deficiency() > 0;
}

}  // namespace odyn
