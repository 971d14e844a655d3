// The bushing (spatial/bushing.hpp, planar/bushing.hpp) against independent references:
// - its force is minus the gradient of its energy, written out here from the frames (with
//   Eigen's angle-axis for the rotation), at large displacements and anisotropic coupled
//   stiffness; its damper's power is -x'^T C x', with x' by differences along the motion;
// - small vibrations of a body on an offset, coupled bushing follow the modes of the
//   generalized eigenproblem (A^T K A) phi = w^2 M phi, A the linearized displacement map;
// - a damped, preloaded, loaded mount against the closed-form damped oscillator, its outputs
//   (displacement, rate and force components) too;
// - energy is conserved over a large motion; generalized-alpha with the blocks by differences
//   converges to the same motion; bad matrices are refused by name.

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <odyn/odyn.hpp>

namespace test_bushing {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using odyn::BodyId;

/// A random symmetric positive definite matrix with couplings, scaled per component.
template <int N>
Eigen::Matrix<double, N, N> coupled_matrix(std::mt19937& random,
                                           const Eigen::Matrix<double, N, 1>& scales) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::Matrix<double, N, N> b;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) b(i, j) = uniform(random);
  const Eigen::Matrix<double, N, N> core =
      0.5 * Eigen::Matrix<double, N, N>::Identity() + b * b.transpose() / N;
  const auto root = scales.cwiseSqrt().asDiagonal();
  return root * core * root;
}

Matrix3d random_rotation(std::mt19937& random, double largest_angle) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Vector3d axis = Vector3d(uniform(random), uniform(random), uniform(random)).normalized();
  return Eigen::AngleAxisd(largest_angle * uniform(random), axis).toRotationMatrix();
}

/// dop853 at 1e-12 over 1.5 periods of a mode at angular frequency omega, 16 outputs a period.
odyn::DynamicsSettings mode_run(double omega) {
  odyn::DynamicsSettings settings;
  settings.integrator = "dop853";
  settings.rtol = settings.atol = 1e-12;
  const double period = 2.0 * std::numbers::pi / omega;
  settings.t_end = 1.5 * period;
  settings.output_interval = period / 16.0;
  return settings;
}

// --- Spatial: force = -grad(energy), damper power --------------------------------------------

/// The bushing's energy written out from two frames: d and theta with Eigen's angle-axis.
double spatial_energy(const sp::Bushing& bushing, const std::array<odyn::Spatial::Frame, 2>& f) {
  const Matrix3d axes_a = bushing.axes(0, f[0]), axes_b = bushing.axes(1, f[1]);
  const Vector3d d = axes_a.transpose() *
                     (f[1].point(bushing.frame(1).point) - f[0].point(bushing.frame(0).point));
  const Eigen::AngleAxisd turn(axes_a.transpose() * axes_b);
  Vector6d x;
  x << d, turn.angle() * turn.axis();
  const auto& law = bushing.law();
  return 0.5 * x.dot(law.stiffness * x) - law.preload.dot(x);
}

