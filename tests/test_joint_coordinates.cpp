// Joint coordinates (analysis/joint_coordinates.hpp) against independent references: the engine
// against its minimal-coordinate solution (dop853; generalized-alpha and HHT at second order), a
// moving chain with springs under generalized-alpha against dop853 in absolute coordinates, an open
// chain of every tree-joint kind against the same chain in absolute coordinates (a different
// formulation, converged) and its energy, the steady top (a ball joint in the tree) against the
// gyroscope equation, the conical pendulum (a free root closed by a distance) against its
// closed-form motion, a double pendulum of ball joints against its analytic small-oscillation
// modes, a 512-link ball chain and a ladder of spatial four-bars against absolute coordinates, a
// 512-link chain whipping round under large constraint forces (generalized-alpha at second order on
// the sparse path), a driven slider-crank (a driver closing the loop) against the exact kinematics
// and absolute coordinates; in the plane, the engine against its minimal-coordinate solution and a
// mechanism with every planar tree-joint kind, a free root and eight loops against absolute
// coordinates; the tree the method picks; and the models it refuses, by name.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include <odyn/odyn.hpp>

#include "bricard_model.hpp"
#include "engine_model.hpp"
#include "parallelogram_chain_model.hpp"
#include "reference/engine_reference.hpp"
#include "reference/steady_top.hpp"
#include "rope_model.hpp"

namespace test_joint_coordinates {

namespace {

namespace sp = odyn::spatial;
using Eigen::Vector3d;

odyn::DynamicsSettings joint_settings(const char* integrator, double tolerance) {
  odyn::DynamicsSettings settings;
  settings.integrator = integrator;
  settings.coordinates = "joint";
  settings.rtol = tolerance;
  settings.atol = tolerance;
  return settings;
}

/// Four bodies in an open chain: a bar on a revolute joint to the ground, a second bar on a
/// universal joint to it, a sleeve on a cylindrical joint along the second bar and a block
/// welded to the first bar; gravity only. Started tilted and moving, so that every joint works.
using ChainModel = sp::DefaultModel;

ChainModel chain() {
  ChainModel model;
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.4, Vector3d::UnitX()));
  const Vector3d down = tilt * -Vector3d::UnitZ();  // along bar 1, from the pivot
  const auto bar = [](const char* name, const Vector3d& centre, const Eigen::Quaterniond& turn) {
    return sp::Body{.name = name,
                    .mass = 1.0,
                    .inertia = sp::Body::principal(0.09, 0.09, 0.005),
                    .position = centre,
                    .orientation = turn};
  };
  sp::Body upper = bar("upper", 0.5 * down, tilt);
  upper.angular_velocity = {2.0, 0.0, 0.0};
  const odyn::BodyId b1 = model.add_body(upper);
  sp::Body lower = bar("lower", 1.5 * down, tilt);
  lower.angular_velocity = {1.0, -1.5, 0.5};
  const odyn::BodyId b2 = model.add_body(lower);
  sp::Body sleeve{.name = "sleeve",
                  .mass = 0.3,
                  .inertia = sp::Body::principal(0.002, 0.002, 0.003),
                  .position = 1.3 * down,
                  .orientation = tilt};
  sleeve.linear_velocity = 0.2 * down;
  const odyn::BodyId b3 = model.add_body(sleeve);
  const odyn::BodyId b4 = model.add_body({.name = "block",
                                          .mass = 0.5,
                                          .inertia = sp::Body::principal(0.01, 0.02, 0.03),
                                          .position = 0.5 * down + tilt * Vector3d(0.2, 0, 0),
                                          .orientation = tilt});
  model.add(sp::Revolute("shoulder", odyn::ground, sp::JointFrame{{0, 0, 0}, Vector3d::UnitX()}, b1,
                         sp::JointFrame{{0, 0, 0.5}, Vector3d::UnitX()}));
  model.add(sp::Universal("elbow", b1, sp::JointFrame{{0, 0, -0.5}, Vector3d::UnitX()}, b2,
                          sp::JointFrame{{0, 0, 0.5}, Vector3d::UnitY()}));
  model.add(sp::Cylindrical("slide", b2, sp::JointFrame{{0, 0, 0}, Vector3d::UnitZ()}, b3,
                            sp::JointFrame{{0, 0, 0}, Vector3d::UnitZ()}));
  model.add(sp::Fixed("weld", b1, sp::JointFrame{{0.2, 0, 0}, Vector3d::UnitZ()}, b4,
                      sp::JointFrame{{0, 0, 0}, Vector3d::UnitZ()}));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  return model;
}

/// The bearing force's scale: the reference's largest |R_z|.
double peak_bearing_force(const std::vector<engine_reference::Sample>& reference) {
  double peak = 0.0;
  for (const auto& sample : reference) peak = std::max(peak, std::abs(sample.R_z));
  return peak;
}

/// The bearing force jumps with the gas force, twice per cycle: reactions are compared away
/// from those crank angles.
bool near_force_jump(double theta) {
  const double phase = std::fmod(theta, 4.0 * std::numbers::pi);
  return std::abs(phase - 2.0 * std::numbers::pi) < 0.05 ||
         std::abs(phase - 3.0 * std::numbers::pi) < 0.05;
}

using RopeModel = rope_model::Model;
using rope_model::rope;

struct ChainRun {
  std::vector<Eigen::VectorXd> positions;  // every body's centre and rotation, per output
  double energy_drift = 0.0;
  double phi = 0.0;
};

ChainRun run_chain(const odyn::DynamicsSettings& settings) {
  ChainModel model = chain();
  odyn::Workspace<ChainModel> ws(model);
  odyn::DynamicsSettings s = settings;
  s.t_end = 1.0;
  s.output_interval = 0.1;
  ChainRun out;
  double energy0 = 0.0;
  odyn::simulate(model, ws, s, [&](const auto& state) {
    Eigen::VectorXd pose(12 * model.num_bodies());
    for (int b = 1; b <= model.num_bodies(); ++b) {
      pose.segment<3>(12 * (b - 1)) = state.frames[b].position;
      pose.segment<9>(12 * (b - 1) + 3) = state.frames[b].rotation.reshaped();
    }
    out.positions.push_back(pose);
    const double energy = odyn::kinetic_energy(model, state) + odyn::potential_energy(model, state);
    if (out.positions.size() == 1) energy0 = energy;
    out.energy_drift = std::max(out.energy_drift, std::abs(energy - energy0));
    out.phi = std::max(out.phi, state.phi.cwiseAbs().maxCoeff());
  });
  return out;
}

}  // namespace

TEST_CASE("Joint coordinates: the engine's tree closes at the crank pin", "[joint]") {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> ws(e.model);
  odyn::assemble(e.model, ws);
  const odyn::JointCoordinates<engine::Model> coordinates(e.model, ws);
  // Kruskal keeps the joints with the most equations: 4 coordinates, 3 closure equations.
  CHECK(coordinates.num_velocities() == 4);
  CHECK(coordinates.num_positions() == 4);
  CHECK(coordinates.num_equations() == 3);
  CHECK(coordinates.loop_closures() == std::vector<std::string>{"crank pin"});
  auto tree = coordinates.tree_joints();
  std::sort(tree.begin(), tree.end());
  CHECK(tree == std::vector<std::string>{"bearing", "cylinder", "piston pin"});
}

