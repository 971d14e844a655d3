// Kinematic analysis (analysis/kinematics.hpp): a fully driven mechanism against closed forms,
// and the mechanisms it must refuse, with dense matrices, on sparse rows (the path of large
// models, forced here by naming a sparse solver) and in joint coordinates.

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <odyn/analysis/kinematics.hpp>
#include <odyn/odyn.hpp>

#include "driven_chain.hpp"
#include "four_bar_model.hpp"

namespace test_kinematics {

namespace pl = odyn::planar;

// The paths of a kinematic analysis: dense matrices ("dense"), sparse rows ("klu"; "auto"
// chooses by the model's size) and joint coordinates ("joint", dense start checks).
odyn::KinematicSettings on_path(const std::string& path) {
  odyn::KinematicSettings s;
  if (path == "joint") {
    s.coordinates = "joint";
    s.linear_solver = odyn::LinearSolver::dense;
  } else {
    s.linear_solver = odyn::linear_solver_from_name(path);
  }
  return s;
}

// The rocker angle of the open four-bar for a crank angle, from Freudenstein's equation (as in
// test_planar.cpp), and its first two time derivatives by central differences of it.
struct Freudenstein {
  four_bar::Parameters p;
  double angle(double t2) const {
    const double d = p.ground, a = p.crank, b = p.coupler, c = p.rocker;
    const double k1 = d / a, k2 = d / c, k3 = (a * a - b * b + c * c + d * d) / (2 * a * c);
    const double aa = std::cos(t2) - k1, bb = std::sin(t2), cc = k2 * std::cos(t2) - k3;
    return std::atan2(bb, aa) - std::acos(-cc / std::hypot(aa, bb));
  }
  double at(double t) const { return angle(p.speed * t); }
  // Differences of angles, which may straddle atan2's cut.
  static double change(double from, double to) {
    return std::remainder(to - from, 2.0 * std::numbers::pi);
  }
  double rate(double t) const {
    const double h = 1e-5;
    return change(at(t - h), at(t + h)) / (2 * h);
  }
  double acceleration(double t) const {
    const double h = 1e-4;
    return (change(at(t), at(t + h)) - change(at(t - h), at(t))) / (h * h);
  }
};

double wrapped(double angle, double near) {
  return angle + 2.0 * std::numbers::pi * std::round((near - angle) / (2.0 * std::numbers::pi));
}

TEST_CASE(
    "A driven four-bar moves as Freudenstein's equation says, with the motor's torque "
    "from the power balance",
    "[kinematics]") {
  const std::string path = GENERATE(as<std::string>{}, "dense", "klu", "joint");
  INFO("path " << path);
  const Freudenstein reference;
  const four_bar::Parameters& p = reference.p;
  four_bar::Linkage l = four_bar::build(p);
  odyn::Workspace<four_bar::Model> ws(l.model);
  std::vector<double> times, energy, power;
  double angle_error = 0.0, rate_error = 0.0, acceleration_error = 0.0;
  double largest_rate = 0.0, largest_acceleration = 0.0;
  odyn::kinematic_analysis(
      l.model, ws, 1.0, 1e-3,
      [&](const auto& s) {
        const auto& rocker = s.frames[l.rocker.index];
        CHECK(s.frames[l.crank.index].angle == Approx(p.speed * s.t).margin(1e-12));
        angle_error = std::max(angle_error,
                               std::abs(rocker.angle - wrapped(reference.at(s.t), rocker.angle)));
        const int spin = (l.rocker.index - 1) * 3 + 2;  // the rocker's angular velocity coordinate
        rate_error = std::max(rate_error, std::abs(s.v[spin] - reference.rate(s.t)));
        acceleration_error =
            std::max(acceleration_error, std::abs(s.vdot[spin] - reference.acceleration(s.t)));
        largest_rate = std::max(largest_rate, std::abs(s.v[spin]));
        largest_acceleration = std::max(largest_acceleration, std::abs(s.vdot[spin]));
        times.push_back(s.t);
        energy.push_back(odyn::kinetic_energy(l.model, s) + odyn::potential_energy(l.model, s));
        power.push_back(odyn::reaction(l.model, s, l.motor, odyn::Side::b).torque[0] * p.speed);
      },
      on_path(path));
  REQUIRE(times.size() == 1001);
  CHECK(times.back() == Approx(1.0).margin(1e-12));
  CHECK(angle_error < 1e-11);
  INFO("rate error " << rate_error << " of " << largest_rate << " rad/s; acceleration error "
                     << acceleration_error << " of " << largest_acceleration << " rad/s^2");
  CHECK(rate_error < 1e-8 * largest_rate);                  // the difference quotients' error
  CHECK(acceleration_error < 1e-5 * largest_acceleration);  // (h^2 and rounding / h^2)
  double largest_power = 0.0, power_error = 0.0;
  for (std::size_t k = 1; k + 1 < times.size(); ++k) {
    const double rate = (energy[k + 1] - energy[k - 1]) / (times[k + 1] - times[k - 1]);
    largest_power = std::max(largest_power, std::abs(power[k]));
    power_error = std::max(power_error, std::abs(power[k] - rate));
  }
  INFO("power balance error " << power_error << " W of " << largest_power << " W");
  CHECK(power_error < 1e-4 * largest_power);
}

TEST_CASE(
    "A driven spatial slider-crank follows its closed form, with the torque from the "
    "energy balance",
    "[kinematics]") {
  // The engine's linkage (crank r, rod L; a revolute bearing about x, a spherical crank pin, a
  // universal piston pin, a cylinder along z) without its gas force, the crank driven at omega.
  namespace sp = odyn::spatial;
  using Eigen::Vector3d;
  using Model = sp::Model<sp::Revolute, sp::Spherical, sp::Universal, sp::Translational,
                          sp::RevoluteDriver, sp::Gravity>;
  const double r = 0.04, L = 0.14, omega = 150.0, g = 9.81;
  const double crank_inertia = 1.524, rod_mass = 0.253, rod_inertia = 0.399, piston_mass = 0.643;
  Model m;
  const odyn::BodyId crank =
      m.add_body({.name = "crank",
                  .mass = 1.399,
                  .inertia = sp::Body::principal(crank_inertia, 1.291, 0.836)});
  const odyn::BodyId rod = m.add_body({.name = "rod",
                                       .mass = rod_mass,
                                       .inertia = sp::Body::principal(rod_inertia, 0.372, 0.0349),
                                       .position = {0.0, 0.0, r + L / 2.0}});
  const odyn::BodyId piston = m.add_body({.name = "piston",
                                          .mass = piston_mass,
                                          .inertia = sp::Body::principal(0.457, 0.506, 0.653),
                                          .position = {0.0, 0.0, r + L}});
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  const sp::Revolute bearing("bearing", odyn::ground, sp::JointFrame{{0, 0, 0}, x}, crank,
                             sp::JointFrame{{0, 0, 0}, x});
  m.add(bearing);
  m.add(sp::Spherical("crank pin", crank, {0, 0, r}, rod, {0, 0, -L / 2.0}));
  m.add(sp::Universal("piston pin", rod, sp::JointFrame{{0, 0, L / 2.0}, x}, piston,
                      sp::JointFrame{{0, 0, 0}, y}));
  m.add(sp::Translational("cylinder", odyn::ground, sp::JointFrame{{0, 0, r + L}, z}, piston,
                          sp::JointFrame{{0, 0, 0}, z}));
  const auto motor =
      m.add(sp::RevoluteDriver("motor", bearing, odyn::Motion::constant_velocity(omega)));
  m.add(sp::Gravity("gravity", {0.0, 0.0, -g}));

  // The closed form: crank angle theta = omega t about x, piston height
  // z = r cos(theta) + D with D = sqrt(L^2 - r^2 sin^2(theta)), and its derivatives.
  struct Closed {
    double z, rate, acceleration, energy;
  };
  auto closed = [&](double t) {
    const double th = omega * t, s = std::sin(th), c = std::cos(th);
    const double d = std::sqrt(L * L - r * r * s * s);
    Closed out{};
    out.z = r * c + d;
    out.rate = omega * (-r * s - r * r * s * c / d);
    out.acceleration =
        omega * omega *
        (-r * c - r * r * (c * c - s * s) / d - std::pow(r, 4) * s * s * c * c / std::pow(d, 3));
    // The rod's centre and its turning rate about x (its direction is (0, r s, D) / L).
    const double rod_y_rate = -r * c * omega / 2.0, rod_z_rate = (-r * s * omega + out.rate) / 2.0;
    const double rod_spin = -r * c * omega / d;
    out.energy = 0.5 * crank_inertia * omega * omega +
                 0.5 * rod_mass * (rod_y_rate * rod_y_rate + rod_z_rate * rod_z_rate) +
                 0.5 * rod_inertia * rod_spin * rod_spin + 0.5 * piston_mass * out.rate * out.rate +
                 g * (rod_mass * (r * c + out.z) / 2.0 + piston_mass * out.z);
    return out;
  };
  const std::string path = GENERATE(as<std::string>{}, "dense", "klu", "joint");
  INFO("path " << path);
  odyn::Workspace<Model> ws(m);
  double z_error = 0.0, rate_error = 0.0, acceleration_error = 0.0, torque_error = 0.0;
  double largest_acceleration = 0.0, largest_torque = 0.0;
  const int lift = (piston.index - 1) * 6 + 2;  // the piston's z velocity coordinate
  odyn::kinematic_analysis(
      m, ws, 0.1, 2e-4,
      [&](const auto& s) {
        const Closed c = closed(s.t);
        z_error = std::max(z_error, std::abs(s.frames[piston.index].position.z() - c.z));
        rate_error = std::max(rate_error, std::abs(s.v[lift] - c.rate));
        acceleration_error = std::max(acceleration_error, std::abs(s.vdot[lift] - c.acceleration));
        largest_acceleration = std::max(largest_acceleration, std::abs(c.acceleration));
        const double h = 1e-6;  // the energy's rate, by a central difference of the closed form
        const double power = (closed(s.t + h).energy - closed(s.t - h).energy) / (2.0 * h);
        const double torque = odyn::reaction(m, s, motor, odyn::Side::b).torque.x();
        torque_error = std::max(torque_error, std::abs(torque - power / omega));
        largest_torque = std::max(largest_torque, std::abs(power / omega));
      },
      on_path(path));
  INFO("piston: z error " << z_error << " m, rate error " << rate_error
                          << " m/s, acceleration error " << acceleration_error << " of "
                          << largest_acceleration << " m/s^2; motor torque error " << torque_error
                          << " of " << largest_torque << " N m");
  CHECK(z_error < 1e-12);
  CHECK(rate_error < 1e-10);
  CHECK(acceleration_error < 1e-9 * largest_acceleration);
  CHECK(torque_error < 1e-6 * largest_torque);  // the difference quotient's error
}

TEST_CASE("A kinematic analysis refuses a mechanism that is not fully driven, or over-driven",
          "[kinematics]") {
  const std::string path = GENERATE(as<std::string>{}, "dense", "klu", "joint");
  INFO("path " << path);
  SECTION("a degree of freedom left") {
    using Model = pl::Model<pl::Revolute, pl::Gravity>;
    Model m;
    const odyn::BodyId bar =
        m.add_body({.name = "bar", .mass = 1.0, .inertia = 0.1, .position = {0.5, 0.0}});
    m.add(pl::Revolute("pivot", odyn::ground, {{0.0, 0.0}}, bar, {{-0.5, 0.0}}));
    odyn::Workspace<Model> ws(m);
    CHECK_THROWS_WITH(
        odyn::kinematic_analysis(
            m, ws, 1.0, 0.1, [](const auto&) {}, on_path(path)),
        Catch::Contains("1 degree of freedom remain") && Catch::Contains("its drivers: none"));
  }
  SECTION("a driver that repeats another") {
    four_bar::Linkage l = four_bar::build();
    const pl::Revolute& o2 = l.model.element(l.o2);
    l.model.add(pl::RevoluteDriver("second motor", o2, odyn::Motion::constant_velocity(1.0)));
    odyn::Workspace<four_bar::Model> ws(l.model);
    CHECK_THROWS_WITH(odyn::kinematic_analysis(
                          l.model, ws, 1.0, 0.1, [](const auto&) {}, on_path(path)),
                      Catch::Contains("over-driven") && Catch::Contains("motor'"));
  }
  SECTION("an output interval too short to count its outputs") {
    four_bar::Linkage l = four_bar::build();
    odyn::Workspace<four_bar::Model> ws(l.model);
    CHECK_THROWS_WITH(odyn::kinematic_analysis(
                          l.model, ws, 1.0, 1e-300, [](const auto&) {}, on_path(path)),
                      Catch::Contains("asks for 1e+300 outputs"));
  }
  SECTION("coordinates it does not know") {
    four_bar::Linkage l = four_bar::build();
    odyn::Workspace<four_bar::Model> ws(l.model);
    odyn::KinematicSettings s = on_path(path);
    s.coordinates = "polar";
    CHECK_THROWS_WITH(odyn::kinematic_analysis(
                          l.model, ws, 1.0, 0.1, [](const auto&) {}, s),
                      Catch::Contains("coordinates 'polar' unknown"));
  }
}

TEST_CASE("A crank driven past its dead centre locks up, named with its time", "[kinematics]") {
  // A slider-crank whose rod is shorter than the crank cannot turn round: at crank angle
  // asin(rod / crank) the rod stands square to the slide, and the drive cannot go on.
  using Model = pl::Model<pl::Revolute, pl::Translational, pl::RevoluteDriver>;
  Model m;
  const double crank = 0.2, rod = 0.1, speed = 1.0;
  const odyn::BodyId arm =
      m.add_body({.name = "crank", .mass = 1.0, .inertia = 0.01, .position = {crank / 2, 0.0}});
  const odyn::BodyId link =
      m.add_body({.name = "rod", .mass = 1.0, .inertia = 0.01, .position = {crank + rod / 2, 0.0}});
  const odyn::BodyId slider =
      m.add_body({.name = "slider", .mass = 1.0, .inertia = 0.01, .position = {crank + rod, 0.0}});
  const pl::Revolute pivot("pivot", odyn::ground, {{0.0, 0.0}}, arm, {{-crank / 2, 0.0}});
  m.add(pivot);
  m.add(pl::Revolute("pin", arm, {{crank / 2, 0.0}}, link, {{-rod / 2, 0.0}}));
  m.add(pl::Revolute("wrist", link, {{rod / 2, 0.0}}, slider, {{0.0, 0.0}}));
  m.add(pl::Translational("slide", odyn::ground, {{0.0, 0.0}, {1.0, 0.0}}, slider,
                          {{0.0, 0.0}, {1.0, 0.0}}));
  m.add(pl::RevoluteDriver("motor", pivot, odyn::Motion::constant_velocity(speed)));
  const std::string path = GENERATE(as<std::string>{}, "dense", "klu", "joint");
  INFO("path " << path);
  odyn::Workspace<Model> ws(m);
  double last = 0.0;
  const double lock = std::asin(rod / crank) / speed;  // the rod square to the slide
  REQUIRE_THROWS_AS(odyn::kinematic_analysis(
                        m, ws, 2.0, 0.01, [&](const auto& s) { last = s.t; }, on_path(path)),
                    odyn::AssemblyError);
  CHECK(last < lock);
  CHECK(last > lock - 0.011);
  odyn::Workspace<Model> again(m);
  CHECK_THROWS_WITH(odyn::kinematic_analysis(
                        m, again, 2.0, 0.01, [](const auto&) {}, on_path(path)),
                    Catch::Contains("locks up after t = 0.5235"));
}

TEST_CASE(
    "A long driven chain moves as its forward kinematics say, with the motors' torques and the "
    "hinges' forces of a recursive Newton-Euler pass",
    "[kinematics]") {
  // tests/driven_chain.hpp: N links hinged end to end, each hinge's angle driven. A pass from
  // the tip to the root gives the force F_i that link i - 1 exerts on link i through hinge i
  // and the motor's torque tau_i:
  //   F_i = m_i (a_i - g) + F_(i+1),
  //   tau_i = I_i alpha_i + tau_(i+1) - (p_i - c_i) x F_i + (p_(i+1) - c_i) x F_(i+1),
  // with p_i the hinge's point and c_i the link's centre. At N = 60 (180 velocities, 180
  // equations) the analysis takes the sparse path by itself; the dense one is checked too.
  using driven_chain::length;
  using Eigen::Vector2d;
  constexpr int links = 60;
  const driven_chain::Chain chain = driven_chain::build(links);
  const driven_chain::Model& m = chain.model;
  REQUIRE(odyn::detail::sparse_kinematics(m, odyn::LinearSolver::automatic));
  auto cross = [](const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };

  const std::string path = GENERATE(as<std::string>{}, "auto", "dense", "joint");
  INFO("path " << path);
  odyn::Workspace<driven_chain::Model> ws(m);
  double position_error = 0.0, velocity_error = 0.0, acceleration_error = 0.0;
  double torque_error = 0.0, largest_torque = 0.0, force_error = 0.0, largest_force = 0.0;
  int outputs = 0;
  odyn::kinematic_analysis(
      m, ws, 0.5, 0.05,
      [&](const auto& s) {
        ++outputs;
        const std::vector<driven_chain::Link> expected = driven_chain::chain_at(links, s.t);
        for (int i = 0; i < links; ++i) {
          const driven_chain::Link& e = expected[i];
          const auto& frame = s.frames[i + 1];
          position_error = std::max({position_error, (frame.position - e.centre).norm(),
                                     std::abs(frame.angle - e.angle)});
          const auto v = s.v.template segment<3>(3 * i), a = s.vdot.template segment<3>(3 * i);
          velocity_error = std::max({velocity_error, (v.template head<2>() - e.velocity).norm(),
                                     std::abs(v[2] - e.rate)});
          acceleration_error =
              std::max({acceleration_error, (a.template head<2>() - e.acceleration).norm(),
                        std::abs(a[2] - e.angular_acceleration)});
        }
        // The tip-to-root pass.
        Vector2d force_above = Vector2d::Zero();
        double torque_above = 0.0;
        for (int i = links - 1; i >= 0; --i) {
          const driven_chain::Link& e = expected[i];
          const double mass = driven_chain::mass(i);
          const Vector2d force = mass * (e.acceleration - driven_chain::gravity) + force_above;
          const Vector2d tip = e.centre + (e.centre - e.hinge);
          const double torque = mass * length * length / 12.0 * e.angular_acceleration +
                                torque_above - cross(e.hinge - e.centre, force) +
                                cross(tip - e.centre, force_above);
          const auto hinge = odyn::reaction(m, s, chain.hinges[i], odyn::Side::b);
          const auto motor = odyn::reaction(m, s, chain.motors[i], odyn::Side::b);
          force_error = std::max(force_error, (hinge.force + motor.force - force).norm());
          torque_error =
              std::max(torque_error, std::abs(hinge.torque[0] + motor.torque[0] - torque));
          largest_force = std::max(largest_force, force.norm());
          largest_torque = std::max(largest_torque, std::abs(torque));
          force_above = force;
          torque_above = torque;
        }
      },
      on_path(path));
  INFO("errors: position " << position_error << ", velocity " << velocity_error << ", acceleration "
                           << acceleration_error << ", force " << force_error << " of "
                           << largest_force << " N, torque " << torque_error << " of "
                           << largest_torque << " N m");
  CHECK(outputs == 11);
  CHECK(position_error < 1e-11);
  CHECK(velocity_error < 1e-10);
  CHECK(acceleration_error < 1e-9);
  CHECK(force_error < 1e-10 * largest_force);
  CHECK(torque_error < 1e-10 * largest_torque);
}

}  // namespace test_kinematics
