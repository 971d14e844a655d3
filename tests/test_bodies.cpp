// Point masses and slender rods (spatial/body.hpp, planar/body.hpp, analysis/massless_motion.hpp)
// against references that use no odyn code:
// - a point mass on a massless rod (a distance element) runs round a cone at the closed form's
//   rate, Omega^2 = g / (L cos alpha), and never turns;
// - a slender rod hung from a spherical joint runs round a cone at Omega^2 = 3 g / (2 L cos
//   alpha) without spinning about its axis, which a spherical joint leaves free;
// - a slender rod on a hinge across it, and a point mass on a pendulum's distance element in the
//   plane, swing as the pendulum equations integrated here by RK4 in the one angle;
// - a point mass welded to a swinging arm, a rod on a hinge not across it, and a point mass
//   or a rod given a spin are refused by name;
// - bodies built from parts (spatial/composite.hpp, planar/composite.hpp): their mass
//   properties against hand-worked values, and a rod with a ball at its end, hinged at the
//   rod's other end, swings as the compound pendulum's one-angle equation.

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

namespace test_bodies {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector2d;
using Eigen::Vector3d;
constexpr double pi = std::numbers::pi;
constexpr double g = 9.81;

odyn::DynamicsSettings settings_for(const std::string& integrator, const std::string& coordinates,
                                    double t_end) {
  odyn::DynamicsSettings s;
  s.integrator = integrator;
  s.coordinates = coordinates;
  s.t_end = t_end;
  s.output_interval = t_end / 50;
  s.rtol = 1e-11;
  s.atol = 1e-13;
  s.step = 2e-4;
  return s;
}

/// theta(t_end) of theta'' = -k sin(theta) from theta0 at rest, by classical RK4 at a step of
/// 1e-5 (its error, about h^4, far below the tests' tolerances).
double pendulum_angle(double k, double theta0, double t_end) {
  const int n = static_cast<int>(std::ceil(t_end / 1e-5));
  const double h = t_end / n;
  double theta = theta0, rate = 0.0;
  const auto accel = [k](double x) { return -k * std::sin(x); };
  for (int i = 0; i < n; ++i) {
    const double k1x = rate, k1v = accel(theta);
    const double k2x = rate + 0.5 * h * k1v, k2v = accel(theta + 0.5 * h * k1x);
    const double k3x = rate + 0.5 * h * k2v, k3v = accel(theta + 0.5 * h * k2x);
    const double k4x = rate + h * k3v, k4v = accel(theta + h * k3x);
    theta += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    rate += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  return theta;
}

TEST_CASE("A point mass on a massless rod runs round a cone", "[bodies]") {
  // The bob starts on the cone's circle at the steady rate, and stays on it.
  const double length = 0.8, alpha = 0.6, mass = 0.3;
  const double rate = std::sqrt(g / (length * std::cos(alpha)));
  const double radius = length * std::sin(alpha), depth = -length * std::cos(alpha);
  const double t_end = 3.0 * 2.0 * pi / rate;  // three turns
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      DYNAMIC_SECTION(integrator << ", " << coordinates) {
        sp::DefaultModel model;
        sp::Body bob{.name = "bob", .mass = mass, .position = {radius, 0.0, depth}};
        bob.linear_velocity = {0.0, rate * radius, 0.0};
        const auto b = model.add_body(bob);
        CHECK(model.massless(b).count == 3);
        model.add(sp::Distance("rod", odyn::ground, Vector3d::Zero(), b, Vector3d::Zero(), length));
        model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
        odyn::Workspace<sp::DefaultModel> ws(model);
        double spin = 0.0;
        odyn::simulate(model, ws, settings_for(integrator, coordinates, t_end), [&](const auto& w) {
          spin = std::max(spin, w.v.template tail<3>().norm());
        });
        const double tolerance = std::string(integrator) == "dop853" ? 1e-8 : 2e-4;
        const Vector3d expected(radius * std::cos(rate * t_end), radius * std::sin(rate * t_end),
                                depth);
        CHECK((ws.frames[1].position - expected).norm() < tolerance * length);
        CHECK(spin == 0.0);  // nothing reaches its rotation: it stays exactly still
      }
    }
  }
}

