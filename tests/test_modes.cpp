// Natural modes about an equilibrium (analysis/modes.hpp) against analytic spectra, in absolute
// and joint coordinates.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include <odyn/analysis/modes.hpp>
#include <odyn/odyn.hpp>

#include "hinge_chain.hpp"
#include "spring_plate.hpp"

namespace test_modes {

namespace pl = odyn::planar;
using odyn::BodyId;
using PlanarModel = pl::Model<pl::Revolute, pl::Translational, pl::Rsda, pl::Tsda, pl::Gravity>;

constexpr double g = 9.81, two_pi = 2.0 * std::numbers::pi;

TEST_CASE("A double pendulum's two frequencies are the roots of its characteristic equation",
          "[modes]") {
  // Two uniform bars hanging straight down; in their angles, M theta'' + K theta = 0 with
  // M = [I1 + m1 d1^2 + m2 l1^2, m2 l1 d2; m2 l1 d2, I2 + m2 d2^2], K = diag((m1 d1 + m2 l1) g,
  // m2 d2 g); det(K - w^2 M) = 0 is a quadratic in w^2.
  const double m1 = 1.0, l1 = 1.0, m2 = 0.6, l2 = 0.8, d1 = l1 / 2, d2 = l2 / 2;
  const double i1 = m1 * l1 * l1 / 12, i2 = m2 * l2 * l2 / 12;
  const double a = i1 + m1 * d1 * d1 + m2 * l1 * l1, b = m2 * l1 * d2, c = i2 + m2 * d2 * d2;
  const double k1 = (m1 * d1 + m2 * l1) * g, k2 = m2 * d2 * g;
  // (a c - b^2) w^4 - (a k2 + c k1) w^2 + k1 k2 = 0
  const double qa = a * c - b * b, qb = -(a * k2 + c * k1), qc = k1 * k2;
  const double root = std::sqrt(qb * qb - 4 * qa * qc);
  const double low = (-qb - root) / (2 * qa), high = (-qb + root) / (2 * qa);

  PlanarModel model;
  const BodyId upper = model.add_body(
      {.name = "upper", .mass = m1, .inertia = i1, .position = {0.0, -d1}, .angle = 0.0});
  const BodyId lower = model.add_body(
      {.name = "lower", .mass = m2, .inertia = i2, .position = {0.0, -l1 - d2}, .angle = 0.0});
  model.add(pl::Revolute("shoulder", odyn::ground, {}, upper, {{0.0, d1}}));
  model.add(pl::Revolute("elbow", upper, {{0.0, -d1}}, lower, {{0.0, d2}}));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<PlanarModel> ws(model);
    const odyn::Modes modes = odyn::natural_modes(model, ws, {.coordinates = coordinates});
    REQUIRE(modes.squared_frequencies.size() == 2);
    CHECK(modes.squared_frequencies[0] == Approx(low).epsilon(1e-10));
    CHECK(modes.squared_frequencies[1] == Approx(high).epsilon(1e-10));
    CHECK(modes.frequencies[0] == Approx(std::sqrt(low) / two_pi).epsilon(1e-10));
    // Undamped: the state matrix's eigenvalues are +-i w, no damping.
    REQUIRE(modes.natural_frequencies.size() == 2);
    CHECK(modes.natural_frequencies[1] == Approx(std::sqrt(high) / two_pi).epsilon(1e-10));
    CHECK(std::abs(modes.damping_ratios[0]) < 1e-10);
    // The lower mode swings both bars the same way: the shoulder and the elbow turn alike in
    // the shape's joint rates, or the bars' angles share a sign.
    const Eigen::VectorXd shape = modes.shapes.col(0);
    if (std::string(coordinates) == "absolute")
      CHECK(shape[2] * shape[5] > 0.0);
    else
      CHECK(shape[0] * (shape[0] + shape[1]) > 0.0);
  }
}

// N blocks of mass m on a line, each on a slide along x, joined by springs of stiffness k and
// to the walls at both ends: w_j = 2 sqrt(k / m) sin(j pi / (2 (N + 1))).
PlanarModel spring_chain(int blocks, double mass, double stiffness, double damping) {
  PlanarModel model;
  BodyId previous = odyn::ground;
  for (int i = 1; i <= blocks; ++i) {
    const std::string name = "block" + std::to_string(i);
    const BodyId block =
        model.add_body({.name = name, .mass = mass, .inertia = 0.01, .position = {double(i), 0.0}});
    model.add(pl::Translational("slide" + std::to_string(i), odyn::ground,
                                {{double(i), 0.0}, {1.0, 0.0}}, block, {{0.0, 0.0}, {1.0, 0.0}}));
    // The first spring's end on the ground is the origin, the others' the block's centre.
    model.add(pl::Tsda("spring" + std::to_string(i), previous, {0.0, 0.0}, block, {0.0, 0.0},
                       {.stiffness = stiffness, .damping = damping, .free_length = 1.0}));
    previous = block;
  }
  model.add(pl::Tsda("spring" + std::to_string(blocks + 1), previous, {0.0, 0.0}, odyn::ground,
                     {double(blocks + 1), 0.0},
                     {.stiffness = stiffness, .damping = damping, .free_length = 1.0}));
  return model;
}

