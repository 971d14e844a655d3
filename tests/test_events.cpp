// Events (analysis/watches.hpp) against closed forms:
// - a compound pendulum released from rest: its turning points (the angular velocity crossing
//   zero) at the half periods of the exact elliptic-integral period, with every integrator and
//   in joint coordinates; rising crossings only; watching leaves the run unchanged;
// - a falling body stopped by a terminal watch on a point's height: the fall time sqrt(2 h / g)
//   and the speed there, the run's last output at the event;
// - a watch that returns NaN is named in the error.

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

#include "reference/elliptic.hpp"

namespace test_events {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector2d;
using Eigen::Vector3d;
using odyn::BodyId;

constexpr double gravity = 9.81;

/// A bar pivoted at `arm` from its centre, released at rest `angle0` from hanging straight down.
struct CompoundPendulum {
  double mass = 1.2, inertia = 0.03, arm = 0.4, angle0 = 2.0;
  /// The exact period: 4 sqrt(J / (m g d)) K(sin(angle0 / 2)), J about the pivot.
  double period() const {
    const double pivot_inertia = inertia + mass * arm * arm;
    return 4.0 * std::sqrt(pivot_inertia / (mass * gravity * arm)) *
           reference::elliptic_k(std::sin(0.5 * angle0));
  }
};

pl::DefaultModel planar_pendulum(const CompoundPendulum& p) {
  pl::DefaultModel model;
  pl::Body bar{.name = "bar", .mass = p.mass, .inertia = p.inertia};
  bar.angle = p.angle0;
  bar.position = p.arm * Vector2d(std::sin(p.angle0), -std::cos(p.angle0));
  const BodyId b = model.add_body(bar);
  // The bar's axis from its centre to the pivot is its local +y.
  model.add(pl::Revolute("pivot", odyn::ground, pl::JointFrame{Vector2d::Zero()}, b,
                         pl::JointFrame{Vector2d(0.0, p.arm)}));
  model.add(pl::Gravity("gravity", Vector2d(0.0, -gravity)));
  return model;
}

sp::DefaultModel spatial_pendulum(const CompoundPendulum& p) {
  sp::DefaultModel model;
  sp::Body bar{
      .name = "bar", .mass = p.mass, .inertia = sp::Body::principal(0.05, 0.05, p.inertia)};
  bar.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(p.angle0, Vector3d::UnitZ()));
  bar.position = p.arm * Vector3d(std::sin(p.angle0), -std::cos(p.angle0), 0.0);
  const BodyId b = model.add_body(bar);
  model.add(sp::Revolute("pivot", odyn::ground, sp::JointFrame{}, b,
                         sp::JointFrame{Vector3d(0.0, p.arm, 0.0)}));
  model.add(sp::Gravity("gravity", Vector3d(0.0, -gravity, 0.0)));
  return model;
}

/// The bar's angular velocity about the pivot's axis (z in both spaces).
template <class Model>
odyn::Watch<Model> turning_points(odyn::Crossing crossing = odyn::Crossing::either) {
  return {.name = "turn",
          .function =
              [](const odyn::Workspace<Model>& ws) {
                if constexpr (std::is_same_v<typename Model::Space, odyn::Planar>)
                  return ws.frames[1].omega();
                else
                  return ws.frames[1].angular_velocity.z();  // body z is global z here
              },
          .crossing = crossing};
}

odyn::DynamicsSettings run_with(const std::string& integrator, double t_end) {
  odyn::DynamicsSettings s;
  s.integrator = integrator;
  s.t_end = t_end;
  s.output_interval = 0.01;
  s.rtol = s.atol = 1e-10;
  s.step = integrator == "adams" ? 2e-4 : 1e-4;
  return s;
}

TEST_CASE("A pendulum's turning points are located at its exact half periods", "[events]") {
  const CompoundPendulum p;
  const double period = p.period();
  const double t_end = 2.2 * period;  // turning points at T/2, T, 3T/2 and 2T
  // Located on the integrator's own solution, so that its phase error is what remains: the
  // bounds are about 10 times the errors measured.
  struct Case {
    std::string integrator, coordinates;
    double tolerance;
  };
  // Measured (planar, spatial): dop853 1.7e-14 s, 1.9e-14 s (joint coordinates 2.1e-14 s);
  // dopri5 1.1e-10 s, 1.4e-10 s; bdf 1.9e-10 s, 9.0e-10 s; generalized-alpha 2.3e-7 s (its phase
  // error at h = 1e-4 s); adams 4.0e-13 s, 6.5e-13 s.
  for (const Case& c : {Case{"dop853", "absolute", 1e-12}, Case{"dopri5", "absolute", 1e-9},
                        Case{"bdf", "absolute", 1e-8}, Case{"generalized-alpha", "absolute", 2e-6},
                        Case{"adams", "absolute", 1e-11}, Case{"dop853", "joint", 1e-12}}) {
    for (const bool spatial : {false, true}) {
      if (c.coordinates == "joint" && !spatial) continue;
      INFO(c.integrator << " in " << c.coordinates << " coordinates, "
                        << (spatial ? "spatial" : "planar"));
      odyn::DynamicsSettings s = run_with(c.integrator, t_end);
      s.coordinates = c.coordinates;
      odyn::RunSummary summary;
      if (spatial) {
        const auto model = spatial_pendulum(p);
        odyn::Workspace<sp::DefaultModel> ws(model);
        const std::vector watches{turning_points<sp::DefaultModel>()};
        summary = odyn::simulate(model, ws, s, [](const auto&) {}, nullptr, watches);
      } else {
        const auto model = planar_pendulum(p);
        odyn::Workspace<pl::DefaultModel> ws(model);
        const std::vector watches{turning_points<pl::DefaultModel>()};
        summary = odyn::simulate(model, ws, s, [](const auto&) {}, nullptr, watches);
      }
      REQUIRE(summary.events.size() == 4);
      CHECK(summary.ended_by.empty());
      double largest = 0.0;
      for (std::size_t k = 0; k < 4; ++k) {
        const odyn::Event& e = summary.events[k];
        CHECK(e.watch == "turn");
        CHECK(e.direction == (k % 2 == 0 ? 1 : -1));  // first back up from swinging down (w < 0)
        largest = std::max(largest, std::abs(e.time - 0.5 * period * static_cast<double>(k + 1)));
      }
      INFO("largest error " << largest << " s");
      CHECK(largest < c.tolerance);
    }
  }
}

