#pragma once
// The tangent of analysis/tangent.hpp (the derivatives of the equations of motion M, C, K and
// Phi_q) for large models in absolute coordinates, sparse and at a cost linear in the model's
// size. An element reads only its own bodies' frames, so body b's velocity coordinates reach
// the residual only in the rows of b and of the bodies that share an element with it (its
// neighbours). Bodies far enough apart (no two in one element, none sharing a neighbour: a
// distance-2 colouring of the graph whose edges are the elements) touch disjoint rows, and one
// difference of the residual moves them all at once: the same differences as column by column,
// read off row block by row block. A chain needs 3 colours, a grid of bodies about 9 and a
// body joined to all others one colour each; each colour costs nv columns of differences, each
// of four residuals of O(N). Phi_q comes exact from the elements' Jacobian blocks.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <vector>

#include "odyn/analysis/absolute_coordinates.hpp"
#include "odyn/analysis/sparse_assembly.hpp"
#include "odyn/analysis/tangent.hpp"

namespace odyn {

/// The sparse counterpart of Tangent: n velocity coordinates, m constraint equations.
struct SparseTangent {
  Eigen::SparseMatrix<double> mass;       // (n x n) dr/dv'
  Eigen::SparseMatrix<double> damping;    // (n x n) dr/dv
  Eigen::SparseMatrix<double> stiffness;  // (n x n) dr/dq
  Eigen::SparseMatrix<double> jacobian;   // (m x n) Phi_q
};

namespace detail {

/// For each moving body (0-based), the moving bodies that share an element with it.
template <class Model>
std::vector<std::vector<int>> body_neighbours(const Model& model) {
  std::vector<std::vector<int>> out(static_cast<std::size_t>(model.num_bodies()));
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (NamedElement<E>) {
      for (const E& element : pool)
        for (const BodyId a : element.bodies())
          for (const BodyId b : element.bodies())
            if (!a.is_ground() && !b.is_ground() && a.index != b.index)
              out[static_cast<std::size_t>(a.index - 1)].push_back(b.index - 1);
    }
  });
  for (std::vector<int>& list : out) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return out;
}

/// Groups of bodies, each body in one, no two of a group within two edges of each other
/// (greedy, in body order): their closed neighbourhoods are disjoint.
inline std::vector<std::vector<int>> distance_two_colours(
    const std::vector<std::vector<int>>& neighbours) {
  const auto count = static_cast<int>(neighbours.size());
  std::vector<int> colour(static_cast<std::size_t>(count), -1);
  std::vector<int> taken_by;  // (colours) the last body that found the colour near it
  std::vector<std::vector<int>> groups;
  for (int b = 0; b < count; ++b) {
    const auto mark = [&](int other) {
      const int c = colour[static_cast<std::size_t>(other)];
      if (c >= 0) taken_by[static_cast<std::size_t>(c)] = b;
    };
    for (const int a : neighbours[static_cast<std::size_t>(b)]) {
      mark(a);
      for (const int second : neighbours[static_cast<std::size_t>(a)]) mark(second);
    }
    int c = 0;
    while (c < static_cast<int>(groups.size()) && taken_by[static_cast<std::size_t>(c)] == b) ++c;
    if (c == static_cast<int>(groups.size())) {
      groups.emplace_back();
      taken_by.push_back(-1);
    }
    colour[static_cast<std::size_t>(b)] = c;
    groups[static_cast<std::size_t>(c)].push_back(b);
  }
  return groups;
}

/// Phi_q of the last evaluate_constraints as an (m x n) sparse matrix.
template <class Model>
Eigen::SparseMatrix<double> sparse_constraint_jacobian(const Model& model,
                                                       const Workspace<Model>& ws) {
  const SparseRows rows = sparse_jacobian(model, ws);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(rows.values.size());
  for (int r = 0; r < rows.num_rows(); ++r)
    for (int k = rows.starts[static_cast<std::size_t>(r)];
         k < rows.starts[static_cast<std::size_t>(r) + 1]; ++k)
      entries.emplace_back(r, rows.columns[static_cast<std::size_t>(k)],
                           rows.values[static_cast<std::size_t>(k)]);
  Eigen::SparseMatrix<double> out(rows.num_rows(), rows.num_columns);
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

}  // namespace detail

