#pragma once
// The assembly's linear algebra for large models, at a cost linear in the model's size: Phi_q
// as sparse rows, which rows repeat earlier ones (linalg/sparse_basis.hpp), which given
// velocity components can be kept, and the saddle-point solves of the assembly's three
// stages by a sparse LU. analysis/assembly.hpp chooses between these and its dense
// counterparts (which small models keep, with their numbers unchanged).
//
// Which velocity components can be kept. The dense assembly keeps the given components one
// by one, in order, while each stays independent of the constraint rows and of the
// components kept before it. In matroid terms it builds a greedy independent set of the
// unit rows e_i over the row space of Phi_q; its complement among the given components, the
// ones left free, is then a greedy basis, in the reverse order, of the columns of Phi_q
// after those of the components not given (the dual matroid's greedy set is the complement of
// the primal's, taken in the reverse order). So the columns of Phi_q are taken one at a time:
// first the components not given, then the given ones from the last to the first; a given
// component whose column is independent of those before it stays free (it is adjusted), the
// others are kept. Same decisions as the dense assembly, on vectors of the size of one
// joint's rows instead of whole matrices.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <utility>
#include <vector>

#include "odyn/analysis/system.hpp"
#include "odyn/linalg/rank_revealing_qr.hpp"
#include "odyn/linalg/sparse_basis.hpp"
#include "odyn/linalg/sparse_lu.hpp"

namespace odyn::detail {

/// Phi_q by rows: row r's entries are k in [starts[r], starts[r + 1]).
struct SparseRows {
  int num_columns = 0;
  std::vector<int> starts;
  std::vector<int> columns;
  std::vector<double> values;
  int num_rows() const { return static_cast<int>(starts.size()) - 1; }
};

/// Phi_q from the Jacobian blocks of the last evaluate_constraints, into `rows`, whose vectors
/// keep their memory from one call to the next (a kinematic analysis's Newton iterations).
template <class Model>
void sparse_jacobian(const Model& model, const Workspace<Model>& ws, SparseRows& rows) {
  constexpr int nv = Model::nv;
  const int m = model.num_equations();
  rows.num_columns = model.num_velocities();
  rows.starts.assign(static_cast<std::size_t>(m) + 1, 0);
  for_each_jacobian_block(model, ws, [&](int row, int, const auto& block) {
    for (int i = 0; i < static_cast<int>(block.rows()); ++i) rows.starts[row + i + 1] += nv;
  });
  for (int r = 0; r < m; ++r) rows.starts[r + 1] += rows.starts[r];
  rows.columns.resize(static_cast<std::size_t>(rows.starts[m]));
  rows.values.resize(rows.columns.size());
  std::vector<int> next(rows.starts.begin(), rows.starts.end() - 1);
  for_each_jacobian_block(model, ws, [&](int row, int column, const auto& block) {
    for (int i = 0; i < static_cast<int>(block.rows()); ++i)
      for (int j = 0; j < nv; ++j) {
        const int k = next[row + i]++;
        rows.columns[k] = column + j;
        rows.values[k] = block(i, j);
      }
  });
}

template <class Model>
SparseRows sparse_jacobian(const Model& model, const Workspace<Model>& ws) {
  SparseRows rows;
  sparse_jacobian(model, ws, rows);
  return rows;
}

/// For each row of Phi_q: false if it repeats others. The rows are eliminated in an order
/// taken from the model's topology, so that the fill stays within each loop whatever the pose
/// (in row order, pivoting on the largest entries, it grew as N^2 on a turned rope). The
/// joints form a graph on the bodies, the ground one of them; those that first reach a body,
/// in the order they were added, form a spanning forest, rooted at the ground. Its joints come
/// first, from the leaves to the roots, each row pivoting on its child body's columns: no row
/// then touches a pivot of those before it, and nothing fills in. The joints that close loops
/// come last, in the order they were added: reduced by the tree's rows, a loop row's entries
/// run along both paths from its bodies up the tree and cancel where the paths meet (rigid
/// motion leaves a joint's equations unchanged), so its fill is its loop's path, and it
/// pivots on the body of that path nearest the root. The rows
/// named dependent are those of the loop joints that repeat others: of two coaxial hinges
/// between the same bodies, the one added later.
/// The order of independent_rows, from the model's topology alone: built once per model.
struct RowOrder {
  struct Rows {
    int first, count;            // an element's rows
    int pivot_begin, pivot_end;  // the columns its rows prefer as pivots (empty: none)
  };
  std::vector<Rows> elements;     // in elimination order
  std::vector<int> column_depth;  // the depth in the tree of each column's body
};

template <class Model>
RowOrder row_order(const Model& model) {
  constexpr int nv = Model::nv;
  struct Edge {
    int row, equations, a, b;  // first row, rows, and its two bodies (0: the ground)
  };
  std::vector<Edge> edges;
  model.for_each_pool([&]<class E>(const std::vector<E>& pool, auto) {
    if constexpr (Constraint<E>) {
      const auto& offsets = model.template rows<E>();
      for (std::size_t i = 0; i < pool.size(); ++i) {
        const auto& bodies = pool[i].bodies();
        const int a = bodies.size() > 0 ? bodies[0].index : 0;
        const int b = bodies.size() > 1 ? bodies[1].index : 0;
        // An element on more than two bodies closes whatever it joins: a loop joint.
        edges.push_back({offsets[i], E::num_equations, a, bodies.size() > 2 ? -1 : b});
      }
    }
  });
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.row < y.row; });
  // The spanning forest (union-find), then each body's depth and tree joint from the roots.
  const int nodes = model.num_bodies() + 1;
  std::vector<int> root(static_cast<std::size_t>(nodes));
  for (int k = 0; k < nodes; ++k) root[k] = k;
  const auto find = [&](int k) {
    while (root[k] != k) k = root[k] = root[root[k]];
    return k;
  };
  std::vector<char> in_tree(edges.size(), 0);
  std::vector<std::vector<std::pair<int, int>>> neighbours(static_cast<std::size_t>(nodes));
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const Edge& edge = edges[e];
    if (edge.b < 0 || edge.a == edge.b || find(edge.a) == find(edge.b)) continue;
    root[find(edge.a)] = find(edge.b);
    in_tree[e] = 1;
    neighbours[edge.a].push_back({edge.b, static_cast<int>(e)});
    neighbours[edge.b].push_back({edge.a, static_cast<int>(e)});
  }
  std::vector<int> depth(static_cast<std::size_t>(nodes), -1), child(edges.size(), 0);
  std::vector<int> queue;
  for (int start = 0; start < nodes; ++start) {
    if (depth[start] >= 0) continue;
    depth[start] = 0;
    queue.assign(1, start);
    for (std::size_t next = 0; next < queue.size(); ++next)
      for (const auto& [other, e] : neighbours[queue[next]])
        if (depth[other] < 0) {
          depth[other] = depth[queue[next]] + 1;
          child[e] = other;
          queue.push_back(other);
        }
  }
  // The tree's joints by their child's depth, deepest first; then the loop joints.
  std::vector<int> order;
  for (std::size_t e = 0; e < edges.size(); ++e)
    if (in_tree[e]) order.push_back(static_cast<int>(e));
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return depth[child[x]] > depth[child[y]]; });
  for (std::size_t e = 0; e < edges.size(); ++e)
    if (!in_tree[e]) order.push_back(static_cast<int>(e));

  RowOrder out;
  for (const int e : order) {
    const int body = in_tree[e] ? child[e] : 0;  // the preferred pivots: its columns
    const int begin = body > 0 ? (body - 1) * nv : 0, end = body > 0 ? begin + nv : 0;
    out.elements.push_back({edges[e].row, edges[e].equations, begin, end});
  }
  // A loop row pivots where its path is nearest the root: the loops further down, whose paths
  // start there, then do not reach its pivots.
  out.column_depth.resize(static_cast<std::size_t>(model.num_velocities()));
  for (int column = 0; column < model.num_velocities(); ++column)
    out.column_depth[column] = depth[column / nv + 1];
  return out;
}