/// The engine (spatial or planar) with dop853 in joint coordinates against its minimal-coordinate
/// solution. Measured: 3.5e-10 rad, 1.4e-11 m, 3.7e-10 of the peak (planar: 1.7e-10 rad,
/// 6.8e-12 m, 2.1e-10); the reactions of tree joints come from the absolute equations at each
/// output.
template <class Engine>
void check_engine_against_reference(Engine e) {
  const auto reference = engine_reference::solve(1.0, 1e-3);
  const double peak = peak_bearing_force(reference);
  odyn::Workspace<typename Engine::Model> ws(e.model);
  std::size_t k = 0;
  double z_error = 0.0, reaction_error = 0.0;
  const auto summary =
      odyn::simulate(e.model, ws, joint_settings("dop853", 1e-9), [&](const auto& state) {
        const auto& sample = reference.at(k++);
        z_error = std::max(z_error, std::abs(engine::piston_height(e, state) - sample.z_piston));
        if (!near_force_jump(sample.theta))
          reaction_error = std::max(
              reaction_error, std::abs(engine::bearing_force_z(e, state) - sample.R_z) / peak);
      });
  const double theta_error = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
  INFO("theta error " << theta_error << " rad, z error " << z_error << " m, R_z error / peak "
                      << reaction_error << ", steps " << summary.statistics.steps);
  CHECK(k == reference.size());
  CHECK(theta_error < 1e-8);
  CHECK(z_error < 1e-9);
  CHECK(reaction_error < 2e-8);
  CHECK(summary.statistics.events ==
        static_cast<long>(std::floor(reference.back().theta / std::numbers::pi)));
  // The tree joints hold by construction, the closures by projection.
  CHECK(summary.max_position_residual < 1e-11);
  CHECK(summary.max_velocity_residual < 1e-9);
}

TEST_CASE("Joint coordinates: the engine against its minimal-coordinate solution",
          "[joint][engine]") {
  check_engine_against_reference(engine::build());
}

TEST_CASE("Joint coordinates with generalized-alpha and HHT: the engine, second order",
          "[joint][engine]") {
  // The minimal-coordinate solution is the reference; the crank angle after 1 s (about 30
  // turns, 60 switches of the gas force) converges at second order, as in absolute coordinates.
  const auto reference = engine_reference::solve(1.0, 1e-2);
  const double peak = peak_bearing_force(reference);
  engine::Engine e = engine::build();
  for (const char* integrator : {"generalized-alpha", "hht"}) {
    std::array<double, 2> theta_error{};
    for (int k = 0; k < 2; ++k) {
      odyn::Workspace<engine::Model> ws(e.model);
      odyn::DynamicsSettings settings = joint_settings(integrator, 1e-6);
      settings.step = k == 0 ? 1e-4 : 5e-5;
      settings.output_interval = 1e-2;
      std::size_t sample = 0;
      double reaction_error = 0.0;
      const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& state) {
        const auto& expected = reference.at(sample++);
        if (!near_force_jump(expected.theta))
          reaction_error = std::max(
              reaction_error, std::abs(engine::bearing_force_z(e, state) - expected.R_z) / peak);
      });
      theta_error[k] = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
      INFO(integrator << " at h = " << settings.step << ": theta error " << theta_error[k]
                      << " rad, R_z error / peak " << reaction_error << ", "
                      << summary.statistics.newton_iterations << " Newton iterations");
      CHECK(sample == reference.size());
      CHECK(summary.max_position_residual < 1e-10);
      // Measured: 2.7e-4 and 1.8e-4 of the peak (generalized-alpha, whose multipliers converge
      // slowly, as in absolute coordinates), 3.1e-4 and 8.1e-5 (hht).
      CHECK(reaction_error < (k == 0 ? 1e-3 : 5e-4));
    }
    // Measured: 5.0e-4 and 1.27e-4 rad (generalized-alpha), 5.9e-4 and 1.49e-4 (hht); in
    // absolute coordinates 4.9e-4 and 1.27e-4, 6.2e-4 and 1.57e-4.
    INFO(integrator << ": theta errors " << theta_error[0] << ", " << theta_error[1] << " rad");
    CHECK(theta_error[0] < 1e-3);
    CHECK(theta_error[0] / theta_error[1] > 3.5);
    CHECK(theta_error[0] / theta_error[1] < 4.5);
  }
}

TEST_CASE("Joint coordinates with BDF: the engine, the top, and every tree-joint kind",
          "[joint][bdf]") {
  SECTION("the engine against its minimal-coordinate solution, as the tolerance tightens") {
    const auto reference = engine_reference::solve(1.0, 1e-2);
    const double peak = peak_bearing_force(reference);
    engine::Engine e = engine::build();
    std::array<double, 2> theta_error{};
    for (int k = 0; k < 2; ++k) {
      odyn::Workspace<engine::Model> ws(e.model);
      odyn::DynamicsSettings settings = joint_settings("bdf", k == 0 ? 1e-8 : 1e-10);
      settings.output_interval = 1e-2;
      std::size_t sample = 0;
      double reaction_error = 0.0;
      const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& state) {
        const auto& expected = reference.at(sample++);
        if (!near_force_jump(expected.theta))
          reaction_error = std::max(
              reaction_error, std::abs(engine::bearing_force_z(e, state) - expected.R_z) / peak);
      });
      theta_error[k] = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
      INFO("tolerance " << settings.rtol << ": theta error " << theta_error[k]
                        << " rad, R_z error / peak " << reaction_error << ", "
                        << summary.statistics.steps << " steps");
      CHECK(sample == reference.size());
      CHECK(summary.max_position_residual < 1e-10);
      // Measured: 1.9e-5 and 6.6e-8 of the peak.
      CHECK(reaction_error < (k == 0 ? 1e-4 : 1e-6));
    }
    INFO("theta errors " << theta_error[0] << ", " << theta_error[1] << " rad");
    // Measured: 3.7e-5 and 1.2e-7 rad (absolute coordinates: 1.3e-5 and 1.6e-7).
    CHECK(theta_error[1] < 5e-7);
    CHECK(theta_error[0] / theta_error[1] > 30.0);
  }
  SECTION("the steady top, its ball joint's quaternion solved implicitly") {
    const auto top = steady_top::run<odyn::JointBdf>(joint_settings("bdf", 1e-10));
    INFO("tilt error " << top.tilt_error << ", spin error " << top.spin_error << ", steps "
                       << top.summary.statistics.steps);
    // Measured: tilt 1.6e-8 rad, spin 3.0e-11 rad/s, in 1211 steps (absolute coordinates: 1.6e-9
    // and 5.9e-11 in 4202 steps).
    CHECK(top.tilt_error < 5e-8);
    CHECK(top.azimuth == Approx(top.precession_rate).epsilon(1e-7));
    CHECK(top.spin_error < 1e-9 * top.spin);
    CHECK(top.unit_error < 1e-15);
  }
  SECTION("the open chain of every tree-joint kind against absolute coordinates") {
    odyn::DynamicsSettings absolute;
    absolute.integrator = "dop853";
    absolute.rtol = absolute.atol = 1e-11;
    const ChainRun reference = run_chain(absolute);
    const ChainRun joint = run_chain(joint_settings("bdf", 1e-10));
    REQUIRE(joint.positions.size() == reference.positions.size());
    double difference = 0.0;
    for (std::size_t k = 0; k < reference.positions.size(); ++k)
      difference =
          std::max(difference, (joint.positions[k] - reference.positions[k]).cwiseAbs().maxCoeff());
    INFO("largest difference " << difference << "; |Phi| " << joint.phi);
    CHECK(difference < 5e-8);  // measured 4.8e-9
    CHECK(joint.phi < 1e-12);
  }
}

