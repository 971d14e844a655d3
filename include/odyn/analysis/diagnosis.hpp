#pragma once
// What to tell a user when Newton fails: the force element that returned NaN or pushes
// hardest, the joint with the largest constraint residual, and a constraint Jacobian that
// momentarily loses rank (a singular configuration), read from the workspace's last evaluation.
// Shared by the integrators' error messages.

#include <Eigen/Core>
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "odyn/analysis/assembly.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/workspace.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"

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

/// Below this ratio to the largest pivot of a rank-revealing QR of Phi_q^T, an equation counts
/// as lost for the moment (a singular configuration); below rank_tolerance, as lost for good (an
/// equation that repeats others, reported by the assembly).
inline constexpr double near_rank_loss = 1e-4;

/// " The constraint Jacobian nearly loses rank here: ..." when Phi_q at the workspace's pose has
/// pivots between the exactly repeated equations' (relative rank_tolerance) and near_rank_loss
/// of the largest: a singular configuration, where the mechanism can move in more ways for an
/// instant and its branches cross (and its reactions grow without bound). Names the joints of
/// the equations pivoted last. Empty otherwise, and for models too large for a dense
/// factorization at the moment of failure (m^2 n above 1e9: about a thousand equations).
template <class Model>
std::string rank_drop(const Model& model, const Workspace<Model>& ws,
                      double threshold = near_rank_loss) {
  const int m = model.num_equations(), n = model.num_velocities();
  if (m == 0 || static_cast<double>(m) * m * n > 1e9) return {};  // about a second at most
  const Eigen::MatrixXd transposed = detail::dense_jacobian(model, ws).transpose();
  if (!transposed.allFinite()) return {};
  const RankRevealingQr exact(transposed, rank_tolerance);
  const RankRevealingQr near(transposed, threshold);
  const auto rank = exact.rank(), near_rank = near.rank();
  if (near_rank >= rank) return {};
  std::vector<std::string> joints;
  for (Eigen::Index k = near_rank; k < rank; ++k) {
    const int row = near.column_order()[static_cast<std::size_t>(k)];
    const std::string name = detail::locate_row(model, row).joint;
    if (std::find(joints.begin(), joints.end(), name) == joints.end()) joints.push_back(name);
  }
  std::string names;
  constexpr std::size_t shown = 8;
  for (std::size_t i = 0; i < std::min(joints.size(), shown); ++i)
    names += (i > 0 ? ", '" : "'") + joints[i] + "'";
  if (joints.size() > shown) names += " and " + std::to_string(joints.size() - shown) + " more";
  return " The constraint Jacobian nearly loses rank here: rank " + std::to_string(rank) +
         " drops to " + std::to_string(near_rank) + " within " + to_text(threshold) +
         " of its largest pivot (equations of " + names +
         "): a singular configuration, where the mechanism can move in more ways for an instant "
         "and its branches cross.";
}

/// rank_drop at the state an integrator's coordinates hold; joint coordinates first fill in
/// every joint's blocks there (complete_workspace), as an absolute-coordinate run leaves them.
template <class Model, class Coordinates>
std::string rank_drop(const Model& model, Workspace<Model>& ws, Coordinates& coordinates,
                      double threshold = near_rank_loss) {
  if constexpr (requires { coordinates.complete_workspace(); }) coordinates.complete_workspace();
  return rank_drop(model, std::as_const(ws), threshold);
}

}  // namespace odyn::diagnosis
