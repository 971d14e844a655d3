// The O-DYN paper's engine (shared/specs/engine.md): dynamic analysis from top dead centre,
// a CSV of the crank angle, piston height and bearing reaction, and a summary.
//
//   engine [--h STEP] [--t-end T] [--dt-out DT] [--out FILE] [--integrator NAME] [--rho-inf R]

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "engine_model.hpp"

namespace {

void usage() {
  std::cerr << "usage: engine [--h STEP] [--t-end T] [--dt-out DT] [--out FILE]\n"
               "              [--integrator generalized-alpha|hht] [--rho-inf R]\n";
}

double number(const char* option, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0') {
    std::cerr << "engine: " << option << " needs a number, got '" << text << "'\n";
    std::exit(1);
  }
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  odyn::DynamicsSettings settings;
  std::string out_path = "engine.csv";
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
    else {
      std::cerr << "engine: unknown option " << option << "\n";
      usage();
      return 1;
    }
  }

  try {
    engine::Engine e = engine::build();
    odyn::Workspace<engine::Model> ws(e.model);
    std::ofstream csv(out_path);
    if (!csv) {
      std::cerr << "engine: cannot write " << out_path << "\n";
      return 1;
    }
    csv << "t,theta,omega,z_piston,R_z,phi_norm,phid_norm\n";
    csv.precision(12);
    const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& state) {
      const auto [phi_norm, phid_norm] = odyn::constraint_residuals(e.model, state);
      const auto reaction = odyn::reaction(e.model, state, e.bearing, odyn::Side::b);
      csv << state.t << ',' << engine::crank_angle(e, state) << ','
          << state.frames[e.crank.index].angular_velocity.x() << ','
          << state.frames[e.piston.index].position.z() << ',' << reaction.force.z() << ','
          << phi_norm << ',' << phid_norm << '\n';
    });
    const auto& stats = summary.statistics;
    std::printf("engine: %s, h = %g s, t_end = %g s -> %s (%ld rows)\n",
                settings.integrator.c_str(), settings.step, settings.t_end, out_path.c_str(),
                summary.outputs);
    std::printf("  steps %ld, Newton iterations %ld (%.2f per step), factorizations %ld\n",
                stats.steps, stats.newton_iterations,
                stats.steps ? double(stats.newton_iterations) / double(stats.steps) : 0.0,
                stats.factorizations);
    std::printf("  wall time %.3f s (%.2f us per step)\n", summary.wall_seconds,
                stats.steps ? 1e6 * summary.wall_seconds / double(stats.steps) : 0.0);
    std::printf("  largest residuals: |Phi| %.2e, |Phi_q v + Phi_t| %.2e\n",
                summary.max_position_residual, summary.max_velocity_residual);
    std::printf("  final: theta %.9f rad, omega %.6f rad/s, z_piston %.9f m\n",
                engine::crank_angle(e, ws), ws.frames[e.crank.index].angular_velocity.x(),
                ws.frames[e.piston.index].position.z());
  } catch (const odyn::Error& error) {
    std::cerr << "engine: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
