// The linear algebra under every analysis: the envelope Cholesky of small Schur complements
// against Eigen's dense LLT; the saddle-point L D L^T of joint coordinates against systems built
// with a known solution; the pivoted LU and the rank-revealing QR against systems built with
// a known solution, rank and null space; the closed-form principal moments against a rotated
// diagonal tensor; and both saddle-point solvers against the system they solve, checked through
// its residual [M Phi_q^T; Phi_q 0] [x; y] - [f; g] with the model's own products (mass_times,
// Phi_q x, Phi_q^T y), which share no code with the factorizations.

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "engine_model.hpp"
#include "odyn/linalg/pivoted_lu.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/saddle_point_ldlt.hpp"
#include "odyn/linalg/small_cholesky.hpp"
#include "odyn/linalg/symmetric_eigenvalues.hpp"

namespace test_linear_solvers {

/// A deterministic dense matrix with entries in [-1, 1] and no structure (the product term
/// keeps it from being a sum of two separable rank-one terms, as sin(f(i) + g(j)) would be).
Eigen::MatrixXd scrambled(Eigen::Index rows, Eigen::Index cols, double seed) {
  Eigen::MatrixXd a(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < cols; ++j) {
      const auto x = static_cast<double>(i), y = static_cast<double>(j);
      a(i, j) = std::sin(seed + 12.9898 * x + 78.233 * y + 3.7 * x * y * (1.0 + y));
    }
  return a;
}

TEST_CASE("Pivoted LU recovers a known solution and flags a singular matrix", "[linalg]") {
  for (const Eigen::Index n : {1, 5, 35}) {
    INFO("n = " << n);
    const Eigen::MatrixXd a = scrambled(n, n, 0.3);
    const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    const Eigen::VectorXd b = a * expected;
    odyn::PivotedLu lu;
    lu.resize(n);
    lu.compute(a);
    REQUIRE(lu.smallest_pivot() > 1e-6 * lu.largest_entry());
    Eigen::VectorXd x = b;
    lu.solve_in_place(x);
    // Backward stable: a residual at rounding level; the forward error also depends on the
    // matrix's condition (about 1e4 for n = 35).
    CHECK((a * x - b).norm() <= 1e-14 * a.norm() * x.norm());
    CHECK((x - expected).norm() <= 1e-9 * expected.norm());
  }
  // Column 3 = column 0 + column 1: a pivot vanishes to rounding.
  Eigen::MatrixXd singular = scrambled(6, 6, 1.1);
  singular.col(3) = singular.col(0) + singular.col(1);
  odyn::PivotedLu lu;
  lu.compute(singular);
  CHECK(lu.smallest_pivot() <= 1e-14 * lu.largest_entry());
  // The fixed-size elimination of the BDF position update.
  const Eigen::Matrix<double, 7, 7> small = scrambled(7, 7, 2.0);
  const Eigen::Matrix<double, 7, 1> known = Eigen::Matrix<double, 7, 1>::LinSpaced(-3.0, 1.0);
  const Eigen::Matrix<double, 7, 1> solved = odyn::solve_small<7>(small, small * known);
  CHECK((solved - known).norm() <= 1e-12 * known.norm());
}

TEST_CASE("Rank-revealing QR: rank, and minimum-norm least-squares solutions", "[linalg]") {
  // A = B C of rank 3: null(A) = null(C) and range(A) = range(B). The minimum-norm
  // least-squares x satisfies the normal equations A^T (A x - b) = 0 and lies in range(C^T);
  // both are checked with products only.
  for (const auto& [rows, cols] : {std::pair{7, 5}, std::pair{5, 7}, std::pair{4, 4}}) {
    INFO(rows << " x " << cols);
    const Eigen::MatrixXd b_factor = scrambled(rows, 3, 0.5), c_factor = scrambled(3, cols, 1.5);
    const Eigen::MatrixXd a = b_factor * c_factor;
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(rows, 1.0, -2.0);  // inconsistent
    const odyn::RankRevealingQr qr(a, odyn::rank_tolerance);
    CHECK(qr.rank() == 3);
    const Eigen::VectorXd x = qr.solve(rhs);
    CHECK((a.transpose() * (a * x - rhs)).norm() <= 1e-12 * a.norm() * a.norm() * rhs.norm());
    const Eigen::Matrix3d gram = c_factor * c_factor.transpose();
    const Eigen::Vector3d w = gram.inverse() * (c_factor * x);
    CHECK((c_factor.transpose() * w - x).norm() <= 1e-12 * x.norm());
    // The columns it lists after the rank depend on the ones before them.
    const auto& order = qr.column_order();
    Eigen::MatrixXd independent(rows, 3);
    for (int k = 0; k < 3; ++k) independent.col(k) = a.col(order[static_cast<std::size_t>(k)]);
    const Eigen::Matrix3d normal = independent.transpose() * independent;
    for (Eigen::Index k = 3; k < cols; ++k) {
      const Eigen::VectorXd column = a.col(order[static_cast<std::size_t>(k)]);
      const Eigen::Vector3d fit = normal.inverse() * (independent.transpose() * column);
      CHECK((independent * fit - column).norm() <= 1e-10 * column.norm());
    }
  }
  SECTION("full rank: the exact solution") {
    const Eigen::MatrixXd a = scrambled(6, 6, 0.9);
    const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(6, 2.0, -1.0);
    const odyn::RankRevealingQr qr(a, odyn::rank_tolerance);
    CHECK(qr.rank() == 6);
    CHECK((qr.solve(a * expected) - expected).norm() <= 1e-12 * expected.norm());
  }
  SECTION("zero matrix: rank 0 and x = 0") {
    const odyn::RankRevealingQr qr(Eigen::MatrixXd::Zero(3, 4), odyn::rank_tolerance);
    CHECK(qr.rank() == 0);
    CHECK(qr.solve(Eigen::VectorXd::Ones(3)).isZero(0.0));
  }
}

TEST_CASE("Principal moments in closed form equal those of a rotated diagonal tensor", "[linalg]") {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  // A disc's J J 2J, nearly equal moments, a thin rod's, an indefinite tensor.
  for (const Eigen::Vector3d& moments :
       {Eigen::Vector3d(0.5, 2.0, 2.25), Eigen::Vector3d(3.0, 3.0, 3.0),
        Eigen::Vector3d(1.0, 1.0, 2.0), Eigen::Vector3d(1.0, 1.0 + 1e-9, 1.5),
        Eigen::Vector3d(1e-3, 1.0, 1.0), Eigen::Vector3d(-1.0, 0.25, 4.0)}) {
    INFO("moments " << moments.transpose());
    const Eigen::Matrix3d tensor = rotation * moments.asDiagonal() * rotation.transpose();
    const Eigen::Vector3d computed = odyn::symmetric_eigenvalues(tensor);
    CHECK((computed - moments).cwiseAbs().maxCoeff() <= 1e-14 * moments.cwiseAbs().maxCoeff());
    CHECK((odyn::symmetric_eigenvalues(Eigen::Matrix3d(moments.reverse().asDiagonal())) - moments)
              .isZero(0.0));
  }
}

/// A random symmetric positive definite n x n matrix whose column j has no entry below row
/// end[j] - 1 (a band of half-width `band` when end is built from it).
Eigen::MatrixXd banded_spd(Eigen::Index n, Eigen::Index band, std::vector<Eigen::Index>& end) {
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(n, n);
  end.assign(static_cast<std::size_t>(n), 0);
  for (Eigen::Index j = 0; j < n; ++j) {
    end[j] = std::min(n, j + band + 1);
    for (Eigen::Index i = j + 1; i < end[j]; ++i) s(i, j) = s(j, i) = std::sin(1.0 + i * 7 + j);
    s(j, j) = 2.0 * static_cast<double>(band) + 1.0;  // diagonally dominant
  }
  return s;
}

TEST_CASE("Envelope Cholesky solves like a dense LLT and rejects indefinite matrices", "[linalg]") {
  for (const Eigen::Index band : {1, 3, 16}) {
    INFO("band " << band);
    std::vector<Eigen::Index> end;
    const Eigen::MatrixXd s = banded_spd(17, band, end);
    odyn::SmallCholesky cholesky;
    cholesky.resize(17, end);
    REQUIRE(cholesky.compute(s));
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(17, -2.0, 3.0);
    Eigen::VectorXd x = rhs;
    cholesky.solve_in_place(x);
    const Eigen::VectorXd expected = s.llt().solve(rhs);
    CHECK((x - expected).norm() <= 1e-13 * expected.norm());
    CHECK((s * x - rhs).norm() <= 1e-13 * rhs.norm());
    // The smallest pivot bounds the smallest eigenvalue from above.
    CHECK(cholesky.smallest_pivot() >=
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(s).eigenvalues().minCoeff());
  }
  std::vector<Eigen::Index> end;
  Eigen::MatrixXd indefinite = banded_spd(6, 2, end);
  indefinite(3, 3) = -1.0;
  odyn::SmallCholesky cholesky;
  cholesky.resize(6);  // dense envelope
  CHECK_FALSE(cholesky.compute(indefinite));
}

template <class Solver>
void check_solves_engine(const odyn::IterationFactors& factors) {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> ws(e.model);
  odyn::assemble(e.model, ws);
  const Eigen::Index n = e.model.num_velocities(), m = e.model.num_equations();
  Solver solver;
  solver.analyze(e.model);
  // Twice: the second factorization may reuse what the first kept (the mass inverses).
  for (int round = 0; round < 2; ++round) {
    REQUIRE(solver.factorize(e.model, ws, factors));
    CHECK(solver.rank_deficiency() == 0);
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n + m, -1.0, 1.0 + round);
    Eigen::VectorXd solution = Eigen::VectorXd::Zero(n + m);
    solver.solve(rhs, solution);
    // Residual with the model's own products; mass terms only (no stiffness or damping).
    Eigen::VectorXd top(n), bottom(m);
    odyn::mass_times(e.model, solution.head(n), top);
    odyn::add_jacobian_transpose_times(e.model, ws, solution.tail(m), top);
    odyn::jacobian_times(e.model, ws, solution.head(n), bottom);
    CHECK((top - rhs.head(n)).norm() <= 1e-10 * rhs.norm() * (1.0 + solution.norm()));
    CHECK((bottom - rhs.tail(m)).norm() <= 1e-10 * rhs.norm() * (1.0 + solution.norm()));
  }
}

