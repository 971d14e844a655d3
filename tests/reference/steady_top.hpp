#pragma once
// The heavy symmetric top in steady precession, run with any integrator settings, and its
// deviations from the gyroscope equation m g l = p (C w3 - A' p cos(theta)), A' = A + m l^2:
// the tilt stays theta, the spin about the figure axis stays w3, and the axis turns about Z at
// the rate p (the slow root). Shared by the integrator tests.

#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include <odyn/odyn.hpp>

namespace steady_top {

struct Run {
  double precession_rate = 0.0;  // p, rad/s: the reference
  double spin = 0.0;             // w3, rad/s
  double tilt_error = 0.0;       // max |tilt - theta|, rad
  double spin_error = 0.0;       // max |w3 - spin|, rad/s
  double azimuth = 0.0;          // angle the axis turned about Z over the run (1 s), rad
  double unit_error = 0.0;       // max ||quaternion| - 1|
  odyn::RunSummary summary;
};

/// Runs the top for 1 s with outputs every 0.01 s, with the integrator named at compile time
/// (only that one is instantiated).
template <template <class> class Integrator>
Run run(odyn::DynamicsSettings settings) {
  namespace sp = odyn::spatial;
  using Eigen::Vector3d;
  const double g = 9.81, m = 1.0, l = 0.05, a = 0.002, c = 0.0035, theta = std::numbers::pi / 6,
               w3 = 40.0;
  const double a_pivot = a + m * l * l;
  Run out;
  out.spin = w3;
  const double p = out.precession_rate =
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
  settings.t_end = 1.0;
  settings.output_interval = 0.01;
  double previous = 0.0;
  out.summary =
      odyn::simulate_with<Integrator>(model, ws, settings, [&](const odyn::Workspace<Model>& w) {
        const Eigen::Matrix3d rotation = w.frames[body.index].rotation;
        const Vector3d e3 = rotation.col(2);
        out.tilt_error = std::max(out.tilt_error, std::abs(std::acos(e3.z()) - theta));
        out.spin_error =
            std::max(out.spin_error, std::abs(w.frames[body.index].angular_velocity.z() - w3));
        out.unit_error = std::max(out.unit_error, std::abs(w.q.segment<4>(3).norm() - 1.0));
        const double angle = std::atan2(e3.y(), e3.x());
        if (w.t > 0.0) out.azimuth += std::remainder(angle - previous, 2.0 * std::numbers::pi);
        previous = angle;
      });
  return out;
}

/// What the explicit methods reach at tolerance 1e-11 (dopri5 and dop853, in absolute and
/// in joint coordinates): the gyroscope equation's tilt, precession rate and spin to 1e-8.
inline void check_precession(const Run& top) {
  INFO("tilt error " << top.tilt_error << ", precession " << top.azimuth << " vs "
                     << top.precession_rate);
  CHECK(top.tilt_error < 1e-8);
  CHECK(top.azimuth == Approx(top.precession_rate).epsilon(1e-8));
  CHECK(top.spin_error < 1e-8 * top.spin);
  CHECK(top.unit_error < 1e-15);
}

}  // namespace steady_top
