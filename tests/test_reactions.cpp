// Joint reactions from odyn::assemble's multipliers against hand statics (and, for a pendulum
// through its lowest point and a block on an incline, hand dynamics). Each case is solved on
// paper in the comments; the bodies' own axes are deliberately turned away from the global axes
// so that every frame transformation in odyn::reaction is exercised.

#include <Eigen/Geometry>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <odyn/odyn.hpp>

// Own namespace: the test files may be compiled together in one unity translation unit.
namespace test_reactions {

namespace {

namespace sp = odyn::spatial;
using Model =
    sp::Model<sp::Revolute, sp::Spherical, sp::Fixed, sp::Distance, sp::Translational, sp::Gravity>;
using Workspace = odyn::Workspace<Model>;
using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;
using odyn::BodyId;
using odyn::ReactionAxes;
using odyn::Side;
constexpr double g = 9.81;

/// A body orientation with no axis along a global one.
Quaterniond tilted() {
  return Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1.0, -2.0, 0.5).normalized()));
}

/// Joint frame given in global terms at the body's pose (x, r): what the user would write in
/// body coordinates.
sp::JointFrame local(const Vector3d& x, const Quaterniond& r, const Vector3d& point,
                     const Vector3d& axis, const Vector3d& reference) {
  const Matrix3d rt = r.toRotationMatrix().transpose();
  return sp::JointFrame{rt * (point - x), rt * axis, rt * reference};
}

void check_vector(const Vector3d& value, const Vector3d& expected, double scale) {
  INFO("value    " << value.transpose() << "\nexpected " << expected.transpose());
  CHECK((value - expected).norm() < 1e-9 * scale);
}

/// Newton's third law at a joint whose two points coincide: the wrench on a is minus that on b.
template <class E>
void check_action_reaction(const Model& model, const Workspace& ws, odyn::Handle<E> joint,
                           double scale) {
  const auto on_a = odyn::reaction(model, ws, joint, Side::a);
  const auto on_b = odyn::reaction(model, ws, joint, Side::b);
  check_vector(on_a.force, -on_b.force, scale);
  check_vector(on_a.torque, -on_b.torque, scale);
}

/// A constraint on one body only, as a downstream element might be: its centre stays at height
/// h (z = h). 1 equation.
class AtHeight {
 public:
  using Space = odyn::Spatial;
  using Input = odyn::ElementInput<Space, 1>;
  static constexpr int num_bodies = 1;
  static constexpr int num_equations = 1;
  AtHeight(std::string name, BodyId body, double height)
      : name_(std::move(name)), bodies_{body}, height_(height) {}
  const std::string& name() const { return name_; }
  const std::array<BodyId, 1>& bodies() const { return bodies_; }
  void evaluate(const Input& in, odyn::ConstraintBlocks<Space, 1, 1>& out) const {
    out.phi[0] = in.body(0).position.z() - height_;
    out.jacobian[0].setZero();
    out.jacobian[0](0, 2) = 1.0;
    out.phi_t.setZero();
  }
  Eigen::Matrix<double, 1, 1> gamma(const Input&) const { return Eigen::Matrix<double, 1, 1>(0.0); }

 private:
  std::string name_;
  std::array<BodyId, 1> bodies_;
  double height_;
};

}  // namespace

TEST_CASE("A constraint on one body: its reaction on side a, none on side b", "[reactions]") {
  // A 2 kg body held at z = 0.3 under gravity: the constraint pushes it up with m g.
  sp::Model<AtHeight, sp::Gravity> model;
  sp::Body body{.name = "block", .mass = 2.0, .inertia = sp::Body::principal(0.1, 0.2, 0.3)};
  body.position = Vector3d(0.1, -0.2, 0.3);
  body.orientation = tilted();
  const BodyId b = model.add_body(body);
  const auto held = model.add(AtHeight("held", b, 0.3));
  model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
  odyn::Workspace<decltype(model)> ws(model);
  odyn::assemble(model, ws);
  const auto on_body = odyn::reaction(model, ws, held, Side::a);
  CHECK((on_body.force - Vector3d(0.0, 0.0, 2.0 * g)).norm() < 1e-12);
  CHECK(on_body.torque.norm() < 1e-12);
  for (const ReactionAxes axes : {ReactionAxes::global, ReactionAxes::joint}) {
    const auto none = odyn::reaction(model, ws, held, Side::b, axes);
    CHECK(none.force.norm() == 0.0);
    CHECK(none.torque.norm() == 0.0);
  }
}

