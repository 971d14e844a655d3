// Andrews' squeezing mechanism (shared/specs/andrews.md): dynamic analysis from rest, a CSV of
// the seven test-set angles and their rates, and a summary.
//
//   andrews [--t-end T] [--h STEP] [--dt-out DT] [--integrator NAME] [--rho-inf R]
//           [--newton-rtol R] [--rtol R] [--atol A] [--out FILE]
//
// The generalized-alpha family runs at a fixed step --h (default 1e-6 s: angles to about 2e-7
// relative at t = 0.03, falling as h^2 down to about 1e-9 at 6.25e-8 s, where rounding over
// 480 000 steps takes over). --newton-rtol only loosens or tightens Newton's tolerance for long
// steps: short ones tighten it by themselves. dopri5, dop853, adams and bdf control their local
// error by --rtol and --atol instead (--h is then the first step).

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "andrews_model.hpp"

namespace {

void usage() {
  std::cerr << "usage: andrews [--t-end T] [--h STEP] [--dt-out DT] [--out FILE]\n"
               "               [--integrator generalized-alpha|hht|auto|dopri5|dop853|bdf]\n"
               "               [--rho-inf R] [--newton-rtol R] [--rtol R] [--atol A]\n";
}

double number(const char* option, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0') {
    std::cerr << "andrews: " << option << " needs a number, got '" << text << "'\n";
    std::exit(1);
  }
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  odyn::DynamicsSettings settings;
  settings.t_end = 0.03;
  settings.integrator = "generalized-alpha";  // at --h (1e-6 s); --integrator auto chooses
  settings.step = 1e-6;
  settings.output_interval = 1e-3;
  std::string out_path = "andrews.csv";
  bool tolerance_given = false;  // --rtol/--atol: generalized-alpha and hht then adapt h
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--help" || option == "-h") {
      usage();
      return 0;
    }
    if (i + 1 >= argc) {
      usage();
      return 1;
    }
    const char* value = argv[++i];
    if (option == "--h")
      settings.step = number("--h", value);
    else if (option == "--t-end")
      settings.t_end = number("--t-end", value);
    else if (option == "--dt-out")
      settings.output_interval = number("--dt-out", value);
    else if (option == "--out")
      out_path = value;
    else if (option == "--integrator")
      settings.integrator = value;
    else if (option == "--rho-inf")
      settings.generalized_alpha.rho_inf = number("--rho-inf", value);
    else if (option == "--newton-rtol")
      settings.generalized_alpha.newton_rtol = number("--newton-rtol", value);
    else if (option == "--rtol")
      settings.rtol = number("--rtol", value), tolerance_given = true;
    else if (option == "--atol")
      settings.atol = number("--atol", value), tolerance_given = true;
    else {
      std::cerr << "andrews: unknown option " << option << "\n";
      usage();
      return 1;
    }
  }
  settings.generalized_alpha.adaptive = tolerance_given;

  try {
    andrews::Mechanism m = andrews::build();
    odyn::Workspace<andrews::Model> ws(m.model);
    std::ofstream csv(out_path);
    if (!csv) {
      std::cerr << "andrews: cannot write " << out_path << "\n";
      return 1;
    }
    csv << "t,beta,Theta,gamma,Phi,delta,Omega,epsilon,"
           "beta_d,Theta_d,gamma_d,Phi_d,delta_d,Omega_d,epsilon_d\n";
    csv.precision(16);
    const auto summary = odyn::simulate(m.model, ws, settings, [&](const auto& state) {
      csv << state.t;
      for (double angle : andrews::test_set_angles(andrews::body_angles(m, state)))
        csv << ',' << angle;
      for (double rate : andrews::test_set_angles(andrews::body_rates(m, state)))
        csv << ',' << rate;
      csv << '\n';
    });
    const auto& stats = summary.statistics;
    const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
    std::printf("andrews: %s, h = %g s, t_end = %g s -> %s (%ld rows)\n",
                settings.integrator.c_str(), settings.step, settings.t_end, out_path.c_str(),
                summary.outputs);
    std::printf("  %d coordinates, %d constraint equations\n", m.model.num_velocities(),
                m.model.num_equations());
    std::printf("  steps %ld, Newton iterations %ld (%.2f per step), factorizations %ld\n",
                stats.steps, stats.newton_iterations,
                stats.steps ? double(stats.newton_iterations) / double(stats.steps) : 0.0,
                stats.factorizations);
    std::printf("  wall time %.3f s (%.2f us per step)\n", summary.wall_seconds,
                stats.steps ? 1e6 * summary.wall_seconds / double(stats.steps) : 0.0);
    std::printf("  largest residuals: |Phi| %.2e, |Phi_q v + Phi_t| %.2e\n",
                summary.max_position_residual, summary.max_velocity_residual);
    std::printf(
        "  final angles: beta %.12f, Theta %.12f, gamma %.12f, Phi %.12f,\n"
        "                delta %.12f, Omega %.12f, epsilon %.12f\n",
        angles[0], angles[1], angles[2], angles[3], angles[4], angles[5], angles[6]);
  } catch (const odyn::Error& error) {
    std::cerr << "andrews: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
