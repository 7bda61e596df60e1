// Multifrontal sparse L D L^T of a symmetric indefinite matrix, with pivoting (1 x 1 and 2 x 2
// pivots) and the inertia, by MUMPS (P. R. Amestoy, I. S. Duff, J. Koster, J.-Y. L'Excellent,
// "A fully asynchronous multifrontal solver using distributed dynamic scheduling", SIAM J.
// Matrix Anal. Appl. 23 (2001) 15-41; Debian libmumps-seq-dev, the sequential library).
// The adapter: MUMPS's headers are included in sparse_mumps.cpp only. Without MUMPS
// (configured with -DKNIT_WITH_MUMPS=OFF or not found) available() is false and the shell keeps
// Eigen's SimplicialLDLT.
//
// Used by ReducedTangent on the supernodal path, for the tangents the supernodal Cholesky
// refuses (indefinite: past a limit or bifurcation point, or a Newton iterate off the stable
// path). Before (session 37), Eigen's SimplicialLDLT factorized those: a column-by-column
// factorization without BLAS, 20-30 times the supernodal Cholesky's time on large patches
// (340 s against 10-20 s at 135,198 unknowns). The frontal matrices of the multifrontal method
// are dense, factorized by BLAS 3 as the supernodes are.
//
// The matrix arrives permuted already (the supernodal path's fill-reducing ordering), so the
// analysis takes it in its own order (MUMPS's ICNTL(7) = 1 with the identity). Singular: a
// null pivot, |pivot| <= 1e-14 of the (scaled) matrix's norm (null pivot detection, ICNTL(24)
// and CNTL(3)), the counterpart of ReducedTangent::kSingularPivotRatio.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

namespace knit::macro {

class MultifrontalLDLT {
 public:
  enum class Status { kOk, kSingular, kFailed };

  /// Whether MUMPS was found at configure time.
  static bool available();

  MultifrontalLDLT();
  ~MultifrontalLDLT();
  MultifrontalLDLT(const MultifrontalLDLT&) = delete;
  MultifrontalLDLT& operator=(const MultifrontalLDLT&) = delete;

  /// Symbolic analysis of the pattern of `lower` (the lower triangle of a symmetric matrix in
  /// compressed columns), taken in its own order (`own_order`, MUMPS's ICNTL(7) = 1 with the
  /// identity: a matrix permuted already) or in MUMPS's choice of a fill-reducing ordering.
  /// The values are not read. Returns false if MUMPS failed (or is absent).
  bool analyze(const Eigen::SparseMatrix<double>& lower, bool own_order);
  /// Numeric factorization P A P^T = L D L^T of a matrix with the analyzed pattern (D block
  /// diagonal with 1 x 1 and 2 x 2 blocks). `lower`'s values must stay alive until the next
  /// factorize() (MUMPS reads them in place).
  Status factorize(const Eigen::SparseMatrix<double>& lower);
  /// The number of negative eigenvalues of D, which by Sylvester's law of inertia is that of
  /// the matrix (MUMPS's INFOG(12)); null pivots are not counted.
  int negative_pivots() const;
  /// The number of null pivots of the last factorization (INFOG(28)); -1 when MUMPS found the
  /// matrix numerically singular without counting them (its error -10).
  int null_pivots() const;
  /// Frees the MUMPS instance with its factors and workspace (after a failure, so that the
  /// factorization taking over has the memory); a later analyze() starts a new one.
  void release();
  /// x = A^-1 b with the last successful factorization (NaN after a failure).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// Why the last analyze() or factorize() failed ("MUMPS error -9 (INFO(2) = ...): the
  /// workspace is too small ..."), "" after a success or a singular matrix.
  std::string failure() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace knit::macro
