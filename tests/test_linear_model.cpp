// State-space models about a state (analysis/linear_model.hpp) against closed forms: a swinging
// pendulum's linearized equation, a double pendulum's frequencies and static gain, and Euler's
// equations of a body spinning about its intermediate axis.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include <odyn/analysis/linear_model.hpp>
#include <odyn/odyn.hpp>

#include "spring_plate.hpp"

namespace test_linear_model {

namespace pl = odyn::planar;
namespace sp = odyn::spatial;
using odyn::BodyId;
// The modes tests' model types: in a unity build they share these instantiations.
using PlanarModel = pl::Model<pl::Revolute, pl::Translational, pl::Rsda, pl::Tsda, pl::Gravity>;
using SpatialModel = spring_plate::Model;

constexpr double g = 9.81;

/// Eigenvalues sorted by imaginary part, then real part.
std::vector<std::complex<double>> sorted_eigenvalues(const Eigen::MatrixXd& a) {
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(a, false);
  std::vector<std::complex<double>> out(solver.eigenvalues().data(),
                                        solver.eigenvalues().data() + a.rows());
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) {
    return x.imag() != y.imag() ? x.imag() < y.imag() : x.real() < y.real();
  });
  return out;
}

TEST_CASE("A swinging pendulum linearizes to its equation of motion about the moving state",
          "[linear_model]") {
  // A bar of mass m and length l pinned at its end, its centre d = l / 2 from the pin, at angle
  // theta from hanging straight down and turning at theta': J_O theta'' = -m g d sin(theta) + u
  // with J_O = I + m d^2, u a torque on the bar. About (theta0, theta0') the linear equation is
  // [dtheta; dtheta']' = [0 1; -kappa cos(theta0) 0] [dtheta; dtheta'] + [0; 1 / J_O] u,
  // kappa = m g d / J_O: its own (theta0') is the drift's first entry, theta0'' the second.
  const double m = 1.5, l = 0.8, d = l / 2, inertia = m * l * l / 12, j_o = inertia + m * d * d;
  const double kappa = m * g * d / j_o, theta0 = 2.0, rate0 = 3.0;
  PlanarModel model;
  const Eigen::Vector2d centre(d * std::sin(theta0), -d * std::cos(theta0));
  const Eigen::Vector2d centre_velocity(d * std::cos(theta0) * rate0, d * std::sin(theta0) * rate0);
  const BodyId bar = model.add_body({.name = "bar",
                                     .mass = m,
                                     .inertia = inertia,
                                     .position = centre,
                                     .angle = theta0,
                                     .linear_velocity = centre_velocity,
                                     .angular_velocity = rate0});
  model.add(pl::Revolute("pin", odyn::ground, {}, bar, {{0.0, d}}));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  // Outputs: the free end's x and its rate, x = l sin(theta): dx/dtheta = l cos(theta0).
  const Eigen::Vector2d tip(0.0, -d);
  const std::vector<odyn::LinearOutput<PlanarModel>> outputs{
      {"tip x", [&](const auto& ws) { return ws.frames[1].point(tip).x(); }},
      {"tip x'", [&](const auto& ws) { return ws.frames[1].point_velocity(tip).x(); }}};
  const std::vector<odyn::LinearInput<odyn::Planar>> inputs{
      {.name = "torque", .body = bar, .torque = Eigen::Matrix<double, 1, 1>(1.0)}};
  const double slope = l * std::cos(theta0);
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<PlanarModel> ws(model);
    const odyn::StateSpace s =
        odyn::linearize(model, ws, inputs, outputs, {.coordinates = coordinates});
    REQUIRE(s.a.rows() == 2);
    REQUIRE(s.b.cols() == 1);
    REQUIRE(s.c.rows() == 2);
    // The drift is (c theta0', c theta0'') in any chart z = c dtheta.
    const double acceleration0 = -kappa * std::sin(theta0);
    CHECK(s.drift[1] / s.drift[0] == Approx(acceleration0 / rate0).epsilon(1e-9));
    CHECK(s.outputs[0] == Approx(l * std::sin(theta0)).epsilon(1e-12));
    // The responses of the outputs' rates to the torque hold in every chart: C B is that of
    // x' (x'(theta0) / J_O, at once), C A B that of x'' for x.
    CHECK((s.c * s.b)(1, 0) == Approx(slope / j_o).epsilon(1e-9));
    CHECK(std::abs((s.c * s.b)(0, 0)) < 1e-12);
    CHECK((s.c * s.a * s.b)(0, 0) == Approx(slope / j_o).epsilon(1e-8));
    CHECK(s.d.norm() == 0.0);
    if (std::string(coordinates) == "joint") {
      // The pin's angle is the state itself: A, B and C are the closed form's.
      Eigen::Matrix2d a;
      a << 0.0, 1.0, -kappa * std::cos(theta0), 0.0;
      CHECK((s.a - a).norm() < 1e-9 * kappa);
      CHECK(s.b(0, 0) == Approx(0.0).margin(1e-14));
      CHECK(s.b(1, 0) == Approx(1.0 / j_o).epsilon(1e-12));
      CHECK(s.c(0, 0) == Approx(slope).epsilon(1e-9));
      CHECK(s.c(1, 1) == Approx(slope).epsilon(1e-9));
      // x' = l cos(theta) theta': its slope in theta is -l sin(theta0) theta0'.
      CHECK(s.c(1, 0) == Approx(-l * std::sin(theta0) * rate0).epsilon(1e-9));
    }
    // The workspace holds the state it was linearized about.
    CHECK(ws.v[2] == Approx(rate0).epsilon(1e-12));
    CHECK(ws.vdot[2] == Approx(acceleration0).epsilon(1e-9));
  }
}

