// Compliant contact (forces/contact.hpp) against independent references:
// - a ball thrown at a plane with no other force leaves at the speed the Hunt-Crossley law's
//   first integral gives, d v_in - ln(1 + d v_in) = -d v_out - ln(1 - d v_out), in space and in
//   the plane, with dop853 and with generalized-alpha;
// - the Newton blocks against the law's derivatives written out here: the normal stiffness
//   n k delta^(n-1) (1 + d delta'), the normal damping k delta^n d, the friction's share of
//   both, and the friction's secant damping mu F_n tanh(s / v_s) / s across the normal;
// - bad parameters are refused by name.

#include <catch2/catch.hpp>
#include <cmath>

#include <odyn/odyn.hpp>

#include "hunt_crossley.hpp"

namespace test_contact {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector2d;
using Eigen::Vector3d;

using hunt_crossley::exit_rate;

TEST_CASE("A ball leaves a plane at the speed of the contact law's first integral", "[contact]") {
  const double v_in = 1.5, d = 0.4, radius = 0.05, mass = 0.3;
  const odyn::ContactLaw law{.stiffness = 1e6, .exponent = 1.5, .dissipation = d};
  const double expected = exit_rate(d, v_in);
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    odyn::DynamicsSettings settings;
    settings.integrator = integrator;
    settings.t_end = 0.03;
    settings.output_interval = 0.03;
    if (settings.integrator == "dop853") {
      settings.rtol = 1e-11;
      settings.atol = 1e-13;
    } else {
      settings.step = 2e-6;
    }
    const double tolerance = settings.integrator == "dop853" ? 1e-8 : 1e-4;
    SECTION(std::string("in space, ") + integrator) {
      sp::DefaultModel model;
      const Vector3d normal(0.0, 0.6, 0.8);
      sp::Body ball{.name = "ball", .mass = mass, .inertia = sp::Body::principal(1e-4, 1e-4, 1e-4)};
      ball.position = (radius + 0.002) * normal;
      ball.linear_velocity = -v_in * normal;
      const auto b = model.add_body(ball);
      model.add(sp::SpherePlane("touch", odyn::ground, {Vector3d::Zero(), normal}, b,
                                Vector3d::Zero(), radius, law));
      odyn::Workspace<sp::DefaultModel> ws(model);
      odyn::simulate(model, ws, settings, [](const auto&) {});
      const Vector3d velocity = ws.v.template head<3>();
      CHECK(std::abs(velocity.dot(normal) - expected) < tolerance * expected);
      CHECK((velocity - velocity.dot(normal) * normal).norm() < 1e-12);
    }
    SECTION(std::string("in the plane, ") + integrator) {
      pl::DefaultModel model;
      const Vector2d normal(0.6, 0.8);
      pl::Body ball{.name = "ball", .mass = mass, .inertia = 1e-4};
      ball.position = (radius + 0.002) * normal;
      ball.linear_velocity = -v_in * normal;
      const auto b = model.add_body(ball);
      model.add(pl::CircleLine("touch", odyn::ground, {Vector2d::Zero(), normal}, b,
                               Vector2d::Zero(), radius, law));
      odyn::Workspace<pl::DefaultModel> ws(model);
      odyn::simulate(model, ws, settings, [](const auto&) {});
      const Vector2d velocity = ws.v.template head<2>();
      CHECK(std::abs(velocity.dot(normal) - expected) < tolerance * expected);
    }
  }
}

