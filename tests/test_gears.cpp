// Gears, rack and pinion, and screw (core/joint_coupling.hpp, core/gear_pairs.hpp,
// spatial/screw_joint.hpp) against independent references:
// - the coupling's Jacobian blocks and gamma against central differences of its Phi, at poses
//   where the joints' own equations do not hold (so that the exact atan2 derivatives are
//   tested, not their on-joint shortcut), and its angle counting the state's whole turns;
// - a torque-driven gear pair turns as one rigid inertia I_a + ratio^2 I_b, for many turns and
//   a ratio that is not an integer, in space and in the plane, in absolute and joint
//   coordinates, with dop853 and generalized-alpha, its mesh passing I_a accel - T to gear a;
// - a pushed rack drives its pinion at s = r theta with (m + I / r^2) s'' = F;
// - a nut on a vertical lead screw sinks under gravity at g m / (m + I (2 pi / p)^2);
// - a planetary gear set built from two three-joint couplers (the sun's and the ring's meshes
//   with the planet, as seen from the carrier) against its Lagrangian in two coordinates, the
//   sun's and the ring's angles: Willis's relation follows, it is not put in;
// - zero ratios, radii, pitches and scales are refused by name.

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>

#include <odyn/odyn.hpp>

namespace test_gears {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Space = odyn::Spatial;
constexpr double pi = std::numbers::pi;

// Deterministic numbers in [-1, 1) (std::mt19937's output is fixed by the standard).
struct Random {
  std::mt19937 engine{20261129u};
  double uniform() { return 2.0 * (static_cast<double>(engine()) / 4294967296.0) - 1.0; }
  // One draw per declarator: a call's arguments are evaluated in an order of the compiler's
  // choosing (g++ and Clang differ), which would change the poses.
  Vector3d vector(double scale) {
    const double x = uniform(), y = uniform(), z = uniform();
    return scale * Vector3d(x, y, z);
  }
};

/// Bodies 1..3 at random poses and velocities (body 0: the ground).
struct Poses {
  std::array<Space::Configuration, 4> q;
  std::array<Space::Velocity, 4> v;
  std::array<Space::Frame, 4> frames;
  explicit Poses(Random& random) {
    q[0] << 0, 0, 0, 1, 0, 0, 0;
    v[0].setZero();
    for (int b = 1; b < 4; ++b) {
      const double w = random.uniform(), x = random.uniform(), y = random.uniform(),
                   z = random.uniform();
      Eigen::Quaterniond r(w, x, y, z);
      r.normalize();
      q[b] << random.vector(0.5), r.w(), r.x(), r.y(), r.z();
      v[b] << random.vector(1.0), random.vector(2.0);
    }
    update();
  }
  void update() {
    for (int b = 0; b < 4; ++b) Space::make_frame(q[b], v[b], frames[b]);
  }
  /// Every body moved along its velocity for dt (body-frame rates constant).
  Poses drifted(double dt) const {
    Poses out = *this;
    for (int b = 1; b < 4; ++b) Space::integrate(q[b], dt * v[b], out.q[b]);
    out.update();
    return out;
  }
};

template <class E>
odyn::InputOf<E> input_of(const E& e, const Poses& p) {
  odyn::InputOf<E> in;
  for (int k = 0; k < E::num_bodies; ++k) in.frames[k] = &p.frames[e.bodies()[k].index];
  return in;
}

/// Phi, its Jacobian blocks and gamma of a coupling against central differences.
template <class E>
void check_blocks(E element, Poses poses) {
  element.bind(input_of(element, poses));
  // Off the joints, then: the bodies move on from the pose the coupling was bound at.
  poses = poses.drifted(0.3);
  const auto state = element.initial_state(input_of(element, poses));
  const auto phi_at = [&](const Poses& p) {
    odyn::BlocksOf<E> blocks;
    element.evaluate(input_of(element, p), state, blocks);
    return blocks.phi[0];
  };
  odyn::BlocksOf<E> blocks;
  element.evaluate(input_of(element, poses), state, blocks);
  const double eps = 1e-6;
  double rate = 0.0;  // Phi_q v
  for (int k = 0; k < E::num_bodies; ++k) {
    const int b = element.bodies()[k].index;
    if (b == 0) continue;  // the ground, or a body another slot holds already
    for (int i = 0; i < Space::nv; ++i) {
      Poses plus = poses, minus = poses;
      Space::integrate(poses.q[b], eps * Space::Velocity::Unit(i), plus.q[b]);
      Space::integrate(poses.q[b], -eps * Space::Velocity::Unit(i), minus.q[b]);
      plus.update();
      minus.update();
      const double numeric = (phi_at(plus) - phi_at(minus)) / (2.0 * eps);
      INFO("body slot " << k << ", coordinate " << i);
      CHECK(blocks.jacobian[k](0, i) == Approx(numeric).epsilon(1e-6).margin(1e-8));
    }
    rate += blocks.jacobian[k].row(0).dot(poses.v[b]);
  }
  CHECK(blocks.phi_t[0] == 0.0);
  // gamma: with v' = 0 in body coordinates, d/dt (Phi_q v) = -gamma.
  const auto rate_at = [&](const Poses& p) {
    odyn::BlocksOf<E> at;
    element.evaluate(input_of(element, p), state, at);
    double sum = 0.0;
    for (int k = 0; k < E::num_bodies; ++k)
      if (element.bodies()[k].index != 0)
        sum += at.jacobian[k].row(0).dot(p.v[element.bodies()[k].index]);
    return sum;
  };
  const double dt = 1e-5;
  const double numeric_gamma =
      -(rate_at(poses.drifted(dt)) - rate_at(poses.drifted(-dt))) / (2 * dt);
  const double gamma = element.gamma(input_of(element, poses), state)[0];
  CHECK(gamma == Approx(numeric_gamma).epsilon(1e-6).margin(1e-7));
  CHECK(std::abs(gamma) > 1e-2);  // the velocity terms are not all zero: a meaningful check
  // Phi's rate along the motion.
  const double numeric_rate =
      (phi_at(poses.drifted(eps)) - phi_at(poses.drifted(-eps))) / (2 * eps);
  CHECK(rate == Approx(numeric_rate).epsilon(1e-6).margin(1e-8));
  // The angles count whole turns from the state's.
  auto turned = state;
  for (double& angle : turned.angle) angle += 6.0 * pi;
  odyn::BlocksOf<E> later;
  element.evaluate(input_of(element, poses), turned, later);
  double expected = 0.0;
  for (int i = 0; i < element.count(); ++i)
    if (element.term(i).kind == odyn::JointCoordinateKind::angle)
      expected += element.term(i).coefficient * 6.0 * pi;
  CHECK(later.phi[0] - blocks.phi[0] == Approx(expected).margin(1e-9));
}

TEST_CASE("Couplings' Jacobians and gamma are their Phi's derivatives", "[gears]") {
  Random random;
  const Poses poses(random);
  const auto frame = [&] {
    return sp::JointFrame{random.vector(0.3), random.vector(1.0), random.vector(1.0)};
  };
  SECTION("a gear between two hinges on a common carrier") {
    const sp::Revolute a("a", odyn::BodyId{1}, frame(), odyn::BodyId{2}, frame());
    const sp::Revolute b("b", odyn::BodyId{1}, frame(), odyn::BodyId{3}, frame());
    const sp::Gear gear("mesh", a, b, -0.37);
    CHECK(gear.bodies()[2].is_ground());  // the carrier takes one slot
    check_blocks(gear, poses);
  }
  SECTION("a rack and pinion on different bodies") {
    const sp::Revolute pinion("pinion", odyn::BodyId{1}, frame(), odyn::BodyId{2}, frame());
    const sp::Translational rack("rack", odyn::ground, frame(), odyn::BodyId{3}, frame());
    check_blocks(sp::RackPinion("drive", pinion, rack, 0.05), poses);
  }
  SECTION("a coupler of three joints, two of them sharing a body, one a slide") {
    const sp::Revolute planet("planet", odyn::BodyId{1}, frame(), odyn::BodyId{2}, frame());
    const sp::Cylindrical sun("sun", odyn::ground, frame(), odyn::BodyId{3}, frame());
    const sp::Revolute carrier("carrier", odyn::ground, frame(), odyn::BodyId{1}, frame());
    using Coordinate = sp::Coupler::Coordinate;
    const sp::Coupler coupler("mesh", Coordinate{planet, odyn::JointCoordinateKind::angle, 18.0},
                              Coordinate{sun, odyn::JointCoordinateKind::slide, 240.0},
                              Coordinate{carrier, odyn::JointCoordinateKind::angle, -24.0});
    CHECK(coupler.bodies()[5].is_ground());  // the carrier takes one slot
    check_blocks(coupler, poses);
  }
  SECTION("a screw") {
    check_blocks(sp::ScrewJoint("lead", odyn::BodyId{2}, frame(), odyn::BodyId{3}, frame(), 0.004),
                 poses);
  }
}

odyn::DynamicsSettings settings_for(const std::string& integrator, const std::string& coordinates,
                                    double t_end) {
  odyn::DynamicsSettings s;
  s.integrator = integrator;
  s.coordinates = coordinates;
  s.t_end = t_end;
  s.output_interval = t_end;
  s.rtol = 1e-11;
  s.atol = 1e-13;
  s.step = 1e-3;
  return s;
}

TEST_CASE("A gear pair turns as one inertia, for many turns", "[gears]") {
  // theta_a'' = T / (I_a + ratio^2 I_b); over 2 s gear a turns 6.4 times, gear b 4.4 times.
  const double torque = 2.0, inertia_a = 0.1, inertia_b = 0.3, ratio = -0.69, t_end = 2.0;
  const double accel = torque / (inertia_a + ratio * ratio * inertia_b);
  const double angle_a = 0.5 * accel * t_end * t_end;
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      const odyn::DynamicsSettings s = settings_for(integrator, coordinates, t_end);
      // generalized-alpha's error in the angle, second order in h = 1e-3: about 1e-6 rad.
      const double tolerance = s.integrator == "dop853" ? 1e-8 : 1e-5;
      SECTION(std::string("in space, ") + integrator + ", " + coordinates) {
        sp::DefaultModel model;
        const Vector3d axis_a = Vector3d(0.0, 0.6, 0.8), axis_b = Vector3d(1.0, 2.0, 2.0) / 3.0;
        const auto disk = [](const char* name, double i) {
          return sp::Body{.name = name, .mass = 1.0, .inertia = sp::Body::principal(i, i, i)};
        };
        const auto a = model.add_body(disk("a", inertia_a));
        auto body_b = disk("b", inertia_b);
        body_b.position = Vector3d(0.3, 0.0, 0.0);
        const auto b = model.add_body(body_b);
        const sp::Revolute hinge_a("hinge_a", odyn::ground, {Vector3d::Zero(), axis_a}, a,
                                   {Vector3d::Zero(), axis_a});
        const sp::Revolute hinge_b("hinge_b", odyn::ground, {Vector3d(0.3, 0.0, 0.0), axis_b}, b,
                                   {Vector3d::Zero(), axis_b});
        model.add(hinge_a);
        model.add(hinge_b);
        model.add(sp::Gear("mesh", hinge_a, hinge_b, ratio));
        model.add(sp::PointTorque("motor", a, Vector3d(torque * axis_a)));
        odyn::Workspace<sp::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        const auto turn_error = [&](int body, const Vector3d& axis, double angle) {
          const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
          return (ws.frames[body].rotation - expected).norm();
        };
        CHECK(turn_error(1, axis_a, angle_a) < tolerance * angle_a);
        CHECK(turn_error(2, axis_b, ratio * angle_a) < tolerance * angle_a);
        const Vector3d omega_b = ws.frames[2].rotation * ws.frames[2].angular_velocity;
        CHECK((omega_b - ratio * accel * t_end * axis_b).norm() < tolerance * accel * t_end);
        // The mesh's torques: I_a accel - T on gear a, I_b theta_b'' on gear b.
        CHECK(odyn::element_output(model, ws, "mesh", "torque_a") ==
              Approx(-ratio * ratio * inertia_b * accel).epsilon(1e3 * tolerance));
        CHECK(odyn::element_output(model, ws, "mesh", "torque_b") ==
              Approx(ratio * inertia_b * accel).epsilon(1e3 * tolerance));
      }
      SECTION(std::string("in the plane, ") + integrator + ", " + coordinates) {
        pl::DefaultModel model;
        const auto a = model.add_body(pl::Body{.name = "a", .mass = 1.0, .inertia = inertia_a});
        const auto b = model.add_body(
            pl::Body{.name = "b", .mass = 1.0, .inertia = inertia_b, .position = {0.3, 0.0}});
        const pl::Revolute hinge_a("hinge_a", odyn::ground, {}, a, {});
        const pl::Revolute hinge_b("hinge_b", odyn::ground, {Vector2d(0.3, 0.0)}, b, {});
        model.add(hinge_a);
        model.add(hinge_b);
        model.add(pl::Gear("mesh", hinge_a, hinge_b, ratio));
        model.add(pl::PointTorque("motor", a, torque));
        odyn::Workspace<pl::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        CHECK(std::abs(ws.frames[1].angle - angle_a) < tolerance * angle_a);
        CHECK(std::abs(ws.frames[2].angle - ratio * angle_a) < tolerance * angle_a);
      }
    }
  }
}