TEST_CASE("A double pendulum's state matrix has its two frequencies and its static gain",
          "[linear_model]") {
  // As in test_modes: two uniform bars hanging straight down, M theta'' + K theta = Q in the
  // bars' angles, det(K - w^2 M) = 0. A torque u on the upper bar (Q = (u, 0)) turns it by
  // u / k1 at rest, and moves the lower bar's free end sideways by l1 u / k1: the static gain
  // -C A^-1 B.
  const double m1 = 1.0, l1 = 1.0, m2 = 0.6, l2 = 0.8, d1 = l1 / 2, d2 = l2 / 2;
  const double i1 = m1 * l1 * l1 / 12, i2 = m2 * l2 * l2 / 12;
  const double a = i1 + m1 * d1 * d1 + m2 * l1 * l1, b = m2 * l1 * d2, c = i2 + m2 * d2 * d2;
  const double k1 = (m1 * d1 + m2 * l1) * g, k2 = m2 * d2 * g;
  const double qa = a * c - b * b, qb = -(a * k2 + c * k1), qc = k1 * k2;
  const double root = std::sqrt(qb * qb - 4 * qa * qc);
  const double low = std::sqrt((-qb - root) / (2 * qa)), high = std::sqrt((-qb + root) / (2 * qa));

  PlanarModel model;
  // Slightly off the hanging pose: find_equilibrium brings it there.
  const BodyId upper = model.add_body(
      {.name = "upper", .mass = m1, .inertia = i1, .position = {0.0, -d1}, .angle = 0.0});
  const BodyId lower = model.add_body(
      {.name = "lower", .mass = m2, .inertia = i2, .position = {0.0, -l1 - d2}, .angle = 0.0});
  model.add(pl::Revolute("shoulder", odyn::ground, {}, upper, {{0.0, d1}}));
  model.add(pl::Revolute("elbow", upper, {{0.0, -d1}}, lower, {{0.0, d2}}));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  const std::vector<odyn::LinearInput<odyn::Planar>> inputs{
      {.name = "shoulder torque", .body = upper, .torque = Eigen::Matrix<double, 1, 1>(1.0)}};
  const std::vector<odyn::LinearOutput<PlanarModel>> outputs{
      {"end x",
       [end = Eigen::Vector2d(0.0, -d2)](const auto& ws) { return ws.frames[2].point(end).x(); }}};
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<PlanarModel> ws(model);
    const odyn::StateSpace s = odyn::linearize(
        model, ws, inputs, outputs, {.coordinates = coordinates, .find_equilibrium = true});
    REQUIRE(s.a.rows() == 4);
    CHECK(s.drift.norm() < 1e-10);
    const auto values = sorted_eigenvalues(s.a);
    const double expected[4] = {-high, -low, low, high};
    for (int i = 0; i < 4; ++i) {
      CHECK(std::abs(values[static_cast<std::size_t>(i)].real()) < 1e-8 * high);
      CHECK(values[static_cast<std::size_t>(i)].imag() == Approx(expected[i]).epsilon(1e-9));
    }
    const double gain = -(s.c * s.a.partialPivLu().solve(s.b))(0, 0);
    CHECK(gain == Approx(l1 / k1).epsilon(1e-8));
  }
}