TEST_CASE("Saddle-point L D L^T solves with a known solution at every size, unrolled or not",
          "[linalg]") {
  // Sizes up to max_unrolled_size take the unrolled kernels, larger ones the loops with bounds
  // known at run time; both must give the solution the system was built from.
  for (const Eigen::Index n : {1, 2, 3, 4, 7, 9, 14, 19}) {
    for (const Eigen::Index m : {0, 1, 3, 5}) {
      if (m > n) continue;
      INFO("n = " << n << ", m = " << m);
      const Eigen::MatrixXd g = scrambled(n, n, 0.7 + static_cast<double>(m));
      const Eigen::MatrixXd a = g * g.transpose() + Eigen::MatrixXd::Identity(n, n);
      const Eigen::MatrixXd b = scrambled(m, n, 1.9 + static_cast<double>(n));
      Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n + m, n + m);
      k.topLeftCorner(n, n) = a;
      k.bottomLeftCorner(m, n) = b;
      k.topRightCorner(n, m) = b.transpose();
      const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(n + m, -2.0, 1.5);
      Eigen::VectorXd x = k * expected;
      odyn::SaddlePointLdlt ldlt;
      ldlt.resize(n, m);
      REQUIRE(ldlt.compute(k));
      ldlt.solve_in_place(x);
      CHECK((x - expected).lpNorm<Eigen::Infinity>() < 1e-10);
      // The Schur complement's pivots and diagonal, against S = B A^-1 B^T formed here and
      // its Cholesky factor (pivot i = L(i, i)^2). Without rows there is no S (and Eigen's
      // triangular solve of an empty right-hand side binds a null reference under UBSan).
      if (m == 0) continue;
      const Eigen::MatrixXd schur = b * a.llt().solve(b.transpose());
      const Eigen::MatrixXd lower = schur.llt().matrixL();
      for (int i = 0; i < static_cast<int>(m); ++i) {
        CHECK(std::abs(ldlt.schur_pivot(i) - lower(i, i) * lower(i, i)) <= 1e-10 * schur(i, i));
        CHECK(std::abs(ldlt.schur_diagonal(i) - schur(i, i)) <= 1e-10 * schur(i, i));
      }
    }
  }
  // A singular A (a zero row and column) or repeated rows of B give a pivot of the wrong sign.
  for (const Eigen::Index n : {4, 18}) {
    INFO("n = " << n);
    const Eigen::MatrixXd g = scrambled(n, n, 0.2);
    Eigen::MatrixXd a = g * g.transpose() + Eigen::MatrixXd::Identity(n, n);
    Eigen::MatrixXd b = scrambled(2, n, 0.4);
    b.row(1) = b.row(0);
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n + 2, n + 2);
    k.topLeftCorner(n, n) = a;
    k.bottomLeftCorner(2, n) = b;
    odyn::SaddlePointLdlt ldlt;
    ldlt.resize(n, 2);
    CHECK_FALSE(ldlt.compute(k));
    b.row(1) = scrambled(1, n, 0.9);
    a.row(1).setZero();
    a.col(1).setZero();
    k.topLeftCorner(n, n) = a;
    k.bottomLeftCorner(2, n) = b;
    CHECK_FALSE(ldlt.compute(k));
  }
}