/// independent_rows in a given order. `fill`, if given, receives the entries the elimination
/// stored (its memory, for the tests); `margins`, if given, each row's margin from depending
/// on the rows before it in that order (SparseBasis::last_margin).
inline std::vector<char> independent_rows(const RowOrder& order, const SparseRows& rows,
                                          double tolerance, std::size_t* fill = nullptr,
                                          std::vector<double>* margins = nullptr) {
  SparseBasis basis;
  basis.reset(rows.num_columns, tolerance);
  basis.rank_entries(&order.column_depth);
  std::vector<char> independent(static_cast<std::size_t>(rows.num_rows()), 0);
  if (margins != nullptr) margins->assign(independent.size(), 0.0);
  std::vector<int> indices;
  std::vector<double> values;
  for (const RowOrder::Rows& element : order.elements)
    for (int r = element.first; r < element.first + element.count; ++r) {
      indices.assign(rows.columns.begin() + rows.starts[r],
                     rows.columns.begin() + rows.starts[r + 1]);
      values.assign(rows.values.begin() + rows.starts[r], rows.values.begin() + rows.starts[r + 1]);
      independent[r] = basis.add(indices, values, element.pivot_begin, element.pivot_end) ? 1 : 0;
      if (margins != nullptr) (*margins)[r] = basis.last_margin();
    }
  if (fill != nullptr) *fill = basis.stored_entries();
  return independent;
}

template <class Model>
std::vector<char> independent_rows(const Model& model, const SparseRows& rows, double tolerance,
                                   std::size_t* fill = nullptr) {
  return independent_rows(row_order(model), rows, tolerance, fill);
}

