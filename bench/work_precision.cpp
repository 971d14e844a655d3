// Work-precision report: every integrator over a ladder of tolerances (or step sizes) on the
// engine and the hard cases, against independent references. Writes one CSV row per run
// (case, integrator, setting, errors, CPU time, counters) and prints a table.
//
//   work_precision [--out FILE.csv] [--repeat N] [--case NAME]... [--quick]
//
// CPU time is the process CPU time of the run (assembly included), the median of N repeats
// (3 by default; runs longer than a second are not repeated). The plot comes from
// bench/plot_work_precision.py; scripts/work_precision.sh does both.

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "andrews_model.hpp"
#include "engine_model.hpp"
#include "reference/andrews_reference.hpp"
#include "reference/engine_reference.hpp"

namespace {

double cpu_seconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// One integrator setting of a ladder.
struct Setting {
  std::string label;       // the family: the integrator and its fixed options
  std::string integrator;  // odyn's name
  bool adaptive = false;   // error control (rtol = atol = tolerance) or fixed step h
  double value = 0.0;      // the tolerance or the step
  double rho_inf = 0.9;
  int order = 6;  // of adams
  std::string coordinates = "absolute";
};

/// What one run measured: errors against the reference (named per case) and the counters.
struct Outcome {
  std::vector<double> errors;
  odyn::IntegratorStatistics statistics;
  double max_phi = 0.0;
  bool failed = false;
  std::string failure;
};

struct Case {
  std::string name;
  std::vector<std::string> error_names;  // the first is the one plotted
  std::function<Outcome(const odyn::DynamicsSettings&)> run;
  std::vector<Setting> ladder;
};

odyn::DynamicsSettings settings_for(const Setting& s) {
  odyn::DynamicsSettings settings;
  settings.integrator = s.integrator;
  settings.generalized_alpha.rho_inf = s.rho_inf;
  settings.adams.order = s.order;
  settings.coordinates = s.coordinates;
  if (s.adaptive) {
    settings.rtol = settings.atol = s.value;
    settings.generalized_alpha.adaptive = true;
    settings.step = 1e-5;  // the first step; the controller takes over
  } else {
    settings.step = s.value;
  }
  return settings;
}

bool known_integrator(const std::string& name) {
  for (const auto& [known, what] : odyn::integrator_names())
    if (known == name) return true;
  return false;
}

/// The ladders every case shares: fixed-step generalized-alpha, the same with error control,
/// HHT, and the integrators with error control that the library registers.
std::vector<Setting> standard_ladder(const std::vector<double>& steps, bool quick,
                                     bool joint_coordinates = false) {
  std::vector<Setting> ladder;
  const std::vector<double> loose = {1e-3, 1e-4, 1e-5, 1e-6};
  // Half decades where the engine crosses its target of 1e-7 rad.
  const std::vector<double> tight = {1e-4, 1e-5, 1e-6, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10, 1e-11};
  for (double h : steps)
    ladder.push_back({"generalized-alpha, fixed h", "generalized-alpha", false, h});
  for (double h : steps) ladder.push_back({"hht, fixed h", "hht", false, h});
  if (known_integrator("adams"))
    for (double h : steps) ladder.push_back({"adams 6, fixed h", "adams", false, 2.0 * h});
  for (double tol : loose)
    ladder.push_back({"generalized-alpha, adaptive", "generalized-alpha", true, tol});
  // auto runs with the defaults, its coordinates "auto" too; the others in absolute ones.
  for (const std::string name : {"dopri5", "dop853", "bdf", "auto"})
    if (known_integrator(name))
      for (double tol : tight)
        ladder.push_back({name, name, true, tol, 0.9, 6, name == "auto" ? "auto" : "absolute"});
  if (joint_coordinates) {  // the same methods on a spanning tree's joint coordinates
    for (double h : steps)
      ladder.push_back({"generalized-alpha, fixed h, joint coordinates", "generalized-alpha", false,
                        h, 0.9, 6, "joint"});
    for (const std::string name : {"dopri5", "dop853"})
      for (double tol : tight)
        ladder.push_back({name + ", joint coordinates", name, true, tol, 0.9, 6, "joint"});
    for (double h : steps)
      ladder.push_back(
          {"adams 6, fixed h, joint coordinates", "adams", false, 2.0 * h, 0.9, 6, "joint"});
  }
  if (quick) {  // the ends of each family only
    std::vector<Setting> ends;
    for (std::size_t i = 0; i < ladder.size(); ++i)
      if (i == 0 || i + 1 == ladder.size() || ladder[i].label != ladder[i - 1].label ||
          ladder[i].label != ladder[i + 1].label)
        ends.push_back(ladder[i]);
    ladder = ends;
  }
  return ladder;
}

/// The engine of shared/specs/engine.md, 1 s, outputs every 1e-3 s: theta(1), the largest
/// z_piston error and the largest R_z error relative to its peak, away from the two jumps.
template <class Build>
Case engine_case(const std::string& name, Build build, bool quick, bool joint_coordinates) {
  static const auto reference = engine_reference::solve(1.0, 1e-3);
  double peak = 0.0;
  for (const auto& sample : reference) peak = std::max(peak, std::abs(sample.R_z));
  auto run = [build, peak](const odyn::DynamicsSettings& base) {
    auto e = build();
    odyn::Workspace<typename decltype(e)::Model> ws(e.model);
    odyn::DynamicsSettings settings = base;
    settings.t_end = 1.0;
    settings.output_interval = 1e-3;
    Outcome out;
    out.errors.assign(3, 0.0);
    std::size_t k = 0;
    const auto summary = odyn::simulate(e.model, ws, settings, [&](const auto& state) {
      const auto& sample = reference.at(k++);
      out.errors[1] =
          std::max(out.errors[1], std::abs(engine::piston_height(e, state) - sample.z_piston));
      // The gas force jumps at ignition (2 pi) and exhaust opening (3 pi) in each 4 pi cycle.
      const double cycle = std::fmod(sample.theta, 4.0 * std::numbers::pi);
      const bool near_jump = std::abs(cycle - 2.0 * std::numbers::pi) < 1e-2 ||
                             std::abs(cycle - 3.0 * std::numbers::pi) < 1e-2;
      if (!near_jump)
        out.errors[2] = std::max(out.errors[2],
                                 std::abs(engine::bearing_force_z(e, state) - sample.R_z) / peak);
    });
    out.errors[0] = std::abs(engine::crank_angle(e, ws) - reference.back().theta);
    out.statistics = summary.statistics;
    out.max_phi = summary.max_position_residual;
    return out;
  };
  return {name,
          {"theta(1) error [rad]", "max z_piston error [m]", "max R_z error / peak"},
          run,
          standard_ladder({2e-4, 1e-4, 5e-5, 2.5e-5, 1.25e-5}, quick, joint_coordinates)};
}

/// Andrews' squeezing mechanism to t = 0.03: the largest relative error of the seven angles.
Case andrews_case(bool quick) {
  static const auto reference = andrews_reference::solve(0.03);
  auto run = [](const odyn::DynamicsSettings& base) {
    andrews::Mechanism m = andrews::build();
    odyn::Workspace<andrews::Model> ws(m.model);
    odyn::DynamicsSettings settings = base;
    settings.t_end = 0.03;
    settings.output_interval = 0.03;
    Outcome out;
    out.errors.assign(1, 0.0);
    const auto summary = odyn::simulate(m.model, ws, settings, [](const auto&) {});
    const auto angles = andrews::test_set_angles(andrews::body_angles(m, ws));
    for (int i = 0; i < 7; ++i)
      out.errors[0] = std::max(
          out.errors[0], std::abs(angles[i] - reference.angle[i]) / std::abs(reference.angle[i]));
    out.statistics = summary.statistics;
    out.max_phi = summary.max_position_residual;
    return out;
  };
  return {"andrews",
          {"max relative angle error"},
          run,
          standard_ladder({4e-6, 2e-6, 1e-6, 5e-7, 2.5e-7}, quick)};
}

void usage() {
  std::cerr << "usage: work_precision [--out FILE.csv] [--repeat N] [--case NAME]... [--quick]\n"
               "cases: engine, engine-planar, andrews\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path = "work_precision.csv";
  int repeat = 3;
  bool quick = false;
  std::vector<std::string> chosen;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--quick") {
      quick = true;
      continue;
    }
    if (option == "--help" || option == "-h" || i + 1 == argc) {
      usage();
      return option == "--help" || option == "-h" ? 0 : 1;
    }
    const std::string value = argv[++i];
    if (option == "--out")
      out_path = value;
    else if (option == "--repeat")
      repeat = std::max(1, std::atoi(value.c_str()));
    else if (option == "--case")
      chosen.push_back(value);
    else {
      usage();
      return 1;
    }
  }

  std::vector<Case> cases;
  cases.push_back(engine_case(
      "engine", [] { return engine::build(); }, quick, true));
  cases.push_back(engine_case(
      "engine-planar", [] { return engine::planar::build(); }, quick, false));
  cases.push_back(andrews_case(quick));

  std::ofstream csv(out_path);
  if (!csv) {
    std::cerr << "work_precision: cannot write " << out_path << "\n";
    return 1;
  }
  csv << "case,family,integrator,adaptive,value,error,error2,error3,cpu_seconds,steps,rejected,"
         "newton_iterations,jacobian_evaluations,factorizations,events,max_phi,status\n";
  csv.precision(6);
  for (const Case& c : cases) {
    if (!chosen.empty() && std::find(chosen.begin(), chosen.end(), c.name) == chosen.end())
      continue;
    std::printf("\n== %s (error: %s)\n", c.name.c_str(), c.error_names.front().c_str());
    std::printf("%-30s %10s %11s %11s %9s %8s %7s\n", "integrator", "h or tol", "error", "CPU [ms]",
                "steps", "Newton", "rejected");
    for (const Setting& s : c.ladder) {
      Outcome outcome;
      std::vector<double> times;
      for (int r = 0; r < repeat; ++r) {
        const double start = cpu_seconds();
        try {
          outcome = c.run(settings_for(s));
        } catch (const std::exception& error) {
          outcome.failed = true;
          outcome.failure = error.what();
        }
        times.push_back(cpu_seconds() - start);
        if (outcome.failed || times.back() > 1.0) break;
      }
      std::sort(times.begin(), times.end());
      const double cpu = times[times.size() / 2];
      std::printf("%-30s %10.2e %11.3e %11.3f %9ld %8ld %7ld%s\n", s.label.c_str(), s.value,
                  outcome.failed ? NAN : outcome.errors[0], 1e3 * cpu, outcome.statistics.steps,
                  outcome.statistics.newton_iterations, outcome.statistics.rejected_steps,
                  outcome.failed ? "  FAILED" : "");
      if (outcome.failed) std::printf("    %s\n", outcome.failure.c_str());
      csv << c.name << ",\"" << s.label << "\"," << s.integrator << "," << (s.adaptive ? 1 : 0)
          << "," << s.value;
      for (std::size_t i = 0; i < 3; ++i)
        csv << "," << (i < outcome.errors.size() && !outcome.failed ? outcome.errors[i] : NAN);
      const auto& st = outcome.statistics;
      csv << "," << cpu << "," << st.steps << "," << st.rejected_steps << ","
          << st.newton_iterations << "," << st.jacobian_evaluations << "," << st.factorizations
          << "," << st.events << "," << outcome.max_phi << "," << (outcome.failed ? "failed" : "ok")
          << "\n";
      std::fflush(stdout);
    }
  }
  std::printf("\nwrote %s\n", out_path.c_str());
  return 0;
}
