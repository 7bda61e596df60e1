// Sparse matrix from a triplet list, bitwise what Eigen's setFromTriplets builds, at the cost
// of one pass over the list while the set of entries is unchanged.
//
// The rod and cell Jacobians are assembled as triplet lists about ten times longer than the
// matrix has entries (the cell at 5.5 mm: 252,000 triplets for 24,800 entries of a 468 x 468
// matrix): every collocation row and every contact pair adds its own block. setFromTriplets
// sorts the whole list every Newton iteration, while contact changes the set of entries only now
// and then. TripletAssembler keeps the compressed pattern and, for small matrices, a dense
// (row, column) -> entry map: an iteration with the same entries (in any order) is one pass over
// the list. Duplicates are summed in list order, the first assigned, as setFromTriplets sums
// them, and the pattern holds the entries of the list and no others (rows sorted in each
// column), so the matrix is bitwise the same and the solver's result unchanged.
#pragma once

#include <Eigen/SparseCore>
#include <cstdint>
#include <vector>

namespace knit::meso::rod {

class TripletAssembler {
 public:
  /// Largest n with the dense entry map (n^2 ints, 64 MB); larger matrices use setFromTriplets.
  static constexpr int kMaxMapped = 4096;

  /// The n x n matrix of the triplets (compressed). Valid until the next call.
  const Eigen::SparseMatrix<double>& build(const std::vector<Eigen::Triplet<double>>& trip, int n);

  /// Whether the last build() changed the pattern (a new symbolic analysis is due).
  bool pattern_changed() const { return changed_; }

  long pattern_builds() const { return pattern_builds_; }
  long value_passes() const { return value_passes_; }

 private:
  bool scatter(const std::vector<Eigen::Triplet<double>>& trip);
  void make_pattern(const std::vector<Eigen::Triplet<double>>& trip);

  Eigen::SparseMatrix<double> J_;
  int n_ = -1;
  std::vector<int> map_;             // row * n + col -> entry, -1 if not in the pattern
  std::vector<std::uint32_t> seen_;  // per entry: the pass that last assigned it
  std::uint32_t pass_ = 0;
  std::vector<int> rows_, cols_, count_, by_row_;  // scratch of make_pattern
  bool changed_ = true;
  long pattern_builds_ = 0, value_passes_ = 0;
};

}  // namespace knit::meso::rod