TEST_CASE("A pushed rack drives its pinion", "[gears]") {
  // (m + I / r^2) s'' = F, theta = s / r.
  const double mass = 2.0, inertia = 0.01, radius = 0.05, force = 3.0, t_end = 1.0;
  const double accel = force / (mass + inertia / (radius * radius));
  const double slide = 0.5 * accel * t_end * t_end;
  for (const char* coordinates : {"absolute", "joint"}) {
    const odyn::DynamicsSettings s = settings_for("dop853", coordinates, t_end);
    SECTION(std::string("in space, ") + coordinates) {
      sp::DefaultModel model;
      const auto pinion = model.add_body(sp::Body{
          .name = "pinion", .mass = 0.5, .inertia = sp::Body::principal(0.2, 0.2, inertia)});
      auto rack_body =
          sp::Body{.name = "rack", .mass = mass, .inertia = sp::Body::principal(1, 1, 1)};
      rack_body.position = Vector3d(0.0, -radius, 0.0);
      const auto rack = model.add_body(rack_body);
      const sp::Revolute hinge("hinge", odyn::ground, {}, pinion, {});
      const sp::Translational guide("guide", odyn::ground,
                                    {Vector3d(0, -radius, 0), Vector3d::UnitX()}, rack,
                                    {Vector3d::Zero(), Vector3d::UnitX()});
      model.add(hinge);
      model.add(guide);
      model.add(sp::RackPinion("drive", hinge, guide, -radius));
      model.add(sp::PointForce("push", rack, Vector3d::Zero(), Vector3d(force, 0.0, 0.0)));
      odyn::Workspace<sp::DefaultModel> ws(model);
      odyn::simulate(model, ws, s, [](const auto&) {});
      CHECK(ws.frames[2].position.x() == Approx(slide).epsilon(1e-9));
      const Eigen::Matrix3d expected =
          Eigen::AngleAxisd(-slide / radius, Vector3d::UnitZ()).toRotationMatrix();
      CHECK((ws.frames[1].rotation - expected).norm() < 1e-8);
    }
    SECTION(std::string("in the plane, ") + coordinates) {
      pl::DefaultModel model;
      const auto pinion =
          model.add_body(pl::Body{.name = "pinion", .mass = 0.5, .inertia = inertia});
      const auto rack = model.add_body(
          pl::Body{.name = "rack", .mass = mass, .inertia = 1.0, .position = {0.0, -radius}});
      const pl::Revolute hinge("hinge", odyn::ground, {}, pinion, {});
      const pl::Translational guide("guide", odyn::ground,
                                    {Vector2d(0, -radius), Vector2d::UnitX()}, rack,
                                    {Vector2d::Zero(), Vector2d::UnitX()});
      model.add(hinge);
      model.add(guide);
      model.add(pl::RackPinion("drive", hinge, guide, -radius));
      model.add(pl::PointForce("push", rack, Vector2d::Zero(), Vector2d(force, 0.0)));
      odyn::Workspace<pl::DefaultModel> ws(model);
      odyn::simulate(model, ws, s, [](const auto&) {});
      CHECK(ws.frames[2].position.x() == Approx(slide).epsilon(1e-9));
      CHECK(ws.frames[1].angle == Approx(-slide / radius).epsilon(1e-9));
    }
  }
}

