// The sparse path for large models, against independent references: the sparse
// factorizations against Eigen's dense ones on systems with a known solution; the sparse
// elimination's independence decisions against dense ranks; every saddle-point factorization
// (dense, CHOLMOD's Schur complement, KLU's whole matrix) against the dense LU on the same
// model matrices; the sparse assembly against the dense one; redundancy named on a large
// model; a chain's small oscillations on the sparse path against the frequencies of its
// minimal-coordinate linearization, written out here from the Lagrangian. (The chain whipping
// round under large constraint forces, a long run, is in test_joint_coordinates.cpp.)

#include <Eigen/Dense>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine_model.hpp"
#include "odyn/linalg/block_sparse.hpp"
#include "odyn/linalg/sparse_basis.hpp"
#include "odyn/linalg/sparse_cholesky.hpp"
#include "odyn/linalg/sparse_lu.hpp"
#include "rope_model.hpp"

namespace test_sparse {

namespace sp = odyn::spatial;
using Eigen::Vector3d;
using ChainModel = rope_model::Model;

/// A deterministic number in [-1, 1] (no structure).
double scrambled(int i, int j, double seed) {
  const auto x = static_cast<double>(i), y = static_cast<double>(j);
  return std::sin(seed + 12.9898 * x + 78.233 * y + 3.7 * x * y * (1.0 + y));
}

/// A block pattern like a model's: 3 x 3 blocks on the diagonal, between neighbours, and a few
/// long-range ones, all in a `blocks` x `blocks` grid.
odyn::BlockSparseMatrix grid_pattern(int blocks, odyn::BlockSparseMatrix::Triangle triangle) {
  odyn::BlockSparseMatrix a;
  a.reset(3 * blocks);
  for (int i = 0; i < blocks; ++i) {
    a.declare(3 * i, 3 * i, 3, 3);
    const int partners[] = {i + 1, (7 * i + 3) % blocks};
    for (const int j : partners) {
      if (j >= blocks || j == i) continue;
      const int lo = std::min(i, j), hi = std::max(i, j);
      a.declare(3 * hi, 3 * lo, 3, 3);
      if (triangle == odyn::BlockSparseMatrix::Triangle::full) a.declare(3 * lo, 3 * hi, 3, 3);
    }
  }
  a.finalize(triangle);
  return a;
}

TEST_CASE("Sparse Cholesky and sparse LU solve like Eigen's dense factorizations", "[sparse]") {
  constexpr int blocks = 40;
  SECTION("Cholesky of a symmetric positive definite matrix (lower triangle stored)") {
    auto a = grid_pattern(blocks, odyn::BlockSparseMatrix::Triangle::lower);
    // Off-diagonal entries in [-1, 1], and a diagonal large enough to dominate.
    for (int id = 0; id < a.num_blocks(); ++id) {
      auto block = a.block(id);
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) block(i, j) = scrambled(id, 3 * i + j, 0.7);
    }
    for (int i = 0; i < blocks; ++i) {
      auto d = a.block<3, 3>(3 * i, 3 * i);
      d = (0.5 * (d + d.transpose())).eval() + 20.0 * Eigen::Matrix3d::Identity();
    }
    a.gather();
    const Eigen::MatrixXd dense = a.to_dense();
    const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(3 * blocks, -1.0, 2.0);
    odyn::SparseCholesky cholesky;
    cholesky.analyze(a.dimension(), a.column_starts(), a.row_indices());
    REQUIRE(cholesky.factorize(a.values()));
    CHECK(cholesky.reciprocal_condition() > 1e-3);
    CHECK(cholesky.smallest_pivot_ratio() > 0.5);  // diagonally dominant
    Eigen::VectorXd x = dense * expected;
    cholesky.solve_in_place(x);
    CHECK((x - expected).norm() <= 1e-12 * expected.norm());
    CHECK((x - dense.llt().solve(dense * expected)).norm() <= 1e-12 * expected.norm());
    // Not positive definite: a negative pivot appears.
    a.block<3, 3>(0, 0) = -Eigen::Matrix3d::Identity();
    CHECK_FALSE(cholesky.factorize(a.gather()));
  }
  SECTION("Cholesky of a dense one (CHOLMOD takes it supernodal)") {
    odyn::BlockSparseMatrix a;
    a.reset(3 * blocks);
    for (int j = 0; j < blocks; ++j)
      for (int i = j; i < blocks; ++i) a.declare(3 * i, 3 * j, 3, 3);
    a.finalize(odyn::BlockSparseMatrix::Triangle::lower);
    for (int id = 0; id < a.num_blocks(); ++id) {
      auto block = a.block(id);
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) block(i, j) = 0.1 * scrambled(id, 3 * i + j, 1.3);
    }
    for (int i = 0; i < blocks; ++i) {
      auto d = a.block<3, 3>(3 * i, 3 * i);
      d = (0.5 * (d + d.transpose())).eval() + 20.0 * Eigen::Matrix3d::Identity();
    }
    a.gather();
    const Eigen::MatrixXd dense = a.to_dense();
    const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(3 * blocks, 3.0, -1.0);
    odyn::SparseCholesky cholesky;
    cholesky.analyze(a.dimension(), a.column_starts(), a.row_indices());
#ifdef ODYN_WITH_SUITESPARSE
    CHECK(cholesky.supernodal());
#endif
    for (int repeat = 0; repeat < 2; ++repeat) {
      REQUIRE(cholesky.factorize(a.values()));
      Eigen::VectorXd x = dense * expected;
      cholesky.solve_in_place(x);
      CHECK((x - expected).norm() <= 1e-12 * expected.norm());
    }
    a.block<3, 3>(6, 6) = -Eigen::Matrix3d::Identity();
    CHECK_FALSE(cholesky.factorize(a.gather()));
  }
  SECTION("LU of an unsymmetric matrix, refactorized with new values, and a singular one") {
    auto a = grid_pattern(blocks, odyn::BlockSparseMatrix::Triangle::full);
    odyn::SparseLu lu;
    lu.analyze(a.dimension(), a.column_starts(), a.row_indices());
    for (const double seed : {0.1, 0.2, 5.0}) {
      INFO("seed " << seed);
      for (int id = 0; id < a.num_blocks(); ++id) {
        auto block = a.block(id);
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) block(i, j) = scrambled(id, 3 * i + j, seed);
      }
      for (int i = 0; i < blocks; ++i) a.block<3, 3>(3 * i, 3 * i).diagonal().array() += 3.0;
      a.gather();
      const Eigen::MatrixXd dense = a.to_dense();
      const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(3 * blocks, 2.0, -1.0);
      REQUIRE(lu.factorize(a.values()));
      Eigen::VectorXd x = dense * expected;
      lu.solve_in_place(x);
      CHECK((x - expected).norm() <= 1e-10 * expected.norm());
      CHECK((x - dense.fullPivLu().solve(dense * expected)).norm() <= 1e-10 * expected.norm());
    }
