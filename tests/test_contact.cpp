// Compliant contact (forces/contact.hpp) against independent references:
// - a ball thrown at a plane with no other force leaves at the speed the Hunt-Crossley law's
//   first integral gives, d v_in - ln(1 + d v_in) = -d v_out - ln(1 - d v_out), in space and in
//   the plane, with dop853 and with generalized-alpha;
// - the Newton blocks against the law's derivatives written out here: the normal stiffness
//   n k delta^(n-1) (1 + d delta'), the normal damping k delta^n d, the friction's share of
//   both, and the friction's secant damping mu F_n tanh(s / v_s) / s across the normal;
// - bad parameters are refused by name;
// - a box (rectangle) landing flat leaves at the same first-integral speed, its corners sharing
//   the load; a box, a rectangle and a planar capsule sliding on a slope accelerate at
//   g (sin alpha - mu cos alpha); a capsule lying across a slope rolls at
//   g sin alpha / (1 + I / (m rho^2)), rho the lever arm of its contact points;
// - a capsule's forces and blocks are those of two spheres at its ends.

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

TEST_CASE("A box lands flat on its four corners and leaves at the first integral's speed",
          "[contact]") {
  // Each corner carries a quarter of the mass by the same law, so the box leaves as a ball
  // would: v_out depends on d v_in only. Landing flat, it does not turn.
  const double v_in = 1.5, d = 0.4, mass = 2.0;
  const odyn::ContactLaw law{.stiffness = 1e6, .exponent = 1.0, .dissipation = d};
  const double expected = exit_rate(d, v_in);
  odyn::DynamicsSettings settings;
  settings.integrator = "dop853";
  settings.rtol = 1e-11;
  settings.atol = 1e-13;
  settings.t_end = settings.output_interval = 0.03;
  SECTION("a box on a plane") {
    sp::DefaultModel model;
    const Vector3d half(0.2, 0.1, 0.05);
    sp::Body box{.name = "box", .mass = mass, .inertia = sp::Body::principal(0.01, 0.02, 0.03)};
    box.position = Vector3d(0.3, -0.1, half.z() + 0.002);
    box.linear_velocity = Vector3d(0.0, 0.0, -v_in);
    const auto b = model.add_body(box);
    model.add(sp::BoxPlane("floor", odyn::ground, {Vector3d::Zero(), Vector3d::UnitZ()}, b,
                           {Vector3d::Zero(), half}, law));
    odyn::Workspace<sp::DefaultModel> ws(model);
    odyn::simulate(model, ws, settings, [](const auto&) {});
    CHECK(std::abs(ws.v[2] - expected) < 1e-8 * expected);
    CHECK(ws.v.template head<2>().norm() < 1e-12);
    CHECK(ws.v.template tail<3>().norm() < 1e-10);
    CHECK(odyn::element_output(model, ws, "floor", "points") == 0.0);
  }
  SECTION("a rectangle on a line") {
    pl::DefaultModel model;
    const Vector2d half(0.2, 0.05);
    pl::Body box{.name = "box", .mass = mass, .inertia = 0.02};
    box.position = Vector2d(0.3, half.y() + 0.002);
    box.linear_velocity = Vector2d(0.0, -v_in);
    const auto b = model.add_body(box);
    model.add(pl::RectangleLine("floor", odyn::ground, {Vector2d::Zero(), Vector2d::UnitY()}, b,
                                {Vector2d::Zero(), half}, law));
    odyn::Workspace<pl::DefaultModel> ws(model);
    odyn::simulate(model, ws, settings, [](const auto&) {});
    CHECK(std::abs(ws.v[1] - expected) < 1e-8 * expected);
    CHECK(std::abs(ws.v[0]) < 1e-12);
    CHECK(std::abs(ws.v[2]) < 1e-10);
  }
}

/// The acceleration along x between t = 0.3 s and 0.6 s of body 1 (the solid) in a model whose
/// gravity has the slope's components (the plane z = 0, or y = 0, is the slope).
template <class Model>
double slope_acceleration(const Model& model) {
  odyn::Workspace<Model> ws(model);
  odyn::DynamicsSettings settings;
  settings.integrator = "dop853";
  settings.rtol = 1e-10;
  settings.atol = 1e-12;
  settings.t_end = 0.6;
  settings.output_interval = 0.3;
  double early = 0.0, late = 0.0;
  odyn::simulate(model, ws, settings, [&](const auto& state) {
    (state.t < 0.45 ? early : late) = state.frames[1].linear_velocity.x();
  });
  return (late - early) / 0.3;
}

