// Planar bodies and elements:
//   - every planar constraint's Jacobian blocks, Phi_t and gamma against finite differences of
//     its own Phi (the planar configuration is a vector space, so plain central differences);
//   - force elements' generalized forces against -dV/dq of their potential energy, and their
//     Newton blocks against finite differences of Q;
//   - a compound pendulum's large-amplitude period against the elliptic-integral solution;
//   - hand-solved static reactions, and a driven slider's reaction against m (a + g).

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

#include "four_bar_model.hpp"
#include "reference/elliptic.hpp"

namespace test_planar {

namespace {

namespace pl = odyn::planar;
using Model = pl::DefaultModel;
using Workspace = odyn::Workspace<Model>;
using Space = odyn::Planar;
using Eigen::Vector2d;
using Eigen::Vector3d;
using odyn::BodyId;

constexpr double kTime = 0.37;

class Random {
 public:
  explicit Random(std::uint32_t seed) : engine_(seed) {}
  double uniform() { return 2.0 * (static_cast<double>(engine_()) / 4294967296.0) - 1.0; }
  // One draw per declarator: a call's arguments are evaluated in an order of the compiler's
  // choosing (g++ and Clang differ), which would change the poses.
  Vector2d vector(double scale) {
    const double x = uniform(), y = uniform();
    return scale * Vector2d(x, y);
  }

 private:
  std::mt19937 engine_;
};

/// Two bodies (a may be the ground) at random poses and velocities, with random joint points
/// and axes; a's angle is beyond a full turn, to exercise the joint angle's turn counting.
struct Scene {
  bool ground_a = false;
  Vector3d q_a = Vector3d::Zero(), q_b, v_a = Vector3d::Zero(), v_b;
  pl::JointFrame on_a, on_b;
};

Scene make_scene(std::uint32_t seed, bool ground_a) {
  Random random(seed);
  Scene s;
  s.ground_a = ground_a;
  if (!ground_a) {
    s.q_a << random.vector(1.0), 7.0 + random.uniform();
    s.v_a << random.vector(2.0), 3.0 * random.uniform();
  }
  s.q_b << random.vector(1.0), random.uniform();
  s.v_b << random.vector(2.0), 3.0 * random.uniform();
  s.on_a = {random.vector(0.5), random.vector(1.0)};
  s.on_b = {random.vector(0.5), random.vector(1.0)};
  return s;
}

odyn::Motion harmonic_motion() {
  return odyn::Motion::harmonic(0.7, 3.0, 0.4, 0.2);
}

template <class E>
E make_joint(const Scene& s, BodyId a, BodyId b);
template <>
pl::Revolute make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::Revolute("pin", a, s.on_a, b, s.on_b);
}
template <>
pl::Translational make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::Translational("slider", a, s.on_a, b, s.on_b);
}
template <>
pl::Fixed make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::Fixed("weld", a, s.on_a, b, s.on_b);
}
template <>
pl::Distance make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::Distance("rod", a, s.on_a.point, b, s.on_b.point, 0.8);
}
template <>
pl::InLine make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::InLine("pin in slot", a, s.on_a, b, s.on_b);
}
template <>
pl::RevoluteDriver make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::RevoluteDriver("angle driver", a, s.on_a, b, s.on_b, harmonic_motion());
}
template <>
pl::TranslationalDriver make_joint(const Scene& s, BodyId a, BodyId b) {
  return pl::TranslationalDriver("slide driver", a, s.on_a, b, s.on_b,
                                 odyn::Motion::polynomial({0.1, -0.3, 0.8, 0.5}));
}

/// The element's own view of two body states: frames from (q, v) and its input.
struct Frames {
  Space::Frame a, b;
  odyn::ElementInput<Space, 2> input(double t) const { return {{&a, &b}, t}; }
  void set(const Vector3d& q_a, const Vector3d& v_a, const Vector3d& q_b, const Vector3d& v_b) {
    Space::make_frame(q_a, v_a, a);
    Space::make_frame(q_b, v_b, b);
  }
};

