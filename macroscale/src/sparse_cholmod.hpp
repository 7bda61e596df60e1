// Supernodal sparse Cholesky factorization of a symmetric positive definite matrix by CHOLMOD
// (SuiteSparse; T. A. Davis, Y. Chen, W. W. Hager, S. Rajamanickam, "Algorithm 887: CHOLMOD,
// supernodal sparse Cholesky factorization and update/downdate", ACM TOMS 35 (2008) 22).
// The adapter: CHOLMOD's headers are included in sparse_cholmod.cpp only. Without CHOLMOD
// (configured with -DKNIT_WITH_CHOLMOD=OFF or not found) available() is false and the shell
// uses Eigen's SimplicialLDLT.
//
// Used by ReducedTangent on the sparse symmetric path: the fill-reducing ordering (CHOLMOD's
// AMD or METIS, or the matrix's own order: the fewest flops) and the symbolic analysis
// (supernodal elimination tree) once per run, then per Newton iteration a numeric supernodal
// L L^T. An indefinite matrix (past a limit or
// bifurcation point) makes factorize() return kNotPositiveDefinite; the caller then uses an
// LDL^T that counts the negative pivots.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

namespace knit::macro {

class SupernodalCholesky {
 public:
  enum class Status { kOk, kNotPositiveDefinite, kFailed };

  /// Whether CHOLMOD was found at configure time.
  static bool available();

  SupernodalCholesky();
  ~SupernodalCholesky();
  SupernodalCholesky(const SupernodalCholesky&) = delete;
  SupernodalCholesky& operator=(const SupernodalCholesky&) = delete;

  /// The fill-reducing ordering of the pattern of `lower` (the lower triangle of a symmetric
  /// matrix in compressed columns, sorted row indices): CHOLMOD's (AMD, or METIS when AMD's
  /// fill is high) or the matrix's own order, whichever needs fewer flops, postordered. Row k
  /// of the factor is row perm[k] of the matrix. Empty if CHOLMOD failed (or is absent).
  /// `chosen`: set to the ordering taken ("natural", "AMD", "METIS").
  static std::vector<int> fill_reducing_ordering(const Eigen::SparseMatrix<double>& lower,
                                                 std::string* chosen = nullptr);
  /// Symbolic analysis of the pattern of `lower`, taken in its own order (permute it by
  /// fill_reducing_ordering() first). Returns false if CHOLMOD failed (or is absent).
  bool analyze(const Eigen::SparseMatrix<double>& lower);
  /// Numeric factorization P A P^T = L L^T of a matrix with the analyzed pattern.
  Status factorize(const Eigen::SparseMatrix<double>& lower);
  /// The pivots d_k = L_kk^2 (the D of the equivalent L D L^T), in elimination order.
  Eigen::VectorXd pivots() const;
  /// x = A^-1 b with the last successful factorization.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// Why the last analyze() or factorize() failed: CHOLMOD's status by name and in words
  /// ("CHOLMOD_TOO_LARGE: the factor's size overflows an int index"), "" after a success or
  /// an indefinite matrix (session 37: at 256 x 256 elements of degree 5 the shell fell back to
  /// Eigen's SimplicialLDLT without a word, 37 s per iteration against 6.9 s at 192 x 192).
  std::string failure() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace knit::macro