#ifdef ODYN_WITH_SUITESPARSE
    // The same values again: KLU keeps its pivots (klu_refactor), it does not choose them anew.
    const long pivoting = lu.pivoting_factorizations();
    REQUIRE(lu.factorize(a.values()));
    CHECK(lu.pivoting_factorizations() == pivoting);
#endif
    // Column 4 = column 1: singular.
    for (int id = 0; id < a.num_blocks(); ++id) a.block(id).setZero();
    for (int i = 0; i < blocks; ++i) a.block<3, 3>(3 * i, 3 * i).setIdentity();
    a.block<3, 3>(3, 3).col(1) = a.block<3, 3>(3, 3).col(0);
    CHECK_FALSE(lu.factorize(a.gather()));
  }
}

TEST_CASE("Sparse elimination finds the same dependent vectors as dense ranks", "[sparse]") {
  // Sparse vectors of dimension 60 with 4 entries each; every fifth one is a combination of
  // two earlier ones, plus one vector of zeros and one repeated scaled copy.
  constexpr int dimension = 60;
  std::vector<Eigen::VectorXd> vectors;
  for (int k = 0; k < 80; ++k) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(dimension);
    if (k % 5 == 4) {
      v = 0.3 * vectors[k - 1] - 1.7 * vectors[k / 2];
    } else if (k == 33) {
      v = -2.0 * vectors[10];
    } else if (k != 41) {
      for (int e = 0; e < 4; ++e) v[(3 * k + 7 * e + e * e) % dimension] += scrambled(k, e, 0.4);
    }
    vectors.push_back(v);
  }
  odyn::SparseBasis basis;
  basis.reset(dimension, odyn::rank_tolerance);
  Eigen::MatrixXd so_far(dimension, 0);
  Eigen::Index rank = 0;
  int dependent = 0;
  for (std::size_t k = 0; k < vectors.size(); ++k) {
    std::vector<int> indices;
    std::vector<double> values;
    for (int i = 0; i < dimension; ++i)
      if (vectors[k][i] != 0.0) {
        indices.push_back(i);
        values.push_back(vectors[k][i]);
      }
    so_far.conservativeResize(Eigen::NoChange, so_far.cols() + 1);
    so_far.rightCols(1) = vectors[k];
    const Eigen::Index new_rank = Eigen::FullPivLU<Eigen::MatrixXd>(so_far).rank();
    INFO("vector " << k);
    CHECK(basis.add(indices, values) == (new_rank > rank));
    dependent += new_rank > rank ? 0 : 1;
    rank = new_rank;
  }
  CHECK(basis.rank() == rank);
  CHECK(dependent > 16);
}

/// The rope (tests/rope_model.hpp), a spring-damper of `stiffness` between neighbours' centres
/// if `springs`; with a `speed`, every link is given that velocity along y.
ChainModel chain(int links, bool springs, double stiffness = 40.0, double speed = 0.0) {
  return rope_model::rope(links, speed,
                          springs ? std::optional(sp::Tsda::Parameters{
                                        .stiffness = stiffness, .damping = 0.5, .free_length = 0.9})
                                  : std::nullopt);
}

/// Every factorization's solve of the Newton matrix at the assembled state, against the dense
/// LU's; the gyroscopic terms make the damping block unsymmetric.
template <class Model>
void check_factorizations(const Model& model, bool coupled) {
  odyn::Workspace<Model> ws(model);
  odyn::assemble(model, ws);
  const Eigen::Index size = model.num_velocities() + model.num_equations();
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(size, -1.0, 1.0);
  for (const odyn::IterationFactors factors :
       {odyn::IterationFactors{}, odyn::IterationFactors{1.0, 2.5e-5, 5e-3}}) {
    odyn::DenseSaddlePoint<Model> dense;
    dense.analyze(model);
    REQUIRE(dense.factorize(model, ws, factors));
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(size);
    dense.solve(rhs, expected);
    for (const odyn::LinearSolver choice :
         {odyn::LinearSolver::dense, odyn::LinearSolver::cholmod, odyn::LinearSolver::klu,
          odyn::LinearSolver::automatic}) {
      if (coupled && choice == odyn::LinearSolver::cholmod) continue;
      INFO(odyn::linear_solver_name(choice) << ", stiffness factor " << factors.stiffness);
      odyn::BlockSchurSaddlePoint<Model> solver;
      solver.choose(choice);
      solver.analyze(model);
      REQUIRE(solver.factorize(model, ws, factors));
      Eigen::VectorXd x = Eigen::VectorXd::Zero(size);
      solver.solve(rhs, x);
      // The Schur paths factorize the symmetric part of A on purpose when it is unsymmetric
      // (see saddle_point.hpp): compare those only on the symmetric matrix.
      const bool schur = std::string(solver.path_name()).find("schur") != std::string::npos;
      if (factors.damping == 0.0 || !schur) CHECK((x - expected).norm() <= 1e-10 * expected.norm());
    }
  }
}