TEST_CASE("A slender rod hung from a spherical joint runs round a cone", "[bodies]") {
  // The rod, along its body z, hangs from its top end at the origin at alpha from the downward
  // vertical. Its angular velocity is Omega about the vertical less the part along the rod,
  // which a slender rod does not have (the spherical joint leaves that spin free).
  const double length = 0.6, alpha = 0.5, mass = 1.5;
  const double rate = std::sqrt(3.0 * g / (2.0 * length * std::cos(alpha)));
  const double t_end = 2.0 * 2.0 * pi / rate;
  const auto axis_at = [&](double t) {  // the rod's direction, from the top end down
    return Vector3d(std::sin(alpha) * std::cos(rate * t), std::sin(alpha) * std::sin(rate * t),
                    -std::cos(alpha));
  };
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      DYNAMIC_SECTION(integrator << ", " << coordinates) {
        sp::DefaultModel model;
        // Body z points up the rod: the top end is at +L/2 on it.
        const Eigen::Quaterniond pose =
            Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), -axis_at(0.0));
        const Vector3d spin_free = rate * (Vector3d::UnitZ() - std::cos(alpha) * -axis_at(0.0));
        sp::Body rod{.name = "rod",
                     .mass = mass,
                     .inertia = sp::Body::slender_rod(mass, length),
                     .position = 0.5 * length * axis_at(0.0),
                     .orientation = pose};
        rod.linear_velocity = Vector3d::UnitZ().cross(rod.position) * rate;
        rod.angular_velocity = pose.conjugate() * spin_free;
        const auto b = model.add_body(rod);
        CHECK(model.massless(b).count == 1);
        CHECK(model.massless(b).axis.cwiseAbs().isApprox(Vector3d::UnitZ()));
        model.add(sp::Spherical("socket", odyn::ground, Vector3d::Zero(), b,
                                Vector3d(0.0, 0.0, 0.5 * length)));
        model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
        odyn::Workspace<sp::DefaultModel> ws(model);
        odyn::simulate(model, ws, settings_for(integrator, coordinates, t_end), [](const auto&) {});
        const double tolerance = std::string(integrator) == "dop853" ? 1e-8 : 2e-4;
        CHECK((ws.frames[1].position - 0.5 * length * axis_at(t_end)).norm() < tolerance * length);
        CHECK((ws.frames[1].rotation * Vector3d::UnitZ() + axis_at(t_end)).norm() < tolerance);
        CHECK(std::abs(ws.frames[1].angular_velocity.z()) < 1e-9 * rate);  // no spin
      }
    }
  }
}

TEST_CASE("A slender rod on a hinge across it swings as a pendulum", "[bodies]") {
  // Hinged at its top end about global y: theta'' = -(3 g / 2 L) sin theta, from 2 rad.
  const double length = 0.9, mass = 0.7, theta0 = 2.0, t_end = 2.5;
  const double expected = pendulum_angle(3.0 * g / (2.0 * length), theta0, t_end);
  for (const char* coordinates : {"absolute", "joint"}) {
    DYNAMIC_SECTION(coordinates) {
      sp::DefaultModel model;
      const Vector3d down(std::sin(theta0), 0.0, -std::cos(theta0));
      const auto b = model.add_body(
          sp::Body{.name = "rod",
                   .mass = mass,
                   .inertia = sp::Body::slender_rod(mass, length),
                   .position = 0.5 * length * down,
                   .orientation = Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), -down)});
      model.add(sp::Revolute("hinge", odyn::ground, {Vector3d::Zero(), Vector3d::UnitY()}, b,
                             {Vector3d(0.0, 0.0, 0.5 * length),
                              model.body(b).orientation.conjugate() * Vector3d::UnitY()}));
      model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
      odyn::Workspace<sp::DefaultModel> ws(model);
      odyn::simulate(model, ws, settings_for("dop853", coordinates, t_end), [](const auto&) {});
      const Vector3d centre = ws.frames[1].position / (0.5 * length);
      CHECK(std::atan2(centre.x(), -centre.z()) == Approx(expected).margin(1e-8));
    }
  }
}

