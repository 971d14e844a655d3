#pragma once
// A square sparse matrix made of dense blocks on a pattern fixed once: the shape of the
// system matrices of a multibody model, whose entries come in blocks (a body's mass block, a
// joint's Jacobian on one body, two joints' coupling in a Schur complement).
//
// Blocks are declared once (declare), then the pattern is frozen (finalize), which also builds
// the compressed-column (CSC) structure that the sparse factorizations read. Values are then
// written block by block with block<R, C>(row, col), a fixed-size map into the block's own
// storage (found by its first row and column, among the few blocks that start on that row),
// and gathered into the CSC value array in one pass: nothing is rebuilt per factorization
// and nothing allocates after finalize. With Triangle::lower only the entries on and below
// the diagonal enter the CSC structure (what a symmetric factorization reads); the blocks
// still store their full rectangle.

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <utility>
#include <vector>

#include "odyn/linalg/compressed_columns.hpp"

namespace odyn {

class BlockSparseMatrix {
 public:
  enum class Triangle { full, lower };

  /// Forgets every block; the matrix becomes `dimension` x `dimension` and empty.
  void reset(int dimension) {
    dimension_ = dimension;
    blocks_.clear();
    row_lists_.assign(static_cast<std::size_t>(dimension), {});
    data_.clear();
    finalized_ = false;
  }

  /// Declares a rows x cols block with its first entry at (row, col). Declaring the same
  /// position again with the same size is allowed (the block is shared); blocks must not
  /// otherwise overlap. Returns the block's number.
  int declare(int row, int col, int rows, int cols) {
    assert(!finalized_ && row >= 0 && col >= 0 && row + rows <= dimension_ &&
           col + cols <= dimension_);
    if (const int existing = find(row, col); existing >= 0) {
      if (blocks_[existing].rows != rows || blocks_[existing].cols != cols)
        throw std::logic_error("BlockSparseMatrix: a block redeclared with another size");
      return existing;
    }
    const int id = static_cast<int>(blocks_.size());
    blocks_.push_back(Block{row, col, rows, cols, static_cast<int>(data_.size())});
    data_.resize(data_.size() + static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
    row_lists_[static_cast<std::size_t>(row)].push_back(id);
    return id;
  }

  /// Freezes the pattern and builds the CSC structure of the whole matrix or of its lower
  /// triangle. Allocates; nothing after it does.
  void finalize(Triangle triangle) {
    triangle_ = triangle;
    // One entry per stored number that enters the structure.
    std::vector<SparseEntry> entries;
    for (const Block& b : blocks_)
      for (int j = 0; j < b.cols; ++j)
        for (int i = 0; i < b.rows; ++i)
          if (triangle == Triangle::full || b.row + i >= b.col + j)
            entries.push_back(SparseEntry{b.col + j, b.row + i, b.offset + j * b.rows + i});
    CompressedColumns csc = compress_columns(std::move(entries), dimension_);
    if (csc.has_duplicates) throw std::logic_error("BlockSparseMatrix: two blocks overlap");
    column_starts_ = std::move(csc.starts);
    row_indices_ = std::move(csc.rows);
    sources_ = std::move(csc.sources);
    values_.assign(row_indices_.size(), 0.0);
    finalized_ = true;
  }

  /// The block declared at (row, col), as a fixed-size map into its storage.
  template <int R, int C>
  Eigen::Map<Eigen::Matrix<double, R, C>> block(Eigen::Index row, Eigen::Index col) {
    const int id = find(static_cast<int>(row), static_cast<int>(col));
    assert(id >= 0 && blocks_[id].rows == R && blocks_[id].cols == C);
    return Eigen::Map<Eigen::Matrix<double, R, C>>(data_.data() + blocks_[id].offset);
  }
  /// Block number `id`, as a map of its declared size.
  Eigen::Map<Eigen::MatrixXd> block(int id) {
    const Block& b = blocks_[static_cast<std::size_t>(id)];
    return Eigen::Map<Eigen::MatrixXd>(data_.data() + b.offset, b.rows, b.cols);
  }

  void set_zero() { std::fill(data_.begin(), data_.end(), 0.0); }

  /// Copies the blocks' values into the CSC value array; returns it.
  const std::vector<double>& gather() {
    for (std::size_t k = 0; k < values_.size(); ++k) values_[k] = data_[sources_[k]];
    return values_;
  }

  int dimension() const { return dimension_; }
  int num_blocks() const { return static_cast<int>(blocks_.size()); }
  Triangle triangle() const { return triangle_; }
  /// CSC structure: column j's entries are k in [column_starts[j], column_starts[j + 1]), in
  /// rows row_indices[k], sorted.
  const std::vector<int>& column_starts() const { return column_starts_; }
  const std::vector<int>& row_indices() const { return row_indices_; }
  const std::vector<double>& values() const { return values_; }
  std::size_t num_entries() const { return row_indices_.size(); }

  /// The gathered matrix as a dense one (the whole matrix, mirrored if only the lower
  /// triangle is stored): for the rare fallbacks and for tests.
  Eigen::MatrixXd to_dense() const {
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(dimension_, dimension_);
    for (int j = 0; j < dimension_; ++j)
      for (int k = column_starts_[j]; k < column_starts_[j + 1]; ++k) {
        dense(row_indices_[k], j) = values_[k];
        if (triangle_ == Triangle::lower) dense(j, row_indices_[k]) = values_[k];
      }
    return dense;
  }

 private:
  struct Block {
    int row, col, rows, cols, offset;  // first entry, size, start in data_
  };

  int find(int row, int col) const {
    for (const int id : row_lists_[static_cast<std::size_t>(row)])
      if (blocks_[id].col == col) return id;
    return -1;
  }

  int dimension_ = 0;
  bool finalized_ = false;
  Triangle triangle_ = Triangle::full;
  std::vector<Block> blocks_;
  std::vector<std::vector<int>> row_lists_;  // (dimension) the blocks that start on each row
  std::vector<double> data_;                 // every block's values, column-major, in a row
  std::vector<int> column_starts_;           // (dimension + 1) CSC
  std::vector<int> row_indices_;             // (entries) CSC
  std::vector<int> sources_;                 // (entries) where in data_ each entry comes from
  std::vector<double> values_;               // (entries) CSC, from the last gather
};

}  // namespace odyn