TEST_CASE("Every saddle-point factorization solves what the dense LU solves", "[sparse]") {
  SECTION("the spatial engine") {
    engine::Engine e = engine::build();
    check_factorizations(e.model, false);
  }
  SECTION("a chain of 40 links") {
    check_factorizations(chain(40, false), false);
  }
  SECTION("a chain of 40 links with a spring-damper along every link") {
    check_factorizations(chain(40, true), true);
  }
  SECTION("cholmod refuses a model whose force elements couple bodies, by name") {
    odyn::BlockSchurSaddlePoint<ChainModel> solver;
    solver.choose(odyn::LinearSolver::cholmod);
    const ChainModel model = chain(3, true);
    CHECK_THROWS_WITH(solver.analyze(model), Catch::Contains("choose klu"));
  }
  SECTION("automatic choices by size") {
    odyn::BlockSchurSaddlePoint<ChainModel> solver;
    solver.analyze(chain(4, false));
    CHECK(std::string(solver.path_name()) == "dense-schur");
    solver.analyze(chain(200, false));
    CHECK(std::string(solver.path_name()) == "cholmod-schur");
    solver.analyze(chain(6, true));
    CHECK(std::string(solver.path_name()) == "dense-lu");
    // A large model whose springs couple bodies keeps the Schur complement while they are soft.
    solver.analyze(chain(200, true));
    CHECK(std::string(solver.path_name()) == "cholmod-schur");
  }
}

TEST_CASE("Springs between moving bodies: the Schur path while they are soft, else KLU",
          "[sparse]") {
  // Generalized-alpha's Newton matrix at h = 1e-3 (rho_inf 0.9): beta' = 2.6e-7, gamma' = 5.2e-4.
  const odyn::IterationFactors factors{1.0, 2.6e-7, 5.2e-4};
  SECTION("stiff springs take the whole matrix and solve exactly") {
    // k beta' = 1 against unit masses: leaving the couplings out would cost Newton half its
    // contraction; the factorization must take the whole matrix and match the dense LU.
    const ChainModel model = chain(200, true, 4e6);
    odyn::Workspace<ChainModel> ws(model);
    odyn::assemble(model, ws);
    odyn::BlockSchurSaddlePoint<ChainModel> solver, exact;
    solver.analyze(model);
    exact.choose(odyn::LinearSolver::klu);
    exact.analyze(model);
    REQUIRE(solver.factorize(model, ws, factors));
    REQUIRE(exact.factorize(model, ws, factors));
    CHECK(solver.dropped_coupling() > 0.1);
    CHECK(solver.whole_matrix());
    const Eigen::Index size = model.num_velocities() + model.num_equations();
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(size, -1.0, 1.0);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(size), expected = x;
    solver.solve(rhs, x);
    exact.solve(rhs, expected);
    CHECK((x - expected).norm() <= 1e-10 * expected.norm());
  }
  SECTION("soft springs keep the Schur path, and the motion is KLU's") {
    // Springs of 40 N/m and dampers of 0.5 N s/m between unit masses: k beta' + c gamma' = 3e-4,
    // twice that on a link between two. Newton converges to the same steps whichever matrix it
    // iterates with; the two runs agree to well within its tolerance.
    const ChainModel model = chain(200, true);
    odyn::Workspace<ChainModel> ws(model), reference_ws(model);
    odyn::assemble(model, ws);
    odyn::assemble(model, reference_ws);
    {
      odyn::BlockSchurSaddlePoint<ChainModel> solver;
      solver.analyze(model);
      REQUIRE(solver.factorize(model, ws, factors));
      CHECK(solver.dropped_coupling() < 1e-3);
      CHECK_FALSE(solver.whole_matrix());
    }
    odyn::GeneralizedAlpha<ChainModel> integrator(model, ws);
    odyn::GeneralizedAlpha<ChainModel> reference(model, reference_ws,
                                                 {.linear_solver = odyn::LinearSolver::klu});
    for (int k = 0; k < 500; ++k) {
      integrator.step(1e-3);
      reference.step(1e-3);
    }
    const double moved = (ws.q - reference_ws.q).cwiseAbs().maxCoeff();
    INFO("largest difference " << moved << " m");
    CHECK(moved <= 1e-8);
    CHECK(std::abs(ws.q[2]) > 1e-3);  // the first link has fallen
  }
}

TEST_CASE("The sparse assembly gives the dense assembly's state", "[sparse][assembly]") {
  // A 30-link chain started off its joints, with velocities given on every link: some
  // components can be kept, the rest are adjusted; both assemblies must decide alike.
  ChainModel model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < 30; ++i) {
    sp::Body link{.name = "link" + std::to_string(i),
                  .mass = 1.0 + 0.1 * i,
                  .inertia = sp::Body::principal(0.01, 1.0 / 12.0, 0.09),
                  .position = {0.5 + 1.01 * i, 0.02 * std::sin(i), -0.01 * i},
                  .orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * i, Vector3d::UnitZ())),
                  .linear_velocity = {0.1 * std::cos(i), 0.2, 0.0},
                  .angular_velocity = {0.0, 0.0, 0.3}};
    if (i % 3 == 0) link.velocity_given = std::array<bool, 6>{true, true, true, true, true, true};
    const odyn::BodyId body = model.add_body(link);
    const Vector3d on_previous = previous.is_ground() ? Vector3d::Zero() : Vector3d(0.5, 0, 0);
    model.add(
        sp::Spherical("ball" + std::to_string(i), previous, on_previous, body, {-0.5, 0.0, 0.0}));
    previous = body;
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  odyn::Workspace<ChainModel> dense_ws(model), sparse_ws(model);
  const auto dense = odyn::assemble(model, dense_ws, {.linear_solver = odyn::LinearSolver::dense});
  const auto sparse = odyn::assemble(model, sparse_ws, {.linear_solver = odyn::LinearSolver::klu});
  CHECK(sparse.kept_velocity_components == dense.kept_velocity_components);
  CHECK(sparse.adjusted_velocity_components == dense.adjusted_velocity_components);
  CHECK(!dense.adjusted_velocity_components.empty());
  CHECK(!dense.kept_velocity_components.empty());
  // The kept components set velocities of up to about 50 m/s: errors are relative to those.
  // (The dense assembly's rank-revealing QR of the whole matrix leaves a velocity residual of
  // about 1e-10 here, the sparse LU about 2e-12.)
  const auto largest = [](const Eigen::VectorXd& x) { return x.cwiseAbs().maxCoeff(); };
  CHECK(sparse.position_residual <= 1e-12);
  CHECK(sparse.velocity_residual <= 1e-12 * largest(dense_ws.v));
  // Both Newton iterations take minimum-norm steps: the same assembled pose.
  CHECK(largest(sparse_ws.q - dense_ws.q) <= 1e-12);
  CHECK(largest(sparse_ws.v - dense_ws.v) <= 1e-8 * largest(dense_ws.v));
  CHECK(largest(sparse_ws.vdot - dense_ws.vdot) <= 1e-8 * largest(dense_ws.vdot));
  CHECK(largest(sparse_ws.lambda - dense_ws.lambda) <= 1e-8 * largest(dense_ws.lambda));
}

