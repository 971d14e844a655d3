// Static equilibrium (analysis/statics.hpp) against closed forms and an independent
// minimization, in absolute and joint coordinates, planar and spatial.

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <string>

#include <odyn/analyses.hpp>
#include <odyn/odyn.hpp>

#include "spring_plate.hpp"

namespace test_statics {

namespace pl = odyn::planar;
namespace sp = odyn::spatial;
using odyn::BodyId;
// Just the element types these tests use: the DefaultModels' every type costs compile time.
using PlanarModel = pl::Model<pl::Revolute, pl::Translational, pl::Rsda, pl::Tsda, pl::Gravity>;
using SpatialModel = spring_plate::Model;

// A 1 m, 1 kg bar hinged at one end, its angle theta from hanging straight down, held by a
// torsional spring whose rest is at theta = rest, under gravity g.
struct SpringPendulum {
  double stiffness = 10.0, rest = 1.2, start = 0.3;
  static constexpr double mass = 1.0, length = 1.0, g = 9.81;
  static constexpr double d = 0.5 * length;  // the pivot to the centre
  static constexpr double inertia_o = mass * length * length / 3.0;

  // k (theta - rest) + m g d sin(theta) = 0 between the hanging pose and the rest, by bisection.
  double equilibrium() const {
    const auto moment = [&](double theta) {
      return stiffness * (theta - rest) + mass * g * d * std::sin(theta);
    };
    double lo = std::min(0.0, rest), hi = std::max(0.0, rest);
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (moment(mid) * moment(lo) > 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  // The small-oscillation stiffness about theta, over the inertia about the pivot: omega^2.
  double squared_frequency(double theta) const {
    return (stiffness + mass * g * d * std::cos(theta)) / inertia_o;
  }

  PlanarModel planar() const {
    PlanarModel model;
    const BodyId bar = model.add_body({.name = "bar",
                                       .mass = mass,
                                       .inertia = mass * length * length / 12.0,
                                       .position = {d * std::sin(start), -d * std::cos(start)},
                                       .angle = start});
    model.add(pl::Revolute("pivot", odyn::ground, {}, bar, {{0.0, d}}));
    // The spring's angle is zero at the start pose.
    model.add(pl::Rsda("spring", odyn::ground, bar,
                       {.stiffness = stiffness, .free_angle = rest - start}));
    model.add(pl::Gravity("gravity", {0.0, -g}));
    return model;
  }

  // The same in space: the bar turns about the global z axis, its own axis along its local y.
  SpatialModel spatial() const {
    SpatialModel model;
    const double moment = mass * length * length / 12.0;
    const BodyId bar = model.add_body(
        {.name = "bar",
         .mass = mass,
         .inertia = Eigen::Vector3d(moment, 1e-3, moment).asDiagonal(),
         .position = {d * std::sin(start), -d * std::cos(start), 0.0},
         .orientation = Eigen::Quaterniond(Eigen::AngleAxisd(start, Eigen::Vector3d::UnitZ()))});
    const sp::JointFrame at_ground{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()};
    const sp::JointFrame on_bar{Eigen::Vector3d(0.0, d, 0.0), Eigen::Vector3d::UnitZ()};
    model.add(sp::Revolute("pivot", odyn::ground, at_ground, bar, on_bar));
    model.add(sp::Rsda("spring", odyn::ground, at_ground, bar, on_bar,
                       {.stiffness = stiffness, .free_angle = rest - start}));
    model.add(sp::Gravity("gravity", {0.0, -g, 0.0}));
    return model;
  }
};

double planar_angle(const PlanarModel::Space::Frame& frame) {
  return frame.angle;
}
double spatial_angle(const SpatialModel::Space::Frame& frame) {
  return std::atan2(frame.rotation(1, 0), frame.rotation(0, 0));
}

// Checks an equilibrium of the spring pendulum: the angle, the hinge's reaction (the weight,
// since the spring is a pure torque), the stability and its squared frequency.
template <class Model, class Angle>
void check_pendulum(const SpringPendulum& p, const Model& model, odyn::Workspace<Model>& ws,
                    const odyn::StaticSummary& summary, Angle&& angle_of) {
  const double theta = angle_of(ws.frames[1]);
  CHECK(theta == Approx(p.equilibrium()).margin(1e-12));
  CHECK(summary.constraint_residual <= 1e-12);
  CHECK(summary.force_residual <= 1e-12);
  CHECK(ws.v.cwiseAbs().maxCoeff() == 0.0);
  using Pivot = std::conditional_t<std::is_same_v<typename Model::Space, odyn::Spatial>,
                                   sp::Revolute, pl::Revolute>;
  const auto hinge = odyn::reaction(model, ws, model.template handle<Pivot>("pivot"));
  CHECK(hinge.force[0] == Approx(0.0).margin(1e-11));
  CHECK(hinge.force[1] == Approx(p.mass * p.g).epsilon(1e-12));
  REQUIRE(summary.stability.squared_frequencies.size() == 1);
  CHECK(summary.stability.stable == (p.squared_frequency(theta) > 0.0));
  CHECK(summary.stability.squared_frequencies[0] ==
        Approx(p.squared_frequency(theta)).epsilon(1e-9));
}

TEST_CASE(
    "A pendulum held by a torsional spring settles where gravity's moment balances the "
    "spring's",
    "[statics]") {
  const SpringPendulum p;
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    const odyn::StaticSettings settings{.coordinates = coordinates};
    {
      const PlanarModel model = p.planar();
      odyn::Workspace<PlanarModel> ws(model);
      const odyn::StaticSummary summary = odyn::static_equilibrium(model, ws, settings);
      check_pendulum(p, model, ws, summary, planar_angle);
      // The bar's turn about the pivot: its angle, and its centre's travel in absolute ones.
      const auto& least_stiff = summary.stability.least_stiff;
      CHECK(std::find(least_stiff.begin(), least_stiff.end(),
                      std::string(coordinates) == "joint" ? "pivot.angle" : "bar.angle") !=
            least_stiff.end());
      // The spring's torque holds the bar: k (rest - theta) = m g d sin(theta).
      const auto spring = odyn::reaction(model, ws, model.handle<pl::Revolute>("pivot"));
      CHECK(spring.torque[0] == Approx(0.0).margin(1e-11));
    }
    {
      const SpatialModel model = p.spatial();
      odyn::Workspace<SpatialModel> ws(model);
      check_pendulum(p, model, ws, odyn::static_equilibrium(model, ws, settings), spatial_angle);
    }
  }
}

TEST_CASE(
    "An inverted pendulum stands unstable where its spring is softer than gravity's "
    "moment, and stable where it is stiffer",
    "[statics]") {
  // Upright is theta = pi; the spring's rest there makes it an equilibrium at any stiffness.
  for (const double stiffness : {3.0, 8.0}) {  // m g d = 4.905 N m
    SpringPendulum p;
    p.stiffness = stiffness;
    p.rest = std::numbers::pi;
    p.start = std::numbers::pi - 0.05;
    for (const char* coordinates : {"absolute", "joint"}) {
      CAPTURE(stiffness, coordinates);
      const PlanarModel model = p.planar();
      odyn::Workspace<PlanarModel> ws(model);
      const odyn::StaticSummary summary =
          odyn::static_equilibrium(model, ws, {.coordinates = coordinates});
      CHECK(ws.frames[1].angle == Approx(std::numbers::pi).margin(1e-12));
      CHECK(summary.stability.stable == (stiffness > p.mass * p.g * p.d));
      CHECK(summary.stability.squared_frequencies[0] ==
            Approx(p.squared_frequency(std::numbers::pi)).epsilon(1e-9));
    }
  }
}

TEST_CASE(
    "A mechanism that the loads move freely has no equilibrium, and the error names the "
    "free motion",
    "[statics]") {
  // A block on a vertical slide, under gravity: nothing holds it up.
  PlanarModel model;
  const BodyId block = model.add_body({.name = "block", .mass = 2.0, .inertia = 0.1});
  model.add(pl::Translational("slide", odyn::ground, {{0.0, 0.0}, {0.0, 1.0}}, block,
                              {{0.0, 0.0}, {0.0, 1.0}}));
  model.add(pl::Gravity("gravity", {0.0, -9.81}));
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<PlanarModel> ws(model);
    const std::string motion = std::string(coordinates) == "joint" ? "slide.travel" : "block.y";
    CHECK_THROWS_WITH(odyn::static_equilibrium(model, ws, {.coordinates = coordinates}),
                      Catch::Contains("the loads drive a free motion along " + motion));
  }
}

TEST_CASE(
    "Where Newton's method fails from the start pose, load steps find the equilibrium, "
    "and relaxation finds a stable one",
    "[statics]") {
  // A soft spring whose rest is 2 rad to the other side, the bar released level: Newton's
  // iteration from there stalls where the moment's slope turns.
  SpringPendulum p;
  p.stiffness = 2.0;
  p.rest = -2.0;
  p.start = std::numbers::pi / 2;
  const PlanarModel model = p.planar();
  const auto moment = [&](double theta) {
    return p.stiffness * (theta - p.rest) + p.mass * p.g * p.d * std::sin(theta);
  };
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::StaticSettings newton_only{.load_stepping = false, .relaxation = false};
    newton_only.coordinates = coordinates;
    odyn::Workspace<PlanarModel> ws(model);
    CHECK_THROWS_WITH(odyn::static_equilibrium(model, ws, newton_only),
                      Catch::Contains("no static equilibrium found by Newton's method"));

    odyn::Workspace<PlanarModel> stepped(model);
    const odyn::StaticSummary by_steps =
        odyn::static_equilibrium(model, stepped, {.coordinates = coordinates});
    CHECK(by_steps.method == "load steps");
    CHECK(stepped.frames[1].angle == Approx(p.equilibrium()).margin(1e-12));
    CHECK(by_steps.stability.stable);

    // Relaxation alone settles where a damped motion would: some stable equilibrium.
    odyn::StaticSettings relaxed{.load_stepping = false};
    relaxed.coordinates = coordinates;
    odyn::Workspace<PlanarModel> settled(model);
    const odyn::StaticSummary by_relaxation = odyn::static_equilibrium(model, settled, relaxed);
    CHECK(by_relaxation.method == "relaxation");
    const double theta = settled.frames[1].angle;
    CHECK(std::abs(moment(theta)) < 1e-11);
    CHECK(by_relaxation.stability.stable);
    CHECK(by_relaxation.stability.squared_frequencies[0] ==
          Approx(p.squared_frequency(theta)).epsilon(1e-9));
  }
}

