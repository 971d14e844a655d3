#pragma once
// Which vectors of a sequence are linearly independent of those before them, for sparse
// vectors, at a cost that follows the fill rather than the dimension: Gaussian elimination
// that takes the vectors one at a time, in the order given. Each vector found independent
// is kept, reduced against the ones kept before it, with its largest entry as its pivot; a
// new vector is reduced by the kept ones whose pivots it touches, in the order they were
// kept (each kept vector is zero at the pivots of those before it, so one pass suffices). It
// is independent if what is left exceeds `tolerance` times its own largest entry.
//
// The assembly uses it on the rows of Phi_q (which constraint equations repeat earlier ones)
// and on its columns (which given velocity components stay free), in orders that follow the
// model's topology; there the fill stays within the reach of a few joints, and the whole
// pass is linear in the model's size.

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>
#include <vector>

namespace odyn {

class SparseBasis {
 public:
  /// Starts an empty basis of vectors with `dimension` entries.
  void reset(int dimension, double tolerance) {
    tolerance_ = tolerance;
    rank_ = nullptr;
    pivot_of_.assign(static_cast<std::size_t>(dimension), -1);
    work_.assign(static_cast<std::size_t>(dimension), 0.0);
    touched_mark_.assign(static_cast<std::size_t>(dimension), 0);
    touched_.clear();
    pivots_.clear();
    entry_index_.clear();
    entry_value_.clear();
  }

  /// Ranks the entries for the pivots of add() without a preferred range: among the entries
  /// within a factor pivot_threshold of the largest, the lowest rank wins (then the largest).
  /// None: the largest entry.
  /// `rank` (one entry per index) must outlive the basis's use.
  void rank_entries(const std::vector<int>* rank) { rank_ = rank; }

  /// Adds the vector with these nonzero entries if it is independent of those added before;
  /// returns whether it was. Its pivot, if kept, is its largest entry, or the largest in the
  /// index range [prefer_begin, prefer_end) if that one is within a factor pivot_threshold of
  /// the largest: a caller that knows where pivots cause no fill (a body's own columns) says so.
  bool add(const std::vector<int>& indices, const std::vector<double>& values, int prefer_begin = 0,
           int prefer_end = 0) {
    double scale = 0.0;
    for (std::size_t k = 0; k < indices.size(); ++k) {
      touch(indices[k]);
      work_[indices[k]] += values[k];
      scale = std::max(scale, std::abs(values[k]));
    }
    // Reduce by the kept vectors whose pivots the vector reaches, in the order they were kept.
    std::priority_queue<int, std::vector<int>, std::greater<int>> due;
    for (const int i : touched_)
      if (pivot_of_[i] >= 0) due.push(pivot_of_[i]);
    int last = -1;
    while (!due.empty()) {
      const int k = due.top();
      due.pop();
      if (k == last) continue;
      last = k;
      const Pivot& pivot = pivots_[k];
      // What rounding leaves at a pivot (where two paths of a loop cancel) is not carried on.
      const double at_pivot = work_[pivot.index];
      work_[pivot.index] = 0.0;
      if (std::abs(at_pivot) <= negligible * scale) continue;
      const double factor = at_pivot / pivot.value;
      for (int e = pivot.begin; e < pivot.end; ++e) {
        const int j = entry_index_[e];
        if (!touched_mark_[j]) {
          touch(j);
          if (pivot_of_[j] > k) due.push(pivot_of_[j]);
        }
        work_[j] -= factor * entry_value_[e];
      }
    }
    // What is left, off the kept pivots.
    int largest_index = -1;
    double largest = 0.0;
    for (const int i : touched_)
      if (pivot_of_[i] < 0 && std::abs(work_[i]) > largest) {
        largest = std::abs(work_[i]);
        largest_index = i;
      }
    last_margin_ = scale > 0.0 ? largest / scale : 0.0;
    const bool independent = scale > 0.0 && largest > tolerance_ * scale;
    if (independent) {
      double preferred = 0.0;
      int preferred_index = -1;
      for (const int i : touched_)
        if (i >= prefer_begin && i < prefer_end && pivot_of_[i] < 0 &&
            std::abs(work_[i]) > preferred) {
          preferred = std::abs(work_[i]);
          preferred_index = i;
        }
      if (preferred_index >= 0 && preferred >= pivot_threshold * largest) {
        largest_index = preferred_index;
      } else if (rank_ != nullptr) {
        const std::vector<int>& rank = *rank_;
        int best = largest_index;
        for (const int i : touched_)
          if (pivot_of_[i] < 0 && std::abs(work_[i]) >= pivot_threshold * largest &&
              (rank[i] < rank[best] ||
               (rank[i] == rank[best] && std::abs(work_[i]) > std::abs(work_[best]))))
            best = i;
        largest_index = best;
      }
      Pivot pivot{largest_index, work_[largest_index], static_cast<int>(entry_index_.size()), 0};
      // Entries below rounding are dropped: they would only spread fill.
      for (const int i : touched_)
        if (i != largest_index && pivot_of_[i] < 0 && std::abs(work_[i]) > negligible * scale) {
          entry_index_.push_back(i);
          entry_value_.push_back(work_[i]);
        }
      pivot.end = static_cast<int>(entry_index_.size());
      pivot_of_[largest_index] = static_cast<int>(pivots_.size());
      pivots_.push_back(pivot);
    }
    for (const int i : touched_) {
      work_[i] = 0.0;
      touched_mark_[i] = 0;
    }
    touched_.clear();
    return independent;
  }

  int rank() const { return static_cast<int>(pivots_.size()); }
  /// What reduction left of the last vector added, relative to its largest entry: 0 for a
  /// vector that depends on the kept ones, near 1 for one far from them.
  double last_margin() const { return last_margin_; }
  /// Entries kept for the reduced vectors (their fill).
  std::size_t stored_entries() const { return entry_index_.size(); }

 private:
  struct Pivot {
    int index;       // the entry the vector was divided by
    double value;    // its value
    int begin, end;  // its other entries in entry_index_ / entry_value_
  };

  void touch(int i) {
    if (touched_mark_[i]) return;
    touched_mark_[i] = 1;
    touched_.push_back(i);
  }

  static constexpr double negligible = 1e-15;     // relative to a vector's largest entry
  static constexpr double pivot_threshold = 0.1;  // for a preferred pivot
  double tolerance_ = 0.0;
  const std::vector<int>* rank_ = nullptr;  // see rank_entries
  double last_margin_ = 0.0;
  std::vector<int> pivot_of_;       // (dimension) the kept vector pivoting on each entry, or -1
  std::vector<double> work_;        // (dimension) the vector being reduced
  std::vector<char> touched_mark_;  // (dimension)
  std::vector<int> touched_;        // its entries that may be nonzero
  std::vector<Pivot> pivots_;       // the kept vectors, in the order they were kept
  std::vector<int> entry_index_;    // their entries, one after the other
  std::vector<double> entry_value_;
};

}  // namespace odyn
