// The variable-order BDF integrator (stabilized index 2) with error control: its achieved
// error against its tolerance (a torque-free body against the closed form, the engine and a
// stiff governor against their minimal-coordinate references), Andrews'
// mechanism and the engine against their independent references, the heavy top's steady
// precession against the gyroscope equation, a stiff spring against its closed-form solution
// (where BDF needs far fewer steps than dopri5, its order climbing to 5), and bad settings.

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "andrews_model.hpp"
#include "engine_model.hpp"
#include "governor_model.hpp"
#include "reference/andrews_reference.hpp"
#include "reference/engine_reference.hpp"
#include "reference/governor_reference.hpp"
#include "reference/steady_top.hpp"
#include "reference/torque_free.hpp"

namespace test_bdf {

namespace {

odyn::DynamicsSettings bdf(double tolerance) {
  odyn::DynamicsSettings settings;
  settings.integrator = "bdf";
  settings.rtol = tolerance;
  settings.atol = tolerance;
  return settings;
}

/// Largest relative error of the 7 angles of Andrews' mechanism at t = 0.03.
double andrews_error(double tolerance, odyn::RunSummary* summary = nullptr) {
  static const auto reference = andrews_reference::solve(0.03);
  andrews::Mechanism m = andrews::build();
  odyn::Workspace<andrews::Model> ws(m.model);
  odyn::DynamicsSettings settings = bdf(tolerance);
  settings.step = 1e-6;
  settings.t_end = 0.03;
  settings.output_interval = 1e-3;
  const auto result = odyn::simulate_with<odyn::Bdf>(m.model, ws, settings, [](const auto&) {});
  if (summary) *summary = result;
  const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
  double error = 0.0;
  for (int i = 0; i < 7; ++i)
    error =
        std::max(error, std::abs(angles[i] - reference.angle[i]) / std::abs(reference.angle[i]));
  return error;
}

namespace pl = odyn::planar;
using StiffModel = pl::DefaultModel;

/// A 1 kg slider on a spring-damper of k = 1e8 N/m (omega = 1e4 rad/s, damping ratio 0.8)
/// loaded by F0 (1 - cos t), from rest: m x'' + c x' + k x = F0 (1 - cos t). The closed form:
/// the steady response F0 / k + Re(X e^{it}), X = -F0 / (k - m + i c), plus the decaying
/// transient that starts from rest. After the transient the motion follows the slow load.
struct Stiff {
  static constexpr double mass = 1.0, stiffness = 1e8, load = 1e5, zeta = 0.8;
  static double damping() { return 2.0 * zeta * std::sqrt(stiffness * mass); }
  StiffModel model;
  odyn::BodyId slider;
  Stiff() {
    slider = model.add_body({.name = "slider", .mass = mass, .inertia = 1.0});
    model.add(pl::Translational("slide", odyn::ground, {{0.0, 0.0}, {1.0, 0.0}}, slider,
                                {{0.0, 0.0}, {1.0, 0.0}}));
    model.add(pl::Tsda("spring", odyn::ground, {-1.0, 0.0}, slider, {0.0, 0.0},
                       {.stiffness = stiffness, .damping = damping(), .free_length = 1.0}));
    model.add(pl::PointForce("load", slider, {0.0, 0.0}, [](double t, const auto&) {
      return Eigen::Vector2d(load * (1.0 - std::cos(t)), 0.0);
    }));
  }
  static double exact(double t) {
    const std::complex<double> x = -load / std::complex<double>(stiffness - mass, damping());
    const double x0 = load / stiffness + x.real(), v0 = -x.imag();
    const double decay = damping() / (2.0 * mass);
    const double wd = std::sqrt(stiffness / mass - decay * decay);
    const double c1 = -x0, c2 = (-v0 + decay * c1) / wd;
    return load / stiffness + (x * std::exp(std::complex<double>(0.0, t))).real() +
           std::exp(-decay * t) * (c1 * std::cos(wd * t) + c2 * std::sin(wd * t));
  }
};

/// Runs the stiff slider to t = 2 with an integrator; the largest error of x at the outputs.
double stiff_run(const std::string& integrator, double tolerance, odyn::RunSummary& summary) {
  Stiff s;
  odyn::Workspace<StiffModel> ws(s.model);
  odyn::DynamicsSettings settings = bdf(tolerance);
  settings.integrator = integrator;
  settings.step = 1e-6;
  settings.t_end = 2.0;
  settings.output_interval = 0.1;
  double error = 0.0;
  summary = odyn::simulate(s.model, ws, settings, [&](const auto& state) {
    error = std::max(error,
                     std::abs(state.frames[s.slider.index].position.x() - Stiff::exact(state.t)));
  });
  return error;
}

/// A torque-free body (1, 2, 3 kg m^2, omega0 = (0, 10, 5) rad/s) beside a welded one: bdf's
/// largest error of omega over three periods, relative to the spin, against the closed form.
double torque_free_error(double tolerance, odyn::RunSummary& summary) {
  namespace sp = odyn::spatial;
  using Model = sp::DefaultModel;
  const torque_free::Body exact;
  Model model;
  sp::Body brick{.name = "brick", .mass = 1.0, .inertia = sp::Body::principal(1.0, 2.0, 3.0)};
  brick.angular_velocity = {0.0, exact.spin, exact.w3};
  const auto body = model.add_body(brick);
  // A welded body beside it, so that the run has constraint equations to keep.
  const auto anchor = model.add_body({.name = "anchor",
                                      .mass = 1.0,
                                      .inertia = sp::Body::principal(1.0, 1.0, 1.0),
                                      .position = {5.0, 0.0, 0.0}});
  model.add(sp::Fixed("weld", odyn::ground, sp::JointFrame{{5.0, 0.0, 0.0}}, anchor, {}));
  odyn::Workspace<Model> ws(model);
  odyn::DynamicsSettings settings = bdf(tolerance);
  settings.t_end = 3.0 * exact.period();
  settings.output_interval = 1e-2;
  double error = 0.0;
  summary = odyn::simulate_with<odyn::Bdf>(model, ws, settings, [&](const auto& state) {
    const Eigen::Vector3d omega = state.v.template segment<3>(Model::velocity_offset(body) + 3);
    const auto w = exact.omega(state.t);
    error = std::max(error, (omega - Eigen::Vector3d(w[0], w[1], w[2])).norm() / exact.spin);
  });
  return error;
}

/// The engine's largest crank-angle error over its first second, relative to the angle.
double engine_error(double tolerance, odyn::RunSummary& summary) {
  static const auto reference = engine_reference::solve(1.0, 1e-3);
  auto e = engine::build();
  odyn::Workspace<decltype(e)::Model> ws(e.model);
  std::size_t k = 0;
  double error = 0.0;
  summary = odyn::simulate_with<odyn::Bdf>(e.model, ws, bdf(tolerance), [&](const auto& state) {
    const double theta = reference.at(k++).theta;
    error = std::max(error, std::abs(engine::crank_angle(e, state) - theta) / std::max(1.0, theta));
  });
  return error;
}

/// The stiff governor (examples/governor_model.hpp) in joint coordinates: the largest error of
/// the arm angle phi over its 1 s speed ramp, against the reference in phi alone.
double governor_error(double tolerance, odyn::RunSummary& summary) {
  static const auto reference = governor_reference::solve(1.0, 1e-3);
  // The model's and the reference's copies of the parameters that move phi agree.
  const auto fields = [](const auto& q) {
    return std::array{q.a,
                      q.b,
                      q.e,
                      q.L,
                      q.arm_mass,
                      q.arm_centre,
                      q.arm_transverse,
                      q.arm_axial,
                      q.sleeve_mass,
                      q.stiffness,
                      q.damping,
                      q.z0,
                      q.design_angle,
                      q.initial_angle,
                      q.omega0,
                      q.omega1,
                      q.ramp_time,
                      q.g};
  };
  const governor::Parameters p;
  REQUIRE(fields(p) == fields(governor_reference::Parameters{}));
  governor::Governor g = governor::build(p);
  odyn::Workspace<governor::Model> ws(g.model);
  odyn::DynamicsSettings settings = bdf(tolerance);
  settings.coordinates = "joint";
  settings.t_end = 1.0;
  settings.output_interval = 1e-3;
  std::size_t k = 0;
  double error = 0.0;
  summary = odyn::simulate_with<odyn::JointBdf>(g.model, ws, settings, [&](const auto& state) {
    error = std::max(error, std::abs(governor::arm_angle(g, state) - reference.at(k++).phi));
  });
  return error;
}

}  // namespace

TEST_CASE("bdf with its defaults: the achieved error within 10 tolerances", "[bdf][tolerance]") {
  // Each step's local error held to 0.03 of the tolerance (local_error_fraction's default), so
  // that the global error, the sum of the local ones, stays near the tolerance. Measured (in
  // units of the tolerance at 1e-4, 1e-6, 1e-8 and 1e-10): torque-free body 6.2, 4.8, 2.5, 6.5
  // (271 to 2716 steps); engine 0.03, 0.26, 1.1, 4.5 (2357 to 21 580 steps); governor (stiff,
  // joint coordinates) 0.004, 0.001, 0.0007, 0.15 (117 to 1433 steps). Held to the whole
  // tolerance (Newton to 0.1 of it), the first two gave up to 319 and 10.4.
  // The governor is stiff: linearized at its equilibrium, a fast eigenvalue near -1.4e4 1/s,
  // 2500 times the slow one, at both ends of its speed ramp.
  const governor_reference::Parameters parameters;
  for (const double speed : {parameters.omega0, parameters.omega1}) {
    const auto modes = governor_reference::modes(speed, parameters);
    CHECK(modes.fast < -1e4);
    CHECK(modes.fast / modes.slow > 1e3);
  }
  for (const double tolerance : {1e-4, 1e-6, 1e-8, 1e-10}) {
    odyn::RunSummary body_run, engine_run, governor_run;
    const double body = torque_free_error(tolerance, body_run);
    const double crank = engine_error(tolerance, engine_run);
    const double arm = governor_error(tolerance, governor_run);
    INFO("tolerance " << tolerance << ": torque-free body " << body / tolerance << " ("
                      << body_run.statistics.steps << " steps), engine " << crank / tolerance
                      << " (" << engine_run.statistics.steps << " steps), governor "
                      << arm / tolerance << " (" << governor_run.statistics.steps << " steps)");
    CHECK(body < 10.0 * tolerance);
    CHECK(crank < 10.0 * tolerance);
    CHECK(arm < 10.0 * tolerance);
  }
}

TEST_CASE("bdf: Andrews' mechanism, error falling with the tolerance", "[bdf][andrews]") {
  odyn::RunSummary summary;
  const double loose = andrews_error(1e-7);
  const double medium = andrews_error(1e-9);
  const double tight = andrews_error(1e-12, &summary);
  INFO("relative errors " << loose << ", " << medium << ", " << tight << "; steps at 1e-12 "
                          << summary.statistics.steps);
  // Measured: 2.6e-6, 1.5e-8 and 7.2e-12 (6394 steps at 1e-12).
  CHECK(loose < 1e-5);
  CHECK(medium < 1e-7);
  CHECK(tight < 1e-9);
  // Tolerance proportionality: two decades of tolerance, more than one of error.
  CHECK(medium < loose / 10.0);
  CHECK(tight < medium / 10.0);
  CHECK(summary.max_position_residual < 1e-11);
  CHECK(summary.statistics.restarts == 1);
  CHECK(summary.statistics.newton_iterations >= summary.statistics.steps);
  CHECK(summary.statistics.jacobian_evaluations > 0);
  CHECK(summary.statistics.factorizations >= summary.statistics.jacobian_evaluations);
  CHECK(summary.statistics.residual_evaluations > summary.statistics.newton_iterations);
  CHECK(summary.statistics.max_error_estimate <= 1.0);
  CHECK(summary.statistics.max_error_estimate > 0.0);
}

TEST_CASE("bdf: the engine through its switches", "[bdf][engine]") {
  const auto reference = engine_reference::solve(1.0, 1e-3);
  auto check = [&](auto e, double tolerance, double theta_bound, double z_bound) {
    odyn::Workspace<typename decltype(e)::Model> ws(e.model);
    std::size_t k = 0;
    double z_error = 0.0;
    const auto summary =
        odyn::simulate_with<odyn::Bdf>(e.model, ws, bdf(tolerance), [&](const auto& state) {
          z_error = std::max(
              z_error, std::abs(engine::piston_height(e, state) - reference.at(k++).z_piston));
        });
    const double theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    INFO("tolerance " << tolerance << ": theta error " << theta_error << " rad, z error " << z_error
                      << " m, steps " << summary.statistics.steps << ", rejected "
                      << summary.statistics.rejected_steps << ", " << summary.wall_seconds << " s");
    CHECK(theta_error < theta_bound);
    CHECK(z_error < z_bound);
    const long events = static_cast<long>(std::floor(reference.back().theta / std::numbers::pi));
    CHECK(summary.statistics.events == events);
    CHECK(summary.statistics.restarts == events + 1);
    CHECK(summary.max_position_residual < 1e-9);
    CHECK(summary.max_velocity_residual < 1e-3 * tolerance / 1e-6);
  };
  // Measured at 1e-10: 2.2e-8 rad and 2.6e-9 m (spatial, 16537 steps), 1.2e-7 rad and 5.1e-9 m
  // (planar, 12121 steps); at 1e-7 (spatial): 5.1e-5 rad and 2.1e-6 m in 4557 steps.
  check(engine::build(), 1e-10, 1e-6, 5e-8);
  check(engine::planar::build(), 1e-10, 1e-6, 5e-8);
  check(engine::build(), 1e-7, 1e-3, 3e-5);
}

TEST_CASE("bdf: heavy symmetric top in steady precession", "[bdf][pendulums]") {
  // Against the gyroscope equation; a spatial body whose quaternion BDF carries as four numbers.
  const auto top = steady_top::run<odyn::Bdf>(bdf(1e-10));
  INFO("tilt error " << top.tilt_error << ", spin error " << top.spin_error << ", precession "
                     << top.azimuth << " vs " << top.precession_rate << ", steps "
                     << top.summary.statistics.steps);
  // Measured: tilt 1.6e-9 rad, spin 5.9e-11 rad/s, in 4202 steps.
  CHECK(top.tilt_error < 2e-8);
  CHECK(top.azimuth == Approx(top.precession_rate).epsilon(1e-7));
  CHECK(top.spin_error < 1e-9 * top.spin);
  CHECK(top.unit_error < 1e-15);
  CHECK(top.summary.max_position_residual < 1e-11);
}

TEST_CASE("bdf: a stiff spring costs BDF far fewer steps than dopri5", "[bdf][stiff]") {
  odyn::RunSummary implicit, explicit_;
  const double bdf_error = stiff_run("bdf", 1e-7, implicit);
  const double dopri5_error = stiff_run("dopri5", 1e-7, explicit_);
  INFO("bdf: error " << bdf_error << " m in " << implicit.statistics.steps << " steps; dopri5: "
                     << dopri5_error << " m in " << explicit_.statistics.steps << " steps");
  // Measured: bdf 7.3e-12 m in 56 steps (995 when it chose its order from the velocities too,
  // see the next test), dopri5 2.9e-11 m in 6178 steps; x is about 2e-3 m and atol 1e-7 m.
  CHECK(bdf_error < 1e-8);
  CHECK(dopri5_error < 2e-9);
  CHECK(implicit.statistics.steps * 20 < explicit_.statistics.steps);
}

TEST_CASE("bdf: its order climbs to 5 on a stiff spring's slow motion", "[bdf][stiff][order]") {
  // The spring holds the slider quasi-static, x = F(t) / k nearly: a smooth motion that the
  // highest order suits, which an order chosen from the velocities' history (there the BDF
  // derivative of x, whose error jumps with every change of step) never reached: 995 steps,
  // nearly all at order 1 or 2. The integrator is driven step by step to see each step's order.
  Stiff s;
  odyn::Workspace<StiffModel> ws(s.model);
  odyn::update_frames(s.model, ws);
  odyn::evaluate_forces(s.model, ws);
  odyn::StepControl control;
  control.rtol = control.atol = 1e-7;
  control.first_step = 1e-6;
  odyn::Bdf<StiffModel> integrator(s.model, ws, {}, control);
  std::array<long, 6> steps_at_order{};
  std::array<double, 6> time_at_order{};  // the part of [0, t_end] each order covered
  const double t_end = 2.0;
  while (integrator.time() < t_end) {
    const auto order = static_cast<std::size_t>(integrator.order());
    const double h = std::min(integrator.proposed_step(), t_end - integrator.time());
    if (integrator.attempt(h) && integrator.error_norm() <= 1.0) {
      integrator.accept();
      ++steps_at_order[order];
      time_at_order[order] += h;
    } else {
      integrator.reject();
    }
  }
  const long steps = integrator.statistics().steps;
  const double error = std::abs(ws.frames[s.slider.index].position.x() - Stiff::exact(t_end));
  INFO("steps at orders 1 to 5: " << steps_at_order[1] << ", " << steps_at_order[2] << ", "
                                  << steps_at_order[3] << ", " << steps_at_order[4] << ", "
                                  << steps_at_order[5] << "; time at orders 4 and 5 "
                                  << time_at_order[4] + time_at_order[5] << " s; error " << error
                                  << " m");
  // Measured: 6, 17, 7, 5 and 21 steps at orders 1 to 5 (the low orders during the first
  // millisecond's transient), orders 4 and 5 over 1.88 s of the 2; error 7.7e-13 m.
  CHECK(steps < 100);
  CHECK(time_at_order[4] + time_at_order[5] > 0.9 * t_end);
  CHECK(error < 1e-8);
}

TEST_CASE("bdf: bad settings and a hopeless step are reported by name", "[bdf][errors]") {
  auto e = engine::planar::build();
  odyn::Workspace<engine::planar::Model> ws(e.model);
  SECTION("tolerances") {
    CHECK_THROWS_WITH(odyn::simulate_with<odyn::Bdf>(e.model, ws, bdf(-1.0), [](const auto&) {}),
                      Catch::Contains("rtol"));
  }
  SECTION("order") {
    odyn::DynamicsSettings settings = bdf(1e-6);
    settings.bdf.max_order = 7;
    CHECK_THROWS_WITH(odyn::simulate_with<odyn::Bdf>(e.model, ws, settings, [](const auto&) {}),
                      Catch::Contains("max_order"));
    settings.bdf.max_order = 5;
    settings.bdf.local_error_fraction = 1.5;
    CHECK_THROWS_WITH(odyn::simulate_with<odyn::Bdf>(e.model, ws, settings, [](const auto&) {}),
                      Catch::Contains("local_error_fraction") && Catch::Contains("1.5"));
  }
  SECTION("a force that turns to NaN") {
    Stiff s;
    s.model.add(pl::PointForce("broken", s.slider, {0.0, 0.0}, [](double t, const auto&) {
      return Eigen::Vector2d(t > 0.01 ? std::numeric_limits<double>::quiet_NaN() : 0.0, 0.0);
    }));
    odyn::Workspace<StiffModel> stiff_ws(s.model);
    odyn::DynamicsSettings settings = bdf(1e-8);
    settings.t_end = 0.1;
    try {
      odyn::simulate_with<odyn::Bdf>(s.model, stiff_ws, settings, [](const auto&) {});
      FAIL("no error");
    } catch (const odyn::SolverError& error) {
      CHECK_THAT(error.what(), Catch::Contains("bdf") && Catch::Contains("'broken'"));
    }
  }
}

}  // namespace test_bdf
