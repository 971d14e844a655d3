#pragma once
// What to tell a user when Newton fails: the force element that returned NaN or pushes
// hardest, and the joint with the largest constraint residual, read from the workspace's last
// evaluation. Shared by the implicit integrators' error messages.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/workspace.hpp"

namespace odyn::diagnosis {

/// "force element 'name'" for the last force element whose force is not finite, or "an
/// element" if none is.
template <class Model>
std::string non_finite_force(const Model& model, const Workspace<Model>& ws) {
  std::string culprit = "an element";
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (ForceElement<E>) {
      const auto& blocks = std::get<type>(ws.blocks);
      for (std::size_t i = 0; i < pool.size(); ++i)
        for (const auto& f : blocks[i].force)
          if (!f.allFinite()) culprit = "force element '" + pool[i].name() + "'";
    }
  });
  return culprit;
}

/// ", largest applied force from 'name' (value)", or nothing if no force element pushes: the
/// usual suspect when Newton diverges.
template <class Model>
std::string strongest_force(const Model& model, const Workspace<Model>& ws) {
  std::string strongest;
  double largest = 0.0;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
    if constexpr (ForceElement<E>) {
      const auto& blocks = std::get<type>(ws.blocks);
      for (std::size_t i = 0; i < pool.size(); ++i)
        for (const auto& f : blocks[i].force)
          if (f.norm() > largest) {
            largest = f.norm();
            strongest = pool[i].name();
          }
    }
  });
  if (strongest.empty()) return {};
  return ", largest applied force from '" + strongest + "' (" + to_text(largest) + ")";
}

/// "largest constraint residual value at 'joint'".
template <class Model>
std::string worst_constraint(const Model& model, const Workspace<Model>& ws) {
  if (model.num_equations() == 0) return "largest constraint residual 0 at '-'";
  Eigen::Index row = 0;
  const double worst = ws.phi.cwiseAbs().maxCoeff(&row);
  return "largest constraint residual " + to_text(worst) + " at '" +
         model.constraint_name(static_cast<int>(row)) + "'";
}

}  // namespace odyn::diagnosis
