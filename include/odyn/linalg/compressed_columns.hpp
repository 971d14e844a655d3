#pragma once
// Compressed-column (CSC) structure from a list of entries: the one layout that CHOLMOD, KLU
// and Eigen's sparse matrices read. Each entry names where its value comes from, so that a
// caller can gather values into the structure without searching.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace odyn {

/// One stored number of a sparse matrix: its place, and where its value comes from.
struct SparseEntry {
  int col, row, source;
};

/// The CSC structure of `entries` for an n-column matrix: column j's entries are k in
/// [starts[j], starts[j + 1]), in rows rows[k] (sorted), with values from sources[k].
struct CompressedColumns {
  std::vector<int> starts, rows, sources;
  /// Whether two entries share a place (after sorting, neighbours).
  bool has_duplicates = false;
};

/// Sorts the entries (by column, then row) and compresses them.
inline CompressedColumns compress_columns(std::vector<SparseEntry> entries, int n) {
  std::sort(entries.begin(), entries.end(), [](const SparseEntry& a, const SparseEntry& b) {
    return a.col != b.col ? a.col < b.col : a.row < b.row;
  });
  CompressedColumns csc;
  csc.starts.assign(static_cast<std::size_t>(n) + 1, 0);
  csc.rows.resize(entries.size());
  csc.sources.resize(entries.size());
  for (std::size_t k = 0; k < entries.size(); ++k) {
    ++csc.starts[static_cast<std::size_t>(entries[k].col) + 1];
    csc.rows[k] = entries[k].row;
    csc.sources[k] = entries[k].source;
    if (k > 0 && entries[k].col == entries[k - 1].col && entries[k].row == entries[k - 1].row)
      csc.has_duplicates = true;
  }
  for (int j = 0; j < n; ++j) csc.starts[j + 1] += csc.starts[j];
  return csc;
}

}  // namespace odyn