TEST_CASE("Statically determined beam: hinge and inclined rod", "[reactions]") {
  // A uniform beam (mass m, length L) along global x from the hinge at the origin (axis global
  // y) to B = (L, 0, 0), where a massless rod goes to the ground anchor A = (L, c, h). Revolute
  // (5 equations) + distance (1) fix all 6 coordinates, so lambda is unique and v' = 0.
  // Statics, with e = (0, c, h)/r, r = |AB|, and the rod tension T acting on the beam along e:
  //   moments about the hinge, y:  -L h T / r + m g L / 2 = 0    =>  T = m g r / (2 h)
  //   moments about the hinge, z:  M_z + L c T / r = 0           =>  M_z = -L c m g / (2 h)
  //   forces:  F + T e - m g z = 0                                =>  F = (0, -c m g/(2h), m g/2)
  // where (F, M) is the hinge's reaction on the beam at the hinge point.
  const double m = 3.0, length = 2.0, c = 0.4, h = 1.5;
  const double r = std::hypot(c, h);
  const double tension = m * g * r / (2.0 * h);
  const Vector3d hinge_force(0.0, -c * m * g / (2.0 * h), 0.5 * m * g);
  const Vector3d hinge_moment(0.0, 0.0, -length * c * m * g / (2.0 * h));
  const Vector3d rod_direction = Vector3d(0.0, c, h) / r;

  const Vector3d x(0.5 * length, 0.0, 0.0), end(length, 0.0, 0.0), anchor(length, c, h);
  const Quaterniond q = tilted();
  Model model;
  const BodyId beam = model.add_body({.name = "beam",
                                      .mass = m,
                                      .inertia = sp::Body::principal(0.01, 1.0, 1.0),
                                      .position = x,
                                      .orientation = q});
  const Vector3d ex = Vector3d::UnitX(), ey = Vector3d::UnitY();
  const auto hinge =
      model.add(sp::Revolute("hinge", odyn::ground, sp::JointFrame{{0, 0, 0}, ey, ex}, beam,
                             local(x, q, Vector3d::Zero(), ey, ex)));
  const auto rod =
      model.add(sp::Distance("rod", odyn::ground, anchor, beam, local(x, q, end, ey, ex).point, r));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));

  Workspace ws(model);
  odyn::assemble(model, ws);
  const double scale = m * g;
  CHECK(ws.vdot.cwiseAbs().maxCoeff() < 1e-9);  // in equilibrium

  SECTION("global axes, on the beam") {
    const auto on_beam = odyn::reaction(model, ws, hinge, Side::b, ReactionAxes::global);
    check_vector(on_beam.force, hinge_force, scale);
    check_vector(on_beam.torque, hinge_moment, scale * length);
    const auto from_rod = odyn::reaction(model, ws, rod, Side::b, ReactionAxes::global);
    check_vector(from_rod.force, tension * rod_direction, scale);
    check_vector(from_rod.torque, Vector3d::Zero(), scale * length);  // a rod pulls, at its end
  }
  SECTION("global axes, on the ground") {
    check_action_reaction(model, ws, hinge, scale);
    const auto hinge_on_ground = odyn::reaction(model, ws, hinge, Side::a, ReactionAxes::global);
    check_vector(hinge_on_ground.force, -hinge_force, scale);
    check_vector(hinge_on_ground.torque, -hinge_moment, scale * length);
    // The rod's ends are apart: equal and opposite forces, each applied at its own end.
    const auto rod_on_ground = odyn::reaction(model, ws, rod, Side::a, ReactionAxes::global);
    check_vector(rod_on_ground.force, -tension * rod_direction, scale);
    check_vector(rod_on_ground.torque, Vector3d::Zero(), scale * length);
  }
  SECTION("joint axes") {
    // The hinge's frame on either side: u = x (the reference), v = w x u = -z, w = y.
    const Matrix3d axes = (Matrix3d() << ex, -Vector3d::UnitZ(), ey).finished();
    const auto on_beam = odyn::reaction(model, ws, hinge, Side::b, ReactionAxes::joint);
    check_vector(on_beam.force, axes.transpose() * hinge_force, scale);
    check_vector(on_beam.torque, axes.transpose() * hinge_moment, scale * length);
    CHECK(std::abs(on_beam.torque.z()) < 1e-9 * scale * length);  // free about its axis
    const auto on_ground = odyn::reaction(model, ws, hinge, Side::a, ReactionAxes::joint);
    check_vector(on_ground.force, -axes.transpose() * hinge_force, scale);
    check_vector(on_ground.torque, -axes.transpose() * hinge_moment, scale * length);
  }
}