TEST_CASE("A large model's redundant joint is named, and the model still runs", "[sparse]") {
  // 100 links (past the dense assembly's size), and a second ball joint repeating the last
  // one: its three equations repeat the first's.
  ChainModel model = chain(100, false);
  model.add(sp::Spherical("repeated", odyn::BodyId{99}, {0.5, 0.0, 0.0}, odyn::BodyId{100},
                          {-0.5, 0.0, 0.0}));
  odyn::Workspace<ChainModel> ws(model);
  odyn::assemble(model, ws);
  const auto redundant = odyn::redundant_equations(model, ws);
  REQUIRE(redundant.size() == 3);
  for (int k = 0; k < 3; ++k) {
    CHECK(redundant[k].joint == "repeated");
    CHECK(redundant[k].equation == k);
  }
  CHECK_THROWS_WITH(odyn::require_independent_constraints(model, ws),
                    Catch::Contains("repeated (equation"));
  odyn::GeneralizedAlpha<ChainModel> integrator(model, ws);
  for (int k = 0; k < 10; ++k) integrator.step(1e-3);
  // Free fall of the whole chain's start: the links' centres drop as g t^2 / 2 at first, the
  // joint keeps the last two together.
  CHECK(std::abs(ws.q[99 * 7 + 2] - (-0.5 * 9.81 * 0.01 * 0.01)) <= 1e-6);
  CHECK(ws.phi.cwiseAbs().maxCoeff() <= 1e-10);
}

TEST_CASE("Runs after the first start from its checked assembled state", "[sparse][assembly]") {
  // A moving rope (every velocity component given, the assembly keeping what the joints
  // allow), small (dense assembly) and large (sparse), and a large one falling from rest (its
  // Phi_q v' is zero: the check must not take rounding there for a change). The reference for
  // a run that reuses the kept state is the same run assembled from scratch.
  for (const auto& [links, speed] : {std::pair{6, 0.1}, std::pair{120, 0.1}, std::pair{120, 0.0}}) {
    CAPTURE(links, speed);
    const ChainModel model = rope_model::rope(links, speed);
    odyn::DynamicsSettings s;
    s.t_end = 0.02;
    s.step = 1e-3;
    s.output_interval = 0.01;
    const auto ignore = [](const auto&) {};
    odyn::AssembledStart<ChainModel> start;
    odyn::Workspace<ChainModel> plain(model), first(model), second(model);
    const odyn::RunSummary reference = odyn::simulate(model, plain, s, ignore);
    const odyn::RunSummary filled = odyn::simulate(model, first, s, ignore, &start);
    REQUIRE(start.state.has_value());
    const odyn::RunSummary reused = odyn::simulate(model, second, s, ignore, &start);
    CHECK_FALSE(reference.assembly_reused);
    CHECK_FALSE(filled.assembly_reused);
    CHECK(reused.assembly_reused);
    // The same start and the same arithmetic: the same run, to the bit.
    CHECK(second.q == plain.q);
    CHECK(second.lambda == plain.lambda);
    CHECK(reused.assembly.kept_velocity_components == reference.assembly.kept_velocity_components);
    CHECK(reused.statistics.newton_iterations == reference.statistics.newton_iterations);

    // Other assembly settings: assembled afresh (and kept in place of the first).
    odyn::DynamicsSettings klu = s;
    klu.linear_solver = odyn::LinearSolver::klu;
    odyn::Workspace<ChainModel> third(model);
    CHECK_FALSE(odyn::simulate(model, third, klu, ignore, &start).assembly_reused);
    CHECK(start.settings.linear_solver == odyn::LinearSolver::klu);

    // What the check finds in a kept state that no longer fits.
    const odyn::AssemblySettings& settings = start.settings;
    odyn::Workspace<ChainModel> kept = *start.state;
    REQUIRE(odyn::check_assembled(model, kept, settings, start.report) ==
            odyn::AssembledCheck::assembled);
    kept.vdot[2] += 1e-3;  // as after a change of the forces: solve the accelerations again
    CHECK(odyn::check_assembled(model, kept, settings, start.report) ==
          odyn::AssembledCheck::forces_changed);
    odyn::assemble_accelerations(model, kept, settings);
    CHECK((kept.vdot - start.state->vdot).cwiseAbs().maxCoeff() <=
          1e-12 * start.state->vdot.cwiseAbs().maxCoeff());
    kept.v[1] += 1e-3;  // off the velocity constraints
    CHECK(odyn::check_assembled(model, kept, settings, start.report) ==
          odyn::AssembledCheck::not_assembled);
    kept = *start.state;
    kept.q[0] += 1e-9;  // off the position constraints
    CHECK(odyn::check_assembled(model, kept, settings, start.report) ==
          odyn::AssembledCheck::not_assembled);
  }
}