TEST_CASE("A chain of masses and springs has the analytic spectrum", "[modes]") {
  const int n = 6;
  const double m = 2.0, k = 100.0;
  const PlanarModel model = spring_chain(n, m, k, 0.0);
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<PlanarModel> ws(model);
    const odyn::Modes modes = odyn::natural_modes(model, ws, {.coordinates = coordinates});
    REQUIRE(modes.frequencies.size() == n);
    for (int j = 1; j <= n; ++j) {
      const double w = 2.0 * std::sqrt(k / m) * std::sin(j * std::numbers::pi / (2.0 * (n + 1)));
      CHECK(modes.frequencies[j - 1] == Approx(w / two_pi).epsilon(1e-10));
    }
  }
}

TEST_CASE("A damped oscillator's damping ratio and damped frequency", "[modes]") {
  // One block between two spring-dampers: k_total = 2 k, c_total = 2 c.
  const double m = 2.0, k = 50.0, c = 1.5;
  const double wn = std::sqrt(2 * k / m), zeta = 2 * c / (2.0 * std::sqrt(2 * k * m));
  const PlanarModel model = spring_chain(1, m, k, c);
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<PlanarModel> ws(model);
    const odyn::Modes modes = odyn::natural_modes(model, ws, {.coordinates = coordinates});
    REQUIRE(modes.eigenvalues.size() == 1);
    CHECK(modes.natural_frequencies[0] == Approx(wn / two_pi).epsilon(1e-10));
    CHECK(modes.damping_ratios[0] == Approx(zeta).epsilon(1e-10));
    CHECK(modes.damped_frequencies[0] ==
          Approx(wn * std::sqrt(1 - zeta * zeta) / two_pi).epsilon(1e-10));
    CHECK(modes.frequencies[0] == Approx(wn / two_pi).epsilon(1e-10));  // undamped
  }
}

TEST_CASE("Modes about a pose that is not an equilibrium are refused by coordinate", "[modes]") {
  PlanarModel model = spring_chain(2, 1.0, 10.0, 0.0);
  model.add(pl::Gravity("gravity", {-9.81, 0.0}));  // along the slides: the springs stretch
  odyn::Workspace<PlanarModel> ws(model);
  CHECK_THROWS_WITH(
      odyn::natural_modes(model, ws, {.find_equilibrium = false}),
      Catch::Contains("not one: a force imbalance") && Catch::Contains("on block1.x"));
  CHECK_THROWS_WITH(odyn::natural_modes(model, ws, {.coordinates = "auto"}),
                    Catch::Contains("coordinates 'auto' unknown"));
  // Found first, the equilibrium gives the same spectrum as without the load (linear springs).
  const odyn::Modes modes = odyn::natural_modes(model, ws);
  CHECK(modes.frequencies[0] ==
        Approx(2 * std::sqrt(10.0) * std::sin(std::numbers::pi / 6) / two_pi).epsilon(1e-10));
}

