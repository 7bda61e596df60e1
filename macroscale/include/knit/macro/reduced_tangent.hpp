// The reduced tangent Z^T K Z of the shell (constraints.hpp) and its factorization, for the
// Newton iterations of newton.hpp.
//
// Built once per run: the element-to-free-DOF scatter map (one integer per entry of every
// element tangent: where it goes in the value array of the reduced matrix, or -1), and on the
// sparse path the compressed-column pattern and the symbolic analysis (fill-reducing ordering,
// elimination tree). Every Newton iteration then only scatters the element tangents into the
// values (one routine for the dense and the sparse storage) and refactorizes numerically.
//
// Four factorizations:
//   unsymmetric (a material that is not hyperelastic, e.g. the eq. 17 response surface):
//     dense PartialPivLU, sparse SparseLU (COLAMD ordering);
//   symmetric (a hyperelastic material: C = d2W/dE2, the shell tangent is a Hessian):
//     only the lower triangle is assembled; dense LDLT (diagonal pivoting), sparse: the
//     supernodal Cholesky L L^T of CHOLMOD (sparse_cholmod.hpp; ordering by CHOLMOD, AMD or
//     METIS) while the tangent is positive definite; when it is not (the Cholesky stops at the
//     first non-positive pivot) MUMPS's multifrontal LDLT with 1 x 1 and 2 x 2 pivots
//     (sparse_mumps.hpp; since session 38), or without MUMPS, or once it failed in a run,
//     Eigen's SimplicialLDLT (AMD ordering), which is also the path without CHOLMOD. The
//     inertia of the reduced tangent is the number of negative entries of D (Sylvester's law of
//     inertia: P K P^T = L D L^T is a congruence): a negative count means the equilibrium is
//     unstable (past a limit or bifurcation point).
// Singularity is detected from the factorization's pivots (min |pivot| / max |pivot| below
// kSingularPivotRatio; MUMPS: a null pivot, |pivot| <= 1e-14 of the scaled matrix's norm), not
// from a condition estimate (which cost 11 % of a run).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "knit/macro/constraints.hpp"
#include "knit/macro/shell_model.hpp"

namespace knit::macro {

enum class LinearSolver {
  kAuto,    ///< dense up to SolverOptions::dense_limit unknowns, sparse above
  kDense,   ///< dense LU / LDLT
  kSparse,  ///< sparse LU / LDLT
};

struct Factorization {
  bool ok = false;
  std::string why;  ///< why the factorization is unusable (singular)
  /// Number of negative pivots of D (LDLT): the number of negative eigenvalues of the reduced
  /// tangent. -1 on the LU paths (not available).
  int negative_pivots = -1;
  /// Sign of the determinant of the reduced tangent (+1 or -1; 0 when singular). On the LDLT
  /// paths (-1)^negative_pivots; on the LU paths the product of the signs of U's diagonal and
  /// of the permutations: det K < 0 means an odd number of negative real eigenvalues, the one
  /// stability indicator an LU gives (it cannot tell 0 from 2 negative eigenvalues).
  int determinant_sign = 0;
  double pivot_ratio = 0.0;  ///< min |pivot| / max |pivot|
  /// Which factorization was made ("supernodal Cholesky", "sparse LDLT", ...): the sparse
  /// LDLT on the supernodal path means an indefinite tangent (or a CHOLMOD failure).
  const char* method = "";
};

class ReducedTangent : public ElementTangentSink {
 public:
  /// Pivot ratio below which the tangent counts as singular. Round-off leaves a pivot of
  /// ~1e-16 max|pivot| on an exactly singular matrix; the thinnest shells here (h/L = 1e-2)
  /// keep ratios above 1e-10.
  static constexpr double kSingularPivotRatio = 1e-14;

  /// `symmetric`: assemble the lower triangle only and factorize by LDLT (the element
  /// tangents must be symmetric). `sparse`: sparse storage and factorization.
  /// `supernodal` (sparse symmetric only): try CHOLMOD's supernodal Cholesky first (ignored
  /// when the build has no CHOLMOD); `multifrontal` (with `supernodal`): the tangents it
  /// refuses go to MUMPS's multifrontal LDLT (ignored when the build has no MUMPS), else to the
  /// SimplicialLDLT.
  ReducedTangent(const ShellModel& model, const DofMap& dofs, bool symmetric, bool sparse,
                 bool supernodal = true, bool multifrontal = true);
  ~ReducedTangent() override;
  ReducedTangent(const ReducedTangent&) = delete;
  ReducedTangent& operator=(const ReducedTangent&) = delete;