/// A column of `cells` parallelograms in the x-y plane, hanging from the ground under gravity
/// along -y: in each, two links along x (1 m, 1 kg) hinged about z between the previous bar (or
/// the ground) and a bar along y. Every loop of four parallel hinges repeats 3 equations (20
/// equations on 18 coordinates, mobility 1).
using HingedModel = sp::Model<sp::Revolute, sp::Gravity>;
HingedModel hinged_ladder(int cells) {
  HingedModel model;
  const auto hinge = [&](const std::string& name, odyn::BodyId a, const Vector3d& on_a,
                         odyn::BodyId b, const Vector3d& on_b) {
    model.add(sp::Revolute(name, a, sp::JointFrame{on_a, Vector3d::UnitZ()}, b,
                           sp::JointFrame{on_b, Vector3d::UnitZ()}));
  };
  odyn::BodyId previous = odyn::ground;
  for (int cell = 0; cell < cells; ++cell) {
    const std::string c = std::to_string(cell);
    const auto link = [&](const std::string& name, const Vector3d& centre,
                          const Vector3d& inertia) {
      return model.add_body(
          sp::Body{.name = name + c,
                   .mass = 1.0,
                   .inertia = sp::Body::principal(inertia[0], inertia[1], inertia[2]),
                   .position = centre});
    };
    const Vector3d along_x(5e-5, 1.0 / 12.0, 1.0 / 12.0), along_y(1.0 / 12.0, 5e-3, 1.0 / 12.0);
    const odyn::BodyId left = link("left", {cell + 0.5, -0.5, 0.0}, along_x);
    const odyn::BodyId right = link("right", {cell + 0.5, 0.5, 0.0}, along_x);
    const odyn::BodyId bar = link("bar", {cell + 1.0, 0.0, 0.0}, along_y);
    hinge("left-bottom" + c, previous, {0.0, -0.5, 0.0}, left, {-0.5, 0.0, 0.0});
    hinge("left-top" + c, left, {0.5, 0.0, 0.0}, bar, {0.0, -0.5, 0.0});
    hinge("right-bottom" + c, previous, {0.0, 0.5, 0.0}, right, {-0.5, 0.0, 0.0});
    hinge("right-top" + c, right, {0.5, 0.0, 0.0}, bar, {0.0, 0.5, 0.0});
    previous = bar;
  }
  model.add(sp::Gravity("gravity", {0.0, -9.81, 0.0}));
  return model;
}

TEST_CASE("A large over-constrained model stays on the sparse path", "[sparse][redundant]") {
  // 10 parallelograms: 30 bodies, 200 equations of which 30 repeat others (past the dense
  // Schur complement's 120 equations). The reference is
  // the dense solvers' minimum-norm path on the same model; the pinned rows' multipliers
  // differ from it, the constraint forces B^T lambda and the motion do not.
  const HingedModel model = hinged_ladder(10);
  odyn::Workspace<HingedModel> ws(model);
  odyn::assemble(model, ws);
  REQUIRE(odyn::redundant_equations(model, ws).size() == 30);
  const Eigen::Index n = model.num_velocities(), m = model.num_equations();
  SECTION("one factorization against the dense minimum-norm solve") {
    for (const auto& [choice, path] : {std::pair{odyn::LinearSolver::automatic, "cholmod-schur"},
                                       std::pair{odyn::LinearSolver::klu, "klu"}})
      for (const odyn::IterationFactors factors :
           {odyn::IterationFactors{}, odyn::IterationFactors{1.0, 2.5e-5, 0.0}}) {
        INFO(path << ", stiffness factor " << factors.stiffness);
        odyn::BlockSchurSaddlePoint<HingedModel> pinned, dense;
        pinned.choose(choice);
        dense.choose(odyn::LinearSolver::dense);
        pinned.analyze(model);
        dense.analyze(model);
        CHECK(std::string(pinned.path_name()) == path);
        REQUIRE(pinned.factorize(model, ws, factors));
        // Again: now the rows pinned before are looked for first.
        REQUIRE(pinned.factorize(model, ws, factors));
        REQUIRE(dense.factorize(model, ws, factors));
        CHECK(pinned.multipliers_pinned());
        CHECK(pinned.rank_deficiency() == 30);
        CHECK(dense.rank_deficiency() == 30);
        CHECK_FALSE(odyn::needs_minimum_norm_multipliers(pinned));
        CHECK(odyn::needs_minimum_norm_multipliers(dense));
        // A consistent right-hand side: g = B x0 for some x0.
        Eigen::VectorXd x0 = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0), rhs(n + m);
        rhs.head(n) = Eigen::VectorXd::LinSpaced(n, 2.0, -3.0);
        Eigen::VectorXd g(m);
        odyn::jacobian_times(model, ws, x0, g);
        rhs.tail(m) = g;
        Eigen::VectorXd a = Eigen::VectorXd::Zero(n + m), b = Eigen::VectorXd::Zero(n + m);
        pinned.solve(rhs, a);
        dense.solve(rhs, b);
        // Both solve the system (A = M here: no force has stiffness blocks) to rounding, and
        // agree on x to the conditioning of S (long hinged chains: see singular_pivot_ratio).
        const auto residual = [&](const Eigen::VectorXd& solution) {
          Eigen::VectorXd top(n), bottom(m);
          odyn::mass_times(model, solution.head(n), top);
          odyn::add_jacobian_transpose_times(model, ws, solution.tail(m), top);
          odyn::jacobian_times(model, ws, solution.head(n), bottom);
          return std::max((top - rhs.head(n)).cwiseAbs().maxCoeff(),
                          (bottom - g).cwiseAbs().maxCoeff());
        };
        const auto scale = [&](const Eigen::VectorXd& solution) {
          return std::max(rhs.cwiseAbs().maxCoeff(), solution.cwiseAbs().maxCoeff());
        };
        CHECK(residual(a) <= 1e-11 * scale(a));
        CHECK(residual(b) <= 1e-11 * scale(b));
        CAPTURE(residual(a), residual(b), scale(a), scale(b));
        CHECK((a.head(n) - b.head(n)).norm() <= 1e-8 * b.head(n).norm());
        Eigen::VectorXd forces_a = Eigen::VectorXd::Zero(n), forces_b = Eigen::VectorXd::Zero(n);
        odyn::add_jacobian_transpose_times(model, ws, a.tail(m), forces_a);
        odyn::add_jacobian_transpose_times(model, ws, b.tail(m), forces_b);
        CHECK((forces_a - forces_b).norm() <= 1e-8 * forces_b.norm());
        for (const auto& e : odyn::redundant_equations(model, ws)) CHECK(a[n + e.row] == 0.0);
      }
  }
  SECTION("a run against the dense path's run") {
    odyn::DynamicsSettings s;
    s.integrator = "generalized-alpha";
    s.t_end = 0.05;
    s.step = 1e-3;
    s.output_interval = 0.05;
    odyn::Workspace<HingedModel> sparse_ws(model), dense_ws(model);
    const auto ignore = [](const auto&) {};
    const odyn::RunSummary sparse = odyn::simulate(model, sparse_ws, s, ignore);
    s.linear_solver = odyn::LinearSolver::dense;
    const odyn::RunSummary dense = odyn::simulate(model, dense_ws, s, ignore);
    CHECK(sparse.redundant_equations.size() == 30);
    CHECK((sparse_ws.q - dense_ws.q).cwiseAbs().maxCoeff() <= 1e-9);
    CHECK(sparse_ws.phi.cwiseAbs().maxCoeff() <= 1e-10);
    // A parallelogram's bar translates: every bar keeps its orientation (identity).
    for (int cell = 0; cell < 10; ++cell) {
      const Eigen::Vector4d orientation = sparse_ws.q.segment<4>((3 * cell + 2) * 7 + 3);
      CHECK((orientation - Eigen::Vector4d(1, 0, 0, 0)).cwiseAbs().maxCoeff() <= 1e-9);
    }
    // The bars have fallen: the last one by more than 5 mm (free fall: 12 mm).
    CHECK(sparse_ws.q[(3 * 9 + 2) * 7 + 1] < -0.005);
    Eigen::VectorXd forces_sparse = Eigen::VectorXd::Zero(n),
                    forces_dense = Eigen::VectorXd::Zero(n);
    odyn::update_frames(model, sparse_ws);
    odyn::evaluate_constraints(model, sparse_ws);
    odyn::add_jacobian_transpose_times(model, sparse_ws, sparse_ws.lambda, forces_sparse);
    odyn::add_jacobian_transpose_times(model, sparse_ws, dense_ws.lambda, forces_dense);
    CHECK((forces_sparse - forces_dense).cwiseAbs().maxCoeff() <=
          1e-6 * forces_dense.cwiseAbs().maxCoeff());
    CHECK(sparse.statistics.steps == 50);
  }
}

