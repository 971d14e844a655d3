#pragma once
// odyn: multibody dynamics in which every body, joint and force is an object that computes its
// own blocks of M v' + Phi_q^T lambda = Q, Phi(q, t) = 0. One include for building models,
// assembling and simulating them, and their reactions; odyn/analyses.hpp adds the other analyses.

#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/outputs.hpp"
#include "odyn/analysis/reactions.hpp"
#include "odyn/analysis/system.hpp"
#include "odyn/core/model.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/dynamics.hpp"
#include "odyn/integrators/generalized_alpha.hpp"
#include "odyn/planar.hpp"
#include "odyn/spatial.hpp"
