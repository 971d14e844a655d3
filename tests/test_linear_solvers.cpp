// The linear algebra under every analysis: the envelope Cholesky of small Schur complements
// against Eigen's dense LLT, and both saddle-point solvers against the system they solve,
// checked through its residual [M Phi_q^T; Phi_q 0] [x; y] - [f; g] with the model's own
// products (mass_times, Phi_q x, Phi_q^T y), which share no code with the factorizations.

#include <Eigen/Cholesky>
#include <catch2/catch.hpp>
#include <vector>

#include "engine_model.hpp"
#include "odyn/linalg/small_cholesky.hpp"

namespace test_linear_solvers {

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