TEST_CASE("A spring-hung plate's three frequencies are those of its small free vibrations",
          "[modes]") {
  using Model = spring_plate::Model;
  using Space = Model::Space;
  const spring_plate::SpringPlate plate;
  const Model model = plate.model();
  odyn::Workspace<Model> ws(model);
  const odyn::Modes modes = odyn::natural_modes(model, ws);
  REQUIRE(modes.frequencies.size() == 3);
  odyn::Workspace<Model> in_joints(model);
  const odyn::Modes joint = odyn::natural_modes(model, in_joints, {.coordinates = "joint"});
  // The ball joint's modes, as the plate's motion, are the absolute coordinates' (up to sign).
  CHECK(modes.body_shapes == modes.shapes);
  for (int k = 0; k < 3; ++k) {
    CHECK(joint.frequencies[k] == Approx(modes.frequencies[k]).epsilon(1e-10));
    const Eigen::VectorXd a = modes.body_shapes.col(k), b = joint.body_shapes.col(k);
    CHECK(std::min((a - b).norm(), (a + b).norm()) < 1e-8 * a.norm());
  }

  // Released from the equilibrium moved 1e-4 rad along one mode, the plate swings in that mode
  // alone: its modal coordinate z = shape^T M (displacement) crosses zero every half period.
  const Eigen::VectorXd rest = ws.q;
  const Eigen::Matrix3d rest_rotation = ws.frames[1].rotation;
  const auto& body = model.body(BodyId{1});
  for (int mode = 0; mode < 3; ++mode) {
    CAPTURE(mode);
    const Eigen::Matrix<double, 6, 1> shape = modes.shapes.col(mode);
    const double period = 1.0 / modes.frequencies[mode];
    odyn::Workspace<Model> run(model);
    Space::integrate(rest, (1e-4 / shape.tail<3>().norm()) * shape, run.q);
    run.v.setZero();
    odyn::DynamicsSettings s;
    s.integrator = "dop853";
    s.coordinates = "absolute";
    s.rtol = s.atol = 1e-12;
    s.t_end = 3.3 * period;
    s.output_interval = period / 400;
    std::vector<double> crossings;
    double last_t = 0.0, last_z = 0.0;
    odyn::simulate(model, run, s, [&](const odyn::Workspace<Model>& state) {
      const Eigen::AngleAxisd turn(rest_rotation.transpose() * state.frames[1].rotation);
      const Eigen::Vector3d travel = state.frames[1].position - rest.head<3>();
      const double z = body.mass * shape.head<3>().dot(travel) +
                       shape.tail<3>().dot(body.inertia * (turn.angle() * turn.axis()));
      if (state.t > 0.0 && (z > 0.0) != (last_z > 0.0))
        crossings.push_back(last_t + (state.t - last_t) * last_z / (last_z - z));
      last_t = state.t;
      last_z = z;
    });
    REQUIRE(crossings.size() >= 6);
    const double measured =
        2.0 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    CHECK(1.0 / measured == Approx(modes.frequencies[mode]).epsilon(1e-8));
  }
}

