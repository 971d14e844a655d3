// Absolute against joint coordinates: dop853 at one tolerance on the examples' models and on
// chains of parallelogram four-bars, the median CPU time of 3 runs in each coordinate set, and
// what coordinates "auto" chooses for the model (see choose_coordinates in odyn/dynamics.hpp,
// whose rule these figures support; docs/integrators.md, "Which coordinates: auto").
//
//   cmake --build build --target coordinates && ./build/bench/coordinates [--out FILE.md]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

#include "andrews_model.hpp"
#include "bricard_model.hpp"
#include "engine_model.hpp"
#include "four_bar_model.hpp"
#include "governor_model.hpp"
#include "heavy_top_model.hpp"
#include "parallelogram_chain_model.hpp"

namespace {

struct Timing {
  double milliseconds = 0.0;
  long steps = 0;
};

template <class Model>
Timing time_dop853(const Model& model, const char* coordinates, double t_end, double tolerance) {
  std::vector<double> times;
  long steps = 0;
  for (int repeat = 0; repeat < 3; ++repeat) {
    odyn::DynamicsSettings settings;
    settings.integrator = "dop853";
    settings.coordinates = coordinates;
    settings.rtol = settings.atol = tolerance;
    settings.t_end = t_end;
    settings.output_interval = t_end / 100.0;
    odyn::Workspace<Model> ws(model);
    const auto started = std::chrono::steady_clock::now();
    steps = odyn::simulate(model, ws, settings, [](const auto&) {}).statistics.steps;
    times.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count());
  }
  std::sort(times.begin(), times.end());
  return {times[1], steps};
}

template <class Model>
std::string row(const std::string& name, const Model& model, double t_end, double tolerance) {
  odyn::Workspace<Model> ws(model);
  odyn::assemble(model, ws);
  const long closures = odyn::JointCoordinates<Model>::closure_equations(model);
  const Timing absolute = time_dop853(model, "absolute", t_end, tolerance);
  const Timing joint = time_dop853(model, "joint", t_end, tolerance);
  odyn::DynamicsSettings settings;  // integrator and coordinates "auto"
  const std::string chosen =
      odyn::choose_coordinates(model, settings, odyn::redundant_equations(model, ws)).coordinates;
  char line[256];
  std::snprintf(line, sizeof line, "| %s | %d + %d | %ld | %.2f (%ld) | %.2f (%ld) | %.2f | %s |",
                name.c_str(), model.num_velocities(), model.num_equations(), closures,
                absolute.milliseconds, absolute.steps, joint.milliseconds, joint.steps,
                absolute.milliseconds / joint.milliseconds, chosen.c_str());
  std::cout << line << std::endl;
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--out") out = argv[++i];
  std::ostringstream table;
  table
      << "| model | absolute: coordinates + equations | closure equations | absolute, ms "
         "(steps) | joint, ms (steps) | absolute / joint | auto |\n|---|---|---|---|---|---|---|\n";
  std::cout << table.str();
  table << row("engine (spatial), 1 s", engine::build().model, 1.0, 1e-8) << '\n';
  table << row("engine (planar), 1 s", engine::planar::build().model, 1.0, 1e-8) << '\n';
  table << row("Andrews' mechanism, 0.03 s", andrews::build().model, 0.03, 1e-8) << '\n';
  table << row("four-bar (planar), 1 s", four_bar::build().model, 1.0, 1e-8) << '\n';
  table << row("Bricard's linkage, 1 s", bricard::build().model, 1.0, 1e-8) << '\n';
  table << row("governor, 1 s", governor::build().model, 1.0, 1e-8) << '\n';
  table << row("heavy top, 1 s", heavy_top::build().model, 1.0, 1e-8) << '\n';
  for (const int n : {2, 5, 10, 40}) {
    parallelogram_chain::Parameters p;
    p.four_bars = n;
    const std::string size = std::to_string(n) + " parallelogram four-bars";
    table << row(size + " (planar), 0.3 s", parallelogram_chain::planar::build(p).model, 0.3, 1e-8)
          << '\n';
    table << row(size + " (spatial), 0.3 s", parallelogram_chain::spatial::build(p).model, 0.3,
                 1e-8)
          << '\n';
  }
  if (!out.empty()) std::ofstream(out) << table.str();
}