/// Turns a model's initial state rigidly, about a skew axis through the origin: a consistent
/// pose where no Jacobian entry is zero by symmetry.
template <class Model>
void turn_rigidly(const Model& model, odyn::Workspace<Model>& ws) {
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.7, Vector3d(0.3, 0.5, 1.0).normalized()));
  for (int b = 0; b < model.num_bodies(); ++b) {
    ws.q.template segment<3>(7 * b) = turn * Vector3d(ws.q.template segment<3>(7 * b));
    const Eigen::Quaterniond q(ws.q[7 * b + 3], ws.q[7 * b + 4], ws.q[7 * b + 5], ws.q[7 * b + 6]);
    const Eigen::Quaterniond turned = turn * q;
    ws.q.template segment<4>(7 * b + 3) << turned.w(), turned.x(), turned.y(), turned.z();
  }
  odyn::update_frames(model, ws);
  odyn::evaluate_constraints(model, ws);
}

TEST_CASE("Pinned rows are kept while they repeat others, and decided again when they stop",
          "[sparse][redundant]") {
  // The rank pass that decides the pinned rows runs once; a pose where they still repeat
  // others (the ladder turned rigidly) keeps them. Tilting one link's hinges makes its loop's
  // rows independent: the pinned solve then leaves their equations unsolved, the solver sees
  // it, and the next factorization decides again, as the dense rank does.
  const HingedModel model = hinged_ladder(10);
  const Eigen::Index n = model.num_velocities(), m = model.num_equations();
  for (const auto& [choice, path] : {std::pair{odyn::LinearSolver::automatic, "cholmod-schur"},
                                     std::pair{odyn::LinearSolver::klu, "klu"}}) {
    INFO(path);
    odyn::Workspace<HingedModel> ws(model);
    odyn::assemble(model, ws);
    odyn::BlockSchurSaddlePoint<HingedModel> pinned, dense;
    pinned.choose(choice);
    dense.choose(odyn::LinearSolver::dense);
    pinned.analyze(model);
    dense.analyze(model);
    // g = B x0: consistent whatever the rank.
    const auto solve_and_check = [&](double tolerance) {
      const Eigen::VectorXd x0 = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
      Eigen::VectorXd rhs(n + m), g(m), solution = Eigen::VectorXd::Zero(n + m);
      rhs.head(n) = Eigen::VectorXd::LinSpaced(n, 2.0, -3.0);
      odyn::jacobian_times(model, ws, x0, g);
      rhs.tail(m) = g;
      pinned.solve(rhs, solution);
      Eigen::VectorXd top(n), bottom(m);
      odyn::mass_times(model, solution.head(n), top);
      odyn::add_jacobian_transpose_times(model, ws, solution.tail(m), top);
      odyn::jacobian_times(model, ws, solution.head(n), bottom);
      const double residual =
          std::max((top - rhs.head(n)).cwiseAbs().maxCoeff(), (bottom - g).cwiseAbs().maxCoeff());
      const double scale = std::max(rhs.cwiseAbs().maxCoeff(), solution.cwiseAbs().maxCoeff());
      CAPTURE(residual, scale);
      if (tolerance > 0.0)
        CHECK(residual <= tolerance * scale);
      else
        CHECK(residual > 1e-3 * scale);  // the pinned rows' equations, left unsolved
    };
    REQUIRE(pinned.factorize(model, ws, odyn::IterationFactors{}));
    CHECK(pinned.rank_deficiency() == 30);
    solve_and_check(1e-11);
    turn_rigidly(model, ws);
    REQUIRE(pinned.factorize(model, ws, odyn::IterationFactors{}));
    CHECK(pinned.rank_deficiency() == 30);
    CHECK(pinned.pin_decisions() == 1);
    solve_and_check(1e-11);
    // The last cell's left link, tilted by 0.1 rad about its own axis: its two hinges no
    // longer parallel the others of its loop.
    const int link = 3 * 9;
    const Eigen::Quaterniond q(ws.q[7 * link + 3], ws.q[7 * link + 4], ws.q[7 * link + 5],
                               ws.q[7 * link + 6]);
    const Eigen::Quaterniond tilted =
        q * Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Vector3d::UnitX()));
    ws.q.segment<4>(7 * link + 3) << tilted.w(), tilted.x(), tilted.y(), tilted.z();
    odyn::update_frames(model, ws);
    odyn::evaluate_constraints(model, ws);
    REQUIRE(dense.factorize(model, ws, odyn::IterationFactors{}));
    REQUIRE(pinned.factorize(model, ws, odyn::IterationFactors{}));  // the rows kept
    CHECK(pinned.pin_decisions() == 1);
    solve_and_check(-1.0);
    REQUIRE(pinned.factorize(model, ws, odyn::IterationFactors{}));  // decided again
    CHECK(pinned.pin_decisions() == 2);
    CHECK(dense.rank_deficiency() < 30);
    CHECK(pinned.rank_deficiency() == dense.rank_deficiency());
    solve_and_check(1e-11);
  }
}