TEST_CASE("The sparse path gives a long spring chain's lowest frequencies", "[modes]") {
  // 300 blocks: 900 velocity coordinates, over the automatic method's threshold, so statics and
  // modes both run sparse; the lowest 20 of the analytic spectrum, as the dense test's.
  const int n = 300;
  const double m = 2.0, k = 100.0;
  const PlanarModel model = spring_chain(n, m, k, 0.0);
  odyn::Workspace<PlanarModel> ws(model);
  const odyn::Modes modes = odyn::natural_modes(model, ws, {.count = 20});
  REQUIRE(modes.frequencies.size() == 20);
  for (int j = 1; j <= 20; ++j) {
    const double w = 2.0 * std::sqrt(k / m) * std::sin(j * std::numbers::pi / (2.0 * (n + 1)));
    CHECK(modes.frequencies[j - 1] == Approx(w / two_pi).epsilon(1e-10));
    // Nothing damps: the damped modes are the undamped ones.
    CHECK(modes.natural_frequencies[j - 1] == Approx(w / two_pi).epsilon(1e-10));
    CHECK(modes.damping_ratios[j - 1] == 0.0);
  }
  // Shapes are mass-normalized and move each block along its slide only.
  const Eigen::VectorXd shape = modes.shapes.col(0);
  CHECK(m * shape(Eigen::seq(0, Eigen::last, 3)).squaredNorm() ==
        Approx(1.0 - 0.01 * shape(Eigen::seq(2, Eigen::last, 3)).squaredNorm()).epsilon(1e-12));
  CHECK(shape(Eigen::seq(1, Eigen::last, 3)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(modes.linearization.mass.size() == 0);  // the sparse path forms no reduced matrices

  // With dampers the damped modes are left to the dense method.
  const PlanarModel damped = spring_chain(n, m, k, 0.5);
  odyn::Workspace<PlanarModel> damped_ws(damped);
  const odyn::Modes undamped_only = odyn::natural_modes(damped, damped_ws, {.count = 5});
  CHECK(undamped_only.frequencies.size() == 5);
  CHECK(undamped_only.eigenvalues.size() == 0);
}

TEST_CASE("Sparse statics and modes of a hanging chain agree with the dense joint coordinates",
          "[modes]") {
  // 40 hinged links turned by 0.3 rad: statics bring the chain down (sparse Newton in absolute
  // coordinates, against Newton on a dense tangent in joint coordinates), then the lowest 8
  // modes (shift-invert Lanczos, against the dense generalized eigenproblem).
  const hinge_chain::Model model = hinge_chain::build(40, 0.3);
  odyn::Workspace<hinge_chain::Model> sparse_ws(model), joint_ws(model);
  const odyn::Modes sparse =
      odyn::natural_modes(model, sparse_ws, {.count = 8, .method = "sparse"});
  const odyn::Modes joint =
      odyn::natural_modes(model, joint_ws, {.coordinates = "joint", .count = 8});
  REQUIRE(sparse.frequencies.size() == 8);
  REQUIRE(sparse.natural_frequencies.size() == 8);
  REQUIRE(joint.frequencies.size() == 8);
  for (int b = 1; b <= model.num_bodies(); ++b)
    CHECK((sparse_ws.frames[b].position - joint_ws.frames[b].position).norm() < 1e-10);
  for (int k = 0; k < 8; ++k) {
    CAPTURE(k);
    CHECK(sparse.frequencies[k] == Approx(joint.frequencies[k]).epsilon(1e-9));
    // Nothing damps (C is rounding, 1e-28): the damped modes are the undamped ones.
    CHECK(sparse.natural_frequencies[k] == Approx(joint.frequencies[k]).epsilon(1e-9));
    const Eigen::VectorXd a = sparse.body_shapes.col(k), b = joint.body_shapes.col(k);
    CHECK(std::min((a - b).norm(), (a + b).norm()) < 1e-7 * a.norm());
  }
  // Statics alone, sparse against dense in the same coordinates: the same pose, the same
  // multipliers (the hinges repeat no equation), the same lowest squared frequency.
  odyn::Workspace<hinge_chain::Model> a_ws(model), b_ws(model);
  const odyn::StaticSummary a = odyn::static_equilibrium(model, a_ws, {.method = "sparse"});
  const odyn::StaticSummary b = odyn::static_equilibrium(model, b_ws, {.method = "dense"});
  CHECK((a_ws.q - b_ws.q).cwiseAbs().maxCoeff() < 1e-10);
  CHECK((a_ws.lambda - b_ws.lambda).cwiseAbs().maxCoeff() <
        1e-8 * b_ws.lambda.cwiseAbs().maxCoeff());
  CHECK(a.stability.stable);
  CHECK(a.stability.squared_frequencies[0] ==
        Approx(b.stability.squared_frequencies[0]).epsilon(1e-9));
  CHECK(a.force_residual < 1e-12);
}

TEST_CASE("Shift-invert Lanczos finds a pencil's largest theta through thick restarts", "[modes]") {
  // K = diag(1..200), M = 2 I: Op = K^-1 M has theta_k = 2 / k. A basis of 14 vectors for 6
  // pairs restarts several times; 5 unknowns exhaust the Krylov space before 8 pairs.
  for (const int n : {200, 5}) {
    CAPTURE(n);
    const Eigen::VectorXd k = Eigen::VectorXd::LinSpaced(n, 1.0, double(n));
    const auto apply = [&](const Eigen::Ref<const Eigen::VectorXd>& x,
                           Eigen::Ref<Eigen::VectorXd> y) { y = 2.0 * x.cwiseQuotient(k); };
    const auto mass = [](const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::Ref<Eigen::VectorXd> y) { y = 2.0 * x; };
    const int wanted = n == 200 ? 6 : 8;
    const odyn::LanczosResult found =
        odyn::shift_invert_lanczos(n, wanted, apply, mass, 14, 1e-12, 4000);
    CHECK(found.converged);
    const int pairs = std::min(wanted, n);
    REQUIRE(found.values.size() == pairs);
    if (n == 200) CHECK(found.operator_applications > 14);  // it restarted
    for (int i = 0; i < pairs; ++i) CHECK(found.values[i] == Approx(2.0 / (i + 1)).epsilon(1e-10));
    const Eigen::MatrixXd gram = 2.0 * found.vectors.transpose() * found.vectors;
    CHECK((gram - Eigen::MatrixXd::Identity(pairs, pairs)).cwiseAbs().maxCoeff() < 1e-10);
  }
}

TEST_CASE("A method or count that does not apply is refused by name", "[modes]") {
  const PlanarModel model = spring_chain(2, 1.0, 10.0, 0.0);
  odyn::Workspace<PlanarModel> ws(model);
  CHECK_THROWS_WITH(odyn::natural_modes(model, ws, {.coordinates = "joint", .method = "sparse"}),
                    Catch::Contains("sparse method runs in absolute coordinates"));
  CHECK_THROWS_WITH(odyn::natural_modes(model, ws, {.method = "fast"}),
                    Catch::Contains("method 'fast' unknown"));
  CHECK_THROWS_WITH(odyn::natural_modes(model, ws, {.count = -1}),
                    Catch::Contains("count must be 0 (all) or positive"));
  CHECK_THROWS_WITH(odyn::static_equilibrium(model, ws, {.method = "fast"}),
                    Catch::Contains("method 'fast' unknown"));
  // Dense with a count: the lowest of all modes.
  const odyn::Modes two = odyn::natural_modes(model, ws, {.count = 1, .method = "dense"});
  CHECK(two.frequencies.size() == 1);
  CHECK(two.eigenvalues.size() == 1);
}

}  // namespace test_modes
