// Joint friction (forces/joint_friction.hpp) against independent references:
// - its damping block against central differences of its force in the bodies' velocities, for
//   a turning, a sliding and a cylindrical joint, slipping fast, in the Stribeck range and
//   nearly sticking;
// - a block launched down a slope flatter than the friction angle slows at g (mu_k cos - sin),
//   sticks, then creeps at v_t atanh(tan / mu(v)); one on a steeper slope slides off at
//   g (sin - mu_k cos): each against the one-coordinate equation m v' = m g sin - F(v) with
//   N = m g cos, integrated by classical Runge-Kutta with small steps;
// - a pendulum with a rubbing pin, in space and in the plane, against the one-coordinate
//   equation of its angle, whose normal load (the pin's reaction) depends on the angular
//   acceleration that the friction changes (solved there by its own fixed point);
// - a joint that is not revolute, translational or cylindrical, or a missing radius, is refused
//   by name.

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

namespace test_joint_friction {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Space = odyn::Spatial;
constexpr double g = 9.81;

odyn::FrictionLaw law(double mu, double mu_s, double radius = 0.0) {
  odyn::FrictionLaw out;
  out.coefficient = mu;
  out.static_coefficient = mu_s;
  out.stribeck_velocity = 0.01;
  out.transition_velocity = 1e-4;
  out.radius = radius;
  return out;
}

/// x' = f(t, x) for a state (position, velocity) by classical Runge-Kutta, sampled every
/// `interval` (a multiple of h).
std::vector<Vector2d> runge_kutta(const std::function<Vector2d(double, const Vector2d&)>& f,
                                  Vector2d x, double t_end, double h, double interval) {
  std::vector<Vector2d> samples{x};
  const int per_sample = static_cast<int>(std::lround(interval / h));
  const int n = static_cast<int>(std::lround(t_end / h));
  double t = 0.0;
  for (int i = 1; i <= n; ++i) {
    const Vector2d k1 = f(t, x), k2 = f(t + h / 2, x + h / 2 * k1),
                   k3 = f(t + h / 2, x + h / 2 * k2), k4 = f(t + h, x + h * k3);
    x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    t += h;
    if (i % per_sample == 0) samples.push_back(x);
  }
  return samples;
}

TEST_CASE("Joint friction's damping block is the derivative of its force", "[friction]") {
  std::mt19937 engine(20261129u);
  const auto uniform = [&] { return 2.0 * (static_cast<double>(engine()) / 4294967296.0) - 1.0; };
  // One draw per declarator: a call's arguments are evaluated in an order of the compiler's
  // choosing (g++ and Clang differ), which would change the poses.
  const auto vector = [&](double scale) {
    const double x = uniform(), y = uniform(), z = uniform();
    return Vector3d(scale * Vector3d(x, y, z));
  };
  std::array<Space::Frame, 2> frames;
  std::array<Space::Configuration, 2> q;
  for (auto& c : q) {
    const double w = uniform(), x = uniform(), y = uniform(), z = uniform();
    Eigen::Quaterniond r(w, x, y, z);
    r.normalize();
    c << vector(0.5), r.w(), r.x(), r.y(), r.z();
  }
  const sp::JointFrame on_a{vector(0.3), vector(1.0), vector(1.0)};
  const sp::JointFrame on_b{vector(0.3), vector(1.0), vector(1.0)};
  const sp::Revolute hinge("hinge", odyn::BodyId{1}, on_a, odyn::BodyId{2}, on_b);
  const sp::Translational slider("slider", odyn::BodyId{1}, on_a, odyn::BodyId{2}, on_b);
  const sp::Cylindrical sleeve("sleeve", odyn::BodyId{1}, on_a, odyn::BodyId{2}, on_b);
  auto friction_law = law(0.3, 0.45, 0.02);
  friction_law.viscous = 2.0;
  friction_law.bending_arm = 0.1;
  sp::JointFriction on_hinge("f", "hinge", friction_law), on_slider("f", "slider", friction_law),
      on_sleeve("f", "sleeve", friction_law);
  on_hinge.attach(hinge, 0, 0);
  on_slider.attach(slider, 0, 0);
  on_sleeve.attach(sleeve, 0, 0);
  sp::JointFriction::State state;
  state.reaction << vector(20.0), vector(3.0);
  for (double speed : {1.0, 0.012, 3e-4, 2e-6, 5e-8}) {
    Space::Velocity v0, v1;
    v0 << vector(1.0), vector(1.0);
    v1 << vector(1.0), vector(1.0);
    for (const sp::JointFriction* friction : {&on_hinge, &on_slider, &on_sleeve}) {
      // Scale the velocities to the slip speed wanted.
      const auto forces_at = [&](const Space::Velocity& a, const Space::Velocity& b) {
        Space::make_frame(q[0], a, frames[0]);
        Space::make_frame(q[1], b, frames[1]);
        odyn::ElementInput<Space, 2> in{{&frames[0], &frames[1]}, 0.0};
        odyn::ForceBlocks<Space, 2> out;
        friction->evaluate(in, state, out);
        friction->jacobians(in, state, out);
        return out;
      };
      forces_at(v0, v1);
      odyn::ElementInput<Space, 2> in{{&frames[0], &frames[1]}, 0.0};
      const double scale = speed / friction->outputs(in, state)[1];
      const Space::Velocity a = scale * v0, b = scale * v1;
      const auto blocks = forces_at(a, b);
      CHECK(friction->outputs(in, state)[1] == Approx(speed).epsilon(1e-12));
      CHECK(friction->outputs(in, state)[0] > 0.0);
      const double eps = 1e-4 * speed;
      for (int j = 0; j < 12; ++j) {
        Space::Velocity da = Space::Velocity::Zero(), db = Space::Velocity::Zero();
        (j < 6 ? da : db)[j % 6] = eps;
        const auto plus = forces_at(a + da, b + db), minus = forces_at(a - da, b - db);
        for (int i = 0; i < 12; ++i) {
          const double numeric = -((i < 6 ? plus.force[0][i] : plus.force[1][i - 6]) -
                                   (i < 6 ? minus.force[0][i] : minus.force[1][i - 6])) /
                                 (2.0 * eps);
          INFO(friction->joint_name() << ", slip speed " << speed << ", entry " << i << ", " << j);
          CHECK(blocks.damping(i, j) ==
                Approx(numeric).epsilon(1e-6).margin(1e-8 * blocks.damping.cwiseAbs().maxCoeff()));
        }
      }
    }
  }
}

odyn::DynamicsSettings settings_for(const std::string& integrator, double t_end, double interval) {
  odyn::DynamicsSettings s;
  s.integrator = integrator;
  s.coordinates = "absolute";
  s.t_end = t_end;
  s.output_interval = interval;
  s.rtol = 1e-10;
  s.atol = 1e-12;
  s.step = 1e-4;
  return s;
}

/// The block's velocity along the slope at every output, from a run with `integrator`.
std::vector<double> slope_run(double angle, double v0, const odyn::FrictionLaw& friction,
                              const std::string& integrator, double t_end, double interval) {
  sp::DefaultModel model;
  sp::Body block{.name = "block", .mass = 2.0, .inertia = sp::Body::principal(0.1, 0.2, 0.3)};
  block.linear_velocity = Vector3d(v0, 0.0, 0.0);
  const auto body = model.add_body(block);
  // The slope is tilted by tilting gravity: down the slope is +x.
  model.add(sp::Translational("rail", odyn::ground, {Vector3d::Zero(), Vector3d::UnitX()}, body,
                              {Vector3d::Zero(), Vector3d::UnitX()}));
  model.add(sp::JointFriction("rubbing", "rail", friction));
  model.add(sp::Gravity("gravity", Vector3d(g * std::sin(angle), 0.0, -g * std::cos(angle))));
  odyn::Workspace<sp::DefaultModel> ws(model);
  std::vector<double> speeds;
  odyn::simulate(model, ws, settings_for(integrator, t_end, interval),
                 [&](const auto& w) { speeds.push_back(w.v[0]); });
  return speeds;
}

TEST_CASE("A block on a slope slows, sticks, creeps and slides as Coulomb's law says",
          "[friction]") {
  const double mu = 0.5, mu_s = 0.6, pi = std::numbers::pi;
  const odyn::FrictionLaw friction = law(mu, mu_s);
  const auto reference = [&](double angle, double v0, double t_end, double interval) {
    const double normal = 2.0 * g * std::cos(angle);
    return runge_kutta(
        [&](double, const Vector2d& x) {
          return Vector2d(x[1],
                          g * std::sin(angle) -
                              std::copysign(friction.force(std::abs(x[1]), normal), x[1]) / 2.0);
        },
        Vector2d(0.0, v0), t_end, 2e-6, interval);
  };
  SECTION("flatter than the friction angle: it stops, then creeps") {
    const double angle = 20.0 * pi / 180.0, v0 = 1.0, t_end = 1.2, interval = 0.01;
    const double deceleration = g * (mu * std::cos(angle) - std::sin(angle));
    const auto expected = reference(angle, v0, t_end, interval);
    for (const char* integrator : {"dop853", "bdf"}) {
      const auto speeds = slope_run(angle, v0, friction, integrator, t_end, interval);
      REQUIRE(speeds.size() == expected.size());
      double stick_time = -1.0;
      for (std::size_t i = 0; i < speeds.size(); ++i) {
        INFO(integrator << " at t = " << i * interval);
        CHECK(std::abs(speeds[i] - expected[i][1]) < 2e-6);
        if (stick_time < 0.0 && speeds[i] < 1e-3) stick_time = i * interval;
      }
      // Slipping, it slows at the kinetic deceleration; it sticks at v0 / deceleration, less
      // the Stribeck range's shortcut (under 3 v_s (1 / deceleration - 1 / the static one)).
      CHECK(speeds[40] == Approx(v0 - deceleration * 0.4).epsilon(1e-7));
      CHECK(std::abs(stick_time - v0 / deceleration) < 0.015);
      // Stuck, it creeps where mu(v) N tanh(v / v_t) holds gravity's pull: v = v_t
      // atanh(tan / mu(v)), mu(v) within 1e-5 of mu_s there.
      double creep = 1e-4 * std::atanh(std::tan(angle) / mu_s);
      for (int pass = 0; pass < 20; ++pass)
        creep = 1e-4 * std::atanh(std::tan(angle) / friction.friction_coefficient(creep));
      CHECK(speeds.back() == Approx(creep).epsilon(1e-7));
    }
  }
  SECTION("steeper than the friction angle: it slides off") {
    const double angle = 35.0 * pi / 180.0, t_end = 1.0, interval = 0.05;
    const auto expected = reference(angle, 0.0, t_end, interval);
    for (const char* integrator : {"dop853", "generalized-alpha"}) {
      const auto speeds = slope_run(angle, 0.0, friction, integrator, t_end, interval);
      REQUIRE(speeds.size() == expected.size());
      // generalized-alpha steps over the onset's transient (the friction builds up in about
      // m v_t / (mu_s N) = 2e-5 s) with 1e-4 s steps: an offset of the speed of about g h / 2
      // stays. The acceleration after it is exact.
      const bool exact = std::string(integrator) == "dop853";
      const double tolerance = exact ? 1e-7 : 5e-4;
      for (std::size_t i = 0; i < speeds.size(); ++i) {
        INFO(integrator << " at t = " << i * interval);
        CHECK(std::abs(speeds[i] - expected[i][1]) < tolerance);
      }
      const double acceleration = g * (std::sin(angle) - mu * std::cos(angle));
      CHECK((speeds[20] - speeds[10]) / 0.5 == Approx(acceleration).epsilon(exact ? 1e-9 : 1e-7));
    }
  }
}

/// The pendulum's angle (from hanging down) at every output, from the one-coordinate equation
///   J theta'' = -m g L sin(theta) - r F(r |theta'|) sign(theta'),
/// J the inertia about the pin, F's normal load the pin's reaction |m (a_centre - gravity)|,
/// which holds theta'' (solved by a fixed point at each evaluation).
std::vector<Vector2d> pendulum_reference(double mass, double inertia, double length,
                                         const odyn::FrictionLaw& friction, double theta0,
                                         double t_end, double interval) {
  const double pivot_inertia = inertia + mass * length * length;
  const double r = friction.radius;
  return runge_kutta(
      [&](double, const Vector2d& x) {
        const double s = std::sin(x[0]), c = std::cos(x[0]), rate = x[1];
        double accel = -mass * g * length * s / pivot_inertia;
        for (int pass = 0; pass < 15; ++pass) {  // it contracts by about 0.04 a pass
          // Centre at L (sin, -cos): a = L theta'' (cos, sin) - L theta'^2 (sin, -cos).
          const Vector2d centre_accel =
              length * accel * Vector2d(c, s) - length * rate * rate * Vector2d(s, -c);
          const double normal = (mass * (centre_accel - Vector2d(0.0, -g))).norm();
          const double torque =
              -r * std::copysign(friction.force(r * std::abs(rate), normal), rate);
          accel = (-mass * g * length * s + torque) / pivot_inertia;
        }
        return Vector2d(rate, accel);
      },
      Vector2d(theta0, 0.0), t_end, 1e-5, interval);
}

TEST_CASE("A pendulum with a rubbing pin loses its swing as its pin's reaction says",
          "[friction]") {
  const double mass = 1.5, inertia = 0.02, length = 0.4, theta0 = 1.2, t_end = 1.5;
  const double interval = 0.05;
  odyn::FrictionLaw friction = law(0.3, 0.3, 0.05);
  friction.transition_velocity = 1e-3;
  const auto expected =
      pendulum_reference(mass, inertia, length, friction, theta0, t_end, interval);
  // The friction changes the swing by far more than the tolerances below:
  const auto frictionless =
      pendulum_reference(mass, inertia, length, law(0.0, 0.0, 0.05), theta0, t_end, interval);
  CHECK(std::abs(expected.back()[0] - frictionless.back()[0]) > 0.01);
  SECTION("in space") {
    sp::DefaultModel model;
    sp::Body bob{.name = "bob", .mass = mass, .inertia = sp::Body::principal(0.03, inertia, 0.01)};
    // Hanging down along -z at theta = 0; about -y, theta > 0 swings the centre towards +x.
    const Vector3d axis = -Vector3d::UnitY();
    bob.position = length * Vector3d(std::sin(theta0), 0.0, -std::cos(theta0));
    bob.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(theta0, axis));
    const auto body = model.add_body(bob);
    model.add(sp::Revolute("pin", odyn::ground, {Vector3d::Zero(), axis}, body,
                           {Vector3d(0.0, 0.0, length), axis}));
    model.add(sp::JointFriction("rubbing", "pin", friction));
    model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
    for (const char* integrator : {"dop853", "bdf"}) {
      odyn::Workspace<sp::DefaultModel> ws(model);
      std::vector<double> angles;
      odyn::simulate(model, ws, settings_for(integrator, t_end, interval), [&](const auto& w) {
        const Vector3d p = w.frames[1].position;
        angles.push_back(std::atan2(p.x(), -p.z()));
      });
      REQUIRE(angles.size() == expected.size());
      const double tolerance = std::string(integrator) == "dop853" ? 1e-7 : 1e-5;
      for (std::size_t i = 0; i < angles.size(); ++i) {
        INFO(integrator << " at t = " << i * interval);
        CHECK(std::abs(angles[i] - expected[i][0]) < tolerance);
      }
    }
  }
  SECTION("in the plane") {
    pl::DefaultModel model;
    const auto body =
        model.add_body(pl::Body{.name = "bob",
                                .mass = mass,
                                .inertia = inertia,
                                .position = length * Vector2d(std::sin(theta0), -std::cos(theta0)),
                                .angle = theta0});
    model.add(pl::Revolute("pin", odyn::ground, {}, body, {Vector2d(0.0, length)}));
    model.add(pl::JointFriction("rubbing", "pin", friction));
    model.add(pl::Gravity("gravity", Vector2d(0.0, -g)));
    odyn::Workspace<pl::DefaultModel> ws(model);
    std::vector<double> angles;
    odyn::simulate(model, ws, settings_for("dop853", t_end, interval),
                   [&](const auto& w) { angles.push_back(w.frames[1].angle); });
    REQUIRE(angles.size() == expected.size());
    for (std::size_t i = 0; i < angles.size(); ++i) {
      INFO("t = " << i * interval);
      CHECK(std::abs(angles[i] - expected[i][0]) < 1e-7);
    }
  }
}