TEST_CASE("A nut sinks down a lead screw", "[gears]") {
  // s'' = -g m / (m + I (2 pi / p)^2), theta = 2 pi s / p.
  const double mass = 0.4, inertia = 2e-5, pitch = 0.01, g = 9.81, t_end = 0.5;
  const double lead = 2.0 * pi / pitch;
  const double accel = -g * mass / (mass + inertia * lead * lead);
  const double slide = 0.5 * accel * t_end * t_end;
  for (const char* integrator : {"dop853", "bdf"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      DYNAMIC_SECTION(integrator << ", " << coordinates) {
        sp::DefaultModel model;
        const auto nut = model.add_body(sp::Body{
            .name = "nut", .mass = mass, .inertia = sp::Body::principal(1e-5, 1e-5, inertia)});
        const sp::Cylindrical shaft("shaft", odyn::ground, {}, nut, {});
        model.add(shaft);
        model.add(sp::ScrewJoint("thread", shaft, pitch));
        model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
        odyn::Workspace<sp::DefaultModel> ws(model);
        odyn::simulate(model, ws, settings_for(integrator, coordinates, t_end), [](const auto&) {});
        const double tolerance = std::string(integrator) == "dop853" ? 1e-9 : 1e-5;
        CHECK(ws.frames[1].position.z() == Approx(slide).epsilon(tolerance));
        const Eigen::Matrix3d expected =
            Eigen::AngleAxisd(lead * slide, Vector3d::UnitZ()).toRotationMatrix();
        CHECK((ws.frames[1].rotation - expected).norm() < tolerance * std::abs(lead * slide));
      }
    }
  }
}