template <class E>
E bound_joint(const Scene& s) {
  const BodyId a = s.ground_a ? odyn::ground : BodyId{1};
  const BodyId b{2};
  E joint = make_joint<E>(s, a, b);
  Frames f;
  f.set(s.q_a, s.v_a, s.q_b, s.v_b);
  joint.bind(f.input(kTime));
  return joint;
}

template <class E>
void check_against_differences(const Scene& s) {
  const E joint = bound_joint<E>(s);
  using Blocks = odyn::BlocksOf<E>;
  constexpr int m = E::num_equations;
  Frames f;
  auto blocks_at = [&](const Vector3d& q_a, const Vector3d& q_b, double t) {
    f.set(q_a, s.v_a, q_b, s.v_b);
    Blocks out;
    joint.evaluate(f.input(t), out);
    return out;
  };
  const Blocks at = blocks_at(s.q_a, s.q_b, kTime);
  const double eps = 1e-6;
  // Jacobian blocks: columns of dPhi/dq for each body (a only if it moves).
  for (int side = s.ground_a ? 1 : 0; side < 2; ++side) {
    for (int j = 0; j < 3; ++j) {
      Vector3d dq = Vector3d::Zero();
      dq[j] = eps;
      const Vector3d qa_plus = side == 0 ? Vector3d(s.q_a + dq) : s.q_a;
      const Vector3d qa_minus = side == 0 ? Vector3d(s.q_a - dq) : s.q_a;
      const Vector3d qb_plus = side == 1 ? Vector3d(s.q_b + dq) : s.q_b;
      const Vector3d qb_minus = side == 1 ? Vector3d(s.q_b - dq) : s.q_b;
      const Eigen::Matrix<double, m, 1> column =
          (blocks_at(qa_plus, qb_plus, kTime).phi - blocks_at(qa_minus, qb_minus, kTime).phi) /
          (2.0 * eps);
      INFO(joint.name() << " side " << side << " column " << j);
      CHECK((at.jacobian[side].col(j) - column).norm() < 1e-8);
    }
  }
  // Phi_t.
  const Eigen::Matrix<double, m, 1> phi_t =
      (blocks_at(s.q_a, s.q_b, kTime + eps).phi - blocks_at(s.q_a, s.q_b, kTime - eps).phi) /
      (2.0 * eps);
  CHECK((at.phi_t - phi_t).norm() < 1e-8);
  // gamma: along q(t) = q0 + v (t - kTime), d/dt (Phi_q v + Phi_t) = -gamma.
  auto velocity_residual = [&](double dt) {
    const Blocks out = blocks_at(s.q_a + dt * s.v_a, s.q_b + dt * s.v_b, kTime + dt);
    Eigen::Matrix<double, m, 1> c = out.jacobian[1] * s.v_b + out.phi_t;
    if (!s.ground_a) c += out.jacobian[0] * s.v_a;
    return c;
  };
  const Eigen::Matrix<double, m, 1> rate =
      (velocity_residual(eps) - velocity_residual(-eps)) / (2.0 * eps);
  f.set(s.q_a, s.v_a, s.q_b, s.v_b);
  const Eigen::Matrix<double, m, 1> gamma = joint.gamma(f.input(kTime));
  INFO(joint.name() << " gamma " << gamma.transpose() << " vs " << -rate.transpose());
  CHECK((gamma + rate).norm() < 1e-6 * (1.0 + gamma.norm()));
  // Geometric stiffness: body k's block is d(J_k^T lambda)/d(q_k).
  if constexpr (odyn::HasGeometricStiffness<E>) {
    const Eigen::Matrix<double, m, 1> lambda = Eigen::Matrix<double, m, 1>::LinSpaced(m, 3.0, -2.0);
    odyn::GeometricStiffness<Space, 2> analytic;
    for (auto& block : analytic) block.setZero();
    f.set(s.q_a, s.v_a, s.q_b, s.v_b);
    joint.add_geometric_stiffness(f.input(kTime), lambda, analytic);
    for (int side = s.ground_a ? 1 : 0; side < 2; ++side) {
      Eigen::Matrix3d numeric;
      for (int j = 0; j < 3; ++j) {
        Vector3d dq = Vector3d::Zero();
        dq[j] = eps;
        const auto share = [&](double sign) {
          const Blocks out = blocks_at(side == 0 ? Vector3d(s.q_a + sign * dq) : s.q_a,
                                       side == 1 ? Vector3d(s.q_b + sign * dq) : s.q_b, kTime);
          return Vector3d(out.jacobian[side].transpose() * lambda);
        };
        numeric.col(j) = (share(1.0) - share(-1.0)) / (2.0 * eps);
      }
      INFO(joint.name() << " geometric stiffness, side " << side << "\n"
                        << analytic[side] << "\nnumeric\n"
                        << numeric);
      CHECK((analytic[side] - numeric).norm() < 1e-7 * (1.0 + numeric.norm()));
    }
  }
}

}  // namespace