TEST_CASE("Joint friction refuses joints it cannot sit on and laws that cannot work",
          "[friction]") {
  sp::DefaultModel model;
  const auto body =
      model.add_body(sp::Body{.name = "b", .mass = 1.0, .inertia = sp::Body::principal(1, 1, 1)});
  model.add(sp::Spherical("ball", odyn::ground, Vector3d::Zero(), body, Vector3d::Zero()));
  model.add(sp::Revolute("hinge", odyn::ground, {}, body, {}));
  CHECK_THROWS_WITH(model.add(sp::JointFriction("f", "ball", law(0.2, 0.2, 0.01))),
                    Catch::Contains("'ball' is a spherical joint") &&
                        Catch::Contains("revolute, translational or cylindrical"));
  CHECK_THROWS_WITH(model.add(sp::JointFriction("f1", "nowhere", law(0.2, 0.2, 0.01))),
                    Catch::Contains("f1") && Catch::Contains("no joint named 'nowhere'"));
  CHECK_THROWS_WITH(model.add(sp::JointFriction("f2", "hinge", law(0.2, 0.2))),
                    Catch::Contains("f2") && Catch::Contains("pin radius"));
  CHECK_THROWS_WITH(sp::JointFriction("f3", "hinge", law(0.2, 0.1, 0.01)),
                    Catch::Contains("f3") && Catch::Contains("static_coefficient is 0.1"));
  CHECK_THROWS_WITH(sp::JointFriction("f4", "hinge", law(-0.2, 0.1, 0.01)),
                    Catch::Contains("f4") && Catch::Contains("coefficient is -0.2"));
  // Joint coordinates do not solve the reactions it reads while stepping.
  model.add(sp::JointFriction("f5", "hinge", law(0.2, 0.2, 0.01)));
  odyn::Workspace<sp::DefaultModel> ws(model);
  auto s = settings_for("dop853", 0.1, 0.1);
  s.coordinates = "joint";
  CHECK_THROWS_WITH(odyn::simulate(model, ws, s, [](const auto&) {}),
                    Catch::Contains("f5") && Catch::Contains("absolute"));
}

}  // namespace test_joint_friction