TEST_CASE("Spatial bushing: force is minus the energy's gradient, damper power is -x'C x'",
          "[bushing]") {
  for (const std::uint32_t seed : {1u, 2u, 3u}) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    const auto vector = [&](double scale) {
      return Vector3d(scale * uniform(random), scale * uniform(random), scale * uniform(random));
    };
    sp::Bushing::Law law;
    Vector6d scales;
    scales << 3e4, 1e4, 2e4, 300.0, 100.0, 500.0;
    law.stiffness = coupled_matrix<6>(random, scales);
    law.preload << vector(50.0), vector(5.0);
    const sp::JointFrame on_a{vector(0.3), vector(1.0), vector(1.0)};
    const sp::JointFrame on_b{vector(0.3), vector(1.0), vector(1.0)};
    const sp::Bushing spring("mount", BodyId{1}, on_a, BodyId{2}, on_b, law);

    // Two bodies apart and turned by up to 2.5 rad from each other (below the half turn).
    std::array<odyn::Spatial::Frame, 2> frames;
    frames[0].position = vector(1.0);
    frames[0].rotation = random_rotation(random, 3.0);
    frames[1].position = vector(1.0);
    frames[1].rotation = frames[0].rotation * random_rotation(random, 2.5);
    const odyn::ElementInput<odyn::Spatial, 2> in{{&frames[0], &frames[1]}, 0.0};
    odyn::ForceBlocks<odyn::Spatial, 2> blocks;
    spring.evaluate(in, blocks);
    INFO("seed " << seed << ", rotation " << spring.displacement(in).x.tail<3>().norm());
    CHECK(std::abs(spring.potential_energy(in) - spatial_energy(spring, frames)) <
          1e-9 * std::abs(spatial_energy(spring, frames)));

    // -dV/d(velocity coordinate) by central differences: positions moved globally, the
    // orientation turned about body axes (as the body's velocity coordinates are).
    const double h = 1e-6;
    for (int k = 0; k < 2; ++k) {
      Vector6d gradient;
      for (int j = 0; j < 6; ++j) {
        double energy[2];
        for (const int side : {0, 1}) {
          std::array<odyn::Spatial::Frame, 2> moved = frames;
          const double step = side == 0 ? h : -h;
          if (j < 3)
            moved[k].position[j] += step;
          else
            moved[k].rotation =
                frames[k].rotation * Eigen::AngleAxisd(step, Vector3d::Unit(j - 3)).matrix();
          energy[side] = spatial_energy(spring, moved);
        }
        gradient[j] = (energy[0] - energy[1]) / (2.0 * h);
      }
      INFO("body " << k << "\nforce    " << blocks.force[k].transpose() << "\n-gradient "
                   << -gradient.transpose());
      CHECK((blocks.force[k] + gradient).norm() < 1e-6 * gradient.norm());
    }

    // A damper alone: the power of its forces is -x'^T C x', x' the rate of the displacement
    // along the motion (differences of x over +-h in time, the bodies moving with their
    // velocities).
    sp::Bushing::Law damper_law;
    damper_law.damping = coupled_matrix<6>(random, scales / 100.0);
    const sp::Bushing damper("damper", BodyId{1}, on_a, BodyId{2}, on_b, damper_law);
    for (auto& frame : frames) {
      frame.linear_velocity = vector(2.0);
      frame.angular_velocity = vector(3.0);
    }
    std::array<Vector6d, 2> x;
    for (const int side : {0, 1}) {
      std::array<odyn::Spatial::Frame, 2> moved = frames;
      const double dt = side == 0 ? h : -h;
      for (auto& frame : moved) {
        frame.position += dt * frame.linear_velocity;
        frame.rotation =
            frame.rotation * odyn::quaternion_exp(dt * frame.angular_velocity).toRotationMatrix();
      }
      x[side] = damper.displacement({{&moved[0], &moved[1]}, 0.0}).x;
    }
    const Vector6d rate = (x[0] - x[1]) / (2.0 * h);
    CHECK((damper.displacement(in).rate - rate).norm() < 1e-7 * rate.norm());
    damper.evaluate(in, blocks);
    double power = 0.0;
    for (int k = 0; k < 2; ++k) {
      Vector6d velocity;
      velocity << frames[k].linear_velocity, frames[k].angular_velocity;
      power += blocks.force[k].dot(velocity);
    }
    const double dissipation = rate.dot(damper_law.damping * rate);
    CHECK(std::abs(power + dissipation) < 1e-7 * dissipation);
  }
}

// --- Spatial: small vibrations against the eigenproblem ---------------------------------------