/// Which given velocity components (indices into v, in the order the dense assembly takes
/// them) can be kept with the independent rows of Phi_q; see the top of this file.
inline std::vector<char> keepable_components(const SparseRows& rows,
                                             const std::vector<char>& independent_row,
                                             const std::vector<int>& given) {
  if (given.empty()) return {};
  const int n = rows.num_columns;
  // Phi_q's independent rows by columns.
  std::vector<int> column_starts(static_cast<std::size_t>(n) + 1, 0);
  for (int r = 0; r < rows.num_rows(); ++r)
    if (independent_row[r])
      for (int k = rows.starts[r]; k < rows.starts[r + 1]; ++k)
        ++column_starts[rows.columns[k] + 1];
  for (int j = 0; j < n; ++j) column_starts[j + 1] += column_starts[j];
  std::vector<int> row_of(static_cast<std::size_t>(column_starts[n]));
  std::vector<double> value_of(row_of.size());
  std::vector<int> next(column_starts.begin(), column_starts.end() - 1);
  for (int r = 0; r < rows.num_rows(); ++r)
    if (independent_row[r])
      for (int k = rows.starts[r]; k < rows.starts[r + 1]; ++k) {
        const int at = next[rows.columns[k]]++;
        row_of[at] = r;
        value_of[at] = rows.values[k];
      }
  SparseBasis basis;
  basis.reset(rows.num_rows(), rank_tolerance);
  std::vector<int> indices;
  std::vector<double> values;
  const auto add_column = [&](int j) {
    indices.assign(row_of.begin() + column_starts[j], row_of.begin() + column_starts[j + 1]);
    values.assign(value_of.begin() + column_starts[j], value_of.begin() + column_starts[j + 1]);
    return basis.add(indices, values);
  };
  std::vector<char> is_given(static_cast<std::size_t>(n), 0);
  for (const int j : given) is_given[j] = 1;
  // The components not given only span what the given ones are tested against, so their order
  // is free: the last first, like the given ones, which on a model built from its root outwards
  // (a tree numbered breadth first) eliminates from the leaves and keeps the fill local.
  for (int j = n; j-- > 0;)
    if (!is_given[j]) add_column(j);
  std::vector<char> keep(given.size(), 0);
  for (std::size_t k = given.size(); k-- > 0;) keep[k] = add_column(given[k]) ? 0 : 1;
  return keep;
}

/// Solves [D R^T; R 0] [x; y] = [f; g] by a sparse LU, where D is block diagonal (one
/// nv x nv block per body) and R holds the rows of Phi_q marked in `use_row` followed by the
/// unit rows e_i of `unit_rows`; y has one entry per row of R. False if the matrix is
/// singular.
template <int nv, class Blocks>
bool solve_sparse_saddle_point(const Blocks& diagonal_blocks, const SparseRows& rows,
                               const std::vector<char>& use_row, const std::vector<int>& unit_rows,
                               const Eigen::VectorXd& f, const Eigen::VectorXd& g,
                               Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const int n = rows.num_columns;
  std::vector<Eigen::Triplet<double, int>> entries;
  for (int b = 0; b < n / nv; ++b) {
    const auto block = diagonal_blocks(b);
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nv; ++i)
        if (block(i, j) != 0.0) entries.emplace_back(b * nv + i, b * nv + j, block(i, j));
  }
  int r_size = 0;
  for (int r = 0; r < rows.num_rows(); ++r) {
    if (!use_row[r]) continue;
    for (int k = rows.starts[r]; k < rows.starts[r + 1]; ++k) {
      entries.emplace_back(n + r_size, rows.columns[k], rows.values[k]);
      entries.emplace_back(rows.columns[k], n + r_size, rows.values[k]);
    }
    ++r_size;
  }
  for (const int i : unit_rows) {
    entries.emplace_back(n + r_size, i, 1.0);
    entries.emplace_back(i, n + r_size, 1.0);
    ++r_size;
  }
  const int size = n + r_size;
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> matrix(size, size);
  matrix.setFromTriplets(entries.begin(), entries.end());
  matrix.makeCompressed();
  const std::vector<int> starts(matrix.outerIndexPtr(), matrix.outerIndexPtr() + size + 1);
  const std::vector<int> row_indices(matrix.innerIndexPtr(),
                                     matrix.innerIndexPtr() + matrix.nonZeros());
  const std::vector<double> values(matrix.valuePtr(), matrix.valuePtr() + matrix.nonZeros());
  SparseLu lu;
  lu.analyze(size, starts, row_indices);
  // The rows are independent (the rank pass chose them): only rounding counts as singular.
  if (!lu.factorize(values, SparseLu::independent_rows_ratio)) return false;
  Eigen::VectorXd solution(size);
  solution << f, g;
  lu.solve_in_place(solution);
  if (!solution.allFinite()) return false;
  x = solution.head(n);
  y = solution.tail(r_size);
  return true;
}

}  // namespace odyn::detail
