// The O-DYN paper's engine (shared/specs/engine.md), built from spatial bodies and joints:
// dynamic analysis from top dead centre, a CSV of the crank angle, piston height and bearing
// reaction, and a summary.
//
//   engine [--h STEP] [--t-end T] [--dt-out DT] [--out FILE] [--integrator NAME] [--rho-inf R]

#include "engine_cli.hpp"

int main(int argc, char** argv) {
  return engine::run_command_line(
      "engine", [] { return engine::build(); }, argc, argv);
}