TEST_CASE("Cantilever: weld reaction force and moment", "[reactions]") {
  // A uniform beam (m, L) welded to the ground at the origin, along global x. The weld holds
  // F = (0, 0, m g) and M = -(L/2, 0, 0) x (0, 0, -m g) = (0, -m g L / 2, 0).
  const double m = 2.0, length = 1.2;
  const Vector3d x(0.5 * length, 0.0, 0.0);
  const Quaterniond q = tilted();
  Model model;
  const BodyId beam = model.add_body({.name = "beam",
                                      .mass = m,
                                      .inertia = sp::Body::principal(0.3, 0.2, 0.4),
                                      .position = x,
                                      .orientation = q});
  const Vector3d ex = Vector3d::UnitX(), ez = Vector3d::UnitZ();
  const auto weld = model.add(sp::Fixed("weld", odyn::ground, sp::JointFrame{{0, 0, 0}, ez, ex},
                                        beam, local(x, q, Vector3d::Zero(), ez, ex)));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
  Workspace ws(model);
  odyn::assemble(model, ws);
  const Vector3d force(0.0, 0.0, m * g), moment(0.0, -0.5 * m * g * length, 0.0);
  const auto on_beam = odyn::reaction(model, ws, weld, Side::b);
  check_vector(on_beam.force, force, m * g);
  check_vector(on_beam.torque, moment, m * g * length);
  check_action_reaction(model, ws, weld, m * g);
  // Joint axes u = x, v = z x x = y, w = z: the same components here.
  const auto in_joint = odyn::reaction(model, ws, weld, Side::b, ReactionAxes::joint);
  check_vector(in_joint.force, force, m * g);
  check_vector(in_joint.torque, moment, m * g * length);
  CHECK(ws.vdot.cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("Hanging chain of two bodies: reactions between moving bodies", "[reactions]") {
  // Upper body (m1) on a hinge to the ground, lower body (m2) on a ball joint below it, both
  // hanging straight down at rest: an equilibrium. The ball joint holds the lower body's weight,
  // the hinge both weights; no moments (every weight acts on the vertical through the joints).
  const double m1 = 1.5, m2 = 0.8, l1 = 0.6, l2 = 0.4;
  const Quaterniond q1 = tilted();
  const Quaterniond q2(Eigen::AngleAxisd(-1.1, Vector3d(0.3, 0.2, 1.0).normalized()));
  const Vector3d x1(0, 0, -0.5 * l1), joint(0, 0, -l1), x2(0, 0, -l1 - 0.5 * l2);
  Model model;
  const BodyId upper = model.add_body({.name = "upper",
                                       .mass = m1,
                                       .inertia = sp::Body::principal(0.05, 0.06, 0.02),
                                       .position = x1,
                                       .orientation = q1});
  const BodyId lower = model.add_body({.name = "lower",
                                       .mass = m2,
                                       .inertia = sp::Body::principal(0.02, 0.03, 0.04),
                                       .position = x2,
                                       .orientation = q2});
  const Vector3d ey = Vector3d::UnitY(), ex = Vector3d::UnitX();
  const auto hinge =
      model.add(sp::Revolute("hinge", odyn::ground, sp::JointFrame{{0, 0, 0}, ey, ex}, upper,
                             local(x1, q1, Vector3d::Zero(), ey, ex)));
  const auto ball = model.add(sp::Spherical("ball", upper, local(x1, q1, joint, ey, ex).point,
                                            lower, local(x2, q2, joint, ey, ex).point));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
  Workspace ws(model);
  odyn::assemble(model, ws);
  CHECK(ws.vdot.cwiseAbs().maxCoeff() < 1e-9);
  const double scale = (m1 + m2) * g;

  const auto ball_on_lower = odyn::reaction(model, ws, ball, Side::b);
  check_vector(ball_on_lower.force, Vector3d(0, 0, m2 * g), scale);
  check_vector(ball_on_lower.torque, Vector3d::Zero(), scale);
  const auto ball_on_upper = odyn::reaction(model, ws, ball, Side::a);
  check_vector(ball_on_upper.force, Vector3d(0, 0, -m2 * g), scale);
  check_vector(ball_on_upper.torque, Vector3d::Zero(), scale);
  const auto hinge_on_upper = odyn::reaction(model, ws, hinge, Side::b);
  check_vector(hinge_on_upper.force, Vector3d(0, 0, (m1 + m2) * g), scale);
  check_vector(hinge_on_upper.torque, Vector3d::Zero(), scale);
  check_action_reaction(model, ws, hinge, scale);
  check_action_reaction(model, ws, ball, scale);
}

TEST_CASE("Pendulum through its lowest point: hinge force m g + m omega^2 d", "[reactions]") {
  // A compound pendulum (centre of mass d below a hinge about global y) passing its lowest point
  // with angular velocity omega. There the tangential acceleration is zero and the centre of mass
  // accelerates towards the hinge by omega^2 d, so the hinge pulls the body up with
  // m g + m omega^2 d; with the rotation about a principal axis, no moment.
  const double m = 2.0, d = 0.5, omega = 3.0;
  Model model;
  sp::Body bob{.name = "bob",
               .mass = m,
               .inertia = sp::Body::principal(0.05, 0.08, 0.06),
               .position = {0.0, 0.0, -d}};
  bob.angular_velocity = {0.0, omega, 0.0};  // body = global axes here
  const BodyId body = model.add_body(bob);
  const Vector3d ey = Vector3d::UnitY();
  const auto hinge = model.add(sp::Revolute("hinge", odyn::ground, sp::JointFrame{{0, 0, 0}, ey},
                                            body, sp::JointFrame{{0, 0, d}, ey}));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
  Workspace ws(model);
  odyn::assemble(model, ws);
  const double scale = m * g;

  // The assembly kept the given angular velocity and found the velocity of the centre of mass.
  CHECK(ws.v.segment<3>(0).isApprox(Vector3d(-omega * d, 0.0, 0.0), 1e-12));
  CHECK(ws.v.segment<3>(3).isApprox(Vector3d(0.0, omega, 0.0), 1e-12));
  // Accelerations: centripetal only.
  check_vector(ws.vdot.head<3>(), Vector3d(0.0, 0.0, omega * omega * d), g);
  check_vector(ws.vdot.tail<3>(), Vector3d::Zero(), g);

  const Vector3d expected(0.0, 0.0, m * g + m * omega * omega * d);
  const auto on_bob = odyn::reaction(model, ws, hinge, Side::b);
  check_vector(on_bob.force, expected, scale);
  check_vector(on_bob.torque, Vector3d::Zero(), scale * d);
  check_action_reaction(model, ws, hinge, scale);
  // Joint axes on the bob (default reference): the force has no component along the axis w and
  // its size is unchanged.
  const auto in_joint = odyn::reaction(model, ws, hinge, Side::b, ReactionAxes::joint);
  CHECK(std::abs(in_joint.force.z()) < 1e-9 * scale);
  CHECK(in_joint.force.norm() == Approx(expected.norm()).epsilon(1e-12));
  CHECK(in_joint.torque.norm() < 1e-9 * scale * d);
}

TEST_CASE("Block on a frictionless incline: translational joint reaction", "[reactions]") {
  // A block slides along a ground rail inclined at alpha in the x-z plane, its joint point at
  // its centre of mass. It accelerates down the slope at g sin(alpha); the rail pushes it along
  // the slope's normal n = (-sin alpha, 0, cos alpha) with m g cos(alpha) and holds no moment.
  const double m = 1.7, alpha = 0.5;
  const Vector3d slope(std::cos(alpha), 0.0, std::sin(alpha));
  const Vector3d normal(-std::sin(alpha), 0.0, std::cos(alpha));
  const Vector3d x = 0.4 * slope;  // on the rail
  const Quaterniond q = tilted();
  Model model;
  const BodyId block = model.add_body({.name = "block",
                                       .mass = m,
                                       .inertia = sp::Body::principal(0.1, 0.15, 0.2),
                                       .position = x,
                                       .orientation = q});
  const auto rail =
      model.add(sp::Translational("rail", odyn::ground, sp::JointFrame{{0, 0, 0}, slope, normal},
                                  block, local(x, q, x, slope, normal)));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
  Workspace ws(model);
  odyn::assemble(model, ws);

  check_vector(ws.vdot.head<3>(), -g * std::sin(alpha) * slope, g);
  check_vector(ws.vdot.tail<3>(), Vector3d::Zero(), g);
  const auto on_block = odyn::reaction(model, ws, rail, Side::b);
  check_vector(on_block.force, m * g * std::cos(alpha) * normal, m * g);
  check_vector(on_block.torque, Vector3d::Zero(), m * g);
  // Joint axes on the block: u = normal, v = w x u, w = slope: the force is all along u.
  const auto in_joint = odyn::reaction(model, ws, rail, Side::b, ReactionAxes::joint);
  check_vector(in_joint.force, Vector3d(m * g * std::cos(alpha), 0.0, 0.0), m * g);
  // The rail's joint point on the ground is the origin, not the block's point, so the moments
  // on the two sides differ by the lever arm: M_a = -(M_b + (P_b - P_a) x F_b).
  const auto on_ground = odyn::reaction(model, ws, rail, Side::a);
  check_vector(on_ground.force, -on_block.force, m * g);
  check_vector(on_ground.torque, -(on_block.torque + x.cross(on_block.force)), m * g);
}

namespace {

/// The torque that turns the crank of a slider-crank at constant speed omega, from the
/// minimal-coordinate (crank angle theta) Lagrangian: tau = J'(theta) omega^2 / 2 + V'(theta),
/// J the generalized mass from the velocity coefficients below, V the rod's potential. The
/// crank's centre of mass sits on its pivot; the piston slides on y = 0 along x.
struct SliderCrank {
  double r = 0.04, length = 0.14;               // crank and rod, m
  double crank_inertia = 0.02;                  // about the pivot, kg m^2
  double rod_mass = 0.25, rod_inertia = 4e-4;   // kg, kg m^2 (about its centre)
  double piston_mass = 0.64;                    // kg
  double omega = 2.0 * std::numbers::pi * 5.0;  // rad/s

  double generalized_mass(double theta) const {
    const double sb = -r * std::sin(theta) / length, cb = std::sqrt(1.0 - sb * sb);
    const double db = -r * std::cos(theta) / (length * cb);            // beta'
    const double dxr = -r * std::sin(theta) - 0.5 * length * sb * db;  // rod centre x'
    const double dyr = 0.5 * r * std::cos(theta);                      // rod centre y'
    const double dxp = -r * std::sin(theta) - length * sb * db;        // piston x'
    return crank_inertia + rod_mass * (dxr * dxr + dyr * dyr) + rod_inertia * db * db +
           piston_mass * dxp * dxp;
  }

  /// J' by a fourth-order central difference (error ~1e-12 of J at this spacing).
  double torque(double theta) const {
    constexpr double e = 1e-3;
    const double dj = (-generalized_mass(theta + 2 * e) + 8 * generalized_mass(theta + e) -
                       8 * generalized_mass(theta - e) + generalized_mass(theta - 2 * e)) /
                      (12 * e);
    return 0.5 * dj * omega * omega + rod_mass * g * 0.5 * r * std::cos(theta);
  }
};

struct TorqueRun {
  double error = 0.0;  // max |motor torque - closed form| over the outputs, N m
  double largest = 0.0;
};

/// The slider-crank driven at its bearing, built from planar elements, run with
/// generalized-alpha (or HHT) at step h; the motor's torque on the crank against the closed form.
TorqueRun run_driven_slider_crank(const SliderCrank& c, double h, bool hht, bool consistent) {
  namespace pl = odyn::planar;
  using Model = pl::DefaultModel;
  Model model;
  const BodyId crank = model.add_body({.name = "crank", .mass = 1.0, .inertia = c.crank_inertia});
  const BodyId rod = model.add_body({.name = "rod",
                                     .mass = c.rod_mass,
                                     .inertia = c.rod_inertia,
                                     .position = {c.r + c.length / 2, 0.0}});
  const BodyId piston = model.add_body({.name = "piston",
                                        .mass = c.piston_mass,
                                        .inertia = 1e-3,
                                        .position = {c.r + c.length, 0.0}});
  const pl::Revolute bearing("bearing", odyn::ground, {}, crank, {});
  model.add(bearing);
  model.add(pl::Revolute("crank pin", crank, {{c.r, 0.0}}, rod, {{-c.length / 2, 0.0}}));
  model.add(pl::Revolute("piston pin", rod, {{c.length / 2, 0.0}}, piston, {}));
  model.add(
      pl::Translational("cylinder", odyn::ground, {{c.r + c.length, 0.0}, {1.0, 0.0}}, piston, {}));
  const auto motor =
      model.add(pl::RevoluteDriver("motor", bearing, odyn::Motion::constant_velocity(c.omega)));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  odyn::Workspace<Model> ws(model);
  odyn::DynamicsSettings settings;
  settings.integrator = hht ? "hht" : "generalized-alpha";
  settings.generalized_alpha.consistent_outputs = consistent;
  settings.step = h;
  settings.t_end = 0.4;  // two turns
  settings.output_interval = 4e-3;
  TorqueRun run;
  odyn::simulate_with<odyn::GeneralizedAlpha>(model, ws, settings, [&](const auto& w) {
    // The driver's equation is theta_crank - theta_ground - omega t = 0: its generalized force
    // on the crank, -Phi_q^T lambda, is the torque -lambda.
    const double torque = -w.lambda[model.row(motor)];
    const double expected = c.torque(w.q[3 * (crank.index - 1) + 2]);
    run.error = std::max(run.error, std::abs(torque - expected));
    run.largest = std::max(run.largest, std::abs(expected));
  });
  return run;
}

}  // namespace

TEST_CASE("Driver torque of generalized-alpha and HHT converges at second order", "[reactions]") {
  // The index-3 step's own multipliers do not converge at second order as h shrinks; those
  // solved at the outputs from the index-1 equations (consistent_outputs, the default) follow q
  // and v. Both are measured; the second must be of second order.
  const SliderCrank c;
  for (const bool hht : {false, true}) {
    std::vector<double> errors, own;
    double largest = 0.0;
    for (const double h : {4e-4, 2e-4, 1e-4, 5e-5}) {
      errors.push_back(run_driven_slider_crank(c, h, hht, true).error);
      const TorqueRun step_own = run_driven_slider_crank(c, h, hht, false);
      own.push_back(step_own.error);
      largest = step_own.largest;
    }
    INFO((hht ? "HHT" : "generalized-alpha")
         << ": torque errors at h = 4e-4, 2e-4, 1e-4, 5e-5 s: " << errors[0] << ", " << errors[1]
         << ", " << errors[2] << ", " << errors[3] << " N m; the step's own multipliers: " << own[0]
         << ", " << own[1] << ", " << own[2] << ", " << own[3] << " N m; torque up to " << largest
         << " N m");
    for (std::size_t i = 1; i < errors.size(); ++i) CHECK(errors[i - 1] / errors[i] > 3.5);
    CHECK(errors.back() < 2e-7 * largest);  // 7e-8 N m measured, of 0.86 N m
  }
}

namespace {

/// A rigid pendulum (centre of mass l below its pin when theta = 0) released from rest at
/// theta0, in minimal coordinates: theta'' = -m g l sin(theta) / (I + m l^2), integrated by RK4
/// at a step whose error is far below every tolerance tried.
struct SwingingRod {
  double mass = 1.2, inertia = 0.03, l = 0.35, theta0 = 2.0;  // kg, kg m^2, m, rad

  double acceleration(double theta) const {
    return -mass * g * l * std::sin(theta) / (inertia + mass * l * l);
  }

  /// theta and theta' at the times 0, dt, 2 dt, ..., n dt.
  std::vector<Eigen::Vector2d> solve(double dt, int n) const {
    constexpr int substeps = 400;
    const double h = dt / substeps;
    auto rate = [&](const Eigen::Vector2d& y) { return Eigen::Vector2d(y[1], acceleration(y[0])); };
    std::vector<Eigen::Vector2d> out{Eigen::Vector2d(theta0, 0.0)};
    Eigen::Vector2d y = out.front();
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < substeps; ++j) {
        const Eigen::Vector2d k1 = rate(y), k2 = rate(y + 0.5 * h * k1),
                              k3 = rate(y + 0.5 * h * k2), k4 = rate(y + h * k3);
        y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      }
      out.push_back(y);
    }
    return out;
  }

  /// The pin's force on the rod, m a - m g, from theta and theta'.
  Eigen::Vector2d pin_force(double theta, double rate) const {
    const Eigen::Vector2d tangent(std::cos(theta), std::sin(theta));
    const Eigen::Vector2d inward(-std::sin(theta), std::cos(theta));  // from the mass to the pin
    const Eigen::Vector2d accel = l * acceleration(theta) * tangent + l * rate * rate * inward;
    return mass * accel - mass * Eigen::Vector2d(0.0, -g);
  }
};

/// Largest error of the pin force over 2 s (outputs every 0.01 s), relative to the weight,
/// for an integrator with error control at rtol = atol = tol.
double pin_force_error(const SwingingRod& rod, const std::string& integrator, double tol) {
  namespace pl = odyn::planar;
  using Model = pl::DefaultModel;
  Model model;
  const BodyId body =
      model.add_body({.name = "rod",
                      .mass = rod.mass,
                      .inertia = rod.inertia,
                      .position = {rod.l * std::sin(rod.theta0), -rod.l * std::cos(rod.theta0)},
                      .angle = rod.theta0});
  const auto pin = model.add(pl::Revolute("pin", odyn::ground, {}, body, {{0.0, rod.l}}));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  odyn::Workspace<Model> ws(model);
  odyn::DynamicsSettings settings;
  settings.integrator = integrator;
  settings.rtol = settings.atol = tol;
  settings.t_end = 2.0;
  settings.output_interval = 0.01;
  const auto reference = rod.solve(settings.output_interval, 200);
  std::size_t k = 0;
  double error = 0.0;
  odyn::simulate(model, ws, settings, [&](const auto& w) {
    const Eigen::Vector2d& y = reference.at(k++);
    const auto force = odyn::reaction(model, w, pin, Side::b).force;
    error = std::max(error, (force - rod.pin_force(y[0], y[1])).norm());
  });
  CHECK(k == reference.size());
  return error / (rod.mass * g);
}

}  // namespace

