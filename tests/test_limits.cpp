// Stops on joint coordinates (forces/joint_limit.hpp, spatial/limits.hpp, planar/limits.hpp)
// against independent references:
// - a rotor on a revolute joint, and a slider on a translational joint, with no other force,
//   leave a stop at the rate the Hunt-Crossley law's first integral gives,
//   d v_in - ln(1 + d v_in) = -d v_out - ln(1 - d v_out), in space and in the plane, in absolute
//   and joint coordinates, with dop853 and generalized-alpha; the spatial rotor's stop lies
//   beyond half a turn, so that its angle must count turns;
// - a slider on an incline settles on its lower stop at the static penetration
//   (m g sin(alpha) / k)^(1/n);
// - the law's stiffness and damping against central differences of its force;
// - bad limits and laws are refused by name.

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include <odyn/odyn.hpp>

#include "hunt_crossley.hpp"

namespace test_limits {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector2d;
using Eigen::Vector3d;

using hunt_crossley::exit_rate;

odyn::DynamicsSettings settings_for(const std::string& integrator, const std::string& coordinates,
                                    double t_end) {
  odyn::DynamicsSettings s;
  s.integrator = integrator;
  s.coordinates = coordinates;
  s.t_end = t_end;
  s.output_interval = t_end;
  if (integrator == "dop853") {
    s.rtol = 1e-11;
    s.atol = 1e-13;
  } else {
    s.step = 2e-5;
  }
  return s;
}

TEST_CASE("A rotor leaves a stop at the rate of the law's first integral", "[limits]") {
  // Free rotation at 10 rad/s into a stop 3.5 rad away (past half a turn): it arrives at
  // 0.35 s, the contact (k = 100 N m/rad, n = 1, I = 0.01) lasts about 31 ms.
  const double rate_in = 10.0, upper = 3.5, d = 0.05, inertia = 0.01;
  const odyn::LimitLaw law{.upper = upper, .stiffness = 100.0, .exponent = 1.0, .dissipation = d};
  const double expected = exit_rate(d, rate_in);
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      const odyn::DynamicsSettings s = settings_for(integrator, coordinates, 0.5);
      const double tolerance = s.integrator == "dop853" ? 1e-8 : 2e-4;
      SECTION(std::string("in space, ") + integrator + ", " + coordinates) {
        sp::DefaultModel model;
        // The hinge's axis is tilted; the rotor spins about it.
        const Vector3d axis = Vector3d(0.0, 0.6, 0.8);
        sp::Body rotor{.name = "rotor",
                       .mass = 2.0,
                       .inertia = sp::Body::principal(inertia, inertia, inertia)};
        rotor.angular_velocity = rate_in * axis;
        const auto b = model.add_body(rotor);
        const sp::Revolute hinge("hinge", odyn::ground, {Vector3d::Zero(), axis}, b,
                                 {Vector3d::Zero(), axis});
        model.add(hinge);
        model.add(sp::RevoluteLimit("stop", hinge, law));
        odyn::Workspace<sp::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        const Vector3d omega = ws.frames[1].rotation * ws.frames[1].angular_velocity;
        CHECK(std::abs(omega.dot(axis) + expected) < tolerance * expected);
        CHECK((omega - omega.dot(axis) * axis).norm() < 1e-9);
      }
      SECTION(std::string("in the plane, ") + integrator + ", " + coordinates) {
        pl::DefaultModel model;
        pl::Body rotor{.name = "rotor", .mass = 2.0, .inertia = inertia};
        rotor.angular_velocity = rate_in;
        const auto b = model.add_body(rotor);
        const pl::Revolute hinge("hinge", odyn::ground, {}, b, {});
        model.add(hinge);
        model.add(pl::RevoluteLimit("stop", hinge, law));
        odyn::Workspace<pl::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        CHECK(std::abs(ws.frames[1].omega() + expected) < tolerance * expected);
      }
    }
  }
}

TEST_CASE("A slider leaves a stop at the rate of the law's first integral", "[limits]") {
  // At 0.5 m/s into a stop 0.1 m away, with k = 1e5 N/m^1.5, n = 1.5 and a mass of 2 kg.
  const double speed = 0.5, d = 0.6;
  const odyn::LimitLaw law{
      .lower = -0.3, .upper = 0.1, .stiffness = 1e5, .exponent = 1.5, .dissipation = d};
  const double expected = exit_rate(d, speed);
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      const odyn::DynamicsSettings s = settings_for(integrator, coordinates, 0.4);
      const double tolerance = s.integrator == "dop853" ? 1e-8 : 2e-4;
      SECTION(std::string("in space, ") + integrator + ", " + coordinates) {
        sp::DefaultModel model;
        const Vector3d axis = Vector3d(2.0, -1.0, 2.0) / 3.0;
        sp::Body slider{
            .name = "slider", .mass = 2.0, .inertia = sp::Body::principal(0.1, 0.2, 0.3)};
        slider.linear_velocity = speed * axis;
        const auto b = model.add_body(slider);
        const sp::Translational guide("guide", odyn::ground, {Vector3d::Zero(), axis}, b,
                                      {Vector3d::Zero(), axis});
        model.add(guide);
        model.add(sp::TranslationalLimit("stop", guide, law));
        odyn::Workspace<sp::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        const Vector3d velocity = ws.v.head<3>();
        CHECK(std::abs(velocity.dot(axis) + expected) < tolerance * expected);
        CHECK((velocity - velocity.dot(axis) * axis).norm() < 1e-9);
      }
      SECTION(std::string("in the plane, ") + integrator + ", " + coordinates) {
        pl::DefaultModel model;
        const Vector2d axis(0.6, -0.8);
        pl::Body slider{.name = "slider", .mass = 2.0, .inertia = 0.1};
        slider.linear_velocity = speed * axis;
        const auto b = model.add_body(slider);
        const pl::Translational guide("guide", odyn::ground, {Vector2d::Zero(), axis}, b,
                                      {Vector2d::Zero(), axis});
        model.add(guide);
        model.add(pl::TranslationalLimit("stop", guide, law));
        odyn::Workspace<pl::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        const Vector2d velocity = ws.v.head<2>();
        CHECK(std::abs(velocity.dot(axis) + expected) < tolerance * expected);
      }
    }
  }
}

