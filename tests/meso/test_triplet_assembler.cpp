// TripletAssembler (knit/meso/rod/triplet_assembler.hpp): the matrix is bitwise what Eigen's
// setFromTriplets builds, over a sequence of lists that keep, reorder, grow and shrink the set of
// entries, and the pattern is rebuilt exactly when that set changes.
#include <Eigen/SparseCore>
#include <catch2/catch.hpp>
#include <cstring>
#include <random>
#include <vector>

#include "knit/meso/rod/triplet_assembler.hpp"

using knit::meso::rod::TripletAssembler;
using Trip = Eigen::Triplet<double>;

namespace {

// Same pattern (outer and inner indices) and the same bits in every value.
bool bitwise_equal(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
  const auto nnz = static_cast<std::size_t>(a.nonZeros());
  const auto outer = static_cast<std::size_t>(a.outerSize() + 1);
  if (std::memcmp(a.outerIndexPtr(), b.outerIndexPtr(), outer * sizeof(int)) != 0) return false;
  if (nnz == 0) return true;  // the index and value arrays may be null (memcmp must not see them)
  return std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), nnz * sizeof(int)) == 0 &&
         std::memcmp(a.valuePtr(), b.valuePtr(), nnz * sizeof(double)) == 0;
}

Eigen::SparseMatrix<double> reference(const std::vector<Trip>& t, int n) {
  Eigen::SparseMatrix<double> J(n, n);
  J.setFromTriplets(t.begin(), t.end());
  J.makeCompressed();
  return J;
}

// A list of `count` triplets on `entries` random (row, col) pairs, with duplicates and values
// spread over many magnitudes (so that the summation order shows in the last bits).
std::vector<Trip> random_list(std::mt19937& g, int n, int entries, int count) {
  std::uniform_int_distribution<int> idx(0, n - 1);
  std::vector<std::pair<int, int>> rc(static_cast<std::size_t>(entries));
  for (auto& p : rc) p = {idx(g), idx(g)};
  std::uniform_int_distribution<int> pick(0, entries - 1);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> ex(-20, 20);
  std::vector<Trip> t;
  for (int k = 0; k < count; ++k) {
    const auto& p = rc[static_cast<std::size_t>(pick(g))];
    t.emplace_back(p.first, p.second, std::ldexp(mant(g), ex(g)));
  }
  return t;
}

}  // namespace

TEST_CASE("triplet assembler: bitwise setFromTriplets over changing lists", "[unit]") {
  std::mt19937 g(7);
  TripletAssembler a;
  const int n = 40;
  std::vector<Trip> t = random_list(g, n, 200, 2000);
  CHECK(bitwise_equal(a.build(t, n), reference(t, n)));
  CHECK(a.pattern_changed());

  // Same entries, new values: no new pattern.
  for (auto& x : t) x = Trip(x.row(), x.col(), 3.0 * x.value() + 1e-3);
  CHECK(bitwise_equal(a.build(t, n), reference(t, n)));
  CHECK_FALSE(a.pattern_changed());

  // Same entries in another order: the sums follow the new order, the pattern stays.
  std::shuffle(t.begin(), t.end(), g);
  CHECK(bitwise_equal(a.build(t, n), reference(t, n)));
  CHECK_FALSE(a.pattern_changed());

  // A new entry.
  t.emplace_back(n - 1, 0, 2.5);
  t.emplace_back(0, n - 1, -0.0);  // an explicit (negative) zero is an entry too
  const auto Jg = reference(t, n);
  CHECK(bitwise_equal(a.build(t, n), Jg));
  CHECK(a.pattern_changed());

  // An entry gone (every triplet of the first entry removed).
  const int r0 = t.front().row(), c0 = t.front().col();
  std::vector<Trip> fewer;
  for (const auto& x : t)
    if (x.row() != r0 || x.col() != c0) fewer.push_back(x);
  CHECK(bitwise_equal(a.build(fewer, n), reference(fewer, n)));
  CHECK(a.pattern_changed());
  CHECK(a.build(fewer, n).nonZeros() == Jg.nonZeros() - 1);

  // Another size, an empty list, and random lists in a row.
  std::vector<Trip> none;
  CHECK(bitwise_equal(a.build(none, 7), reference(none, 7)));
  for (int i = 0; i < 20; ++i) {
    const int m = 5 + i % 3;
    const auto l = random_list(g, m, 12, 30 + i);
    CHECK(bitwise_equal(a.build(l, m), reference(l, m)));
  }
}

TEST_CASE("triplet assembler: above the mapped size, then back", "[unit]") {
  std::mt19937 g(11);
  TripletAssembler a;
  const int small = 30, large = TripletAssembler::kMaxMapped + 1;
  const auto s = random_list(g, small, 80, 400);
  const auto l = random_list(g, large, 300, 900);
  CHECK(bitwise_equal(a.build(s, small), reference(s, small)));
  CHECK(bitwise_equal(a.build(l, large), reference(l, large)));
  // The small list again: the map must not be trusted after the large matrix.
  CHECK(bitwise_equal(a.build(s, small), reference(s, small)));
  CHECK(a.pattern_changed());
}