TEMPLATE_TEST_CASE("planar constraint blocks match finite differences", "[planar][joints]",
                   pl::Revolute, pl::Translational, pl::Fixed, pl::Distance, pl::InLine,
                   pl::RevoluteDriver, pl::TranslationalDriver) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    check_against_differences<TestType>(make_scene(seed, false));
    check_against_differences<TestType>(make_scene(seed + 100, true));
  }
}

TEST_CASE("planar joint angle counts turns and starts from the axes", "[planar][joints]") {
  // Body b already turned by 2 full turns plus 0.3 rad; no axes given: the angle starts at 0.
  Scene s = make_scene(7, true);
  s.on_a.axis.setZero();
  s.on_b.axis.setZero();
  s.q_b[2] = 4.0 * std::numbers::pi + 0.3;
  const auto joint = bound_joint<pl::Revolute>(s);
  Frames f;
  f.set(s.q_a, s.v_a, s.q_b, s.v_b);
  CHECK(joint.angle(f.input(0.0)) == Approx(0.0).margin(1e-14));
  // Three more turns: the angle keeps counting.
  Vector3d turned = s.q_b;
  turned[2] += 6.0 * std::numbers::pi + 0.1;
  f.set(s.q_a, s.v_a, turned, s.v_b);
  CHECK(joint.angle(f.input(0.0)) == Approx(6.0 * std::numbers::pi + 0.1).epsilon(1e-14));
  // Both axes given: the angle is the one between them, read within (-pi, pi] at the start.
  s.on_a.axis = {1.0, 0.0};
  s.on_b.axis = {0.0, 2.0};  // 90 degrees in body b
  const auto given = bound_joint<pl::Revolute>(s);
  f.set(s.q_a, s.v_a, s.q_b, s.v_b);
  CHECK(given.angle(f.input(0.0)) == Approx(0.3 + std::numbers::pi / 2.0).epsilon(1e-14));
}

namespace {

/// Generalized forces of one force element on two free bodies, and its potential energy.
template <class E>
struct ForceProbe {
  const E& element;
  Vector3d v_a = Vector3d::Zero(), v_b = Vector3d::Zero();
  Eigen::Matrix<double, 6, 1> force(const Vector3d& q_a, const Vector3d& q_b) const {
    Frames f;
    f.set(q_a, v_a, q_b, v_b);
    odyn::ForceBlocks<Space, 2> out;
    element.evaluate(f.input(0.0), out);
    Eigen::Matrix<double, 6, 1> q;
    q << out.force[0], out.force[1];
    return q;
  }
  double potential(const Vector3d& q_a, const Vector3d& q_b) const {
    Frames f;
    f.set(q_a, v_a, q_b, v_b);
    return element.potential_energy(f.input(0.0));
  }
  /// -dV/dq by central differences.
  Eigen::Matrix<double, 6, 1> potential_force(const Vector3d& q_a, const Vector3d& q_b) const {
    Eigen::Matrix<double, 6, 1> out;
    const double eps = 1e-6;
    for (int j = 0; j < 6; ++j) {
      Vector3d da = Vector3d::Zero(), db = Vector3d::Zero();
      (j < 3 ? da[j] : db[j - 3]) = eps;
      out[j] = -(potential(q_a + da, q_b + db) - potential(q_a - da, q_b - db)) / (2.0 * eps);
    }
    return out;
  }
};

}  // namespace

