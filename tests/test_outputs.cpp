// Element outputs (core/outputs.hpp) and point motion (analysis/outputs.hpp) against independent
// references:
// - a mass on a spring: length, rate and tension against the closed-form oscillation;
// - a damped rotor: a rotational damper's angle (counting many turns), rate and torque against
//   the closed-form spin-down, in space (where the angle is unwrapped from a state) and in the
//   plane;
// (a bushing's outputs are tested in test_bushing.cpp, on its damped oscillator);
// - points on a spinning top and a planar pendulum: velocity and acceleration against central
//   differences of the recorded positions and velocities;
// - outputs by name, and the error naming the element's outputs for an unknown one;
// - the output times of a run: every interval, then t_end when it falls between two (a body
//   falling freely, against its parabola), with every integrator.

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

namespace test_outputs {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector3d;
using odyn::BodyId;

odyn::DynamicsSettings tight_run(double t_end, double output_interval) {
  odyn::DynamicsSettings settings;
  settings.integrator = "dop853";
  settings.rtol = settings.atol = 1e-12;
  settings.t_end = t_end;
  settings.output_interval = output_interval;
  return settings;
}

TEST_CASE("A spring's length, rate and tension follow the closed-form oscillation", "[outputs]") {
  // A free mass hangs on a spring from the origin along -z, released stretched by a:
  // L = L0 + a cos(w t), L' = -a w sin(w t), tension k a cos(w t).
  const double mass = 2.0, k = 800.0, free_length = 0.5, a = 0.05;
  const double omega = std::sqrt(k / mass);
  sp::DefaultModel model;
  sp::Body body{.name = "mass", .mass = mass, .inertia = sp::Body::principal(0.1, 0.1, 0.1)};
  body.position = Vector3d(0.0, 0.0, -(free_length + a));
  const BodyId b = model.add_body(body);
  sp::Tsda::Parameters law;
  law.stiffness = k;
  law.free_length = free_length;
  const auto spring =
      model.add(sp::Tsda("spring", odyn::ground, Vector3d::Zero(), b, Vector3d::Zero(), law));
  odyn::Workspace<sp::DefaultModel> ws(model);
  double worst[3] = {0.0, 0.0, 0.0};
  int outputs = 0;
  odyn::simulate(model, ws, tight_run(1.0, 0.01), [&](const auto& w) {
    const auto values = odyn::element_outputs(model, w, spring);
    const double c = std::cos(omega * w.t), s = std::sin(omega * w.t);
    worst[0] = std::max(worst[0], std::abs(values[0] - (free_length + a * c)));
    worst[1] = std::max(worst[1], std::abs(values[1] + a * omega * s));
    worst[2] = std::max(worst[2], std::abs(values[2] - k * a * c));
    ++outputs;
  });
  CHECK(outputs == 101);
  CHECK(worst[0] < 1e-10);
  CHECK(worst[1] < 1e-9 * a * omega);
  CHECK(worst[2] < 1e-9 * k * a);
}

/// The spin-down of a rotor of inertia J on a damper c from w0: w = w0 e^(-c t / J), the
/// angle J w0 / c (1 - e^(-c t / J)).
struct SpinDown {
  double inertia, damping, omega0;
  double rate(double t) const { return omega0 * std::exp(-damping * t / inertia); }
  double angle(double t) const { return inertia / damping * (omega0 - rate(t)); }
};

TEST_CASE("A rotational damper's angle counts the turns of a spinning-down rotor", "[outputs]") {
  const SpinDown spin{0.02, 0.01, 40.0};  // 31.5 rad (five turns) by t = 1 s
  std::vector<double> worst(3, 0.0);
  double last_angle = 0.0;
  const auto check = [&](double t, const std::array<double, 3>& values) {
    worst[0] = std::max(worst[0], std::abs(values[0] - spin.angle(t)));
    worst[1] = std::max(worst[1], std::abs(values[1] - spin.rate(t)));
    worst[2] = std::max(worst[2], std::abs(values[2] + spin.damping * spin.rate(t)));
    last_angle = values[0];
  };
  SECTION("in space") {
    sp::DefaultModel model;
    sp::Body rotor{
        .name = "rotor", .mass = 1.0, .inertia = sp::Body::principal(0.05, 0.05, spin.inertia)};
    rotor.angular_velocity = Vector3d(0.0, 0.0, spin.omega0);
    const BodyId b = model.add_body(rotor);
    model.add(sp::Revolute("bearing", odyn::ground, {}, b, {}));
    sp::Rsda::Parameters law;
    law.damping = spin.damping;
    const auto damper = model.add(sp::Rsda("damper", odyn::ground, {}, b, {}, law));
    odyn::Workspace<sp::DefaultModel> ws(model);
    odyn::simulate(model, ws, tight_run(1.0, 0.01),
                   [&](const auto& w) { check(w.t, odyn::element_outputs(model, w, damper)); });
  }
  SECTION("in the plane") {
    pl::DefaultModel model;
    pl::Body rotor{.name = "rotor", .mass = 1.0, .inertia = spin.inertia};
    rotor.angular_velocity = spin.omega0;
    const BodyId b = model.add_body(rotor);
    model.add(pl::Revolute("bearing", odyn::ground, {}, b, {}));
    pl::Rsda::Parameters law;
    law.damping = spin.damping;
    const auto damper = model.add(pl::Rsda("damper", odyn::ground, b, law));
    odyn::Workspace<pl::DefaultModel> ws(model);
    odyn::simulate(model, ws, tight_run(1.0, 0.01),
                   [&](const auto& w) { check(w.t, odyn::element_outputs(model, w, damper)); });
  }
  CHECK(last_angle > 31.0);
  CHECK(worst[0] < 1e-9 * spin.angle(1.0));
  CHECK(worst[1] < 1e-9 * spin.omega0);
  CHECK(worst[2] < 1e-9 * spin.damping * spin.omega0);
}

/// Central differences over three successive outputs: the middle one's derivative.
template <class V>
V central(const V& before, const V& after, double dt) {
  return (after - before) / (2.0 * dt);
}

TEST_CASE("A point's velocity and acceleration are the derivatives of its recorded motion",
          "[outputs]") {
  const double dt = 1e-4;
  SECTION("a spinning top") {
    sp::DefaultModel model;
    sp::Body top{.name = "top", .mass = 1.5, .inertia = sp::Body::principal(0.02, 0.02, 0.006)};
    const Vector3d pivot(0.0, 0.0, -0.1);  // body coordinates
    top.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vector3d::UnitX()));
    top.position = -(top.orientation * pivot);
    top.angular_velocity = Vector3d(1.0, -2.0, 60.0);
    const BodyId b = model.add_body(top);
    model.add(sp::Spherical("tip", odyn::ground, Vector3d::Zero(), b, pivot));
    model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -9.81)));
    odyn::Workspace<sp::DefaultModel> ws(model);
    const Vector3d rim(0.04, -0.02, 0.03);
    std::vector<odyn::PointMotion<odyn::Spatial>> motion;
    odyn::simulate(model, ws, tight_run(0.05, dt),
                   [&](const auto& w) { motion.push_back(odyn::point_motion(model, w, b, rim)); });
    REQUIRE(motion.size() == 501);
    double worst_velocity = 0.0, worst_acceleration = 0.0, speed = 0.0, acceleration = 0.0;
    for (std::size_t i = 1; i + 1 < motion.size(); ++i) {
      const Vector3d v = central(motion[i - 1].position, motion[i + 1].position, dt);
      const Vector3d a = central(motion[i - 1].velocity, motion[i + 1].velocity, dt);
      worst_velocity = std::max(worst_velocity, (motion[i].velocity - v).norm());
      worst_acceleration = std::max(worst_acceleration, (motion[i].acceleration - a).norm());
      speed = std::max(speed, motion[i].velocity.norm());
      acceleration = std::max(acceleration, motion[i].acceleration.norm());
    }
    INFO("speed " << speed << ", acceleration " << acceleration);
    CHECK(acceleration > 100.0);  // the rim's centripetal acceleration
    CHECK(worst_velocity < 1e-5 * speed);
    CHECK(worst_acceleration < 1e-5 * acceleration);
    // A ground point stays where it is.
    const auto fixed = odyn::point_motion(model, ws, odyn::ground, rim);
    CHECK(fixed.position == rim);
    CHECK(fixed.velocity.norm() + fixed.acceleration.norm() == 0.0);
  }
  SECTION("a planar pendulum") {
    pl::DefaultModel model;
    pl::Body bar{.name = "bar", .mass = 1.0, .inertia = 0.1};
    bar.position = Eigen::Vector2d(0.5, 0.0);
    const BodyId b = model.add_body(bar);
    model.add(pl::Revolute("pivot", odyn::ground, pl::JointFrame{Eigen::Vector2d::Zero()}, b,
                           pl::JointFrame{Eigen::Vector2d(-0.5, 0.0)}));
    model.add(pl::Gravity("gravity", Eigen::Vector2d(0.0, -9.81)));
    odyn::Workspace<pl::DefaultModel> ws(model);
    const Eigen::Vector2d tip(0.5, 0.1);
    std::vector<odyn::PointMotion<odyn::Planar>> motion;
    odyn::simulate(model, ws, tight_run(0.3, dt),
                   [&](const auto& w) { motion.push_back(odyn::point_motion(model, w, b, tip)); });
    double worst_velocity = 0.0, worst_acceleration = 0.0;
    for (std::size_t i = 1; i + 1 < motion.size(); ++i) {
      worst_velocity = std::max(
          worst_velocity,
          (motion[i].velocity - central(motion[i - 1].position, motion[i + 1].position, dt))
              .norm());
      worst_acceleration = std::max(
          worst_acceleration,
          (motion[i].acceleration - central(motion[i - 1].velocity, motion[i + 1].velocity, dt))
              .norm());
    }
    CHECK(motion.back().velocity.norm() > 1.0);
    CHECK(worst_velocity < 1e-6);
    CHECK(worst_acceleration < 1e-5);
  }
}

