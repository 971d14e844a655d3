#pragma once
// Householder QR with column pivoting, A P = Q R, completed to a complete orthogonal
// decomposition (the first rank rows of R are [L^T 0] Z^T, L upper triangular) for
// minimum-norm least-squares solutions. It decides the rank of a constraint Jacobian (which
// equations are redundant) and solves systems that may be singular: assembly's Newton steps,
// minimum-norm multipliers, a singular Schur complement.
//
// Written as plain loops over column-major storage rather than with Eigen's
// CompleteOrthogonalDecomposition: for the matrices here (tens of rows) both run at the same
// speed, but every translation unit that includes this library compiles it, and Eigen's version
// costs several seconds of g++ time per unit against a fraction of one here.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace odyn {

/// Relative size below which a pivot of a rank-revealing factorization of constraint equations
/// (Phi_q, the Schur complement S, the dense saddle-point matrix) counts as zero: the equations
/// it belongs to are redundant.
inline constexpr double rank_tolerance = 1e-10;

class RankRevealingQr {
 public:
  RankRevealingQr() = default;
  RankRevealingQr(const Eigen::MatrixXd& a, double threshold) { compute(a, threshold); }

  /// Factorizes a (m x n). The rank is the number of leading diagonal entries |R_kk| above
  /// threshold times the largest one (the first pivot). Allocates nothing when the sizes are
  /// those of the previous call.
  void compute(const Eigen::MatrixXd& a, double threshold) {
    m_ = a.rows();
    n_ = a.cols();
    const Eigen::Index steps = std::min(m_, n_);
    qr_ = a;
    tau_.resize(steps);
    order_.resize(static_cast<std::size_t>(n_));
    for (Eigen::Index j = 0; j < n_; ++j) order_[static_cast<std::size_t>(j)] = static_cast<int>(j);
    double* r = qr_.data();
    for (Eigen::Index k = 0; k < steps; ++k) {
      // The remaining column of largest norm (the first of equal ones) becomes column k.
      Eigen::Index pivot = k;
      double largest = -1.0;
      for (Eigen::Index j = k; j < n_; ++j) {
        const double norm = squared_norm(r + j * m_ + k, m_ - k);
        if (norm > largest) {
          largest = norm;
          pivot = j;
        }
      }
      if (pivot != k) {
        std::swap_ranges(r + k * m_, r + (k + 1) * m_, r + pivot * m_);
        std::swap(order_[static_cast<std::size_t>(k)], order_[static_cast<std::size_t>(pivot)]);
      }
      tau_[k] = make_reflector(r + k * m_ + k, m_ - k);
      for (Eigen::Index j = k + 1; j < n_; ++j)
        apply_reflector(r + k * m_ + k, tau_[k], r + j * m_ + k, m_ - k);
    }
    const double cutoff = steps > 0 ? threshold * std::abs(qr_(0, 0)) : 0.0;
    rank_ = 0;
    while (rank_ < steps && std::abs(qr_(rank_, rank_)) > cutoff) ++rank_;
    // [R11 R12] (the first rank rows of R) = [L^T 0] Z^T, from a QR of its transpose.
    z_.resize(n_, steps);  // the first rank columns are used: a change of rank allocates nothing
    z_tau_.resize(steps);
    for (Eigen::Index i = 0; i < rank_; ++i)
      for (Eigen::Index j = 0; j < n_; ++j) z_(j, i) = j >= i ? qr_(i, j) : 0.0;
    double* z = z_.data();
    for (Eigen::Index k = 0; k < rank_; ++k) {
      z_tau_[k] = make_reflector(z + k * n_ + k, n_ - k);
      for (Eigen::Index j = k + 1; j < rank_; ++j)
        apply_reflector(z + k * n_ + k, z_tau_[k], z + j * n_ + k, n_ - k);
    }
  }

  Eigen::Index rank() const { return rank_; }

  /// The columns of A in pivot order: the first rank() of them are independent, and each later
  /// one depends (within the threshold) on those before it.
  const std::vector<int>& column_order() const { return order_; }

  /// x = the minimum-norm least-squares solution of A x = b (b and x of sizes m and n; x must
  /// not alias b). work (size m) is scratch space, so that a solve allocates nothing.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, Eigen::VectorXd& work) const {
    work = b;
    const Eigen::Index steps = std::min(m_, n_);
    const double* r = qr_.data();
    for (Eigen::Index k = 0; k < steps; ++k)  // Q^T b
      apply_reflector(r + k * m_ + k, tau_[k], work.data() + k, m_ - k);
    // L^T y = (Q^T b)(0 : rank), by forward substitution (L is upper triangular).
    x.setZero(n_);
    for (Eigen::Index i = 0; i < rank_; ++i) {
      double sum = work[i];
      for (Eigen::Index j = 0; j < i; ++j) sum -= z_(j, i) * x[j];
      x[i] = sum / z_(i, i);
    }
    // z = Z [y; 0], applied as the reflectors in reverse order.
    const double* z = z_.data();
    for (Eigen::Index k = rank_ - 1; k >= 0; --k)
      apply_reflector(z + k * n_ + k, z_tau_[k], x.data() + k, n_ - k);
    // x = P z: entry k of z belongs to column order_[k] of A.
    work = x;
    for (Eigen::Index k = 0; k < n_; ++k) x[order_[static_cast<std::size_t>(k)]] = work[k];
  }

  /// The same, allocating its own scratch space.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    Eigen::VectorXd x, work;
    solve(b, x, work);
    return x;
  }

 private:
  static double squared_norm(const double* v, Eigen::Index size) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < size; ++i) sum += v[i] * v[i];
    return sum;
  }

  /// Turns v (size s) into beta e_1 by H = I - tau u u^T with u = (1, v(1:)/(v0 - beta)): stores
  /// beta in v[0] and u(1:) in v(1:), returns tau (0 if v(1:) is already zero).
  static double make_reflector(double* v, Eigen::Index size) {
    const double tail = squared_norm(v + 1, size - 1);
    if (tail == 0.0) return 0.0;
    const double alpha = v[0];
    const double beta = -std::copysign(std::sqrt(alpha * alpha + tail), alpha);
    const double scale = 1.0 / (alpha - beta);
    for (Eigen::Index i = 1; i < size; ++i) v[i] *= scale;
    v[0] = beta;
    return (beta - alpha) / beta;
  }

  /// y <- (I - tau u u^T) y for the reflector stored in v (u_0 = 1 implied).
  static void apply_reflector(const double* v, double tau, double* y, Eigen::Index size) {
    if (tau == 0.0) return;
    double dot = y[0];
    for (Eigen::Index i = 1; i < size; ++i) dot += v[i] * y[i];
    dot *= tau;
    y[0] -= dot;
    for (Eigen::Index i = 1; i < size; ++i) y[i] -= dot * v[i];
  }

  Eigen::Index m_ = 0, n_ = 0, rank_ = 0;
  Eigen::MatrixXd qr_;      // (m x n) R on and above the diagonal, Q's reflectors below it
  Eigen::VectorXd tau_;     // (min(m, n)) Q's reflector factors
  std::vector<int> order_;  // (n) the column of A in each position of A P
  Eigen::MatrixXd z_;       // (n x min(m, n)) in its first rank columns, the QR of
                            // [R11 R12]^T: L on and above the diagonal, Z's reflectors
                            // below it
  Eigen::VectorXd z_tau_;   // Z's reflector factors (the first rank entries)
};

}  // namespace odyn
