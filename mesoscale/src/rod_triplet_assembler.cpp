// Sparse matrix from triplets with a reused pattern (see triplet_assembler.hpp).
#include "knit/meso/rod/triplet_assembler.hpp"

#include <algorithm>

namespace knit::meso::rod {

bool TripletAssembler::scatter(const std::vector<Eigen::Triplet<double>>& trip) {
  if (++pass_ == 0) {  // wrapped: no entry may look assigned in this pass
    std::fill(seen_.begin(), seen_.end(), 0u);
    pass_ = 1;
  }
  double* v = J_.valuePtr();
  const int n = n_;
  Eigen::Index assigned = 0;
  for (const auto& t : trip) {
    const int e = map_[static_cast<std::size_t>(t.row()) * n + t.col()];
    if (e < 0) return false;  // a new entry
    if (seen_[e] != pass_) {
      seen_[e] = pass_;
      v[e] = t.value();
      ++assigned;
    } else {
      v[e] += t.value();
    }
  }
  return assigned == J_.nonZeros();  // else an entry of the pattern is gone
}

void TripletAssembler::make_pattern(const std::vector<Eigen::Triplet<double>>& trip) {
  const int n = n_;
  // Forget the old pattern's entries.
  for (int c = 0; c < J_.outerSize(); ++c)
    for (int q = J_.outerIndexPtr()[c]; q < J_.outerIndexPtr()[c + 1]; ++q)
      map_[static_cast<std::size_t>(J_.innerIndexPtr()[q]) * n + c] = -1;
  // The distinct entries (map_ marks them -2 while collecting).
  rows_.clear();
  cols_.clear();
  for (const auto& t : trip) {
    int& m = map_[static_cast<std::size_t>(t.row()) * n + t.col()];
    if (m == -1) {
      m = -2;
      rows_.push_back(t.row());
      cols_.push_back(t.col());
    }
  }
  // Compressed columns with sorted rows: the entries by row (counting sort), then placed per
  // column in that order.
  const std::size_t m = rows_.size();
  count_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (const int r : rows_) ++count_[static_cast<std::size_t>(r) + 1];
  for (int i = 0; i < n; ++i) count_[i + 1] += count_[i];
  by_row_.resize(m);
  for (std::size_t k = 0; k < m; ++k) by_row_[count_[rows_[k]]++] = static_cast<int>(k);
  J_.resize(n, n);
  J_.resizeNonZeros(static_cast<Eigen::Index>(m));
  int* outer = J_.outerIndexPtr();
  int* inner = J_.innerIndexPtr();
  std::fill(outer, outer + n + 1, 0);
  for (const int c : cols_) ++outer[c + 1];
  for (int i = 0; i < n; ++i) outer[i + 1] += outer[i];
  count_.assign(outer, outer + n);  // fill cursor per column
  for (const int k : by_row_) {
    const int e = count_[cols_[k]]++;
    inner[e] = rows_[k];
    map_[static_cast<std::size_t>(rows_[k]) * n + cols_[k]] = e;
  }
  seen_.assign(m, 0u);
  pass_ = 0;
  ++pattern_builds_;
}

const Eigen::SparseMatrix<double>& TripletAssembler::build(
    const std::vector<Eigen::Triplet<double>>& trip, int n) {
  ++value_passes_;
  if (n > kMaxMapped) {
    n_ = -1;  // the map no longer describes J_
    J_.resize(n, n);
    J_.setFromTriplets(trip.begin(), trip.end());
    J_.makeCompressed();
    changed_ = true;
    ++pattern_builds_;
    return J_;
  }
  if (n != n_) {
    n_ = n;
    J_.resize(n, n);
    J_.data().clear();
    map_.assign(static_cast<std::size_t>(n) * n, -1);
    seen_.clear();
  }
  changed_ = !scatter(trip);
  if (changed_) {
    make_pattern(trip);
    scatter(trip);
  }
  return J_;
}

}  // namespace knit::meso::rod