TEST_CASE("A body on an offset, coupled spatial bushing vibrates in its six analytic modes",
          "[bushing]") {
  std::mt19937 random(7);
  const double mass = 3.0;
  const Matrix3d inertia = odyn::spatial::Body::principal(0.04, 0.07, 0.09);
  const Vector3d centre(0.1, 0.2, 0.3);
  const Matrix3d orientation = random_rotation(random, 1.0);
  const sp::JointFrame on_b{Vector3d(0.15, -0.05, 0.1), Vector3d(0.3, 1.0, -0.2),
                            Vector3d(1.0, 0.0, 0.4)};
  sp::Bushing::Law law;
  Vector6d scales;
  scales << 4e4, 2e4, 3e4, 400.0, 200.0, 300.0;
  law.stiffness = coupled_matrix<6>(random, scales);
  // The frame on the ground coincides with b's at rest.
  const sp::Bushing probe("probe", odyn::ground, {}, BodyId{1}, on_b, law);
  const Matrix3d triad_b = probe.axes(1, odyn::Spatial::Frame{});  // b's frame, body axes
  const sp::JointFrame on_ground{centre + orientation * on_b.point, orientation * triad_b.col(2),
                                 orientation * triad_b.col(0)};

  // Linearized displacement map at rest: x = A (dc, dphi), dphi about body axes.
  const Matrix3d axes_a = orientation * triad_b;
  Matrix6d map = Matrix6d::Zero();
  map.topLeftCorner<3, 3>() = axes_a.transpose();
  map.topRightCorner<3, 3>() = -axes_a.transpose() * orientation * odyn::skew(on_b.point);
  map.bottomRightCorner<3, 3>() = triad_b.transpose();
  const Matrix6d stiffness_q = map.transpose() * law.stiffness * map;
  Matrix6d mass_matrix = Matrix6d::Zero();
  mass_matrix.topLeftCorner<3, 3>() = mass * Matrix3d::Identity();
  mass_matrix.bottomRightCorner<3, 3>() = inertia;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Matrix6d> modes(stiffness_q, mass_matrix);
  REQUIRE(modes.info() == Eigen::Success);

  // The bushing's own stiffness block (by differences) at rest is the linearization's.
  {
    odyn::Spatial::Frame ground, body;
    body.position = centre;
    body.rotation = orientation;
    sp::Bushing bushing("mount", odyn::ground, on_ground, BodyId{1}, on_b, law);
    const odyn::ElementInput<odyn::Spatial, 2> in{{&ground, &body}, 0.0};
    bushing.bind(in);
    odyn::ForceBlocks<odyn::Spatial, 2> blocks;
    bushing.jacobians(in, blocks);
    const Matrix6d block = blocks.stiffness.bottomRightCorner<6, 6>();
    INFO("block\n" << block << "\nlinearized\n" << stiffness_q);
    CHECK((block - stiffness_q).norm() < 1e-6 * stiffness_q.norm());
  }

  for (int mode = 0; mode < 6; ++mode) {
    const double omega = std::sqrt(modes.eigenvalues()[mode]);
    Vector6d shape = modes.eigenvectors().col(mode);
    shape /= shape.cwiseAbs().maxCoeff();
    const double amplitude = 1e-6;  // m or rad: the motion stays linear to 1e-6
    sp::DefaultModel model;
    sp::Body body{.name = "block", .mass = mass, .inertia = inertia};
    body.position = centre + amplitude * shape.head<3>();
    body.orientation =
        Eigen::Quaterniond(orientation) * odyn::quaternion_exp(amplitude * shape.tail<3>());
    const BodyId b = model.add_body(body);
    model.add(sp::Bushing("mount", odyn::ground, on_ground, b, on_b, law));
    odyn::Workspace<sp::DefaultModel> ws(model);
    odyn::DynamicsSettings settings = mode_run(omega);
    settings.coordinates = "absolute";
    double worst = 0.0;
    odyn::simulate(model, ws, settings, [&](const auto& w) {
      Vector6d motion;
      motion.head<3>() = w.q.template head<3>() - centre;
      const Eigen::Quaterniond q(w.q[3], w.q[4], w.q[5], w.q[6]);
      const Eigen::AngleAxisd turn(orientation.transpose() * q.toRotationMatrix());
      motion.tail<3>() = turn.angle() * turn.axis();
      const Vector6d expected = amplitude * shape * std::cos(omega * w.t);
      worst = std::max(worst, (motion - expected).cwiseAbs().maxCoeff() / amplitude);
    });
    INFO("mode " << mode << ": " << omega / (2.0 * std::numbers::pi) << " Hz, worst " << worst);
    CHECK(worst < 1e-4);
  }
}

// --- Spatial: a damped, preloaded mount; energy over a large motion ---------------------------