TEST_CASE("Rank decisions on large models fill in locally at any pose", "[sparse][redundant]") {
  // In row order, pivoting on the largest entries, the elimination's fill grew as N^2 once the
  // bodies were turned (16 s for a 16384-link rope). In the topological order it stays within
  // each joint and each loop: a few entries per row whatever the size.
  SECTION("the rope, turned") {
    for (const int links : {200, 2000}) {
      const ChainModel model = chain(links, false);
      odyn::Workspace<ChainModel> ws(model);
      turn_rigidly(model, ws);
      std::size_t fill = 0;
      const auto independent = odyn::detail::independent_rows(
          model, odyn::detail::sparse_jacobian(model, ws), odyn::rank_tolerance, &fill);
      CHECK(std::count(independent.begin(), independent.end(), 0) == 0);
      CHECK(fill <= 10 * independent.size());
    }
  }
  SECTION("the hinged ladder, turned, against dense ranks") {
    for (const int cells : {8, 400}) {
      const HingedModel model = hinged_ladder(cells);
      odyn::Workspace<HingedModel> ws(model);
      turn_rigidly(model, ws);
      std::size_t fill = 0;
      const auto independent = odyn::detail::independent_rows(
          model, odyn::detail::sparse_jacobian(model, ws), odyn::rank_tolerance, &fill);
      CAPTURE(cells, fill);
      CHECK(std::count(independent.begin(), independent.end(), 0) == 3 * cells);
      CHECK(fill <= 10 * independent.size());
      if (cells <= 8) {
        // The rows kept are a basis: as many as the dense rank, and of full rank themselves.
        const Eigen::MatrixXd jacobian = odyn::detail::dense_jacobian(model, ws);
        Eigen::MatrixXd kept(std::count(independent.begin(), independent.end(), 1),
                             jacobian.cols());
        for (int r = 0, k = 0; r < jacobian.rows(); ++r)
          if (independent[r]) kept.row(k++) = jacobian.row(r);
        const Eigen::Index rank = Eigen::FullPivLU<Eigen::MatrixXd>(jacobian).rank();
        CHECK(kept.rows() == rank);
        CHECK(Eigen::FullPivLU<Eigen::MatrixXd>(kept).rank() == rank);
      }
    }
  }
}

TEST_CASE("A long hinged chain, whose pivots shrink as N^-3, assembles and falls freely",
          "[sparse][large]") {
  // 8192 slender links hinged about y, released from rest along x: the smallest pivot ratios
  // of its sparse factorizations (about 5e-15 for KLU's assembly matrix, 2e-13 for the Schur
  // complement) lie below the ratios that flag a singular matrix, where the rank pass on
  // Phi_q has the last word. Away from the support the links fall freely at first: the
  // reference is z = -g t^2 / 2, which generalized-alpha integrates exactly.
  constexpr int links = 8192;
  HingedModel model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < links; ++i) {
    const odyn::BodyId body =
        model.add_body(sp::Body{.name = "link" + std::to_string(i),
                                .mass = 1.0,
                                .inertia = sp::Body::principal(5e-5, 1.0 / 12.0, 1.0 / 12.0),
                                .position = {0.5 + i, 0.0, 0.0}});
    model.add(
        sp::Revolute("hinge" + std::to_string(i), previous,
                     sp::JointFrame{previous.is_ground() ? Vector3d::Zero() : Vector3d(0.5, 0, 0),
                                    Vector3d::UnitY()},
                     body, sp::JointFrame{Vector3d(-0.5, 0, 0), Vector3d::UnitY()}));
    previous = body;
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  odyn::Workspace<HingedModel> ws(model);
  odyn::DynamicsSettings s;
  s.integrator = "generalized-alpha";
  s.t_end = 0.005;
  s.step = 1e-3;
  s.output_interval = 0.005;
  const odyn::RunSummary summary = odyn::simulate(model, ws, s, [](const auto&) {});
  CHECK(summary.statistics.steps == 5);
  CHECK(summary.redundant_equations.empty());
  CHECK(ws.phi.cwiseAbs().maxCoeff() <= 1e-10);
  const double fall = 9.81 * 0.005 * 0.005 / 2.0;
  for (const int link : {100, links / 2, links - 1}) {
    INFO("link " << link);
    CHECK(std::abs(ws.q[7 * link + 2] + fall) <= 1e-9 * fall);
  }
}