TEST_CASE("Joint coordinates with generalized-alpha: a moving chain with springs, second order",
          "[joint][large]") {
  // 64 ball-jointed links given 0.1 m/s across, a spring-damper between neighbours' centres,
  // against dop853 at 1e-11 in absolute coordinates (another method and other coordinates).
  const int n = 64;
  const RopeModel model =
      rope(n, 0.1, sp::Tsda::Parameters{.stiffness = 40.0, .damping = 0.5, .free_length = 0.9});
  const auto run = [&](const char* integrator, const char* coordinates, double step) {
    odyn::Workspace<RopeModel> ws(model);
    odyn::DynamicsSettings settings = joint_settings(integrator, 1e-11);
    settings.coordinates = coordinates;
    settings.step = step;
    settings.t_end = 0.5;
    settings.output_interval = 0.5;
    Eigen::VectorXd centres(3 * n);
    const auto summary = odyn::simulate(model, ws, settings, [&](const auto& state) {
      for (int b = 1; b <= n; ++b) centres.segment<3>(3 * (b - 1)) = state.frames[b].position;
    });
    CHECK(summary.max_position_residual < 1e-10);
    return centres;
  };
  const Eigen::VectorXd reference = run("dop853", "absolute", 1e-4);
  const double coarse = (run("generalized-alpha", "joint", 1e-3) - reference).cwiseAbs().maxCoeff();
  const double fine = (run("generalized-alpha", "joint", 5e-4) - reference).cwiseAbs().maxCoeff();
  // Measured: 2.55e-5 and 6.8e-6 m, a ratio of 3.75; with Newton's tolerances 1e-4 times
  // tighter the same chain without springs gives 2.42e-5 and 6.3e-6 m, a ratio of 3.84 (the
  // default tolerances leave a few per cent of the error).
  INFO("largest position error " << coarse << " m at h = 1e-3, " << fine << " m at h = 5e-4");
  CHECK(coarse < 5e-5);
  CHECK(coarse / fine > 3.3);
  CHECK(coarse / fine < 4.5);
}

TEST_CASE("Joint coordinates with generalized-alpha: stiff springs between the links",
          "[joint][errors]") {
  // 20 ball-jointed links, a spring-damper between neighbours 0.2 m off their axes: it twists
  // the links about their thin axis (inertia 5e-5), so that its blocks weigh as much as the
  // mass over h^2 at h = 1e-3. Newton's matrix in joint coordinates holds each body's own
  // blocks (without them, the first case failed at t = 0.1 s); the blocks that join two links
  // stay out of it, and with ten times the stiffness the run stops with advice.
  using Model = RopeModel;
  const auto chain = [](double stiffness) {
    return rope(20, 0.0,
                sp::Tsda::Parameters{.stiffness = stiffness, .damping = 50.0, .free_length = 0.9},
                0.2);
  };
  const auto run = [](const Model& model, const char* integrator, const char* coordinates) {
    odyn::Workspace<Model> ws(model);
    odyn::DynamicsSettings settings = joint_settings(integrator, 1e-10);
    settings.coordinates = coordinates;
    settings.step = 1e-3;
    settings.t_end = 0.1;
    settings.output_interval = 0.1;
    Eigen::VectorXd centres(3 * model.num_bodies());
    odyn::simulate(model, ws, settings, [&](const auto& state) {
      for (int b = 1; b <= model.num_bodies(); ++b)
        centres.segment<3>(3 * (b - 1)) = state.frames[b].position;
    });
    return centres;
  };
  const Model model = chain(1e4);
  const Eigen::VectorXd reference = run(model, "dop853", "absolute");
  const double error = (run(model, "generalized-alpha", "joint") - reference).cwiseAbs().maxCoeff();
  // Measured: 5.5e-4 m (absolute coordinates: 6.7e-4 m); the links moved about 5 cm.
  INFO("largest position error " << error << " m");
  CHECK(error < 2e-3);
  CHECK_THROWS_WITH(run(chain(1e5), "generalized-alpha", "joint"),
                    Catch::Contains("absolute coordinates (coordinates 'absolute') converge"));
}

TEST_CASE("Joint coordinates: an open chain of every tree-joint kind against absolute ones",
          "[joint]") {
  odyn::DynamicsSettings absolute;
  absolute.integrator = "dop853";
  absolute.rtol = absolute.atol = 1e-11;
  const ChainRun reference = run_chain(absolute);
  const ChainRun joint = run_chain(joint_settings("dop853", 1e-11));
  const ChainRun joint5 = run_chain(joint_settings("dopri5", 1e-9));
  odyn::DynamicsSettings adams = joint_settings("adams", 1e-6);
  adams.step = 1e-3;
  adams.adams.order = 6;
  const ChainRun joint_adams = run_chain(adams);
  REQUIRE(joint.positions.size() == reference.positions.size());
  REQUIRE(joint_adams.positions.size() == reference.positions.size());
  double difference = 0.0, difference5 = 0.0, difference_adams = 0.0, motion = 0.0;
  const auto largest = [&](double& so_far, const ChainRun& run, std::size_t k) {
    so_far = std::max(so_far, (run.positions[k] - reference.positions[k]).cwiseAbs().maxCoeff());
  };
  for (std::size_t k = 0; k < reference.positions.size(); ++k) {
    largest(difference, joint, k);
    largest(difference5, joint5, k);
    largest(difference_adams, joint_adams, k);
    motion =
        std::max(motion, (reference.positions[k] - reference.positions[0]).cwiseAbs().maxCoeff());
  }
  INFO("largest difference from absolute coordinates: dop853 "
       << difference << ", dopri5 " << difference5 << ", adams " << difference_adams << "; motion "
       << motion);
  INFO("energy drift " << joint.energy_drift << " J; |Phi| " << joint.phi);
  CHECK(motion > 0.5);  // every body really moved
  // Measured: 1.2e-14 (both runs converged), 5.1e-10 for dopri5 at tolerance 1e-9.
  CHECK(difference < 1e-10);
  CHECK(difference5 < 1e-8);
  // Adams of order 6 on fixed steps of 1 ms: measured 2.7e-12.
  CHECK(difference_adams < 1e-10);
  CHECK(joint_adams.phi < 1e-12);
  // No loop: energy is what the integrator keeps (measured 2.5e-14 J), and every joint holds
  // exactly.
  CHECK(joint.energy_drift < 1e-10);
  CHECK(joint.phi < 1e-12);
}