TEST_CASE("Both saddle-point solvers satisfy the engine's mass-constraint system", "[linalg]") {
  SECTION("block Schur") {
    check_solves_engine<odyn::BlockSchurSaddlePoint<engine::Model>>({});
  }
  SECTION("dense LU") {
    check_solves_engine<odyn::DenseSaddlePoint<engine::Model>>({});
  }
  SECTION("block Schur, mass factor 2") {
    // [2M B^T; B 0]: a kept inverse of M must not be reused for 2M.
    engine::Engine e = engine::build();
    odyn::Workspace<engine::Model> ws(e.model);
    odyn::assemble(e.model, ws);
    const Eigen::Index n = e.model.num_velocities(), m = e.model.num_equations();
    odyn::BlockSchurSaddlePoint<engine::Model> schur;
    odyn::DenseSaddlePoint<engine::Model> dense;
    schur.analyze(e.model);
    dense.analyze(e.model);
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n + m, -1.0, 1.0);
    Eigen::VectorXd a = Eigen::VectorXd::Zero(n + m), b = a;
    REQUIRE(schur.factorize(e.model, ws, {}));
    REQUIRE(schur.factorize(e.model, ws, {2.0, 0.0, 0.0}));
    REQUIRE(dense.factorize(e.model, ws, {2.0, 0.0, 0.0}));
    schur.solve(rhs, a);
    dense.solve(rhs, b);
    CHECK((a - b).norm() <= 1e-10 * b.norm());
    // With the stiffness term of the Newton matrix as well (its damping, from the gyroscopic
    // terms, is unsymmetric: the Schur solver then factorizes the symmetric part on purpose).
    const odyn::IterationFactors newton{1.0, 2.5e-9, 0.0};
    REQUIRE(schur.factorize(e.model, ws, newton));
    REQUIRE(dense.factorize(e.model, ws, newton));
    schur.solve(rhs, a);
    dense.solve(rhs, b);
    CHECK((a - b).norm() <= 1e-10 * b.norm());
  }
}

}  // namespace test_linear_solvers