/// A planetary gear set: sun, ring and carrier on hinges about one axis, one planet on the carrier
/// at the pitch radius r_s + r_p. Its two meshes, as the carrier sees them, are couplers of three
/// joint angles (phi the planet's on the carrier):
///   Z_p phi + Z_s (theta_s - theta_c) = 0,   Z_p phi - Z_r (theta_r - theta_c) = 0.
/// Torques on the sun and the carrier, none on the ring.
struct Planetary {
  static constexpr double teeth_sun = 24, teeth_planet = 18, teeth_ring = 60, module = 0.002;
  static constexpr double radius = module * (teeth_sun + teeth_planet) / 2;  // the planet's
  static constexpr double inertia_sun = 0.002, inertia_ring = 0.03, inertia_carrier = 0.01;
  static constexpr double planet_mass = 0.4, inertia_planet = 8e-4;
  static constexpr double torque_sun = 0.05, torque_carrier = -0.03;

  /// The angular velocities (sun, ring, carrier, planet in the ground, planet on the carrier)
  /// from the sun's and the ring's: the meshes solved for the others.
  static Eigen::Matrix<double, 5, 2> velocities() {
    const double c_s = teeth_sun / (teeth_sun + teeth_ring), c_r = 1.0 - c_s;
    Eigen::Matrix<double, 5, 2> a;
    a.row(0) << 1.0, 0.0;
    a.row(1) << 0.0, 1.0;
    a.row(2) << c_s, c_r;
    a.row(4) = -teeth_sun / teeth_planet * (a.row(0) - a.row(2));
    a.row(3) = a.row(2) + a.row(4);
    return a;
  }
  /// The hinges, and the meshes as couplers of their angles.
  template <class Coupler, class Model, class Revolute>
  static void add_joints(Model& model, const Revolute& sun, const Revolute& ring,
                         const Revolute& carrier, const Revolute& planet) {
    for (const auto& hinge : {sun, ring, carrier, planet}) model.add(hinge);
    using Coordinate = typename Coupler::Coordinate;
    constexpr auto angle = odyn::JointCoordinateKind::angle;
    model.add(Coupler("sun mesh", Coordinate{planet, angle, teeth_planet},
                      Coordinate{sun, angle, teeth_sun}, Coordinate{carrier, angle, -teeth_sun}));
    model.add(Coupler("ring mesh", Coordinate{planet, angle, teeth_planet},
                      Coordinate{ring, angle, -teeth_ring},
                      Coordinate{carrier, angle, teeth_ring}));
  }
  /// theta_s'' and theta_r'' from Lagrange's equations in those two coordinates.
  static Eigen::Vector2d accelerations() {
    const Eigen::Matrix<double, 5, 2> a = velocities();
    Eigen::Matrix<double, 5, 1> inertia, torque;
    inertia << inertia_sun, inertia_ring, inertia_carrier + planet_mass * radius * radius,
        inertia_planet, 0.0;
    torque << torque_sun, 0.0, torque_carrier, 0.0, 0.0;
    const Eigen::Matrix2d mass = a.transpose() * inertia.asDiagonal() * a;
    return mass.ldlt().solve(a.transpose() * torque);
  }
};