TEST_CASE("A body spinning about its intermediate axis linearizes to Euler's equations",
          "[linear_model]") {
  // Torque-free, I1 < I2 < I3, spinning at Omega about axis 2: omega' = I^-1 (I omega x omega)
  // has the Jacobian I^-1 ([I omega]x - [omega]x I), whose eigenvalues are 0 and
  // +-Omega sqrt((I2 - I1)(I3 - I2) / (I1 I3)): the spin is unstable. The turn's chart rate,
  // increment_of(q0, q'), has the slope -[omega]x / 2 in the turn and 1 in omega.
  const double i1 = 0.3, i2 = 0.5, i3 = 0.7, spin = 4.0;
  SpatialModel model;
  model.add_body({.name = "top",
                  .mass = 3.0,
                  .inertia = sp::Body::principal(i1, i2, i3),
                  .angular_velocity = Eigen::Vector3d(0.0, spin, 0.0)});
  const Eigen::Vector3d omega(0.0, spin, 0.0);
  const Eigen::Matrix3d inertia = Eigen::Vector3d(i1, i2, i3).asDiagonal();
  const auto cross = [](const Eigen::Vector3d& v) {
    Eigen::Matrix3d out;
    out << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
    return out;
  };
  const Eigen::Matrix3d euler =
      inertia.inverse() * (cross(inertia * omega) - cross(omega) * inertia);
  const double growth = spin * std::sqrt((i2 - i1) * (i3 - i2) / (i1 * i3));
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<SpatialModel> ws(model);
    const odyn::StateSpace s = odyn::linearize(model, ws, {}, {}, {.coordinates = coordinates});
    REQUIRE(s.a.rows() == 12);
    CHECK((s.basis - Eigen::MatrixXd::Identity(6, 6)).norm() == 0.0);
    // State: (travel, turn, velocity, omega).
    CHECK((s.a.block<3, 3>(9, 9) - euler).norm() < 1e-10 * euler.norm());
    CHECK(s.a.block<3, 3>(9, 3).norm() < 1e-10 * euler.norm());
    CHECK((s.a.block<3, 3>(3, 3) + 0.5 * cross(omega)).norm() < 1e-10 * spin);
    CHECK((s.a.block<3, 3>(3, 9) - Eigen::Matrix3d::Identity()).norm() < 1e-10);
    CHECK((s.a.block<3, 3>(0, 6) - Eigen::Matrix3d::Identity()).norm() < 1e-10);
    const auto values = sorted_eigenvalues(s.a);
    double largest = 0.0;
    for (const auto& value : values) largest = std::max(largest, value.real());
    CHECK(largest == Approx(growth).epsilon(1e-9));
    CHECK(s.drift.segment<3>(3).isApprox(omega, 1e-12));
  }
}

TEST_CASE("Linearization refuses outputs and inputs that do not apply", "[linear_model]") {
  PlanarModel model;
  const BodyId bar = model.add_body(
      {.name = "bar", .mass = 1.0, .inertia = 0.1, .position = {0.0, -0.5}, .angle = 0.0});
  model.add(pl::Revolute("pin", odyn::ground, {}, bar, {{0.0, 0.5}}));
  CHECK_THROWS_WITH(odyn::element_linear_output(model, "pin", "angle"),
                    Catch::Contains("the element reports none"));
  CHECK_THROWS_WITH(odyn::element_linear_output(model, "hinge", "angle"),
                    Catch::Contains("no element of that name"));
  odyn::Workspace<PlanarModel> ws(model);
  const std::vector<odyn::LinearInput<odyn::Planar>> inputs{
      {.name = "push", .body = BodyId{2}, .force = {1.0, 0.0}}};
  CHECK_THROWS_WITH(odyn::linearize(model, ws, inputs),
                    Catch::Contains("push") && Catch::Contains("not one of the model's"));
  CHECK_THROWS_WITH(odyn::linearize(model, ws, {}, {}, {.coordinates = "minimal"}),
                    Catch::Contains("'minimal' unknown"));
}

}  // namespace test_linear_model