/// The derivatives at the workspace's state in absolute coordinates (positions, velocities,
/// accelerations and multipliers as the coordinates hold them), with the steps of tangent();
/// the state and its evaluations as found on return.
template <class Model, class Solver>
SparseTangent sparse_tangent(AbsoluteCoordinates<Model, Solver>& c, const Model& model,
                             const Workspace<Model>& ws, double length, Tangent::Parts parts = {}) {
  constexpr int nv = Model::nv, dim = Model::Space::dim;
  const Eigen::Index n = c.num_velocities();
  const std::vector<std::vector<int>> neighbours = detail::body_neighbours(model);
  const std::vector<std::vector<int>> groups = detail::distance_two_colours(neighbours);
  const Eigen::VectorXd q = c.positions(), v = c.velocities(), a = c.accelerations();
  Eigen::VectorXd r0(n), r(n), difference(n), increment = Eigen::VectorXd::Zero(n);
  detail::residual_here(c, r0);
  SparseTangent out;
  out.jacobian = detail::sparse_constraint_jacobian(model, ws);
  std::vector<Eigen::Triplet<double>> mass, damping, stiffness;
  // Column k of each body of the group, read off the rows of the body and its neighbours.
  const auto read = [&](const std::vector<int>& group, int k, const Eigen::VectorXd& column,
                        std::vector<Eigen::Triplet<double>>& entries) {
    for (const int b : group) {
      const auto take = [&](int row_body) {
        for (int i = 0; i < nv; ++i)
          if (const double x = column[row_body * nv + i]; x != 0.0)
            entries.emplace_back(row_body * nv + i, b * nv + k, x);
      };
      take(b);
      for (const int other : neighbours[static_cast<std::size_t>(b)]) take(other);
    }
  };
  const double speed_step = 1e-3 * std::max(1.0, n > 0 ? v.cwiseAbs().maxCoeff() : 0.0);
  for (const std::vector<int>& group : groups)
    for (int k = 0; k < nv; ++k) {
      const auto set = [&](Eigen::VectorXd& vector, const Eigen::VectorXd& base, double s) {
        for (const int b : group) vector[b * nv + k] = base[b * nv + k] + s;
      };
      if (parts.mass) {
        // r is linear in v': a unit step is exact.
        set(c.accelerations(), a, 1.0);
        detail::residual_here(c, r);
        read(group, k, r - r0, mass);
        c.accelerations() = a;
      }
      if (parts.damping) {
        detail::fourth_order_difference(speed_step, difference, r, [&](double s) {
          set(c.velocities(), v, s);
          detail::residual_here(c, r);
        });
        read(group, k, difference, damping);
        c.velocities() = v;
      }
      const double step = k >= dim ? 1e-3 : 1e-3 * length;
      detail::fourth_order_difference(step, difference, r, [&](double s) {
        for (const int b : group) increment[b * nv + k] = s;
        c.integrate(q, increment, c.positions());
        detail::residual_here(c, r);
      });
      read(group, k, difference, stiffness);
      increment.setZero();
      c.positions() = q;
    }
  detail::residual_here(c, r);
  const auto build = [n](const std::vector<Eigen::Triplet<double>>& entries) {
    Eigen::SparseMatrix<double> matrix(n, n);
    matrix.setFromTriplets(entries.begin(), entries.end());
    return matrix;
  };
  if (parts.mass) out.mass = build(mass);
  if (parts.damping) out.damping = build(damping);
  out.stiffness = build(stiffness);
  return out;
}

}  // namespace odyn
