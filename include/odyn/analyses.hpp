#pragma once
// The analyses beyond a run in time (docs/analyses.md): kinematic analysis and inverse dynamics,
// static equilibrium and quasi-static sequences, natural modes, linearization as a state-space
// model. Apart from odyn.hpp, whose programs that only assemble and simulate a model then
// compile without them.

#include "odyn/analysis/kinematics.hpp"
#include "odyn/analysis/linear_model.hpp"
#include "odyn/analysis/modes.hpp"
#include "odyn/analysis/quasi_statics.hpp"
#include "odyn/analysis/statics.hpp"
#include "odyn/odyn.hpp"