TEST_CASE("Rising crossings only; watching leaves the run as it was", "[events]") {
  const CompoundPendulum p;
  const auto model = planar_pendulum(p);
  for (const std::string integrator : {"dop853", "generalized-alpha"}) {
    INFO(integrator);
    const odyn::DynamicsSettings s = run_with(integrator, 2.2 * p.period());
    odyn::Workspace<pl::DefaultModel> plain(model), watched(model);
    std::vector<double> plain_angles, watched_angles;
    odyn::simulate(model, plain, s, [&](const auto& ws) { plain_angles.push_back(ws.q[2]); });
    const std::vector watches{turning_points<pl::DefaultModel>(odyn::Crossing::rising)};
    const odyn::RunSummary summary = odyn::simulate(
        model, watched, s, [&](const auto& ws) { watched_angles.push_back(ws.q[2]); }, nullptr,
        watches);
    REQUIRE(summary.events.size() == 2);  // T/2 and 3T/2
    CHECK(std::abs(summary.events[1].time - 1.5 * p.period()) < 1e-5);
    // Bit for bit on dense output; where the step is attempted again after the shorter ones,
    // to within the Newton iteration's tolerance (its iteration matrix may be another step's).
    REQUIRE(watched_angles.size() == plain_angles.size());
    double largest = 0.0;
    for (std::size_t k = 0; k < plain_angles.size(); ++k)
      largest = std::max(largest, std::abs(watched_angles[k] - plain_angles[k]));
    INFO("largest difference " << largest);
    CHECK(largest <= (integrator == "dop853" ? 0.0 : 1e-9));
  }
}

TEST_CASE("A terminal watch ends a fall on the floor", "[events]") {
  // A free body dropped from rest at height h above a floor: lands at sqrt(2 h / g) at speed
  // g t. A quadratic motion, which every method integrates exactly.
  const double height = 1.0, landing = std::sqrt(2.0 * height / gravity);
  for (const std::string integrator : {"dop853", "generalized-alpha", "bdf"}) {
    INFO(integrator);
    pl::DefaultModel model;
    const BodyId ball = model.add_body(pl::Body{.name = "ball", .mass = 0.5, .inertia = 1e-3});
    model.add(pl::Gravity("gravity", Vector2d(0.0, -gravity)));
    const Vector2d bottom(0.0, -0.1);  // the ball's lowest point, 0.1 below its centre
    const double floor = -height - 0.1;
    std::vector<odyn::Watch<pl::DefaultModel>> watches{
        {.name = "floor",
         .function =
             [&](const auto& ws) {
               return odyn::point_motion(model, ws, ball, bottom).position.y() - floor;
             },
         .crossing = odyn::Crossing::falling,
         .terminal = true},
        {.name = "halfway",
         .function = [&](const auto& ws) { return ws.frames[1].position.y() + 0.5 * height; }}};
    odyn::Workspace<pl::DefaultModel> ws(model);
    double last_time = 0.0, last_speed = 0.0;
    long outputs = 0;
    odyn::DynamicsSettings s = run_with(integrator, 2.0);
    s.step = 1e-3;
    const auto summary = odyn::simulate(
        model, ws, s,
        [&](const auto& w) {
          last_time = w.t, last_speed = -w.v[1];
          ++outputs;
        },
        nullptr, watches);
    REQUIRE(summary.events.size() == 2);
    CHECK(summary.events[0].watch == "halfway");
    CHECK(std::abs(summary.events[0].time - std::sqrt(height / gravity)) < 1e-9);
    CHECK(summary.events[1].watch == "floor");
    CHECK(summary.events[1].terminal);
    CHECK(summary.ended_by == "floor");
    CHECK(std::abs(summary.events[1].time - landing) < 1e-9);
    CHECK(last_time == summary.events[1].time);  // the run's last output is at the event
    CHECK(std::abs(last_speed - gravity * landing) < 1e-8);
    CHECK(outputs == 1 + static_cast<long>(landing / 0.01) + 1);  // t0, the grid, the event
  }
}

TEST_CASE("A watch that returns NaN is named in the error", "[events][errors]") {
  const auto model = planar_pendulum(CompoundPendulum{});
  odyn::Workspace<pl::DefaultModel> ws(model);
  const std::vector<odyn::Watch<pl::DefaultModel>> watches{
      {.name = "broken",
       .function = [](const auto& w) { return w.t > 0.05 ? std::nan("") : 1.0; }}};
  CHECK_THROWS_WITH(
      odyn::simulate(
          model, ws, run_with("dop853", 0.1), [](const auto&) {}, nullptr, watches),
      Catch::Matchers::Contains("broken") && Catch::Matchers::Contains("returned nan"));
}

}  // namespace test_events