TEST_CASE("planar force elements: Q = -dV/dq, and exact Newton blocks where promised",
          "[planar][forces]") {
  const Vector3d q_a(0.3, -0.2, 7.1), q_b(-0.4, 0.5, -0.6);
  SECTION("translational spring") {
    const pl::Tsda spring("spring", BodyId{1}, {0.1, 0.2}, BodyId{2}, {-0.3, 0.05},
                          {.stiffness = 250.0, .free_length = 0.4});
    const ForceProbe<pl::Tsda> probe{spring};
    CHECK((probe.force(q_a, q_b) - probe.potential_force(q_a, q_b)).norm() < 1e-6);
  }
  SECTION("rotational spring, over several turns, with its stiffness and damping blocks") {
    pl::Rsda spring("torsion", BodyId{1}, BodyId{2},
                    {.stiffness = 40.0, .damping = 3.0, .free_angle = 0.25});
    Frames f;
    f.set(Vector3d(0, 0, 0.5), Vector3d::Zero(), Vector3d(0, 0, 0.2), Vector3d::Zero());
    spring.bind(f.input(0.0));  // joint angle 0 at phi_b - phi_a = -0.3
    const ForceProbe<pl::Rsda> still{spring};
    CHECK((still.force(q_a, q_b) - still.potential_force(q_a, q_b)).norm() < 1e-6);
    // Joint angle -0.6 - 7.1 + 0.3: the torque on b is -k (angle - free) (no wrap to a turn).
    const double angle = q_b[2] - q_a[2] + 0.3;
    CHECK(still.force(q_a, q_b)[5] == Approx(-40.0 * (angle - 0.25)).epsilon(1e-14));
    // -dQ/dq and -dQ/dv against differences.
    ForceProbe<pl::Rsda> moving{spring, Vector3d(0.1, 0.2, 1.5), Vector3d(-0.3, 0.0, -2.0)};
    odyn::ForceBlocks<Space, 2> blocks;
    f.set(q_a, moving.v_a, q_b, moving.v_b);
    spring.jacobians(f.input(0.0), blocks);
    const double eps = 1e-6;
    for (int j = 0; j < 6; ++j) {
      Vector3d da = Vector3d::Zero(), db = Vector3d::Zero();
      (j < 3 ? da[j] : db[j - 3]) = eps;
      const Eigen::Matrix<double, 6, 1> dq =
          -(moving.force(q_a + da, q_b + db) - moving.force(q_a - da, q_b - db)) / (2.0 * eps);
      CHECK((blocks.stiffness.col(j) - dq).norm() < 1e-6);
      ForceProbe<pl::Rsda> faster = moving, slower = moving;
      (j < 3 ? faster.v_a[j] : faster.v_b[j - 3]) += eps;
      (j < 3 ? slower.v_a[j] : slower.v_b[j - 3]) -= eps;
      const Eigen::Matrix<double, 6, 1> dv =
          -(faster.force(q_a, q_b) - slower.force(q_a, q_b)) / (2.0 * eps);
      CHECK((blocks.damping.col(j) - dv).norm() < 1e-6);
    }
  }
  SECTION("gravity") {
    const pl::Gravity gravity("gravity", {0.3, -9.81});
    Space::Frame frame;
    Space::make_frame(q_b, Vector3d::Zero(), frame);
    const Vector3d q = gravity.force_on(2.0, frame);
    CHECK(q.isApprox(Vector3d(0.6, -19.62, 0.0)));
    CHECK(gravity.potential_energy(2.0, frame) == Approx(-2.0 * (0.3 * -0.4 - 9.81 * 0.5)));
  }
}