TEST_CASE("A damped, preloaded bushing mount follows the closed-form damped oscillator",
          "[bushing]") {
  // A body on a bushing with stiffness k and damping c along z only, plus a preload p and
  // gravity: z(t) = z* + (z0 - z*) e^(-zeta w t) (cos(w_d t) + zeta / sqrt(1 - zeta^2)
  // sin(w_d t)), z* = (p - m g) / k. The other directions are stiff and stay at rest.
  const double mass = 2.0, k = 5e3, c = 8.0, preload = 30.0, g = 9.81, z0 = 0.004;
  sp::Bushing::Law law;
  law.stiffness.diagonal() << 1e5, 1e5, k, 1e3, 1e3, 1e3;
  law.damping(2, 2) = c;
  law.preload[2] = preload;
  sp::DefaultModel model;
  sp::Body body{.name = "block", .mass = mass, .inertia = sp::Body::principal(0.01, 0.01, 0.01)};
  body.position = Vector3d(0.0, 0.0, z0);
  const BodyId b = model.add_body(body);
  const auto mount = model.add(sp::Bushing("mount", odyn::ground, {}, b, {}, law));
  model.add(sp::Gravity("gravity", Vector3d(0.0, 0.0, -g)));
  odyn::Workspace<sp::DefaultModel> ws(model);
  odyn::DynamicsSettings settings;
  settings.integrator = "dop853";
  settings.rtol = settings.atol = 1e-12;
  settings.t_end = 0.5;
  settings.output_interval = 0.01;
  const double omega = std::sqrt(k / mass), zeta = c / (2.0 * std::sqrt(k * mass));
  const double omega_d = omega * std::sqrt(1.0 - zeta * zeta), rest = (preload - mass * g) / k;
  const double decay = zeta * omega, ratio = zeta / std::sqrt(1.0 - zeta * zeta);
  // The motion, and the mount's outputs (core/outputs.hpp): z, z' and the force along z, the
  // other components at rest.
  double worst = 0.0, worst_output = 0.0, worst_rate = 0.0, worst_force = 0.0;
  odyn::simulate(model, ws, settings, [&](const auto& w) {
    const double e = std::exp(-decay * w.t);
    const double cs = std::cos(omega_d * w.t), sn = std::sin(omega_d * w.t);
    const double z = rest + (z0 - rest) * e * (cs + ratio * sn);
    const double z_rate = -(z0 - rest) * e * (omega * omega / omega_d) * sn;
    worst = std::max({worst, std::abs(w.q[2] - z), w.q.template head<2>().norm()});
    const auto x = odyn::element_outputs(model, w, mount);
    worst_rate = std::max(worst_rate, std::abs(x[8] - z_rate));
    worst_force = std::max(worst_force, std::abs(x[14] - (preload - k * z - c * z_rate)));
    worst_output = std::max(worst_output, std::abs(x[2] - z));
    for (const std::size_t i : {0, 1, 3, 4, 5, 6, 7, 9, 10, 11, 12, 13, 15, 16, 17})
      worst_output = std::max(worst_output, std::abs(x[i]));
  });
  CHECK(worst < 1e-10);
  CHECK(worst_output < 1e-9);
  CHECK(worst_rate < 1e-8);
  CHECK(worst_force < 1e-6);
  CHECK(odyn::element_output(model, ws, "mount", "fz") ==
        odyn::element_outputs(model, ws, mount)[14]);
}