  int size() const { return n_; }
  bool symmetric() const { return symmetric_; }
  bool sparse() const { return sparse_; }
  /// Whether the sparse symmetric path factorizes by the supernodal Cholesky (with the
  /// SimplicialLDLT as the fallback for indefinite tangents).
  bool supernodal() const { return supernodal_; }
  /// The supernodal path's fill-reducing ordering ("natural": the DOF order, "AMD", "METIS";
  /// SupernodalCholesky::fill_reducing_ordering takes the one with the fewest flops); empty on
  /// the other paths.
  const std::string& ordering() const { return ordering_; }
  /// Why the supernodal Cholesky could not be used where it was wanted (the symbolic analysis
  /// or a factorization failed in CHOLMOD, not an indefinite tangent): the first reason, ""
  /// if none; and how many factorizations the SimplicialLDLT made instead.
  const std::string& supernodal_failure() const { return supernodal_failure_; }
  long fallback_factorizations() const { return fallback_factorizations_; }
  /// Whether the tangents the supernodal Cholesky refuses go to MUMPS's multifrontal LDLT
  /// (the build has MUMPS, and it has not failed in this run), not to the SimplicialLDLT.
  bool multifrontal() const { return multifrontal_; }
  /// Why MUMPS failed in this run ("" if it did not); the SimplicialLDLT took over from there.
  const std::string& multifrontal_failure() const { return multifrontal_failure_; }
  /// Factorizations made by the multifrontal LDLT in this run.
  long multifrontal_factorizations() const { return multifrontal_factorizations_; }
  /// Whether the build has the multifrontal LDLT (MUMPS found at configure time).
  static bool multifrontal_available();
  /// Whether the build has the supernodal Cholesky (CHOLMOD found at configure time).
  static bool supernodal_available();
  /// Stored entries of the reduced matrix (n^2 dense, the pattern's non-zeros sparse).
  long stored_entries() const;

  /// Scatters the element tangents into the reduced matrix (values reset first), on the
  /// model's assembly threads (ShellModel::assembly_threads() when this was built), split as
  /// the direct assembly below (each thread its elements' entries, the ones to values of an
  /// earlier thread's elements held back and added after): every value is summed in element
  /// order, so the matrix is bitwise the same for any number of threads. The one scatter of
  /// the dense and sparse paths.
  void assemble(const std::vector<Eigen::MatrixXd>& Ke);
  /// Threads of assemble().
  int scatter_threads() const { return threads_; }

  /// Assembly straight from the element kernel (no element tangents stored): begin_assembly()
  /// zeroes the values, `model`.evaluate(u, true, ev, false, this) (or tangent_from) scatters
  /// each element tangent where the kernel leaves it (element(), on the assembly thread that
  /// computed it), end_assembly() adds the entries held back. Thread t adds an entry directly
  /// when no element of an earlier thread touches its value, and holds it back otherwise; the
  /// held-back ones are added after the threads joined, in thread, element and entry order. So
  /// every value is summed in element order, as by assemble(): the matrix is bitwise the same
  /// (tested). `model` must use the assembly threads it had when this was built (else
  /// std::logic_error).
  void begin_assembly(const ShellModel& model);
  /// (map nullptr: kt is the element tangent itself, column-major.)
  void element(int e, int thread, const double* kt, const int* map) override;
  void end_assembly();
  /// Numeric factorization of the assembled matrix (the symbolic analysis is reused).
  Factorization factorize();
  /// Solves with the last successful factorization.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// y = K x with the assembled matrix (both triangles on the symmetric path).
  Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;

 private:
  void analyze_ldlt();  ///< symbolic analysis of the SimplicialLDLT (once, when first needed)
  /// The multifrontal LDLT (MUMPS) of the assembled matrix, the symbolic analysis on first
  /// need. False if MUMPS failed (multifrontal_failure_ says where; the SimplicialLDLT then
  /// takes this and every later factorization), else `f` is the factorization's verdict.
  bool factorize_multifrontal(Factorization& f);
  /// The compressed-column pattern of the reduced matrix and the scatter map, from the
  /// (stored) index g of every local DOF of every element (nd per element, -1 if constrained).
  void build_pattern(const std::vector<int>& g, int nd);
  /// Solve in the stored order.
  Eigen::VectorXd solve_stored(const Eigen::VectorXd& b) const;

  int n_ = 0;
  bool symmetric_ = false, sparse_ = false, supernodal_ = false;
  /// The indefinite tangents of the supernodal path go to MUMPS's multifrontal LDLT (while
  /// it works) rather than to the SimplicialLDLT.
  bool multifrontal_ = false;
  int block_ = 0;         ///< entries of one element tangent, (3 nloc)^2
  std::vector<int> map_;  ///< block_ entries per element: value index or -1 (construction only)
  int threads_ = 1;
  /// map_ -> the scatter's entries below, without the -1 entries (half of them on the
  /// symmetric path), for the element split of threads_ threads (then frees map_).
  void compact_map(long values);
  /// The direct scatter (begin_assembly): element e's entries [direct_begin_[e],
  /// direct_begin_[e + 1]) add its tangent's entry direct_src_[i] (r + nd s) to
  /// values[direct_dst_[i]]; its held-back entries [held_begin_[e], held_begin_[e + 1]) are
  /// copied to held_[i] and added to values[held_dst_[i]] by end_assembly().
  std::vector<size_t> direct_begin_, held_begin_;
  std::vector<int> direct_src_, direct_dst_, held_src_, held_dst_;
  std::vector<double> held_;
  double* values();
  void zero_values();
  /// Supernodal path: stored row/column k of the sparse matrix is unknown perm_[k] (CHOLMOD's
  /// fill-reducing ordering); empty: the natural order.
  std::vector<int> perm_;
  std::string ordering_;
  std::string supernodal_failure_;
  std::string multifrontal_failure_;
  long multifrontal_factorizations_ = 0;
  long fallback_factorizations_ = 0;
  Eigen::MatrixXd dense_;
  Eigen::SparseMatrix<double> sparse_matrix_;
  struct Factors;  ///< the Eigen factorizations and the Cholesky (reduced_tangent.cpp)
  std::unique_ptr<Factors> f_;
};

}  // namespace knit::macro