TEST_CASE("The contact's Newton blocks match the law's derivatives", "[contact]") {
  // A ball 4 mm into the ground plane z = 0, sinking at 0.2 m/s and sliding along x slower
  // than the slip speed: the friction is then nearly linear in the slip.
  const double k = 2e6, n = 1.5, d = 0.5, mu = 0.4, v_s = 1e-2, radius = 0.1;
  const double depth = 4e-3, sinking = 0.2, slip = 1e-5;
  const sp::SpherePlane contact(
      "c", odyn::ground, {Vector3d::Zero(), Vector3d::UnitZ()}, odyn::BodyId{1}, Vector3d::Zero(),
      radius, {.stiffness = k, .exponent = n, .dissipation = d, .friction = mu, .slip_speed = v_s});
  odyn::Spatial::Frame ground, ball;
  ball.position = Vector3d(0.3, -0.2, radius - depth);
  ball.linear_velocity = Vector3d(slip, 0.0, -sinking);
  odyn::ElementInput<odyn::Spatial, 2> in{{&ground, &ball}, 0.0};
  odyn::ForceBlocks<odyn::Spatial, 2> out;
  contact.evaluate(in, out);
  const double normal = k * std::pow(depth, n) * (1.0 + d * sinking);
  CHECK(out.force[1][2] == Approx(normal).epsilon(1e-12));
  contact.jacobians(in, out);
  // Body b's blocks: rows and columns 6..11; z is 8, x is 6.
  CHECK(out.stiffness(8, 8) ==
        Approx(n * k * std::pow(depth, n - 1.0) * (1.0 + d * sinking)).epsilon(1e-12));
  CHECK(out.damping(8, 8) == Approx(k * std::pow(depth, n) * d).epsilon(1e-12));
  // The friction's block is its secant, mu F_n tanh(s / v_s) / s, along and across the slip.
  const double secant = mu * normal * std::tanh(slip / v_s) / slip;
  CHECK(out.damping(6, 6) == Approx(secant).epsilon(1e-12));
  CHECK(out.damping(7, 7) == Approx(secant).epsilon(1e-12));
  CHECK(std::abs(out.damping(6, 7)) < 1e-9 * secant);
  // The friction follows the normal force: -d(F_x)/dz = -mu tanh(s / v_s) dF_n/d(delta).
  const double friction = mu * std::tanh(slip / v_s);
  CHECK(out.stiffness(6, 8) ==
        Approx(-friction * n * k * std::pow(depth, n - 1.0) * (1.0 + d * sinking)).epsilon(1e-12));
  CHECK(out.damping(6, 8) == Approx(-friction * k * std::pow(depth, n) * d).epsilon(1e-12));
  // Apart, no force and no blocks.
  ball.position.z() = radius + 0.01;
  contact.evaluate(in, out);
  contact.jacobians(in, out);
  CHECK(out.force[1].norm() == 0.0);
  CHECK(out.stiffness.norm() == 0.0);
}

TEST_CASE("Bad contact parameters are refused by name", "[contact]") {
  const auto make = [](double radius, odyn::ContactLaw law, Vector3d normal) {
    return sp::SpherePlane("floor", odyn::ground, {Vector3d::Zero(), normal}, odyn::BodyId{1},
                           Vector3d::Zero(), radius, law);
  };
  const Vector3d up = Vector3d::UnitZ();
  CHECK_THROWS_WITH(make(0.0, {.stiffness = 1.0}, up), Catch::Contains("radius_b"));
  CHECK_THROWS_WITH(make(0.1, {.stiffness = 0.0}, up), Catch::Contains("stiffness"));
  CHECK_THROWS_WITH(make(0.1, {.stiffness = 1.0, .exponent = 0.5}, up),
                    Catch::Contains("exponent"));
  CHECK_THROWS_WITH(make(0.1, {.stiffness = 1.0}, Vector3d::Zero()), Catch::Contains("normal"));
  CHECK_THROWS_WITH(make(0.1, {.stiffness = 1.0, .slip_speed = 0.0}, up),
                    Catch::Contains("slip_speed"));
  CHECK_THROWS_WITH(sp::SphereSphere("pair", odyn::BodyId{1}, {Vector3d::Zero(), 0.1},
                                     odyn::BodyId{1}, Vector3d::Zero(), 0.1, {.stiffness = 1.0}),
                    Catch::Contains("same body"));
}

}  // namespace test_contact