TEST_CASE("Two bodies on coupled bushings keep their energy over a large motion", "[bushing]") {
  // Ground - bushing - body 1 - bushing - body 2, anisotropic coupled stiffness, turns of a
  // radian and more: the energy (kinetic plus the bushings') is constant. Generalized-alpha,
  // which needs the bushings' blocks (by differences), reaches the same state at a small step.
  std::mt19937 random(11);
  Vector6d scales;
  scales << 2e3, 1e3, 3e3, 3.0, 2.0, 3.0;
  sp::Bushing::Law first, second;
  first.stiffness = coupled_matrix<6>(random, scales);
  second.stiffness = coupled_matrix<6>(random, scales);
  sp::DefaultModel model;
  sp::Body one{.name = "one", .mass = 1.0, .inertia = sp::Body::principal(0.02, 0.03, 0.04)};
  one.linear_velocity = Vector3d(1.0, -0.5, 0.8);
  one.angular_velocity = Vector3d(12.0, -6.0, 8.0);
  sp::Body two{.name = "two", .mass = 0.5, .inertia = sp::Body::principal(0.01, 0.02, 0.01)};
  two.position = Vector3d(0.3, 0.0, 0.0);
  two.angular_velocity = Vector3d(-10.0, 16.0, 4.0);
  const BodyId b1 = model.add_body(one), b2 = model.add_body(two);
  model.add(sp::Bushing("first", odyn::ground, {}, b1, {}, first));
  model.add(sp::Bushing("second", b1, sp::JointFrame{Vector3d(0.15, 0.0, 0.0)}, b2,
                        sp::JointFrame{Vector3d(-0.15, 0.0, 0.0)}, second));
  std::vector<double> final_state[2];
  for (const char* integrator : {"dop853", "generalized-alpha"}) {
    odyn::Workspace<sp::DefaultModel> ws(model);
    odyn::DynamicsSettings settings;
    settings.integrator = integrator;
    settings.rtol = settings.atol = 1e-11;
    settings.step = 1e-4;
    settings.t_end = 1.0;
    settings.output_interval = 0.05;
    double energy0 = 0.0, largest_drift = 0.0, largest_turn = 0.0;
    odyn::simulate(model, ws, settings, [&](const auto& w) {
      const double energy = odyn::kinetic_energy(model, w) + odyn::potential_energy(model, w);
      if (w.t == 0.0) energy0 = energy;
      largest_drift = std::max(largest_drift, std::abs(energy - energy0));
      const Eigen::Quaterniond q(w.q[3], w.q[4], w.q[5], w.q[6]);
      largest_turn = std::max(largest_turn, Eigen::AngleAxisd(q).angle());
    });
    const bool explicit_run = std::string(integrator) == "dop853";
    final_state[explicit_run ? 0 : 1].assign(ws.q.data(), ws.q.data() + ws.q.size());
    INFO(integrator << ": energy " << energy0 << ", drift " << largest_drift << ", turn "
                    << largest_turn);
    CHECK(largest_turn > 1.0);
    if (explicit_run) CHECK(largest_drift < 1e-8 * energy0);
  }
  double difference = 0.0;
  for (std::size_t i = 0; i < final_state[0].size(); ++i)
    difference = std::max(difference, std::abs(final_state[0][i] - final_state[1][i]));
  CHECK(difference < 1e-4);
}

// --- Planar --------------------------------------------------------------------------------