TEST_CASE("planar compound pendulum: large-amplitude period", "[planar][dynamics]") {
  // A bar of length 1 m and mass 1 kg swinging about one end from 2 rad at rest:
  // T = 4 sqrt(I_O / (m g d)) K(sin(theta0 / 2)), I_O = 1/3 kg m^2, d = 0.5 m.
  const double theta0 = 2.0, g = 9.81;
  Model model;
  pl::Body bar{.name = "bar",
               .mass = 1.0,
               .inertia = 1.0 / 12.0,
               .position = {0.5 * std::sin(theta0), -0.5 * std::cos(theta0)},
               .angle = theta0};
  const BodyId b = model.add_body(bar);
  model.add(pl::Revolute("pivot", odyn::ground, {}, b, {{0.0, 0.5}}));
  model.add(pl::Gravity("gravity", {0.0, -g}));
  Workspace ws(model);
  odyn::DynamicsSettings settings;
  settings.step = 1e-4;
  settings.t_end = 3.0;
  settings.output_interval = 1e-4;
  // Turning points: the angular velocity changes sign; interpolate linearly between samples.
  std::vector<double> turns;
  double t_prev = 0.0, w_prev = 0.0;
  odyn::simulate_with<odyn::GeneralizedAlpha>(model, ws, settings, [&](const Workspace& state) {
    const double w = state.v[2];
    if (state.t > 0.0 && w_prev != 0.0 && (w > 0.0) != (w_prev > 0.0))
      turns.push_back(t_prev + (state.t - t_prev) * w_prev / (w_prev - w));
    t_prev = state.t;
    w_prev = w;
  });
  const double period =
      4.0 * std::sqrt((1.0 / 3.0) / (0.5 * g)) * reference::elliptic_k(std::sin(theta0 / 2));
  REQUIRE(turns.size() >= 2);
  CHECK(2.0 * turns[0] == Approx(period).epsilon(1e-6));
  CHECK(turns[1] - turns[0] == Approx(period / 2.0).epsilon(1e-6));
}

TEST_CASE("planar reactions: hand-solved statics and a driven slider", "[planar][reactions]") {
  SECTION("a bar on a pin and a vertical rod carries half its weight on each") {
    Model model;
    const BodyId bar = model.add_body(
        pl::Body{.name = "bar", .mass = 2.0, .inertia = 1.0 / 6.0, .position = {0.5, 0.0}});
    const auto pin =
        model.add(pl::Revolute("pin", odyn::ground, {{0.0, 0.0}, {0.0, 1.0}}, bar, {{-0.5, 0.0}}));
    const auto rod = model.add(pl::Distance("rod", odyn::ground, {1.0, 1.0}, bar, {0.5, 0.0}));
    model.add(pl::Gravity("gravity", {0.0, -9.81}));
    Workspace ws(model);
    odyn::assemble(model, ws);
    CHECK(ws.vdot.norm() < 1e-12);
    const auto on_bar = odyn::reaction(model, ws, pin, odyn::Side::b);
    CHECK(on_bar.force.x() == Approx(0.0).margin(1e-12));
    CHECK(on_bar.force.y() == Approx(9.81).epsilon(1e-12));
    CHECK(on_bar.torque[0] == Approx(0.0).margin(1e-12));
    // The ground's side feels the opposite force; in the joint's axes (axis = global y first).
    CHECK(odyn::reaction(model, ws, pin, odyn::Side::a).force.y() == Approx(-9.81).epsilon(1e-12));
    const auto in_joint = odyn::reaction(model, ws, pin, odyn::Side::a, odyn::ReactionAxes::joint);
    CHECK(in_joint.force.x() == Approx(-9.81).epsilon(1e-12));
    CHECK(in_joint.force.y() == Approx(0.0).margin(1e-12));
    CHECK(odyn::reaction(model, ws, rod, odyn::Side::b).force.y() == Approx(9.81).epsilon(1e-12));
  }
  SECTION("a slider driven up a vertical guide needs m (a + g)") {
    Model model;
    const BodyId block = model.add_body(pl::Body{.name = "block", .mass = 3.0, .inertia = 0.1});
    const pl::Translational guide("guide", odyn::ground, {{0.0, 0.0}, {0.0, 1.0}}, block, {});
    model.add(guide);
    const double a = 2.0;
    const auto lift =
        model.add(pl::TranslationalDriver("lift", guide, odyn::Motion::polynomial({0, 0, a / 2})));
    model.add(pl::Gravity("gravity", {0.0, -9.81}));
    Workspace ws(model);
    odyn::DynamicsSettings settings;
    settings.step = 1e-3;
    settings.t_end = 0.5;
    settings.output_interval = 0.5;
    odyn::simulate_with<odyn::GeneralizedAlpha>(model, ws, settings, [](const Workspace&) {});
    CHECK(ws.q[1] == Approx(a / 2 * 0.25).epsilon(1e-10));
    CHECK(ws.v[1] == Approx(a * 0.5).epsilon(1e-10));
    const auto force = odyn::reaction(model, ws, lift, odyn::Side::b).force;
    CHECK(force.y() == Approx(3.0 * (a + 9.81)).epsilon(1e-8));
    CHECK(force.x() == Approx(0.0).margin(1e-9));
  }
}