TEST_CASE("Joint coordinates: a ball joint carries the top (the steady top)",
          "[joint][pendulums]") {
  const auto top = steady_top::run<odyn::JointDormandPrince853>(joint_settings("dop853", 1e-11));
  steady_top::check_precession(top);
}

TEST_CASE("Joint coordinates: a free root closed by a distance (the conical pendulum)",
          "[joint][pendulums]") {
  // A body on a massless rod of length L from a fixed point, in steady conical motion: the rod
  // at the angle theta from the vertical turns at Omega = sqrt(g / (L cos theta)). The rod acts
  // through the centre, so the body does not turn. The body is a free root (6 rates) and the
  // distance its only equation.
  using Model = sp::DefaultModel;
  const double g = 9.81, length = 1.0, theta = 0.5;
  const double radius = length * std::sin(theta), height = -length * std::cos(theta);
  const double rate = std::sqrt(g / (length * std::cos(theta)));
  Model model;
  sp::Body bob{.name = "bob",
               .mass = 1.0,
               .inertia = sp::Body::principal(0.01, 0.02, 0.03),
               .position = {radius, 0.0, height}};
  bob.linear_velocity = {0.0, radius * rate, 0.0};
  const odyn::BodyId body = model.add_body(bob);
  model.add(sp::Distance("rod", odyn::ground, Vector3d::Zero(), body, Vector3d::Zero()));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
  odyn::Workspace<Model> ws(model);
  odyn::assemble(model, ws);
  const odyn::JointCoordinates<Model> coordinates(model, ws);
  CHECK(coordinates.num_velocities() == 6);
  CHECK(coordinates.loop_closures() == std::vector<std::string>{"rod"});
  odyn::DynamicsSettings settings = joint_settings("dop853", 1e-11);
  settings.t_end = 2.0;
  settings.output_interval = 0.05;
  double position_error = 0.0, turn = 0.0;
  odyn::simulate(model, ws, settings, [&](const auto& state) {
    const Vector3d expected(radius * std::cos(rate * state.t), radius * std::sin(rate * state.t),
                            height);
    position_error = std::max(position_error, (state.frames[1].position - expected).norm());
    turn = std::max(turn, state.frames[1].angular_velocity.norm());
  });
  INFO("position error " << position_error << " m, largest angular velocity " << turn);
  CHECK(position_error < 1e-8);
  CHECK(turn < 1e-10);
}

TEST_CASE("Joint coordinates: a double pendulum of ball joints against its analytic modes",
          "[joint][pendulums]") {
  // Two links of 1 m and 1 kg (inertia 1/12 across) hanging from ball joints, started at rest
  // in one of the two small-oscillation modes of the compound double pendulum, within the
  // x-z plane: M phi'' + K phi = 0 with M = [I + m a^2 + m l^2, m l a; m l a, I + m a^2],
  // K = g diag(m a + m l, m a), a = l / 2. Each link's angle must follow eps v cos(omega t).
  using Model = sp::Model<sp::Spherical, sp::Gravity>;
  const double g = 9.81, l = 1.0, a = 0.5, m = 1.0, across = 1.0 / 12.0, eps = 1e-4;
  Eigen::Matrix2d mass, stiffness;
  mass << across + m * a * a + m * l * l, m * l * a, m * l * a, across + m * a * a;
  stiffness << g * (m * a + m * l), 0.0, 0.0, g * m * a;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> modes(stiffness, mass);
  for (int mode = 0; mode < 2; ++mode) {
    const double omega = std::sqrt(modes.eigenvalues()[mode]);
    const Eigen::Vector2d shape = modes.eigenvectors().col(mode).normalized();
    Model model;
    const auto turned = [](double angle) {
      return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Vector3d::UnitY()));
    };
    // Link k points down from its pivot along R_y(phi_k) (0, 0, -1).
    const Vector3d down1 = turned(eps * shape[0]) * Vector3d(0, 0, -l);
    const Vector3d down2 = turned(eps * shape[1]) * Vector3d(0, 0, -l);
    const auto link = [&](const char* name, const Vector3d& centre, double angle) {
      return sp::Body{.name = name,
                      .mass = m,
                      .inertia = sp::Body::principal(across, across, 5e-5),
                      .position = centre,
                      .orientation = turned(angle)};
    };
    const odyn::BodyId upper = model.add_body(link("upper", 0.5 * down1, eps * shape[0]));
    const odyn::BodyId lower = model.add_body(link("lower", down1 + 0.5 * down2, eps * shape[1]));
    model.add(sp::Spherical("shoulder", odyn::ground, Vector3d::Zero(), upper, {0, 0, a}));
    model.add(sp::Spherical("elbow", upper, {0, 0, -a}, lower, {0, 0, a}));
    model.add(sp::Gravity("gravity", {0.0, 0.0, -g}));
    odyn::Workspace<Model> ws(model);
    odyn::DynamicsSettings settings = joint_settings("dop853", 1e-12);
    settings.t_end = 2.0 * (2.0 * std::numbers::pi / omega);  // two periods
    settings.output_interval = settings.t_end / 40.0;
    double error = 0.0;
    odyn::simulate(model, ws, settings, [&](const auto& state) {
      for (int k = 0; k < 2; ++k) {
        const Eigen::Matrix3d& rotation = state.frames[k + 1].rotation;
        const double angle = std::atan2(rotation(0, 2), rotation(2, 2));
        error = std::max(error, std::abs(angle - eps * shape[k] * std::cos(omega * state.t)));
      }
    });
    INFO("mode " << mode << ": omega " << omega << " rad/s, largest angle error " << error / eps
                 << " of the amplitude");
    CHECK(error < 1e-6 * eps);
  }
}

TEST_CASE("Joint coordinates: a 512-link ball chain against absolute coordinates",
          "[joint][large]") {
  // The scaling report's rope: links of 1 m and 1 kg, horizontal and at rest, released under
  // gravity. 1536 tree coordinates and no closure against 3584 absolute coordinates and 1536
  // constraint equations (the sparse Schur complement), both with dop853 at 1e-10.
  using Model = RopeModel;
  const int n = 512;
  const Model model = rope(n);
  const auto run = [&](const char* coordinates) {
    odyn::Workspace<Model> ws(model);
    odyn::DynamicsSettings settings = joint_settings("dop853", 1e-10);
    settings.coordinates = coordinates;
    settings.t_end = 0.6;
    settings.output_interval = 0.6;
    Eigen::VectorXd centres(3 * n);
    odyn::simulate(model, ws, settings, [&](const auto& state) {
      for (int b = 1; b <= n; ++b) centres.segment<3>(3 * (b - 1)) = state.frames[b].position;
    });
    return centres;
  };
  const Eigen::VectorXd joint = run("joint"), absolute = run("absolute");
  // The links near the pivot turn down; the far ones fall almost freely.
  const double turn = std::atan2(-joint[2], joint[0]);  // the first link's angle below x
  const double difference = (joint - absolute).cwiseAbs().maxCoeff();
  INFO("first link turned " << turn << " rad; largest difference " << difference << " m");
  CHECK(turn > 0.1);
  CHECK(difference < 1e-8);
}