TEST_CASE("A box, a rectangle and a capsule slide down a slope at g (sin alpha - mu cos alpha)",
          "[contact]") {
  // Sliding much faster than the slip speed, the friction is mu times the normal load at every
  // touching point, and the loads add up to m g cos alpha however they share it. The slope is
  // the plane z = 0 (y = 0 in the plane) under a gravity tilted by alpha; the solid starts at
  // its static penetration, moving down the slope, and its normal vibration dies out.
  const double alpha = 0.4, g = 9.81, mu = 0.3, mass = 2.0, k = 1e6;
  const double expected = g * (std::sin(alpha) - mu * std::cos(alpha));
  const odyn::ContactLaw law{
      .stiffness = k, .exponent = 1.0, .dissipation = 50.0, .friction = mu, .slip_speed = 1e-3};
  SECTION("a box") {
    sp::DefaultModel model;
    const Vector3d half(0.2, 0.1, 0.05);
    sp::Body box{.name = "box", .mass = mass, .inertia = sp::Body::principal(0.01, 0.02, 0.03)};
    box.position = Vector3d(0.0, 0.0, half.z() - mass * g * std::cos(alpha) / (4.0 * k));
    box.linear_velocity = Vector3d(0.5, 0.0, 0.0);
    const auto b = model.add_body(box);
    model.add(sp::BoxPlane("slope", odyn::ground, {Vector3d::Zero(), Vector3d::UnitZ()}, b,
                           {Vector3d::Zero(), half}, law));
    model.add(sp::Gravity("gravity", g * Vector3d(std::sin(alpha), 0.0, -std::cos(alpha))));
    CHECK(slope_acceleration(model) == Approx(expected).epsilon(1e-6));
  }
  SECTION("a rectangle") {
    pl::DefaultModel model;
    const Vector2d half(0.2, 0.05);
    pl::Body box{.name = "box", .mass = mass, .inertia = 0.02};
    box.position = Vector2d(0.0, half.y() - mass * g * std::cos(alpha) / (2.0 * k));
    box.linear_velocity = Vector2d(0.5, 0.0);
    const auto b = model.add_body(box);
    model.add(pl::RectangleLine("slope", odyn::ground, {Vector2d::Zero(), Vector2d::UnitY()}, b,
                                {Vector2d::Zero(), half}, law));
    model.add(pl::Gravity("gravity", g * Vector2d(std::sin(alpha), -std::cos(alpha))));
    CHECK(slope_acceleration(model) == Approx(expected).epsilon(1e-6));
  }
  SECTION("a capsule in the plane, lying along the slope") {
    pl::DefaultModel model;
    const double radius = 0.05;
    pl::Body capsule{.name = "capsule", .mass = mass, .inertia = 0.02};
    capsule.position = Vector2d(0.0, radius - mass * g * std::cos(alpha) / (2.0 * k));
    capsule.linear_velocity = Vector2d(0.5, 0.0);
    const auto b = model.add_body(capsule);
    model.add(pl::CapsuleLine("slope", odyn::ground, {Vector2d::Zero(), Vector2d::UnitY()}, b,
                              {.center = Vector2d::Zero(),
                               .axis = Vector2d::UnitX(),
                               .half_length = 0.2,
                               .radius = radius},
                              law));
    model.add(pl::Gravity("gravity", g * Vector2d(std::sin(alpha), -std::cos(alpha))));
    CHECK(slope_acceleration(model) == Approx(expected).epsilon(1e-6));
  }
}

TEST_CASE("A capsule lying across a slope rolls at g sin alpha / (1 + I / (m rho^2))",
          "[contact]") {
  // Its axis is x, across the slope; it rolls about x on its two end spheres. In steady
  // rolling the contact points creep at a constant slip (the regularized friction's), so the
  // centre accelerates as rho times the angular acceleration, rho = r - delta / 2 the lever arm
  // of the contact point (the midpoint of the overlap delta). Gravity is tilted by alpha in
  // the y-z plane; the capsule starts at rest at its static penetration.
  const double alpha = 0.3, g = 9.81, mass = 1.0, radius = 0.05, k = 1e7, n = 1.5;
  const double inertia = 0.002;  // about the axis
  const double depth = std::pow(mass * g * std::cos(alpha) / (2.0 * k), 1.0 / n);
  const double rho = radius - 0.5 * depth;
  const double expected = g * std::sin(alpha) / (1.0 + inertia / (mass * rho * rho));
  sp::DefaultModel model;
  sp::Body capsule{
      .name = "capsule", .mass = mass, .inertia = sp::Body::principal(inertia, 0.01, 0.01)};
  capsule.position = Vector3d(0.0, 0.0, radius - depth);
  const auto b = model.add_body(capsule);
  const odyn::ContactLaw law{
      .stiffness = k, .exponent = n, .dissipation = 10.0, .friction = 0.5, .slip_speed = 1e-3};
  model.add(sp::CapsulePlane("slope", odyn::ground, {Vector3d::Zero(), Vector3d::UnitZ()}, b,
                             {.center = Vector3d::Zero(),
                              .axis = Vector3d::UnitX(),
                              .half_length = 0.15,
                              .radius = radius},
                             law));
  model.add(sp::Gravity("gravity", g * Vector3d(0.0, std::sin(alpha), -std::cos(alpha))));
  odyn::Workspace<sp::DefaultModel> ws(model);
  odyn::DynamicsSettings settings;
  settings.integrator = "dop853";
  settings.rtol = 1e-10;
  settings.atol = 1e-12;
  settings.t_end = 0.6;
  settings.output_interval = 0.3;
  double early = 0.0, late = 0.0, spin = 0.0;
  odyn::simulate(model, ws, settings, [&](const auto& state) {
    (state.t < 0.45 ? early : late) = state.frames[1].linear_velocity.y();
    spin = (state.frames[1].rotation * state.frames[1].angular_velocity).x();
  });
  CHECK((late - early) / 0.3 == Approx(expected).epsilon(1e-6));
  CHECK(-spin * rho == Approx(late).epsilon(1e-3));  // rolling, up to the creep
  CHECK(odyn::element_output(model, ws, "slope", "points") == 2.0);
  CHECK(odyn::element_output(model, ws, "slope", "normal_force") ==
        Approx(mass * g * std::cos(alpha)).epsilon(1e-5));
}