TEST_CASE("four-bar linkage: closed-form position analysis and the motor's power",
          "[planar][four_bar]") {
  // The rocker angle from the loop closure solved independently (Freudenstein's equation
  // K1 cos(t4) - K2 cos(t2) + K3 = cos(t2 - t4), open branch), and the motor torque from the
  // power balance T omega = d(kinetic + potential energy)/dt.
  const four_bar::Parameters p;
  const double d = p.ground, a = p.crank, b = p.coupler, c = p.rocker;
  const double k1 = d / a, k2 = d / c, k3 = (a * a - b * b + c * c + d * d) / (2 * a * c);
  auto rocker_angle = [&](double t2) {
    // cos(t2 - t4) - k1 cos(t4) + k2 cos(t2) - k3 = 0, from |d + c e^(i t4) - a e^(i t2)| = b.
    const double aa = std::cos(t2) - k1, bb = std::sin(t2), cc = k2 * std::cos(t2) - k3;
    // aa cos(t4) + bb sin(t4) + cc = 0: t4 = atan2(bb, aa) +- acos(-cc / r).
    const double r = std::hypot(aa, bb);
    return std::atan2(bb, aa) - std::acos(-cc / r);
  };
  four_bar::Linkage l = four_bar::build(p);
  odyn::Workspace<four_bar::Model> ws(l.model);
  odyn::DynamicsSettings settings{.step = 1e-4, .t_end = 1.0, .output_interval = 1e-3};
  // Multipliers from index-3 generalized-alpha carry a weakly damped step-to-step ripple at
  // rho_inf = 0.9 (about 1e-3 of the motor torque here); 0.5 damps it within a few steps.
  settings.generalized_alpha.rho_inf = 0.5;
  std::vector<double> times, energy, power;
  double angle_error = 0.0;
  odyn::simulate_with<odyn::GeneralizedAlpha>(l.model, ws, settings, [&](const auto& s) {
    const double t2 = s.frames[l.crank.index].angle;
    CHECK(t2 == Approx(p.speed * s.t).margin(1e-12));
    double t4 = rocker_angle(t2);
    t4 += 2.0 * std::numbers::pi *
          std::round((s.frames[l.rocker.index].angle - t4) / (2.0 * std::numbers::pi));
    angle_error = std::max(angle_error, std::abs(s.frames[l.rocker.index].angle - t4));
    times.push_back(s.t);
    energy.push_back(odyn::kinetic_energy(l.model, s) + odyn::potential_energy(l.model, s));
    power.push_back(odyn::reaction(l.model, s, l.motor, odyn::Side::b).torque[0] * p.speed);
  });
  CHECK(angle_error < 1e-12);
  double largest_power = 0.0, power_error = 0.0;
  for (std::size_t k = 1; k + 1 < times.size(); ++k) {
    const double rate = (energy[k + 1] - energy[k - 1]) / (times[k + 1] - times[k - 1]);
    largest_power = std::max(largest_power, std::abs(power[k]));
    power_error = std::max(power_error, std::abs(power[k] - rate));
  }
  INFO("power balance error " << power_error << " W of " << largest_power << " W");
  CHECK(power_error < 1e-4 * largest_power);  // measured 3e-5 (the difference quotient)
}

}  // namespace test_planar