TEST_CASE("A point mass on a massless rod in the plane swings as a pendulum", "[bodies]") {
  const double length = 1.2, theta0 = 2.5, t_end = 3.0;
  const double expected = pendulum_angle(g / length, theta0, t_end);
  for (const char* integrator : {"dop853", "bdf"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      DYNAMIC_SECTION(integrator << ", " << coordinates) {
        pl::DefaultModel model;
        const auto b = model.add_body(
            pl::Body{.name = "bob",
                     .mass = 0.2,
                     .position = {length * std::sin(theta0), -length * std::cos(theta0)}});
        model.add(pl::Distance("rod", odyn::ground, Vector2d::Zero(), b, Vector2d::Zero(), length));
        model.add(pl::Gravity("gravity", Vector2d(0.0, -g)));
        odyn::Workspace<pl::DefaultModel> ws(model);
        odyn::simulate(model, ws, settings_for(integrator, coordinates, t_end), [](const auto&) {});
        const Vector2d at = ws.frames[1].position;
        const double tolerance = std::string(integrator) == "dop853" ? 1e-8 : 1e-4;
        CHECK(std::atan2(at.x(), -at.y()) == Approx(expected).margin(tolerance));
        CHECK(ws.frames[1].angle == 0.0);
      }
    }
  }
}

/// The message of the ModelError that `run` throws, or "" if it throws none.
std::string refusal(const std::function<void()>& run) {
  try {
    run();
  } catch (const odyn::ModelError& e) {
    return e.what();
  }
  return "";
}

TEST_CASE("Point masses and rods that something turns are refused by name", "[bodies]") {
  const odyn::DynamicsSettings s = settings_for("dop853", "absolute", 0.5);
  SECTION("a point mass welded to a swinging arm") {
    sp::DefaultModel model;
    const auto arm = model.add_body(sp::Body{.name = "arm",
                                             .mass = 1.0,
                                             .inertia = sp::Body::principal(0.1, 0.1, 0.01),
                                             .position = {0.5, 0.0, 0.0}});
    const auto bob = model.add_body(sp::Body{.name = "bob", .mass = 0.5, .position = {1, 0, 0}});
    model.add(sp::Revolute("hinge", odyn::ground, {Vector3d::Zero(), Vector3d::UnitY()}, arm,
                           {Vector3d(-0.5, 0.0, 0.0), Vector3d::UnitY()}));
    model.add(sp::Fixed("weld", arm, {Vector3d(0.5, 0.0, 0.0)}, bob, {}));
    model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
    odyn::Workspace<sp::DefaultModel> ws(model);
    const std::string message = refusal([&] { odyn::simulate(model, ws, s, [](const auto&) {}); });
    CHECK_THAT(message, Catch::Contains("bob") && Catch::Contains("a point mass has no inertia") &&
                            Catch::Contains("point joints"));
  }
  SECTION("a slender rod on a hinge that is not across it") {
    sp::DefaultModel model;
    const auto rod = model.add_body(sp::Body{.name = "rod",
                                             .mass = 1.0,
                                             .inertia = sp::Body::slender_rod(1.0, 0.5),
                                             .position = {0.0, 0.0, -0.25}});
    const Vector3d skew = Vector3d(1.0, 0.0, 1.0).normalized();
    model.add(sp::Revolute("hinge", odyn::ground, {Vector3d::Zero(), skew}, rod,
                           {Vector3d(0.0, 0.0, 0.25), skew}));
    model.add(sp::PointForce("push", rod, Vector3d::Zero(), Vector3d(0.0, 1.0, 0.0)));
    odyn::Workspace<sp::DefaultModel> ws(model);
    const std::string message = refusal([&] { odyn::simulate(model, ws, s, [](const auto&) {}); });
    CHECK_THAT(message, Catch::Contains("rod") && Catch::Contains("a slender rod has no inertia "
                                                                  "to turn about its axis"));
  }
  SECTION("a spin given to a point mass or along a rod") {
    sp::DefaultModel model;
    sp::Body bob{.name = "bob", .mass = 1.0};
    bob.angular_velocity = {0.0, 0.0, 1.0};
    CHECK_THROWS_WITH(model.add_body(bob),
                      Catch::Contains("bob") && Catch::Contains("cannot be given an angular"));
    sp::Body rod{.name = "rod", .mass = 1.0, .inertia = sp::Body::slender_rod(1.0, 0.5)};
    rod.angular_velocity = {1.0, 0.0, 0.5};
    CHECK_THROWS_WITH(model.add_body(rod), Catch::Contains("rod") && Catch::Contains("along its"));
    rod.angular_velocity = {1.0, 0.0, 0.0};  // across it: fine
    CHECK_NOTHROW(model.add_body(rod));
    pl::DefaultModel plane;
    CHECK_THROWS_WITH(plane.add_body(pl::Body{.name = "dot", .mass = 1.0, .angular_velocity = 2}),
                      Catch::Contains("dot") && Catch::Contains("point mass"));
  }
  SECTION("a moment missing where no rod or point mass can lack it") {
    sp::DefaultModel model;
    CHECK_THROWS_WITH(
        model.add_body(
            sp::Body{.name = "plate", .mass = 1.0, .inertia = sp::Body::principal(1.0, 2.0, 0.0)}),
        Catch::Contains("plate") && Catch::Contains("triangle"));
  }
}