TEST_CASE("A planetary gear set of couplers keeps Willis's relation", "[gears]") {
  using P = Planetary;
  const double t_end = 1.5;
  const Eigen::Vector2d accel = P::accelerations();
  const Eigen::Matrix<double, 5, 1> angles = P::velocities() * (0.5 * accel * t_end * t_end);
  // Over 1.5 s the sun and the planet on the carrier turn about 2.4 times each.
  CHECK(std::abs(angles[0]) > 4 * pi);
  CHECK(std::abs(angles[4]) > 3 * pi);
  // The reference itself keeps Willis's relation, (theta_s - theta_c) / (theta_r - theta_c) =
  // -Z_r / Z_s (a check of its algebra; the runs below are checked against it, and
  // tests/python/test_gears.py checks the relation on the program's output at every step).
  CHECK((angles[0] - angles[2]) / (angles[1] - angles[2]) ==
        Approx(-P::teeth_ring / P::teeth_sun).epsilon(1e-12));
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      const odyn::DynamicsSettings s = settings_for(integrator, coordinates, t_end);
      const double tolerance = s.integrator == "dop853" ? 1e-8 : 1e-5;
      SECTION(std::string("in space, ") + integrator + ", " + coordinates) {
        sp::DefaultModel model;
        const Vector3d axis = Vector3d(2.0, -1.0, 2.0) / 3.0;
        const Vector3d across = Vector3d(1.0, 2.0, 0.0).normalized();  // perpendicular to it
        const auto disk = [&](const char* name, double mass, double i, Vector3d at) {
          sp::Body body{.name = name, .mass = mass, .inertia = sp::Body::principal(i, i, i)};
          body.position = at;
          return model.add_body(body);
        };
        const auto sun = disk("sun", 0.3, P::inertia_sun, Vector3d::Zero());
        const auto ring = disk("ring", 1.0, P::inertia_ring, Vector3d::Zero());
        const auto carrier = disk("carrier", 0.5, P::inertia_carrier, Vector3d::Zero());
        const auto planet = disk("planet", P::planet_mass, P::inertia_planet, P::radius * across);
        const sp::JointFrame centre{Vector3d::Zero(), axis};
        const sp::Revolute sun_hinge("sun hinge", odyn::ground, centre, sun, centre);
        const sp::Revolute ring_hinge("ring hinge", odyn::ground, centre, ring, centre);
        const sp::Revolute carrier_hinge("carrier hinge", odyn::ground, centre, carrier, centre);
        const sp::Revolute planet_pin("planet pin", carrier, {P::radius * across, axis}, planet,
                                      centre);
        P::add_joints<sp::Coupler>(model, sun_hinge, ring_hinge, carrier_hinge, planet_pin);
        model.add(sp::PointTorque("motor", sun, Vector3d(P::torque_sun * axis)));
        model.add(sp::PointTorque("load", carrier, Vector3d(P::torque_carrier * axis)));
        odyn::Workspace<sp::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        const std::array<odyn::BodyId, 4> bodies{sun, ring, carrier, planet};
        for (int i = 0; i < 4; ++i) {
          INFO("body " << i);
          const Eigen::Matrix3d expected = Eigen::AngleAxisd(angles[i], axis).toRotationMatrix();
          CHECK((ws.frames[bodies[i].index].rotation - expected).norm() <
                tolerance * std::abs(angles[0]));
        }
        // What the meshes pass on to the sun and the ring: their inertia times their
        // acceleration, less the torque applied on them.
        CHECK(odyn::element_output(model, ws, "sun mesh", "effort_2") ==
              Approx(P::inertia_sun * accel[0] - P::torque_sun).epsilon(1e3 * tolerance));
        CHECK(odyn::element_output(model, ws, "ring mesh", "effort_2") ==
              Approx(P::inertia_ring * accel[1]).epsilon(1e3 * tolerance));
        CHECK(odyn::element_output(model, ws, "sun mesh", "coordinate_2") ==
              Approx(angles[0]).epsilon(tolerance));
        CHECK(odyn::element_output(model, ws, "sun mesh", "coordinate_1") ==
              Approx(angles[4]).epsilon(tolerance));
      }
      SECTION(std::string("in the plane, ") + integrator + ", " + coordinates) {
        pl::DefaultModel model;
        const auto disk = [&](const char* name, double mass, double i, Vector2d at) {
          return model.add_body(pl::Body{.name = name, .mass = mass, .inertia = i, .position = at});
        };
        const auto sun = disk("sun", 0.3, P::inertia_sun, Vector2d::Zero());
        const auto ring = disk("ring", 1.0, P::inertia_ring, Vector2d::Zero());
        const auto carrier = disk("carrier", 0.5, P::inertia_carrier, Vector2d::Zero());
        const auto planet =
            disk("planet", P::planet_mass, P::inertia_planet, Vector2d(0.0, P::radius));
        const pl::Revolute sun_hinge("sun hinge", odyn::ground, {}, sun, {});
        const pl::Revolute ring_hinge("ring hinge", odyn::ground, {}, ring, {});
        const pl::Revolute carrier_hinge("carrier hinge", odyn::ground, {}, carrier, {});
        const pl::Revolute planet_pin("planet pin", carrier, {Vector2d(0.0, P::radius)}, planet,
                                      {});
        P::add_joints<pl::Coupler>(model, sun_hinge, ring_hinge, carrier_hinge, planet_pin);
        model.add(pl::PointTorque("motor", sun, P::torque_sun));
        model.add(pl::PointTorque("load", carrier, P::torque_carrier));
        odyn::Workspace<pl::DefaultModel> ws(model);
        odyn::simulate(model, ws, s, [](const auto&) {});
        const std::array<odyn::BodyId, 4> bodies{sun, ring, carrier, planet};
        for (int i = 0; i < 4; ++i) {
          INFO("body " << i);
          CHECK(ws.frames[bodies[i].index].angle ==
                Approx(angles[i]).margin(tolerance * std::abs(angles[0])));
        }
        CHECK(odyn::element_output(model, ws, "ring mesh", "effort_2") ==
              Approx(P::inertia_ring * accel[1]).epsilon(1e3 * tolerance));
      }
    }
  }
}