TEST_CASE("A spring-hung plate's equilibrium is its potential energy's minimum", "[statics]") {
  // Its energy's minimum in Z-Y-X Euler angles by Newton's method on the energy's differences,
  // with no constraint and no multiplier: a different method from odyn's.
  using spring_plate::SpringPlate;
  const SpringPlate plate;
  const Eigen::Vector3d angles = plate.minimum();
  const Eigen::Matrix3d expected = SpringPlate::rotation(angles);
  CHECK(plate.gradient(angles).norm() < 1e-9);
  const SpatialModel model = plate.model();
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<SpatialModel> ws(model);
    const odyn::StaticSummary summary =
        odyn::static_equilibrium(model, ws, {.coordinates = coordinates});
    CHECK(summary.method == "newton");
    CHECK(summary.constraint_residual <= 1e-12);
    CHECK(summary.force_residual <= 1e-12);
    CHECK(summary.stability.stable);
    CHECK((ws.frames[1].rotation - expected).cwiseAbs().maxCoeff() < 1e-9);
    CHECK((ws.frames[1].position + expected * plate.ball).norm() < 1e-12);
    // The ball joint carries the weight and the springs' pull: the forces on the plate sum up.
    Eigen::Vector3d total = odyn::reaction(model, ws, model.handle<sp::Spherical>("ball")).force;
    total.z() -= SpringPlate::mass * SpringPlate::g;
    for (int i = 1; i <= 3; ++i) {
      const auto& blocks = std::get<SpatialModel::type_index<sp::Tsda>>(ws.blocks)[i - 1];
      total += blocks.force[0].head<3>();
    }
    CHECK(total.norm() < 1e-10);
  }
}