TEST_CASE("Outputs by name; an unknown output names the element's outputs", "[outputs][errors]") {
  sp::DefaultModel model;
  sp::Body body{.name = "mass", .mass = 1.0, .inertia = sp::Body::principal(0.1, 0.1, 0.1)};
  body.position = Vector3d(0.0, 0.0, -1.0);
  const BodyId b = model.add_body(body);
  sp::Tsda::Parameters law;
  law.stiffness = 10.0;
  model.add(sp::Tsda("spring", odyn::ground, Vector3d::Zero(), b, Vector3d::Zero(), law));
  model.add(sp::Spherical("ball", odyn::ground, Vector3d(0.0, 0.0, -1.0), b, Vector3d::Zero()));
  odyn::Workspace<sp::DefaultModel> ws(model);
  odyn::assemble(model, ws);
  CHECK(odyn::element_output(model, ws, "spring", "length") == Approx(1.0));
  CHECK(odyn::element_output(model, ws, "spring", "tension") == Approx(10.0));
  CHECK_THROWS_WITH(odyn::element_output(model, ws, "spring", "force"),
                    Catch::Contains("spring") && Catch::Contains("length, rate, tension"));
  CHECK_THROWS_WITH(odyn::element_output(model, ws, "ball", "length"),
                    Catch::Contains("reports none"));
  static_assert(odyn::HasOutputs<sp::Tsda> && odyn::HasOutputs<sp::Rsda> &&
                odyn::HasOutputs<pl::Bushing> && !odyn::HasOutputs<sp::Spherical>);
}