TEST_CASE("Zero ratios, radii, pitches and scales are refused by name", "[gears]") {
  const sp::Revolute a("a", odyn::ground, {}, odyn::BodyId{1}, {});
  const sp::Translational t("t", odyn::ground, {}, odyn::BodyId{2}, {});
  const sp::Cylindrical c("c", odyn::ground, {}, odyn::BodyId{1}, {});
  CHECK_THROWS_WITH(sp::Gear("mesh", a, a, 0.0),
                    Catch::Contains("mesh") && Catch::Contains("ratio is 0"));
  CHECK_THROWS_WITH(sp::RackPinion("drive", a, t, std::nan("")),
                    Catch::Contains("drive") && Catch::Contains("radius is nan"));
  CHECK_THROWS_WITH(sp::ScrewJoint("lead", c, 0.0),
                    Catch::Contains("lead") && Catch::Contains("pitch is 0"));
  using odyn::JointCoordinateKind::angle;
  using Coordinate = sp::Coupler::Coordinate;
  CHECK_THROWS_WITH(sp::Coupler("couple", Coordinate{a, angle, 1.0}, Coordinate{c, angle, 2.0},
                                Coordinate{t, odyn::JointCoordinateKind::slide, 0.0}),
                    Catch::Contains("couple") && Catch::Contains("scale_3 is 0"));
}

}  // namespace test_gears