TEST_CASE("A body built from parts has the parts' mass, centre and inertia", "[bodies]") {
  // A 1 kg rod of 1 m along the parts frame's z, from the origin down, and a 0.5 kg ball (a
  // point) at its lower end: m = 1.5 kg, the centre 2/3 m down; about it, across the rod,
  // 1/12 + 1 (1/2 - 2/3)^2 + 0.5 (1/3)^2 = 1/6 kg m^2, and nothing about the rod's axis.
  const sp::Composite arm("arm", {{.name = "rod",
                                   .mass = 1.0,
                                   .inertia = sp::Body::slender_rod(1.0, 1.0),
                                   .at = {0.0, 0.0, -0.5}},
                                  {.name = "ball", .mass = 0.5, .at = {0.0, 0.0, -1.0}}});
  CHECK(arm.mass() == Approx(1.5));
  CHECK((arm.center_of_mass() - Vector3d(0.0, 0.0, -2.0 / 3.0)).norm() < 1e-15);
  const Eigen::Matrix3d rod_and_ball = Vector3d(1.0 / 6.0, 1.0 / 6.0, 0.0).asDiagonal();
  CHECK((arm.inertia() - rod_and_ball).norm() < 1e-15);
  CHECK((arm.at("ball", Vector3d::Zero()) - Vector3d(0.0, 0.0, -1.0 / 3.0)).norm() < 1e-15);
  CHECK((arm.at(Vector3d::Zero()) - Vector3d(0.0, 0.0, 2.0 / 3.0)).norm() < 1e-15);

  // A part turned a quarter turn about z swaps its x and y moments; one at (1, 2, 0) with
  // another of equal mass at the origin adds m d^2 / 2 across the line between them.
  const sp::Composite turned(
      "turned",
      {{.name = "block",
        .mass = 2.0,
        .inertia = sp::Body::principal(1.0, 2.0, 3.0),
        .at = {1.0, 2.0, 0.0},
        .orientation = Eigen::Quaterniond(Eigen::AngleAxisd(pi / 2.0, Vector3d::UnitZ()))},
       {.name = "weight", .mass = 2.0}});
  // Offsets +-(0.5, 1, 0) from the centre, 2 kg each: m (|d|^2 I - d d^T) summed.
  Eigen::Matrix3d expected = Vector3d(2.0, 1.0, 3.0).asDiagonal();
  const Vector3d d(0.5, 1.0, 0.0);
  expected += 2.0 * 2.0 * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  CHECK((turned.inertia() - expected).norm() < 1e-14);
  CHECK((turned.at("block", Vector3d::UnitX()) - Vector3d(0.5, 2.0, 0.0)).norm() < 1e-15);

  // The body starts where its parts frame puts the centre, moving with the frame.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Vector3d::UnitX()));
  const Vector3d position(1.0, 2.0, 3.0), velocity(0.1, 0.0, 0.0), spin(2.0, 0.0, 0.0);
  const sp::Body body = arm.body(position, q, velocity, spin);
  const Vector3d centre = position + q * Vector3d(0.0, 0.0, -2.0 / 3.0);
  CHECK((body.position - centre).norm() < 1e-15);
  CHECK(
      (body.linear_velocity - (velocity + q * spin.cross(Vector3d(0.0, 0.0, -2.0 / 3.0)))).norm() <
      1e-15);

  // In the plane: a 1 kg disc (0.02 kg m^2) at (0.3, 0) and a 1 kg point at (-0.3, 0).
  const pl::Composite pair("pair", {{.name = "disc", .mass = 1.0, .inertia = 0.02, .at = {0.3, 0}},
                                    {.name = "dot", .mass = 1.0, .at = {-0.3, 0.0}}});
  CHECK(pair.inertia() == Approx(0.02 + 2 * 0.09));
  CHECK(pair.center_of_mass().norm() < 1e-16);
  const pl::Body planar = pair.body({1.0, 0.0}, pi / 2.0, Vector2d::Zero(), 3.0);
  CHECK((planar.position - Vector2d(1.0, 0.0)).norm() < 1e-15);
  CHECK((pair.at("disc", {0.1, 0.0}) - Vector2d(0.4, 0.0)).norm() < 1e-15);

  SECTION("bad parts are refused by name") {
    using Parts = std::vector<sp::Part>;
    CHECK_THROWS_WITH(sp::Composite("arm", Parts{}), Catch::Contains("at least one part"));
    CHECK_THROWS_WITH(sp::Composite("arm", Parts{{.name = "rod", .mass = 0.0}}),
                      Catch::Contains("arm part 'rod'") && Catch::Contains("mass > 0"));
    CHECK_THROWS_WITH(
        sp::Composite("arm", Parts{{.name = "a", .mass = 1.0}, {.name = "a", .mass = 1.0}}),
        Catch::Contains("arm part 'a'") && Catch::Contains("another part has that name"));
    CHECK_THROWS_WITH(
        sp::Composite(
            "arm",
            Parts{{.name = "plate", .mass = 1.0, .inertia = sp::Body::principal(1.0, 2.0, 4.0)}}),
        Catch::Contains("arm part 'plate'") && Catch::Contains("triangle inequality"));
    CHECK_THROWS_WITH(arm.at("hub", Vector3d::Zero()),
                      Catch::Contains("no part named 'hub'; its parts: rod, ball"));
    CHECK_THROWS_WITH(pl::Composite("pair", {{.name = "disc", .mass = 1.0, .inertia = -1.0}}),
                      Catch::Contains("pair part 'disc'") && Catch::Contains(">= 0"));
  }
}