TEST_CASE("A hanging chain on the sparse path swings at its analytic frequencies",
          "[sparse][dynamics]") {
  // N uniform links (mass m, length l, inertia m l^2 / 12 across) hanging from ball joints.
  // Minimal coordinates theta_k (link k's angle from the vertical, in the x-z plane); the
  // Lagrangian's linearization gives M_ij = sum_k m a_ki a_kj + I delta_ij, with a_kj = l
  // (j < k), l / 2 (j = k), 0 (j > k), and K = diag(m g (l (N - 1 - j) + l / 2)). Each mode
  // shape, started at rest with a small amplitude, swings at its own frequency.
  constexpr int links = 6;
  constexpr double m = 1.0, l = 1.0, g = 9.81, inertia = m * l * l / 12.0;
  Eigen::MatrixXd mass = inertia * Eigen::MatrixXd::Identity(links, links);
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(links, links);
  for (int i = 0; i < links; ++i) {
    stiffness(i, i) = m * g * (l * (links - 1 - i) + 0.5 * l);
    for (int j = 0; j < links; ++j)
      for (int k = std::max(i, j); k < links; ++k)
        mass(i, j) += m * (i < k ? l : 0.5 * l) * (j < k ? l : 0.5 * l);
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> modes(stiffness, mass);
  for (const int mode : {0, 2}) {
    const double omega = std::sqrt(modes.eigenvalues()[mode]);
    Eigen::VectorXd theta = modes.eigenvectors().col(mode);
    theta *= 1e-3 / theta.cwiseAbs().maxCoeff();
    ChainModel model;
    odyn::BodyId previous = odyn::ground;
    Vector3d joint = Vector3d::Zero();
    for (int k = 0; k < links; ++k) {
      const Vector3d down(std::sin(theta[k]), 0.0, -std::cos(theta[k]));
      const odyn::BodyId body = model.add_body(
          {.name = "link" + std::to_string(k),
           .mass = m,
           .inertia = sp::Body::principal(inertia, inertia, 1e-4),
           .position = joint + 0.5 * l * down,
           .orientation = Eigen::Quaterniond(Eigen::AngleAxisd(-theta[k], Vector3d::UnitY()))});
      const Vector3d on_previous =
          previous.is_ground() ? Vector3d::Zero() : Vector3d(0, 0, -0.5 * l);
      model.add(sp::Spherical("ball" + std::to_string(k), previous, on_previous, body,
                              {0.0, 0.0, 0.5 * l}));
      joint += l * down;
      previous = body;
    }
    model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
    odyn::Workspace<ChainModel> ws(model);
    odyn::DynamicsSettings settings;
    settings.step = 1e-3;
    settings.output_interval = 1e-3;
    settings.t_end = 3.2 * 2.0 * std::numbers::pi / omega;
    settings.generalized_alpha.rho_inf = 1.0;
    settings.linear_solver = odyn::LinearSolver::cholmod;
    settings.coordinates = "absolute";  // the sparse path (auto would take joint coordinates)
    // The top link's centre crosses x = 0 every half period.
    std::vector<double> crossings;
    double last_t = 0.0, last_x = 0.0;
    const odyn::RunSummary summary =
        odyn::simulate(model, ws, settings, [&](const odyn::Workspace<ChainModel>& w) {
          const double x = w.q[0];
          if (w.t > 0.0 && ((last_x > 0.0 && x <= 0.0) || (last_x < 0.0 && x >= 0.0)))
            crossings.push_back(last_t + (w.t - last_t) * last_x / (last_x - x));
          last_t = w.t;
          last_x = x;
        });
    CHECK(summary.setup_seconds > 0.0);
    CHECK(summary.setup_seconds < summary.wall_seconds);
    INFO("mode " << mode << ", omega " << omega);
    REQUIRE(crossings.size() >= 5);
    const double half_period =
        (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    CHECK(std::abs(std::numbers::pi / half_period - omega) <= 1e-4 * omega);
  }
}

}  // namespace test_sparse

namespace test_sparse {

TEST_CASE("Slender links spinning fast run with the defaults", "[sparse][hard]") {
  // An 8-link ball-jointed chain of slender links (inertia 5e-5 about their axis against 1/12
  // across), whipping about at up to 10 rad/s: at h = 1e-3 the gyroscopic terms in the rows of
  // the thin axis outweigh its inertia, and a Schur complement
  // built on A's symmetric part stalled Newton (this run stopped at t = 3.8 s). The solver
  // takes the whole matrix for those factorizations; the run must match one forced onto the
  // whole matrix (KLU) throughout, and keep its joints.
  ChainModel model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < 8; ++i) {
    const Vector3d centre(0.5 + i, 0.0, 0.0);
    const odyn::BodyId body =
        model.add_body({.name = "link" + std::to_string(i),
                        .mass = 1.0,
                        .inertia = sp::Body::principal(5e-5, 1.0 / 12.0, 1.0 / 12.0),
                        .position = centre,
                        .linear_velocity = 0.1 * Vector3d(-centre.y(), centre.x(), 0.0),
                        .angular_velocity = {0.0, 0.0, 0.1},
                        .velocity_given = std::array<bool, 6>{true, true, true, true, true, true}});
    const Vector3d on_previous = previous.is_ground() ? Vector3d::Zero() : Vector3d(0.5, 0, 0);
    model.add(
        sp::Spherical("ball" + std::to_string(i), previous, on_previous, body, {-0.5, 0.0, 0.0}));
    previous = body;
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  odyn::Workspace<ChainModel> ws(model), whole(model);
  odyn::assemble(model, ws);
  odyn::assemble(model, whole);
  odyn::GeneralizedAlpha<ChainModel> integrator(model, ws);
  odyn::GeneralizedAlpha<ChainModel> reference(model, whole,
                                               {.linear_solver = odyn::LinearSolver::klu});
  double largest_rate = 0.0;
  for (int k = 1; k <= 6000; ++k) {
    integrator.step(1e-3);
    reference.step(1e-3);
    for (int b = 0; b < 8; ++b)
      largest_rate = std::max(largest_rate, ws.v.segment<3>(6 * b + 3).cwiseAbs().maxCoeff());
    // The chain's motion is chaotic: the runs are compared over its first half second.
    if (k == 500) CHECK((ws.q - whole.q).cwiseAbs().maxCoeff() <= 1e-6);
  }
  CHECK(largest_rate > 5.0);  // rad/s: the links did whip about
  CHECK(ws.phi.cwiseAbs().maxCoeff() <= 1e-10);
  CHECK(integrator.statistics().newton_iterations <= 3 * integrator.statistics().steps);
}

}  // namespace test_sparse
