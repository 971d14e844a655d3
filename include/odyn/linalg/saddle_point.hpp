#pragma once
// Solvers for the saddle-point systems of the analyses,
//   [A  B^T] [x]   [f]
//   [B  0  ] [y] = [g],   A = mass_factor M + stiffness_factor K + damping_factor C,  B = Phi_q,
// behind one interface: analyze(model) once per model, factorize(model, ws, factors) per
// matrix values, solve(rhs, solution). Two implementations:
//  - DenseSaddlePoint: assembles the whole matrix and factorizes it by dense LU; general.
//  - BlockSchurSaddlePoint: when A is block diagonal (no force element couples two moving
//    bodies in the Newton matrix), inverts A body by body and factorizes only the m x m Schur
//    complement B A^-1 B^T; several times cheaper for small and medium models. It falls back
//    to the dense solver by itself when A is not block diagonal.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <vector>

#include "odyn/analysis/system.hpp"
#include "odyn/linalg/dense_lu.hpp"

namespace odyn {

/// Multipliers of M, K = -dQ/dq and C = -dQ/dv in the top-left block.
struct IterationFactors {
  double mass = 1.0;
  double stiffness = 0.0;
  double damping = 0.0;
};

template <class Model>
class DenseSaddlePoint {
 public:
  void analyze(const Model& model) {
    n_ = model.num_velocities();
    const int size = n_ + model.num_equations();
    matrix_ = Eigen::MatrixXd::Zero(size, size);
    lu_.analyze_pattern(matrix_);
  }

  bool factorize(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    matrix_.setZero();
    add_iteration_blocks(model, ws, matrix_, f.mass, f.stiffness, f.damping);
    write_jacobian(model, ws, matrix_, n_, 0, true);
    return lu_.factorize(matrix_);
  }

  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) const {
    lu_.solve(rhs, solution);
  }

 private:
  int n_ = 0;
  Eigen::MatrixXd matrix_;  // (n + m) x (n + m)
  DenseLu lu_;
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

/// Inverse of a symmetric positive definite body block. Eigen inverts up to 4 x 4 in closed
/// form; a 6 x 6 block goes through its 3 x 3 blocks, several times faster than a 6 x 6 LU.
template <int N>
Eigen::Matrix<double, N, N> invert_symmetric(const Eigen::Matrix<double, N, N>& a) {
  if constexpr (N == 6) {
    const Eigen::Matrix3d p_inverse = a.template topLeftCorner<3, 3>().inverse();
    const Eigen::Matrix3d q = a.template topRightCorner<3, 3>();
    const Eigen::Matrix3d p_inverse_q = p_inverse * q;
    const Eigen::Matrix3d schur_inverse =
        (a.template bottomRightCorner<3, 3>() - q.transpose() * p_inverse_q).inverse();
    Eigen::Matrix<double, 6, 6> inverse;
    inverse.template topRightCorner<3, 3>() = -p_inverse_q * schur_inverse;
    inverse.template topLeftCorner<3, 3>() =
        p_inverse - inverse.template topRightCorner<3, 3>() * p_inverse_q.transpose();
    inverse.template bottomLeftCorner<3, 3>() = inverse.template topRightCorner<3, 3>().transpose();
    inverse.template bottomRightCorner<3, 3>() = schur_inverse;
    return inverse;
  } else {
    return a.inverse();
  }
}

/// Lets add_iteration_blocks write into per-body diagonal blocks.
template <int nv>
struct BlockDiagonalView {
  std::vector<Eigen::Matrix<double, nv, nv>>* blocks;
  template <int R, int C>
  Eigen::Matrix<double, nv, nv>& block(Eigen::Index row, Eigen::Index) {
    static_assert(R == nv && C == nv);
    return (*blocks)[row / nv];
  }
};
}  // namespace detail

template <class Model>
class BlockSchurSaddlePoint {
 public:
  static constexpr int nv = Model::nv;
  using Block = Eigen::Matrix<double, nv, nv>;
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, nv>;