TEST_CASE("A run ends at t_end, also between two outputs, with every integrator", "[outputs]") {
  // A free body falls from rest: z = -g t^2 / 2, which every integrator follows closely (bdf
  // starts at order 1, which is not exact for a parabola; its error control holds it).
  const double g = 9.81;
  sp::DefaultModel model;
  model.add_body({.name = "stone", .mass = 1.0, .inertia = sp::Body::principal(0.1, 0.1, 0.1)});
  model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
  const std::string integrator = GENERATE(as<std::string>{}, "generalized-alpha", "hht", "dop853",
                                          "dopri5", "adams", "bdf", "auto");
  const auto times_of_run = [&](double t_end, double output_interval) {
    odyn::DynamicsSettings settings = tight_run(t_end, output_interval);
    settings.integrator = integrator;
    settings.step = 1e-3;
    odyn::Workspace<sp::DefaultModel> ws(model);
    std::vector<double> times;
    double worst = 0.0;
    odyn::simulate(model, ws, settings, [&](const auto& w) {
      times.push_back(w.t);
      worst = std::max(worst, std::abs(w.q[2] + 0.5 * g * w.t * w.t));
    });
    CHECK(ws.t == t_end);
    CHECK(worst < 1e-10);
    return times;
  };
  INFO(integrator);
  const std::vector<double> between = times_of_run(0.015, 0.01);
  REQUIRE(between.size() == 3);
  CHECK(between[1] == Approx(0.01).epsilon(1e-14));
  CHECK(between[2] == 0.015);
  // An interval longer than the run: its start and its end.
  CHECK(times_of_run(0.015, 0.5) == std::vector<double>{0.0, 0.015});
  // A whole number of intervals: no extra output for the rounding of 0.1 / 0.01.
  const std::vector<double> whole = times_of_run(0.1, 0.01);
  REQUIRE(whole.size() == 11);
  CHECK(whole.back() == Approx(0.1).epsilon(1e-14));
}

}  // namespace test_outputs