TEST_CASE("A rod with a ball at its end, built from parts, swings as a compound pendulum",
          "[bodies]") {
  // Hinged at the rod's free end (the parts frame's origin) about y: I_O theta'' = -m g d
  // sin theta with I_O = 1/3 + 0.5 kg m^2, m = 1.5 kg, d = 2/3 m.
  const double theta0 = 1.2, t_end = 2.0;
  const double expected = pendulum_angle(1.5 * g * (2.0 / 3.0) / (1.0 / 3.0 + 0.5), theta0, t_end);
  const sp::Composite arm("arm", {{.name = "rod",
                                   .mass = 1.0,
                                   .inertia = sp::Body::slender_rod(1.0, 1.0),
                                   .at = {0.0, 0.0, -0.5}},
                                  {.name = "ball", .mass = 0.5, .at = {0.0, 0.0, -1.0}}});
  for (const char* coordinates : {"absolute", "joint"}) {
    DYNAMIC_SECTION(coordinates) {
      sp::DefaultModel model;
      const auto b = model.add_body(arm.body(
          Vector3d::Zero(), Eigen::Quaterniond(Eigen::AngleAxisd(theta0, Vector3d::UnitY()))));
      model.add(sp::Revolute("hinge", odyn::ground, {Vector3d::Zero(), Vector3d::UnitY()}, b,
                             {arm.at(Vector3d::Zero()), Vector3d::UnitY()}));
      model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
      odyn::Workspace<sp::DefaultModel> ws(model);
      odyn::simulate(model, ws, settings_for("dop853", coordinates, t_end), [](const auto&) {});
      const Vector3d centre = ws.frames[1].position;
      CHECK(std::atan2(-centre.x(), -centre.z()) == Approx(expected).margin(1e-8));
    }
  }
}

}  // namespace test_bodies