TEST_CASE("Joint coordinates: a ladder of spatial four-bars against absolute coordinates",
          "[joint][large]") {
  // Cells stacked along x, each a bar across y hung on two links from the previous bar (or the
  // ground) by ball joints at all four corners: one closed loop a cell. Six cells: 18 bodies,
  // 54 tree coordinates and 18 closure equations, so the closures go through their Schur
  // complement and the recursive passes (not the small models' whole matrix). Against the same
  // model in absolute coordinates (72 equations), both with dop853 at 1e-10.
  using Model = sp::Model<sp::Spherical, sp::Gravity>;
  Model model;
  odyn::BodyId previous = odyn::ground;
  const auto link = [](const std::string& name, const Vector3d& centre, bool across) {
    return sp::Body{.name = name,
                    .mass = 1.0,
                    .inertia = across ? sp::Body::principal(1.0 / 12.0, 5e-3, 1.0 / 12.0)
                                      : sp::Body::principal(5e-3, 1.0 / 12.0, 1.0 / 12.0),
                    .position = centre};
  };
  for (int cell = 0; cell < 6; ++cell) {
    const std::string c = std::to_string(cell);
    const odyn::BodyId left = model.add_body(link("left" + c, {cell + 0.5, -0.5, 0.0}, false));
    const odyn::BodyId right = model.add_body(link("right" + c, {cell + 0.5, 0.5, 0.0}, false));
    const odyn::BodyId bar = model.add_body(link("bar" + c, {cell + 1.0, 0.0, 0.0}, true));
    model.add(sp::Spherical("left-bottom" + c, previous, {0, -0.5, 0}, left, {-0.5, 0, 0}));
    model.add(sp::Spherical("left-top" + c, left, {0.5, 0, 0}, bar, {0, -0.5, 0}));
    model.add(sp::Spherical("right-bottom" + c, previous, {0, 0.5, 0}, right, {-0.5, 0, 0}));
    model.add(sp::Spherical("right-top" + c, right, {0.5, 0, 0}, bar, {0, 0.5, 0}));
    previous = bar;
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  {
    odyn::Workspace<Model> ws(model);
    odyn::assemble(model, ws);
    const odyn::JointCoordinates<Model> coordinates(model, ws);
    REQUIRE(coordinates.num_velocities() + coordinates.num_equations() >
            odyn::JointCoordinates<Model>::dense_limit);
    CHECK(coordinates.num_equations() == 18);
  }
  const auto run = [&](const char* coordinates) {
    odyn::Workspace<Model> ws(model);
    odyn::DynamicsSettings settings = joint_settings("dop853", 1e-10);
    settings.coordinates = coordinates;
    settings.t_end = 0.5;
    settings.output_interval = 0.05;
    std::vector<Eigen::VectorXd> poses;
    double phi = 0.0;
    odyn::simulate(model, ws, settings, [&](const auto& state) {
      Eigen::VectorXd pose(12 * model.num_bodies());
      for (int b = 1; b <= model.num_bodies(); ++b) {
        pose.segment<3>(12 * (b - 1)) = state.frames[b].position;
        pose.segment<9>(12 * (b - 1) + 3) = state.frames[b].rotation.reshaped();
      }
      poses.push_back(pose);
      phi = std::max(phi, state.phi.cwiseAbs().maxCoeff());
    });
    return std::pair{poses, phi};
  };
  const auto [joint, joint_phi] = run("joint");
  const auto [absolute, absolute_phi] = run("absolute");
  REQUIRE(joint.size() == absolute.size());
  double difference = 0.0;
  for (std::size_t k = 0; k < joint.size(); ++k)
    difference = std::max(difference, (joint[k] - absolute[k]).cwiseAbs().maxCoeff());
  const double drop = -joint.back()[12 * 17 + 2];  // the last bar's centre
  INFO("last bar fell " << drop << " m; largest difference " << difference << "; largest |Phi| "
                        << joint_phi);
  CHECK(drop > 0.5);
  CHECK(difference < 1e-8);
  CHECK(joint_phi < 1e-10);
}

TEST_CASE("Joint coordinates: a driver closes the loop like a joint (driven slider-crank)",
          "[joint]") {
  // The engine's mechanism without its gas force, the crank driven at 10 rad/s: no degree of
  // freedom is left, so positions follow the slider-crank relation exactly and the drive
  // torque and bearing reaction come from the multipliers. Joint coordinates (the driver and
  // the crank pin close the loop) against absolute coordinates and the exact kinematics.
  using Model = sp::Model<sp::Revolute, sp::Spherical, sp::Universal, sp::Translational,
                          sp::RevoluteDriver, sp::Gravity>;
  const double r = 0.04, l = 0.14, speed = 10.0;
  struct Sample {
    double z, reaction, torque;
  };
  const auto run = [&](const char* coordinates) {
    Model model;
    const odyn::BodyId crank = model.add_body({.name = "crank",
                                               .mass = 1.399,
                                               .inertia = sp::Body::principal(1.524, 1.291, 0.836),
                                               .angular_velocity = {speed, 0, 0}});
    const odyn::BodyId rod = model.add_body({.name = "rod",
                                             .mass = 0.253,
                                             .inertia = sp::Body::principal(0.399, 0.372, 0.0349),
                                             .position = {0, 0, r + l / 2}});
    const odyn::BodyId piston = model.add_body({.name = "piston",
                                                .mass = 0.643,
                                                .inertia = sp::Body::principal(0.457, 0.506, 0.653),
                                                .position = {0, 0, r + l}});
    const auto bearing = model.add(sp::Revolute("bearing", odyn::ground,
                                                sp::JointFrame{{0, 0, 0}, Vector3d::UnitX()}, crank,
                                                sp::JointFrame{{0, 0, 0}, Vector3d::UnitX()}));
    model.add(sp::Spherical("crank pin", crank, {0, 0, r}, rod, {0, 0, -l / 2}));
    model.add(sp::Universal("piston pin", rod, sp::JointFrame{{0, 0, l / 2}, Vector3d::UnitX()},
                            piston, sp::JointFrame{{0, 0, 0}, Vector3d::UnitY()}));
    model.add(sp::Translational("cylinder", odyn::ground,
                                sp::JointFrame{{0, 0, r + l}, Vector3d::UnitZ()}, piston,
                                sp::JointFrame{{0, 0, 0}, Vector3d::UnitZ()}));
    const auto motor = model.add(sp::RevoluteDriver("motor", model.element(bearing),
                                                    odyn::Motion::constant_velocity(speed)));
    model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
    odyn::Workspace<Model> ws(model);
    odyn::DynamicsSettings settings = joint_settings("dop853", 1e-10);
    settings.coordinates = coordinates;
    settings.output_interval = 0.05;
    std::vector<Sample> samples;
    odyn::simulate(model, ws, settings, [&](const auto& state) {
      const double theta = speed * state.t;
      const double z_exact =
          r * std::cos(theta) + std::sqrt(l * l - std::pow(r * std::sin(theta), 2));
      CHECK(state.frames[piston.index].position.z() == Approx(z_exact).margin(1e-12));
      samples.push_back({state.frames[piston.index].position.z(),
                         odyn::reaction(model, state, bearing, odyn::Side::b).force.z(),
                         state.lambda[model.row(motor)]});
    });
    return samples;
  };
  const auto joint = run("joint");
  const auto absolute = run("absolute");
  REQUIRE(joint.size() == absolute.size());
  double reaction = 0.0, torque = 0.0, torque_scale = 0.0;
  for (std::size_t k = 0; k < joint.size(); ++k) {
    reaction = std::max(reaction, std::abs(joint[k].reaction - absolute[k].reaction));
    torque = std::max(torque, std::abs(joint[k].torque - absolute[k].torque));
    torque_scale = std::max(torque_scale, std::abs(absolute[k].torque));
  }
  INFO("bearing reaction difference " << reaction << " N, drive multiplier difference " << torque
                                      << " (largest " << torque_scale << ")");
  CHECK(torque_scale > 0.1);  // the drive really works against gravity and inertia
  CHECK(reaction < 1e-8);
  CHECK(torque < 1e-9);
}

TEST_CASE("Joint coordinates: Bricard's redundant closure pinned, moving as its twin",
          "[joint][redundant]") {
  // Bricard's linkage closes its loop with J6's five equations, one of which repeats the
  // others at every pose. Joint coordinates pin it: the motion and the constraint forces on
  // each body (Phi_q^T lambda, over every joint) must be those of the twin whose J6 is
  // cylindrical (29 independent equations), run in absolute coordinates with dop853 at 1e-11.
  struct Output {
    Eigen::VectorXd q, constraint_force;
    double pinned_multiplier = 0.0;
  };
  const auto run = [](bool cylinder, odyn::DynamicsSettings settings, std::size_t* redundant) {
    bricard::Parameters p;
    p.cylinder = cylinder;
    const bricard::Linkage l = bricard::build(p);
    odyn::Workspace<bricard::Model> ws(l.model);
    settings.t_end = 1.1;
    settings.output_interval = 0.05;
    std::vector<Output> outputs;
    const auto summary = odyn::simulate(l.model, ws, settings, [&](const auto& w) {
      const Eigen::MatrixXd jacobian = odyn::detail::dense_jacobian(l.model, w);
      outputs.push_back(
          {w.q, jacobian.transpose() * w.lambda,
           cylinder
               ? 0.0
               : w.lambda.template segment<5>(l.model.row(l.joints[5])).cwiseAbs().minCoeff()});
    });
    *redundant = summary.redundant_equations.size();
    return outputs;
  };
  odyn::DynamicsSettings reference_settings;
  reference_settings.integrator = "dop853";
  reference_settings.rtol = reference_settings.atol = 1e-11;
  std::size_t twin_redundant = 1;
  const auto twin = run(true, reference_settings, &twin_redundant);
  CHECK(twin_redundant == 0);
  for (const auto& [integrator, tolerance, bound] :
       {std::tuple{"dop853", 1e-10, 1e-9}, std::tuple{"bdf", 1e-10, 1e-7},
        std::tuple{"generalized-alpha", 1e-6, 1e-6}}) {
    odyn::DynamicsSettings settings = joint_settings(integrator, tolerance);
    settings.step = 1e-4;
    std::size_t redundant = 0;
    const auto outputs = run(false, settings, &redundant);
    REQUIRE(outputs.size() == twin.size());
    double position = 0.0, force = 0.0, largest_force = 0.0, travel = 0.0;
    for (std::size_t k = 0; k < outputs.size(); ++k) {
      position = std::max(position, (outputs[k].q - twin[k].q).cwiseAbs().maxCoeff());
      force = std::max(
          force, (outputs[k].constraint_force - twin[k].constraint_force).cwiseAbs().maxCoeff());
      largest_force = std::max(largest_force, twin[k].constraint_force.cwiseAbs().maxCoeff());
      travel = std::max(travel, (twin[k].q - twin[0].q).cwiseAbs().maxCoeff());
    }
    INFO(integrator << ": positions differ by " << position << " m (travel " << travel
                    << " m), constraint forces by " << force / largest_force
                    << " of their largest");
    CHECK(redundant == 1);
    CHECK(travel > 0.4);
    CHECK(position < bound);
    CHECK(force < 100 * bound * largest_force);
    // The pinned equation carries nothing: one of J6's multipliers stays zero.
    CHECK(outputs.back().pinned_multiplier == 0.0);
  }
}

TEST_CASE("Joint coordinates: unknown coordinates refused", "[joint][errors]") {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> engine_ws(e.model);
  odyn::DynamicsSettings unknown = joint_settings("dop853", 1e-8);
  unknown.coordinates = "relative";
  CHECK_THROWS_WITH(odyn::simulate(e.model, engine_ws, unknown, [](const auto&) {}),
                    Catch::Contains("unknown coordinates 'relative'"));
}

TEST_CASE("Coordinates auto: joint ones for the engine, absolute ones where they would not pay",
          "[joint][auto]") {
  using Catch::Contains;
  SECTION("the engine with the defaults: joint coordinates, the same answer as absolute ones") {
    const auto reference = engine_reference::solve(1.0, 1e-3);
    engine::Engine e = engine::build();
    odyn::AssembledStart<engine::Model> start;
    const auto run = [&](const char* coordinates, odyn::AssembledStart<engine::Model>* kept) {
      odyn::Workspace<engine::Model> ws(e.model);
      odyn::DynamicsSettings settings;  // integrator and coordinates "auto"
      settings.coordinates = coordinates;
      settings.rtol = settings.atol = 1e-8;
      const auto summary = odyn::simulate(e.model, ws, settings, [](const auto&) {}, kept);
      return std::tuple(summary, engine::crank_angle(e, ws));
    };
    CHECK(odyn::DynamicsSettings{}.coordinates == "auto");
    const auto [chosen, theta] = run("auto", &start);
    const auto [absolute, theta_absolute] = run("absolute", nullptr);
    INFO(chosen.coordinates_choice << "; theta(1) errors " << theta - reference.back().theta
                                   << " (auto), " << theta_absolute - reference.back().theta
                                   << " (absolute)");
    CHECK(chosen.coordinates == "joint");
    CHECK_THAT(chosen.coordinates_choice, Contains("3 closure equations"));
    CHECK(chosen.integrator == "dop853");
    CHECK(absolute.coordinates == "absolute");
    CHECK(absolute.coordinates_choice.empty());
    // Measured: 3e-8 rad (auto, joint coordinates) and 2.6e-7 rad (absolute).
    CHECK(std::abs(theta - reference.back().theta) < 1e-6);
    CHECK(std::abs(theta_absolute - reference.back().theta) < 1e-6);
    // The choice assembles first; the run counts that assembly as its own, and a second run
    // from the kept start reuses it.
    CHECK_FALSE(chosen.assembly_reused);
    CHECK(chosen.setup_seconds > 0.0);
    const auto [again, theta_again] = run("auto", &start);
    CHECK(again.assembly_reused);
    CHECK(again.coordinates == "joint");
    CHECK(theta_again == theta);
  }
  SECTION("absolute coordinates: planar, implicit, redundant, springs between bodies, loops") {
    const auto choice = [](const auto& model, const char* integrator) {
      using Model = std::remove_cvref_t<decltype(model)>;
      odyn::Workspace<Model> ws(model);
      odyn::DynamicsSettings settings;
      settings.integrator = integrator;
      settings.t_end = 1e-3;
      const auto summary = odyn::simulate(model, ws, settings, [](const auto&) {});
      return summary.coordinates + ": " + summary.coordinates_choice;
    };
    CHECK_THAT(choice(engine::planar::build().model, "auto"),
               Contains("absolute: ") && Contains("planar"));
    CHECK_THAT(choice(engine::build().model, "generalized-alpha"),
               Contains("absolute: ") && Contains("implicit"));
    CHECK_THAT(choice(engine::build().model, "adams"), Contains("joint: "));
    // Bricard's linkage: one redundant equation, minimum-norm in absolute coordinates.
    CHECK_THAT(choice(bricard::build().model, "auto"),
               Contains("absolute: ") && Contains("1 redundant"));
    // Springs between moving links: absolute for auto (it may turn to bdf), joint for dop853.
    const RopeModel springs =
        rope(6, 0.1, sp::Tsda::Parameters{.stiffness = 40.0, .damping = 0.5, .free_length = 0.9});
    CHECK_THAT(choice(springs, "auto"),
               Contains("absolute: ") && Contains("joins two moving bodies"));
    CHECK_THAT(choice(springs, "dop853"), Contains("joint: ") && Contains("0 closure"));
    // Ten spatial four-bars leave 50 closure equations (the rule's own limit, whatever the
    // redundancy that the run finds at its start).
    parallelogram_chain::Parameters ten;
    ten.four_bars = 10;
    const auto chain = parallelogram_chain::spatial::build(ten);
    using ChainModel = std::remove_cvref_t<decltype(chain.model)>;
    CHECK(odyn::JointCoordinates<ChainModel>::closure_equations(chain.model) == 50);
    odyn::DynamicsSettings settings;
    const odyn::CoordinatesChoice loops = odyn::choose_coordinates(chain.model, settings, {});
    CHECK(loops.coordinates == "absolute");
    CHECK_THAT(loops.reason, Contains("50 closure equations"));
    ten.four_bars = 2;
    const auto two = parallelogram_chain::spatial::build(ten);
    CHECK(odyn::choose_coordinates(two.model, settings, {}).coordinates == "joint");
    CHECK_THAT(choice(two.model, "auto"), Contains("absolute: ") && Contains("redundant"));
  }
  SECTION("the count of closure equations is the tree's") {
    engine::Engine e = engine::build();
    odyn::Workspace<engine::Model> ws(e.model);
    odyn::assemble(e.model, ws);
    const odyn::JointCoordinates<engine::Model> coordinates(e.model, ws);
    CHECK(odyn::JointCoordinates<engine::Model>::closure_equations(e.model) ==
          coordinates.num_equations());
  }
}

// ---- Planar models: the same tree in the plane (3 numbers per motion, see tree_algebra.hpp).

TEST_CASE("Joint coordinates in the plane: the engine against its minimal-coordinate solution",
          "[joint][engine][planar]") {
  engine::planar::Engine e = engine::planar::build();
  {
    odyn::Workspace<engine::planar::Model> ws(e.model);
    odyn::assemble(e.model, ws);
    odyn::JointCoordinates<engine::planar::Model> coordinates(e.model, ws);
    CHECK(coordinates.num_positions() == 3);  // crank angle, rod angle, piston angle
    CHECK(coordinates.num_equations() == 2);  // the loop closes at the cylinder
    CHECK(coordinates.loop_closures() == std::vector<std::string>{"cylinder"});
  }
  check_engine_against_reference(e);
}

namespace {

namespace pl = odyn::planar;
using Eigen::Vector2d;
// The library's planar model type, which other tests simulate too: no further instantiation.
using PlanarModel = pl::DefaultModel;

/// Every planar tree-joint kind and a free root at once: a cart sliding on an inclined track
/// (translational), a pendulum hinged to it with a spring to the cart, a loose body tied to
/// the pendulum by a distance and to the ground by a spring (a free root, closed by the
/// distance), and a ladder of `cells` four-bars hanging from the cart (a loop per cell).
PlanarModel planar_mechanism(int cells) {
  PlanarModel model;
  const auto cart = model.add_body(
      pl::Body{.name = "cart", .mass = 2.0, .inertia = 0.1, .linear_velocity = {0.3, 0.06}});
  model.add(pl::Translational("track", odyn::ground, {Vector2d(0, 0), Vector2d(1, 0.2)}, cart, {}));
  const auto bob = model.add_body(
      pl::Body{.name = "bob", .mass = 1.0, .inertia = 0.05, .position = {0.4, -0.3}, .angle = 0.5});
  model.add(pl::Revolute("hinge", cart, {Vector2d(0, 0)}, bob, {Vector2d(-0.4, 0.3)}));
  model.add(pl::Tsda("hinge spring", cart, Vector2d(0.3, 0.0), bob, Vector2d(0.0, 0.0),
                     {.stiffness = 30.0, .damping = 0.2, .free_length = 0.25}));
  const auto loose = model.add_body(pl::Body{.name = "loose",
                                             .mass = 0.5,
                                             .inertia = 0.02,
                                             .position = {1.2, -0.3},
                                             .angle = 0.2,
                                             .angular_velocity = 2.0});
  model.add(pl::Distance("rope", bob, Vector2d(0.1, 0.0), loose, Vector2d(-0.1, 0.05)));
  model.add(pl::Tsda("anchor", odyn::ground, Vector2d(2, 1), loose, Vector2d(0, 0),
                     {.stiffness = 20.0, .damping = 0.3, .free_length = 1.0}));
  odyn::BodyId base = cart;
  for (int c = 0; c < cells; ++c) {
    const std::string n = std::to_string(c);
    const double top = -0.5 * c, down = -std::numbers::pi / 2;
    const auto link = [&](const std::string& name, const Vector2d& centre, double angle) {
      return model.add_body(pl::Body{
          .name = name + n, .mass = 1.0, .inertia = 0.02, .position = centre, .angle = angle});
    };
    const auto left = link("left", {-0.2, top - 0.25}, down);
    const auto right = link("right", {0.2, top - 0.25}, down);
    const auto bar = link("bar", {0.0, top - 0.5}, 0.0);
    model.add(pl::Revolute("left top" + n, base, {Vector2d(-0.2, 0)}, left, {Vector2d(-0.25, 0)}));
    model.add(pl::Revolute("right top" + n, base, {Vector2d(0.2, 0)}, right, {Vector2d(-0.25, 0)}));
    model.add(pl::Revolute("left bottom" + n, left, {Vector2d(0.25, 0)}, bar, {Vector2d(-0.2, 0)}));
    model.add(
        pl::Revolute("right bottom" + n, right, {Vector2d(0.25, 0)}, bar, {Vector2d(0.2, 0)}));
    base = bar;
  }
  model.add(pl::Gravity("gravity", {0.0, -9.81}));
  return model;
}

/// Every body's (x, y, angle) and velocities at each output, and the largest |Phi|.
struct PlanarRun {
  std::vector<Eigen::VectorXd> states;
  double phi = 0.0;
};

PlanarRun run_planar(const PlanarModel& model, const odyn::DynamicsSettings& settings) {
  odyn::Workspace<PlanarModel> ws(model);
  PlanarRun out;
  odyn::simulate(model, ws, settings, [&](const auto& state) {
    Eigen::VectorXd row(state.q.size() + state.v.size());
    row << state.q, state.v;
    out.states.push_back(row);
    out.phi = std::max(out.phi, state.phi.cwiseAbs().maxCoeff());
  });
  return out;
}

double largest_difference(const PlanarRun& a, const PlanarRun& b) {
  REQUIRE(a.states.size() == b.states.size());
  double difference = 0.0;
  for (std::size_t k = 0; k < a.states.size(); ++k)
    difference = std::max(difference, (a.states[k] - b.states[k]).cwiseAbs().maxCoeff());
  return difference;
}

}  // namespace

TEST_CASE(
    "Joint coordinates in the plane: every tree-joint kind, a free root and a ladder of "
    "four-bars against absolute coordinates",
    "[joint][planar]") {
  // Eight loops put the model on the recursive path (more unknowns than dense_limit). The
  // reference is the same model in absolute coordinates, converged (dop853 at 1e-12).
  const PlanarModel model = planar_mechanism(8);
  {
    odyn::Workspace<PlanarModel> ws(model);
    odyn::assemble(model, ws);
    odyn::JointCoordinates<PlanarModel> coordinates(model, ws);
    CHECK(coordinates.num_velocities() == 1 + 1 + 3 + 3 * 8);  // track, hinge, free root, ladder
    CHECK(coordinates.num_equations() == 1 + 2 * 8);           // the rope, one pin per cell
  }
  odyn::DynamicsSettings settings;
  settings.t_end = 0.5;
  settings.output_interval = 0.05;
  settings.integrator = "dop853";
  settings.rtol = settings.atol = 1e-12;
  const PlanarRun reference = run_planar(model, settings);
  settings.coordinates = "joint";
  settings.rtol = settings.atol = 1e-10;
  const PlanarRun dop853 = run_planar(model, settings);
  settings.integrator = "bdf";
  settings.rtol = settings.atol = 1e-9;
  const PlanarRun bdf = run_planar(model, settings);
  settings.integrator = "generalized-alpha";
  settings.step = 2e-4;
  const PlanarRun coarse = run_planar(model, settings);
  settings.step = 1e-4;
  const PlanarRun fine = run_planar(model, settings);
  double motion = 0.0;
  for (const Eigen::VectorXd& state : reference.states)
    motion = std::max(motion, (state - reference.states.front()).cwiseAbs().maxCoeff());
  const double dop853_error = largest_difference(dop853, reference);
  const double bdf_error = largest_difference(bdf, reference);
  const double coarse_error = largest_difference(coarse, reference);
  const double fine_error = largest_difference(fine, reference);
  INFO("largest motion " << motion << "; differences from absolute coordinates: dop853 "
                         << dop853_error << ", bdf " << bdf_error << ", generalized-alpha "
                         << coarse_error << " (h = 2e-4) and " << fine_error << " (h = 1e-4)");
  // Measured: 7.1e-13, 3.1e-7, 1.35e-5 and 3.4e-6 (largest motion 2.8).
  CHECK(motion > 0.5);
  CHECK(dop853_error < 1e-10);
  CHECK(bdf_error < 3e-6);
  CHECK(coarse_error / fine_error == Approx(4.0).epsilon(0.25));  // second order
  CHECK(dop853.phi < 1e-11);
  CHECK(fine.phi < 1e-9);
}

TEST_CASE("A chain whipping round under large constraint forces runs with the defaults",
          "[sparse][hard]") {
  // 512 links of 1 m and 1 kg, horizontal, every link given a speed across: the assembly keeps
  // what the joints allow, a zigzag whose links turn at twice that speed in rad/s. Their
  // centripetal terms add up along the chain to a tension of about 2 (speed N)^2 newtons at the
  // pivot (84 kN at 0.4 m/s), whose geometric stiffness is 14 % of the links' inertia over the
  // step squared at h = 1e-3 and 0.4 m/s: without it in the Newton matrix the iteration
  // contracts by only 1/10 a step, and this run stopped in its first step. At 0.8 m/s the
  // first steps of 1 ms do not converge even so, and are cut (advance_to) until the chain has
  // settled into its motion. Generalized-alpha with its defaults must run both and converge at
  // second order to the same chain in joint coordinates (dop853 at 1e-11, no constraint
  // equation at all), which the absolute-coordinate dop853 run confirms.
  const int n = 512;
  const double t_end = 0.05;
  const auto speed = GENERATE(0.4, 0.8);
  const RopeModel model = rope(n, speed);
  long rejected = 0;
  const auto centres_at_end = [&](const char* integrator, const char* coordinates, double h) {
    odyn::Workspace<RopeModel> ws(model);
    odyn::DynamicsSettings settings;
    settings.integrator = integrator;
    settings.coordinates = coordinates;
    settings.step = h;
    settings.rtol = settings.atol = 1e-11;
    settings.t_end = t_end;
    settings.output_interval = t_end;
    Eigen::VectorXd centres(3 * n);
    const auto summary = odyn::simulate(model, ws, settings, [&](const auto& state) {
      for (int b = 1; b <= n; ++b) centres.segment<3>(3 * (b - 1)) = state.frames[b].position;
    });
    rejected = summary.statistics.rejected_steps;
    return centres;
  };
  const Eigen::VectorXd reference = centres_at_end("dop853", "joint", 1e-4);
  CHECK((centres_at_end("dop853", "absolute", 1e-4) - reference).cwiseAbs().maxCoeff() < 1e-9);
  Eigen::VectorXd coarse, fine;
  REQUIRE_NOTHROW(coarse = centres_at_end("generalized-alpha", "absolute", 1e-3));
  const long coarse_rejected = rejected;
  REQUIRE_NOTHROW(fine = centres_at_end("generalized-alpha", "absolute", 5e-4));
  const double coarse_error = (coarse - reference).cwiseAbs().maxCoeff();
  const double fine_error = (fine - reference).cwiseAbs().maxCoeff();
  INFO(speed << " m/s: errors " << coarse_error << " m at h = 1e-3 (" << coarse_rejected
             << " attempts rejected), " << fine_error << " m at 5e-4 (" << rejected << ")");
  if (speed == 0.4) {
    CHECK(coarse_rejected == 0);
    CHECK(coarse_error < 3e-3);              // the links moved about 2 cm; measured 1.9e-3
    CHECK(coarse_error > 3.0 * fine_error);  // second order
  } else {
    CHECK(coarse_rejected > 0);    // the full step failed, and was cut
    CHECK(coarse_error < 1.5e-2);  // the links moved about 4 cm; measured 1.2e-2
    // Second order, less the steps that were cut anyway: measured 3.0.
    CHECK(coarse_error > 2.5 * fine_error);
  }
}

}  // namespace test_joint_coordinates