TEST_CASE("Reactions of the error-controlled integrators follow their tolerance", "[reactions]") {
  // The pin force of a pendulum swinging through 115 degrees. At every output it comes from the
  // index-1 equations at the interpolated state, so its error is the state's: it must fall with
  // the tolerance, within the factor each method's global error keeps to it. Measured (of the
  // weight, tol 1e-6 / 1e-8 / 1e-10): dop853 1.5e-7 / 4.2e-10 / 1.9e-13, dopri5 2.3e-5 /
  // 1.6e-7 / 1.9e-9, bdf 7.7e-6 / 6.6e-8 / 1.1e-9 (3.4e-5 / 9.6e-6 / 8.1e-8 when each step
  // was held to the whole tolerance; docs/integrators.md, "bdf against its tolerance").
  struct Case {
    std::string integrator;
    double factor;  // error bound in units of the tolerance
  };
  const SwingingRod rod;
  for (const Case& c :
       {Case{"dop853", 1.0}, Case{"auto", 1.0}, Case{"dopri5", 50.0}, Case{"bdf", 20.0}}) {
    std::vector<double> errors;
    for (const double tol : {1e-6, 1e-8, 1e-10}) {
      errors.push_back(pin_force_error(rod, c.integrator, tol));
      CHECK(errors.back() < c.factor * tol);
    }
    INFO(c.integrator << ": pin force errors at tol 1e-6, 1e-8, 1e-10: " << errors[0] << ", "
                      << errors[1] << ", " << errors[2] << " of the weight");
    CHECK(errors[1] < errors[0] / 10.0);
    CHECK(errors[2] < errors[1] / 10.0);
  }
}

}  // namespace test_reactions