  void analyze(const Model& model) {
    dense_fallback_ = detail::couples_bodies(model);
    if (dense_fallback_) {
      dense_.analyze(model);
      return;
    }
    bodies_ = model.num_bodies();
    n_ = model.num_velocities();
    m_ = model.num_equations();
    blocks_.assign(bodies_, Block::Zero());
    inverses_.assign(bodies_, Block::Zero());
    // The constraint rows that act on each body: S = B A^-1 B^T only couples those.
    rows_.assign(bodies_, {});
    model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
      if constexpr (Constraint<E>) {
        for (std::size_t i = 0; i < pool.size(); ++i)
          for (const BodyId body : pool[i].bodies())
            if (!body.is_ground())
              for (int r = 0; r < E::num_equations; ++r)
                rows_[body.index - 1].push_back(model.template rows<E>()[i] + r);
      }
    });
    gathered_.clear();
    weighted_.clear();
    local_.clear();
    for (const auto& rows : rows_) {
      const auto size = static_cast<Eigen::Index>(rows.size());
      gathered_.emplace_back(Rows::Zero(size, nv));
      weighted_.emplace_back(Rows::Zero(size, nv));
      local_.emplace_back(Eigen::MatrixXd::Zero(size, size));
    }
    jacobian_ = Eigen::MatrixXd::Zero(m_, n_);
    schur_ = Eigen::MatrixXd::Zero(m_, m_);
    schur_llt_.compute(Eigen::MatrixXd::Identity(m_, m_));  // sizes it; info() defined
    schur_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(m_);
    work_n_ = Eigen::VectorXd::Zero(n_);
    work_m_ = Eigen::VectorXd::Zero(m_);
  }

  bool factorize(const Model& model, const Workspace<Model>& ws, const IterationFactors& f) {
    if (dense_fallback_) return dense_.factorize(model, ws, f);
    for (Block& block : blocks_) block.setZero();
    detail::BlockDiagonalView<nv> view{&blocks_};
    add_iteration_blocks(model, ws, view, f.mass, f.stiffness, f.damping);
    write_jacobian(model, ws, jacobian_, 0, 0, false);
    schur_.setZero();
    for (int b = 0; b < bodies_; ++b) {
      // Gyroscopic damping makes A slightly unsymmetric; Cholesky then needs its symmetric
      // part, which only slows Newton's convergence a little, never its result.
      inverses_[b] = detail::invert_symmetric<nv>(0.5 * (blocks_[b] + blocks_[b].transpose()));
      if (!inverses_[b].allFinite()) return false;
      if (rows_[b].empty()) continue;
      const auto& rows = rows_[b];
      const auto size = static_cast<Eigen::Index>(rows.size());
      for (Eigen::Index i = 0; i < size; ++i)
        gathered_[b].row(i) = jacobian_.block<1, nv>(rows[i], b * nv);
      weighted_[b].noalias() = gathered_[b] * inverses_[b];
      local_[b].noalias() = weighted_[b] * gathered_[b].transpose();
      for (Eigen::Index j = 0; j < size; ++j)
        for (Eigen::Index i = 0; i < size; ++i) schur_(rows[i], rows[j]) += local_[b](i, j);
    }
    if (m_ == 0) return true;
    schur_llt_.compute(schur_);
    use_lu_ = schur_llt_.info() != Eigen::Success;
    if (!use_lu_) return true;
    // Not positive definite (A itself is not): fall back to LU on the same matrix.
    schur_lu_.compute(schur_);
    const double largest = schur_lu_.matrixLU().cwiseAbs().maxCoeff();
    return schur_lu_.matrixLU().diagonal().cwiseAbs().minCoeff() > 1e-13 * largest;
  }

  /// rhs = [f; g] -> solution = [x; y]: y = S^-1 (B A^-1 f - g), x = A^-1 (f - B^T y).
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
    if (dense_fallback_) return dense_.solve(rhs, solution);
    for (int b = 0; b < bodies_; ++b)
      work_n_.segment<nv>(b * nv).noalias() = inverses_[b] * rhs.segment<nv>(b * nv);
    if (m_ > 0) {
      work_m_.noalias() = jacobian_ * work_n_;
      work_m_ -= rhs.tail(m_);
      if (use_lu_)
        solution.tail(m_).noalias() = schur_lu_.solve(work_m_);
      else
        solution.tail(m_).noalias() = schur_llt_.solve(work_m_);
      work_n_.noalias() = rhs.head(n_) - jacobian_.transpose() * solution.tail(m_);
      for (int b = 0; b < bodies_; ++b)
        solution.segment<nv>(b * nv).noalias() = inverses_[b] * work_n_.segment<nv>(b * nv);
    } else {
      solution.head(n_) = work_n_;
    }
  }

 private:
  bool dense_fallback_ = false;
  DenseSaddlePoint<Model> dense_;
  int bodies_ = 0, n_ = 0, m_ = 0;
  bool use_lu_ = false;
  std::vector<Block> blocks_;              // (nb) diagonal blocks of A
  std::vector<Block> inverses_;            // (nb) inverses of their symmetric parts
  std::vector<std::vector<int>> rows_;     // (nb) constraint rows acting on each body
  std::vector<Rows> gathered_, weighted_;  // (nb) B restricted to those rows, times A^-1
  std::vector<Eigen::MatrixXd> local_;     // (nb) their contribution to S
  Eigen::MatrixXd jacobian_;               // (m x n) B
  Eigen::MatrixXd schur_;                  // (m x m) S = B A^-1 B^T
  Eigen::LLT<Eigen::MatrixXd> schur_llt_;
  Eigen::PartialPivLU<Eigen::MatrixXd> schur_lu_;
  Eigen::VectorXd work_n_, work_m_;
};

}  // namespace odyn
