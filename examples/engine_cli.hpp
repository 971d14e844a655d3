#pragma once
// The command line shared by the engine examples (spatial `engine`, planar
// `slider_crank_planar`): options, the CSV of the paper's outputs and the summary.
//
//   NAME [--h STEP] [--t-end T] [--dt-out DT] [--out FILE] [--integrator NAME] [--rho-inf R]
//        [--order K] [--rtol R] [--atol A] [--coordinates auto|absolute|joint]

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "engine_model.hpp"

namespace engine {

namespace cli {
inline double number(const std::string& program, const char* option, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0') {
    std::cerr << program << ": " << option << " needs a number, got '" << text << "'\n";
    std::exit(1);
  }
  return value;
}
}  // namespace cli

/// Parses the options, runs the engine that `build()` returns and writes its CSV
/// (t,theta,omega,z_piston,R_z,phi_norm,phid_norm). Returns the process exit status.
template <class Build>
int run_command_line(const std::string& program, Build build, int argc, char** argv) {
  odyn::DynamicsSettings settings;
  settings.integrator = "generalized-alpha";  // the paper's method, at --h (1e-4 s)
  std::string out_path = program + ".csv";
  const auto usage = [&] {
    std::cerr << "usage: " << program
              << " [--h STEP] [--t-end T] [--dt-out DT] [--out FILE]\n"
                 "       [--integrator generalized-alpha|hht|auto|dopri5|dop853|bdf|adams]\n"
                 "       [--rho-inf R] [--order K (adams, 1 to 6)] [--rtol R] [--atol A]\n"
                 "       [--coordinates auto|absolute|joint]\n"
                 "(with --rtol/--atol, error control: --h is then the first step)\n";
  };
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
      settings.step = cli::number(program, "--h", value);
    else if (option == "--t-end")
      settings.t_end = cli::number(program, "--t-end", value);
    else if (option == "--dt-out")
      settings.output_interval = cli::number(program, "--dt-out", value);
    else if (option == "--out")
      out_path = value;
    else if (option == "--integrator")
      settings.integrator = value;
    else if (option == "--coordinates")
      settings.coordinates = value;
    else if (option == "--order")
      settings.adams.order = static_cast<int>(cli::number(program, "--order", value));
    else if (option == "--rho-inf")
      settings.generalized_alpha.rho_inf = cli::number(program, "--rho-inf", value);
    else if (option == "--rtol")
      settings.rtol = cli::number(program, "--rtol", value), tolerance_given = true;
    else if (option == "--atol")
      settings.atol = cli::number(program, "--atol", value), tolerance_given = true;
    else {
      std::cerr << program << ": unknown option " << option << "\n";
      usage();
      return 1;
    }
  }
  settings.generalized_alpha.adaptive = tolerance_given;

  try {
    auto e = build();
    using Model = typename decltype(e)::Model;
    odyn::Workspace<Model> ws(e.model);
    std::ofstream csv(out_path);
    if (!csv) {
      std::cerr << program << ": cannot write " << out_path << "\n";
      return 1;
    }
    csv << "t,theta,omega,z_piston,R_z,phi_norm,phid_norm\n";
    csv.precision(12);
    const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& state) {
      const auto [phi_norm, phid_norm] = odyn::constraint_residuals(e.model, state);
      csv << state.t << ',' << crank_angle(e, state) << ',' << crank_rate(e, state) << ','
          << piston_height(e, state) << ',' << bearing_force_z(e, state) << ',' << phi_norm << ','
          << phid_norm << '\n';
    });
    const auto& stats = summary.statistics;
    std::printf("%s: %s, h = %g s, t_end = %g s -> %s (%ld rows)\n", program.c_str(),
                summary.integrator.c_str(), settings.step, settings.t_end, out_path.c_str(),
                summary.outputs);
    if (!summary.integrator_choice.empty())
      std::printf("  %s\n", summary.integrator_choice.c_str());
    std::printf("  %d coordinates, %d constraint equations in absolute coordinates%s\n",
                e.model.num_velocities(), e.model.num_equations(),
                summary.coordinates == "joint" ? "; stepped in joint coordinates" : "");
    if (!summary.coordinates_choice.empty())
      std::printf("  %s\n", summary.coordinates_choice.c_str());
    std::printf("  steps %ld, Newton iterations %ld (%.2f per step), factorizations %ld\n",
                stats.steps, stats.newton_iterations,
                stats.steps ? double(stats.newton_iterations) / double(stats.steps) : 0.0,
                stats.factorizations);
    std::printf("  wall time %.3f s (%.2f us per step)\n", summary.wall_seconds,
                stats.steps ? 1e6 * summary.wall_seconds / double(stats.steps) : 0.0);
    std::printf("  largest residuals: |Phi| %.2e, |Phi_q v + Phi_t| %.2e\n",
                summary.max_position_residual, summary.max_velocity_residual);
    std::printf("  final: theta %.9f rad, omega %.6f rad/s, z_piston %.9f m\n", crank_angle(e, ws),
                crank_rate(e, ws), piston_height(e, ws));
  } catch (const odyn::Error& error) {
    std::cerr << program << ": " << error.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace engine