TEST_CASE("Planar bushing: energy's gradient, and the three modes of an offset mount",
          "[bushing][planar]") {
  std::mt19937 random(5);
  Vector3d scales(2e4, 1e4, 200.0);
  pl::Bushing::Law law;
  law.stiffness = coupled_matrix<3>(random, scales);
  law.preload << 20.0, -10.0, 3.0;
  const pl::JointFrame on_a{Eigen::Vector2d(0.2, -0.1), Eigen::Vector2d(1.0, 0.5)};
  const pl::JointFrame on_b{Eigen::Vector2d(-0.1, 0.25), Eigen::Vector2d(0.2, 1.0)};

  // Force against the energy written out: x = (R_a^T (p_b - p_a), angle between the axes).
  pl::Bushing spring("mount", BodyId{1}, on_a, BodyId{2}, on_b, law);
  std::array<odyn::Planar::Frame, 2> frames;
  const auto place = [](odyn::Planar::Frame& f, Eigen::Vector2d p, double angle) {
    f.position = p;
    f.angle = angle;
    f.rotation = odyn::Planar::rotation(angle);
  };
  place(frames[0], {0.3, -0.2}, 0.4);
  place(frames[1], {0.9, 0.5}, 0.4 + std::atan2(0.5, 1.0) - std::atan2(1.0, 0.2));
  const odyn::ElementInput<odyn::Planar, 2> in0{{&frames[0], &frames[1]}, 0.0};
  spring.bind(in0);  // the joint angle is 0 here
  place(frames[1], {0.9, 0.5}, frames[1].angle + 1.3);
  const auto energy = [&](const std::array<odyn::Planar::Frame, 2>& f) {
    const double axis_a = f[0].angle + std::atan2(0.5, 1.0);
    const double axis_b = f[1].angle + std::atan2(1.0, 0.2);
    Vector3d x;
    x << odyn::Planar::rotation(axis_a).transpose() *
             (f[1].point(on_b.point) - f[0].point(on_a.point)),
        axis_b - axis_a;
    return 0.5 * x.dot(law.stiffness * x) - law.preload.dot(x);
  };
  odyn::ForceBlocks<odyn::Planar, 2> blocks;
  spring.evaluate(in0, blocks);
  CHECK(std::abs(spring.potential_energy(in0) - energy(frames)) < 1e-9 * std::abs(energy(frames)));
  const double h = 1e-6;
  for (int k = 0; k < 2; ++k) {
    Vector3d gradient;
    for (int j = 0; j < 3; ++j) {
      auto plus = frames, minus = frames;
      if (j < 2) {
        plus[k].position[j] += h;
        minus[k].position[j] -= h;
      } else {
        place(plus[k], plus[k].position, plus[k].angle + h);
        place(minus[k], minus[k].position, minus[k].angle - h);
      }
      gradient[j] = (energy(plus) - energy(minus)) / (2.0 * h);
    }
    CHECK((blocks.force[k] + gradient).norm() < 1e-6 * gradient.norm());
  }

  // Small vibrations of a body on the mount (frames coincident at rest) against the
  // eigenproblem of the linearized map x = A (dc, dphi).
  const double mass = 1.5, inertia = 0.02, amplitude = 1e-6;
  const Eigen::Vector2d centre(0.4, 0.1);
  const double angle = 0.3;
  law.preload.setZero();
  const double axis_b = angle + std::atan2(on_b.axis.y(), on_b.axis.x());
  const Eigen::Vector2d point = centre + odyn::Planar::rotation(angle) * on_b.point;
  const pl::JointFrame on_ground{point, Eigen::Vector2d(std::cos(axis_b), std::sin(axis_b))};
  Eigen::Matrix3d map = Eigen::Matrix3d::Zero();
  const Eigen::Matrix2d axes_t = odyn::Planar::rotation(axis_b).transpose();
  map.topLeftCorner<2, 2>() = axes_t;
  map.topRightCorner<2, 1>() =
      axes_t * odyn::Planar::perpendicular(odyn::Planar::rotation(angle) * on_b.point);
  map(2, 2) = 1.0;
  const Eigen::Matrix3d stiffness_q = map.transpose() * law.stiffness * map;
  const Eigen::Matrix3d mass_matrix = Vector3d(mass, mass, inertia).asDiagonal();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> modes(stiffness_q, mass_matrix);
  for (int mode = 0; mode < 3; ++mode) {
    const double omega = std::sqrt(modes.eigenvalues()[mode]);
    Vector3d shape = modes.eigenvectors().col(mode);
    shape /= shape.cwiseAbs().maxCoeff();
    pl::DefaultModel model;
    pl::Body body{.name = "block", .mass = mass, .inertia = inertia};
    body.position = centre + amplitude * shape.head<2>();
    body.angle = angle + amplitude * shape[2];
    const BodyId b = model.add_body(body);
    model.add(pl::Bushing("mount", odyn::ground, on_ground, b, on_b, law));
    odyn::Workspace<pl::DefaultModel> ws(model);
    const odyn::DynamicsSettings settings = mode_run(omega);
    double worst = 0.0;
    odyn::simulate(model, ws, settings, [&](const auto& w) {
      const Vector3d motion(w.q[0] - centre.x(), w.q[1] - centre.y(), w.q[2] - angle);
      const Vector3d expected = amplitude * shape * std::cos(omega * w.t);
      worst = std::max(worst, (motion - expected).cwiseAbs().maxCoeff() / amplitude);
    });
    INFO("mode " << mode);
    CHECK(worst < 1e-4);
  }
}

TEST_CASE("A bushing refuses a stiffness or damping that is not symmetric positive semidefinite",
          "[bushing][errors]") {
  const auto message = [](const sp::Bushing::Law& law) {
    try {
      sp::Bushing("mount", odyn::ground, {}, BodyId{1}, {}, law);
    } catch (const odyn::ModelError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  sp::Bushing::Law law;
  law.stiffness.diagonal().setConstant(100.0);
  law.stiffness(0, 1) = 5.0;
  CHECK_THAT(message(law), Catch::Contains("mount") && Catch::Contains("not symmetric"));
  law.stiffness(1, 0) = 5.0;
  CHECK(message(law) == "accepted");
  law.stiffness(4, 4) = -1.0;
  CHECK_THAT(message(law), Catch::Contains("stiffness matrix is not positive semidefinite"));
  law.stiffness(4, 4) = 1.0;
  law.damping(2, 2) = -0.5;
  CHECK_THAT(message(law), Catch::Contains("damping matrix is not positive semidefinite"));
  law.damping(2, 2) = std::nan("");
  CHECK_THAT(message(law), Catch::Contains("damping must be finite"));
}

}  // namespace test_bushing
