// The engine of shared/specs/engine.md built from planar elements: the same geometry, masses,
// gas force and load in the Y-Z plane, with the crank's and rod's Ixx as planar moments of
// inertia. 9 coordinates and 8 equations instead of 18 and 17; same options and CSV columns as
// the spatial `engine` example.
//
//   slider_crank_planar [--h STEP] [--t-end T] [--dt-out DT] [--out FILE] [--integrator NAME]
//                       [--rho-inf R]

#include "engine_cli.hpp"

int main(int argc, char** argv) {
  return engine::run_command_line(
      "slider_crank_planar", [] { return engine::planar::build(); }, argc, argv);
}