TEST_CASE("A capsule's forces and Newton blocks are those of two spheres at its ends",
          "[contact]") {
  // The sphere's blocks are checked against the law's derivatives above; a capsule tilted so
  // that one end is deeper than the other, sliding and turning, must sum two of them.
  const odyn::ContactLaw law{
      .stiffness = 2e6, .exponent = 1.5, .dissipation = 0.5, .friction = 0.4, .slip_speed = 1e-2};
  const Vector3d axis = Vector3d(1.0, 0.2, 0.1).normalized(), center(0.01, 0.02, -0.03);
  const double half_length = 0.15, radius = 0.05;
  const odyn::contact_shape::Plane<odyn::Spatial> plane{Vector3d(0.0, 0.0, 0.01),
                                                        Vector3d::UnitZ()};
  const sp::CapsulePlane capsule(
      "c", odyn::ground, plane, odyn::BodyId{1},
      {.center = center, .axis = axis, .half_length = half_length, .radius = radius}, law);
  const sp::SpherePlane low("low", odyn::ground, plane, odyn::BodyId{1},
                            center - half_length * axis, radius, law);
  const sp::SpherePlane high("high", odyn::ground, plane, odyn::BodyId{1},
                             center + half_length * axis, radius, law);
  odyn::Spatial::Frame ground, body;
  body.position = Vector3d(0.3, -0.2, 0.065);
  body.rotation = Eigen::AngleAxisd(0.1, Vector3d(0.2, 1.0, 0.3).normalized()).toRotationMatrix();
  body.linear_velocity = Vector3d(0.02, -0.01, -0.2);
  body.angular_velocity = Vector3d(0.3, -0.5, 0.7);
  odyn::ElementInput<odyn::Spatial, 2> in{{&ground, &body}, 0.0};
  odyn::ForceBlocks<odyn::Spatial, 2> both, one, other;
  for (const auto* sphere : {&low, &high}) {
    sphere->evaluate(in, one);
    INFO(sphere->name() << " force " << one.force[1].transpose());
    CHECK(one.force[1].norm() > 1.0);  // both ends are in
  }
  capsule.evaluate(in, both);
  low.evaluate(in, one);
  high.evaluate(in, other);
  CHECK((both.force[1] - one.force[1] - other.force[1]).norm() < 1e-12 * both.force[1].norm());
  CHECK((both.force[0] - one.force[0] - other.force[0]).norm() < 1e-12 * both.force[1].norm());
  capsule.jacobians(in, both);
  low.jacobians(in, one);
  high.jacobians(in, other);
  CHECK((both.stiffness - one.stiffness - other.stiffness).norm() < 1e-12 * both.stiffness.norm());
  CHECK((both.damping - one.damping - other.damping).norm() < 1e-12 * both.damping.norm());
  CHECK(capsule.potential_energy(in) ==
        Approx(low.potential_energy(in) + high.potential_energy(in)).epsilon(1e-14));
}

TEST_CASE("Bad box and capsule parameters are refused by name", "[contact]") {
  const odyn::ContactLaw law{.stiffness = 1e6};
  const odyn::contact_shape::Plane<odyn::Spatial> floor{Vector3d::Zero(), Vector3d::UnitZ()};
  CHECK_THROWS_WITH(sp::BoxPlane("box", odyn::ground, floor, odyn::BodyId{1},
                                 {Vector3d::Zero(), Vector3d(0.1, 0.0, 0.1)}, law),
                    Catch::Contains("box: half_extents is (") &&
                        Catch::Contains("each half edge length must be positive"));
  using Capsule = odyn::contact_shape::Capsule<odyn::Spatial>;
  CHECK_THROWS_WITH(
      sp::CapsulePlane("rod", odyn::ground, floor, odyn::BodyId{1},
                       Capsule{.axis = Vector3d::Zero(), .half_length = 0.1, .radius = 0.1}, law),
      Catch::Contains("rod: axis_b"));
  CHECK_THROWS_WITH(sp::CapsulePlane("rod", odyn::ground, floor, odyn::BodyId{1},
                                     Capsule{.half_length = 0.0, .radius = 0.1}, law),
                    Catch::Contains("half_length is 0"));
  CHECK_THROWS_WITH(sp::CapsulePlane("rod", odyn::ground, floor, odyn::BodyId{1},
                                     Capsule{.half_length = 0.1, .radius = -1.0}, law),
                    Catch::Contains("radius_b is -1"));
}

}  // namespace test_contact
