// The explicit Dormand-Prince 5(4) integrator with error control (index 1 + projection):
// Andrews' mechanism and the engine against their independent references, the heavy top's
// steady precession against the gyroscope equation, and bad settings.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "andrews_model.hpp"
#include "engine_model.hpp"
#include "reference/andrews_reference.hpp"
#include "reference/engine_reference.hpp"

namespace test_dopri5 {

namespace {

odyn::DynamicsSettings dopri5(double tolerance) {
  odyn::DynamicsSettings settings;
  settings.integrator = "dopri5";
  settings.rtol = tolerance;
  settings.atol = tolerance;
  return settings;
}

}  // namespace

TEST_CASE("dopri5: Andrews' mechanism to ten digits", "[dopri5][andrews]") {
  const auto reference = andrews_reference::solve(0.03);
  auto largest_error = [&](double tolerance) {
    andrews::Mechanism m = andrews::build();
    odyn::Workspace<andrews::Model> ws(m.model);
    odyn::DynamicsSettings settings = dopri5(tolerance);
    settings.step = 1e-6;
    settings.t_end = 0.03;
    settings.output_interval = 1e-3;
    const auto summary = odyn::simulate(m.model, ws, settings, [](const auto&) {});
    CHECK(summary.max_position_residual < 1e-11);
    CHECK(summary.max_velocity_residual < 1e-11);
    const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
    double error = 0.0;
    for (int i = 0; i < 7; ++i)
      error =
          std::max(error, std::abs(angles[i] - reference.angle[i]) / std::abs(reference.angle[i]));
    return error;
  };
  // Measured: 5.0e-11 at 1e-10 and 1.1e-8 at 1e-8.
  CHECK(largest_error(1e-10) < 1e-9);
  CHECK(largest_error(1e-8) < 1e-7);
}

TEST_CASE("dopri5: the engine through its switches", "[dopri5][engine]") {
  const auto reference = engine_reference::solve(1.0, 1e-3);
  auto check = [&](auto e) {
    odyn::Workspace<typename decltype(e)::Model> ws(e.model);
    std::size_t k = 0;
    double z_error = 0.0;
    const auto summary = odyn::simulate(e.model, ws, dopri5(1e-10), [&](const auto& state) {
      z_error =
          std::max(z_error, std::abs(engine::piston_height(e, state) - reference.at(k++).z_piston));
    });
    const double theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    INFO("theta error " << theta_error << " rad, z error " << z_error << " m, steps "
                        << summary.statistics.steps);
    // Measured (spatial): 4.9e-9 rad.
    CHECK(theta_error < 2e-8);
    CHECK(z_error < 1e-9);
    CHECK(summary.statistics.events ==
          static_cast<long>(std::floor(reference.back().theta / std::numbers::pi)));
    CHECK(summary.max_position_residual < 1e-11);
  };
  check(engine::build());
  check(engine::planar::build());
}

TEST_CASE("dopri5: heavy symmetric top in steady precession", "[dopri5][pendulums]") {
  // As in the generalized-alpha test: m g l = p (C w3 - A' p cos(theta)), A' = A + m l^2; the
  // quaternion is integrated as four numbers and renormalized.
  namespace sp = odyn::spatial;
  using Eigen::Vector3d;
  const double g = 9.81, m = 1.0, l = 0.05, a = 0.002, c = 0.0035, theta = std::numbers::pi / 6,
               w3 = 40.0;
  const double a_pivot = a + m * l * l;
  const double p =
      (c * w3 - std::sqrt(c * c * w3 * w3 - 4.0 * a_pivot * std::cos(theta) * m * g * l)) /
      (2.0 * a_pivot * std::cos(theta));
  const Eigen::Matrix3d r = Eigen::AngleAxisd(theta, Vector3d::UnitX()).toRotationMatrix();
  const Vector3d axis = r.col(2);
  const Vector3d omega = p * Vector3d::UnitZ() + (w3 - p * std::cos(theta)) * axis;
  using Model = sp::Model<sp::Spherical, sp::Gravity>;
  Model model;
  sp::Body top{.name = "top",
               .mass = m,
               .inertia = sp::Body::principal(a, a, c),
               .position = l * axis,
               .orientation = Eigen::Quaterniond(r)};
  top.angular_velocity = r.transpose() * omega;
  const odyn::BodyId body = model.add_body(top);
  model.add(sp::Spherical("tip", odyn::ground, Vector3d::Zero(), body, {0.0, 0.0, -l}));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
  odyn::Workspace<Model> ws(model);
  odyn::DynamicsSettings settings = dopri5(1e-11);
  settings.output_interval = 0.01;
  double tilt_error = 0.0, spin_error = 0.0, azimuth = 0.0, previous = 0.0, unit_error = 0.0;
  odyn::simulate(model, ws, settings, [&](const odyn::Workspace<Model>& w) {
    const Eigen::Matrix3d rotation = w.frames[body.index].rotation;
    const Vector3d e3 = rotation.col(2);
    tilt_error = std::max(tilt_error, std::abs(std::acos(e3.z()) - theta));
    spin_error = std::max(spin_error, std::abs(w.frames[body.index].angular_velocity.z() - w3));
    unit_error = std::max(unit_error, std::abs(w.q.segment<4>(3).norm() - 1.0));
    const double angle = std::atan2(e3.y(), e3.x());
    if (w.t > 0.0) azimuth += std::remainder(angle - previous, 2.0 * std::numbers::pi);
    previous = angle;
  });
  INFO("tilt error " << tilt_error << ", precession " << azimuth << " vs " << p);
  CHECK(tilt_error < 1e-8);
  CHECK(azimuth == Approx(p).epsilon(1e-8));
  CHECK(spin_error < 1e-8 * w3);
  CHECK(unit_error < 1e-15);
}

TEST_CASE("dopri5: bad tolerances are refused by name", "[dopri5][errors]") {
  auto e = engine::planar::build();
  odyn::Workspace<engine::planar::Model> ws(e.model);
  odyn::DynamicsSettings settings = dopri5(-1.0);
  CHECK_THROWS_WITH(odyn::simulate(e.model, ws, settings, [](const auto&) {}),
                    Catch::Contains("rtol"));
}

}  // namespace test_dopri5