TEST_CASE("A slowly turned slider-crank needs the torque that the virtual work gives",
          "[statics]") {
  // The crank (r, mass mc) turned by a motor against a spring on the slider (to a wall at x_w)
  // and the bars' weight: at rest at every angle, tau = dV/dtheta with
  //   V = k (x_w - x - L0)^2 / 2 + g (mc + mr) (r / 2) sin(theta),
  //   x = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)).
  using Model =
      pl::Model<pl::Revolute, pl::Translational, pl::Tsda, pl::Gravity, pl::RevoluteDriver>;
  const double r = 0.2, l = 0.5, mc = 1.0, mr = 0.5, k = 200.0, wall = 1.0, free = 0.4, g = 9.81;
  Model m;
  const BodyId crank =
      m.add_body({.name = "crank", .mass = mc, .inertia = 0.01, .position = {r / 2, 0.0}});
  const BodyId rod =
      m.add_body({.name = "rod", .mass = mr, .inertia = 0.02, .position = {r + l / 2, 0.0}});
  const BodyId slider =
      m.add_body({.name = "slider", .mass = 2.0, .inertia = 0.01, .position = {r + l, 0.0}});
  const pl::Revolute pivot("pivot", odyn::ground, {{0.0, 0.0}}, crank, {{-r / 2, 0.0}});
  m.add(pivot);
  m.add(pl::Revolute("pin", crank, {{r / 2, 0.0}}, rod, {{-l / 2, 0.0}}));
  m.add(pl::Revolute("wrist", rod, {{l / 2, 0.0}}, slider, {{0.0, 0.0}}));
  m.add(pl::Translational("slide", odyn::ground, {{0.0, 0.0}, {1.0, 0.0}}, slider,
                          {{0.0, 0.0}, {1.0, 0.0}}));
  m.add(pl::Tsda("spring", slider, {0.0, 0.0}, odyn::ground, {wall, 0.0},
                 {.stiffness = k, .damping = 0.0, .free_length = free}));
  m.add(pl::Gravity("gravity", {0.0, -g}));
  const auto motor =
      m.add(pl::RevoluteDriver("motor", pivot, odyn::Motion::constant_velocity(1.0)));
  const auto torque = [&](double theta) {
    const double root = std::sqrt(l * l - r * r * std::sin(theta) * std::sin(theta));
    const double x = r * std::cos(theta) + root;
    const double slope = -r * std::sin(theta) - r * r * std::sin(theta) * std::cos(theta) / root;
    return -k * (wall - x - free) * slope + g * (mc + mr) * (r / 2) * std::cos(theta);
  };
  for (const char* coordinates : {"absolute", "joint"}) {
    CAPTURE(coordinates);
    odyn::Workspace<Model> ws(m);
    odyn::QuasiStaticSettings s;
    s.statics.coordinates = coordinates;
    double worst = 0.0, largest = 0.0;
    int rows = 0;
    odyn::quasi_static_analysis(
        m, ws, 6.0, 0.1,
        [&](const odyn::Workspace<Model>& at, const odyn::StaticSummary& summary) {
          ++rows;
          CHECK(summary.force_residual < 1e-12);
          const double angle = at.frames[crank.index].angle;  // the motor's: t
          CHECK(std::abs(std::remainder(angle - at.t, 2 * std::numbers::pi)) < 1e-10);
          const double expected = torque(at.t);
          worst = std::max(
              worst, std::abs(odyn::reaction(m, at, motor, odyn::Side::b).torque[0] - expected));
          largest = std::max(largest, std::abs(expected));
        },
        s);
    CHECK(rows == 61);
    INFO("torque error " << worst << " of " << largest << " N m");
    CHECK(worst < 1e-9 * largest);
  }
}

}  // namespace test_statics