TEST_CASE("A slider on an incline rests on its stop at the static penetration", "[limits]") {
  // The guide rises at 30 degrees; the slider, released 1 cm above its lower stop, falls onto
  // it and settles (the law's damping, near critical) where k delta^n = m g sin(alpha).
  const double mass = 3.0, g = 9.81, alpha = std::numbers::pi / 6.0, k = 2e4, n = 1.5;
  const double depth = std::pow(mass * g * std::sin(alpha) / k, 1.0 / n);
  const odyn::LimitLaw law{.lower = -0.01, .stiffness = k, .exponent = n, .dissipation = 10.0};
  const Vector3d axis(std::cos(alpha), 0.0, std::sin(alpha));
  for (const char* integrator : {"generalized-alpha", "bdf"}) {
    DYNAMIC_SECTION(integrator) {
      sp::DefaultModel model;
      const auto b = model.add_body(
          sp::Body{.name = "slider", .mass = mass, .inertia = sp::Body::principal(0.1, 0.1, 0.1)});
      model.add(sp::Translational("guide", odyn::ground, {Vector3d::Zero(), axis}, b,
                                  {Vector3d::Zero(), axis}));
      model.add(sp::TranslationalLimit("stop", odyn::ground, {Vector3d::Zero(), axis}, b,
                                       {Vector3d::Zero(), axis}, law));
      model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
      odyn::DynamicsSettings s;
      s.integrator = integrator;
      s.t_end = 3.0;
      s.output_interval = 3.0;
      s.step = 1e-3;
      s.rtol = 1e-10;
      s.atol = 1e-12;
      odyn::Workspace<sp::DefaultModel> ws(model);
      odyn::simulate(model, ws, s, [](const auto&) {});
      const double slide = ws.frames[1].position.dot(axis);
      CHECK(std::abs(slide - (-0.01 - depth)) < 1e-6 * depth);
    }
  }
}

TEST_CASE("The stop law's stiffness and damping are its force's derivatives", "[limits]") {
  const odyn::LimitLaw law{
      .lower = -0.2, .upper = 0.3, .stiffness = 5e3, .exponent = 1.5, .dissipation = 0.7};
  // Past the upper limit moving in and out, past the lower one, and between them.
  for (const auto& [x, rate] :
       {std::pair{0.31, 0.4}, std::pair{0.32, -0.5}, std::pair{-0.25, -0.3}, std::pair{0.1, 2.0}}) {
    const auto r = law.at(x, rate);
    const double h = 1e-7;
    const double stiffness = -(law.at(x + h, rate).force - law.at(x - h, rate).force) / (2 * h);
    const double damping = -(law.at(x, rate + h).force - law.at(x, rate - h).force) / (2 * h);
    CHECK(r.stiffness == Approx(stiffness).epsilon(1e-6).margin(1e-9));
    CHECK(r.damping == Approx(damping).epsilon(1e-6).margin(1e-9));
    // The energy's slope is the elastic part of the force (d = 0).
    const double elastic =
        odyn::LimitLaw{law.lower, law.upper, law.stiffness, law.exponent, 0.0}.at(x, rate).force;
    CHECK(-(law.energy(x + h) - law.energy(x - h)) / (2 * h) ==
          Approx(elastic).epsilon(1e-6).margin(1e-9));
  }
  CHECK(law.at(0.1, 2.0).force == 0.0);
  CHECK(law.clearance(0.25) == Approx(0.05));
  CHECK(law.clearance(-0.25) == Approx(-0.05));
}

TEST_CASE("Bad stops are refused by name", "[limits]") {
  const auto refuses = [](odyn::LimitLaw law, const char* what) {
    try {
      sp::TranslationalLimit("stop", odyn::ground, {}, odyn::BodyId{1}, {}, law);
      FAIL("accepted: " << what);
    } catch (const odyn::ModelError& e) {
      CHECK_THAT(e.what(), Catch::Contains("stop") && Catch::Contains(what));
    }
  };
  refuses({.stiffness = 1.0}, "neither lower nor upper");
  refuses({.lower = 0.2, .upper = 0.1, .stiffness = 1.0}, "lower must be below upper");
  refuses({.lower = 0.0, .stiffness = 0.0}, "stiffness");
  refuses({.lower = 0.0, .stiffness = 1.0, .exponent = 0.5}, "exponent");
  refuses({.lower = 0.0, .stiffness = 1.0, .dissipation = -1.0}, "dissipation");
  refuses({.upper = std::numeric_limits<double>::infinity(), .stiffness = 1.0}, "finite");
}

}  // namespace test_limits
