// MUMPS adapter (sparse_mumps.hpp): the only file that includes MUMPS's headers.
#include "sparse_mumps.hpp"

#ifdef KNIT_HAVE_MUMPS
#include <dmumps_c.h>
#endif

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "blas_threads.hpp"

namespace knit::macro {

#ifdef KNIT_HAVE_MUMPS

namespace {

/// MUMPS's control arrays are 1-based in its documentation: ICNTL(k) is icntl[k - 1].
constexpr int icntl(int k) {
  return k - 1;
}

/// Null pivot threshold, relative to the norm of the (scaled) matrix (CNTL(3) > 0).
constexpr double kNullPivot = 1e-14;

/// MUMPS's error code INFOG(1) < 0 in words (the MUMPS 5.5 user guide, section "Error
/// diagnostics"); INFOG(2) is its detail.
std::string error_text(int code, int detail) {
  std::string what;
  switch (code) {
    case -5:
    case -7:
    case -13:
      what = "a memory allocation failed";
      break;
    case -8:
    case -9:
    case -14:
    case -15:
    case -17:
    case -20:
      what = "a workspace is too small even after enlarging it";
      break;
    case -10:
      what = "the matrix is numerically singular";
      break;
    case -19:
      what = "the memory limit was reached";
      break;
    default:
      what = "see the MUMPS user guide";
  }
  return "MUMPS error " + std::to_string(code) + " (INFOG(2) = " + std::to_string(detail) +
         "): " + what;
}

/// A workspace error that more memory relaxation (ICNTL(14)) can mend: the pivoting of an
/// indefinite matrix delays pivots, so the fronts grow past the analysis's estimate.
bool workspace_error(int code) {
  return code == -8 || code == -9 || code == -14 || code == -15 || code == -17 || code == -20;
}

}  // namespace

struct MultifrontalLDLT::Impl {
  DMUMPS_STRUC_C id{};
  std::vector<int> irn, jcn, perm;  ///< 1-based coordinates of the lower triangle; identity
  bool initialized = false, analyzed = false, factorized = false;
  int null_pivots = 0;  ///< of the last factorization; -1: numerically singular (error -10)
  std::string failure;
  Impl() {
    id.par = 1;                 // the host works (the sequential library has no other)
    id.sym = 2;                 // general symmetric: L D L^T with 1 x 1 and 2 x 2 pivots
    id.comm_fortran = -987654;  // USE_COMM_WORLD (the sequential library's dummy MPI)
    id.job = -1;
    dmumps_c(&id);
    initialized = id.infog[0] >= 0;
    if (!initialized) failure = "the initialization: " + error_text(id.infog[0], id.infog[1]);
    id.icntl[icntl(1)] = -1;  // no error, diagnostic or global output
    id.icntl[icntl(2)] = -1;
    id.icntl[icntl(3)] = -1;
    id.icntl[icntl(4)] = 0;
    id.icntl[icntl(12)] = 1;  // the usual ordering on the given pattern (no value-based 2 x 2
                              // compression: the analysis precedes the first values)
    id.icntl[icntl(24)] = 1;  // null pivot detection
    id.cntl[2] = kNullPivot;  // CNTL(3)
  }
  ~Impl() {
    if (!initialized) return;
    id.job = -2;  // frees MUMPS's factors and workspace
    dmumps_c(&id);
  }
};

bool MultifrontalLDLT::available() {
  return true;
}

// The MUMPS instance is made on first need (a ReducedTangent whose tangents stay positive
// definite never starts one) and released by release().
MultifrontalLDLT::MultifrontalLDLT() = default;
MultifrontalLDLT::~MultifrontalLDLT() = default;

void MultifrontalLDLT::release() {
  impl_.reset();
}

bool MultifrontalLDLT::analyze(const Eigen::SparseMatrix<double>& lower, bool own_order) {
  if (!impl_) impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  if (!m.initialized) return false;
  const int n = static_cast<int>(lower.cols());
  m.irn.resize(static_cast<size_t>(lower.nonZeros()));
  m.jcn.resize(m.irn.size());
  for (int j = 0; j < n; ++j)
    for (int k = lower.outerIndexPtr()[j]; k < lower.outerIndexPtr()[j + 1]; ++k) {
      m.irn[size_t(k)] = lower.innerIndexPtr()[k] + 1;
      m.jcn[size_t(k)] = j + 1;
    }
  m.perm.resize(size_t(n));
  for (int k = 0; k < n; ++k) m.perm[size_t(k)] = k + 1;
  m.id.n = n;
  m.id.nnz = static_cast<MUMPS_INT8>(lower.nonZeros());
  m.id.irn = m.irn.data();
  m.id.jcn = m.jcn.data();
  m.id.a = const_cast<double*>(lower.valuePtr());
  m.id.perm_in = m.perm.data();
  m.id.icntl[icntl(7)] = own_order ? 1 : 7;  // given (the identity), or MUMPS's choice
  m.id.job = 1;
  dmumps_c(&m.id);
  m.analyzed = m.id.infog[0] >= 0;
  m.factorized = false;
  m.failure = m.analyzed ? std::string() : error_text(m.id.infog[0], m.id.infog[1]);
  return m.analyzed;
}

MultifrontalLDLT::Status MultifrontalLDLT::factorize(const Eigen::SparseMatrix<double>& lower) {
  if (!impl_ || !impl_->analyzed) {
    if (impl_) impl_->failure = "no symbolic analysis";
    return Status::kFailed;
  }
  Impl& m = *impl_;
  m.factorized = false;
  serial_blas();
  m.id.a = const_cast<double*>(lower.valuePtr());
  m.id.job = 2;
  dmumps_c(&m.id);
  // Delayed pivots can outgrow the analysis's estimate: more relaxation, up to 8 times.
  for (int k = 0; k < 3 && workspace_error(m.id.infog[0]); ++k) {
    m.id.icntl[icntl(14)] = 2 * std::max(20, m.id.icntl[icntl(14)]);
    dmumps_c(&m.id);
  }
  if (m.id.infog[0] == -10) {
    m.failure.clear();
    m.null_pivots = -1;
    return Status::kSingular;
  }
  if (m.id.infog[0] < 0) {
    m.failure = error_text(m.id.infog[0], m.id.infog[1]);
    return Status::kFailed;
  }
  m.failure.clear();
  m.factorized = true;
  m.null_pivots = m.id.infog[27];
  return m.null_pivots > 0 ? Status::kSingular : Status::kOk;
}

int MultifrontalLDLT::negative_pivots() const {
  return impl_ && impl_->factorized ? impl_->id.infog[11] : -1;
}

int MultifrontalLDLT::null_pivots() const {
  return impl_ ? impl_->null_pivots : 0;
}

Eigen::VectorXd MultifrontalLDLT::solve(const Eigen::VectorXd& b) const {
  Eigen::VectorXd x = b;
  if (!impl_ || !impl_->factorized) {
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return x;
  }
  Impl& m = *impl_;
  m.id.rhs = x.data();
  m.id.nrhs = 1;
  m.id.lrhs = m.id.n;
  m.id.job = 3;
  dmumps_c(&m.id);
  if (m.id.infog[0] < 0) x.setConstant(std::numeric_limits<double>::quiet_NaN());
  return x;
}

std::string MultifrontalLDLT::failure() const {
  return impl_ ? impl_->failure : std::string();
}

#else  // without MUMPS: never used (available() is false)

struct MultifrontalLDLT::Impl {};
bool MultifrontalLDLT::available() {
  return false;
}
MultifrontalLDLT::MultifrontalLDLT() = default;
MultifrontalLDLT::~MultifrontalLDLT() = default;
void MultifrontalLDLT::release() {}
bool MultifrontalLDLT::analyze(const Eigen::SparseMatrix<double>&, bool) {
  return false;
}
MultifrontalLDLT::Status MultifrontalLDLT::factorize(const Eigen::SparseMatrix<double>&) {
  return Status::kFailed;
}
int MultifrontalLDLT::negative_pivots() const {
  return -1;
}
int MultifrontalLDLT::null_pivots() const {
  return 0;
}
Eigen::VectorXd MultifrontalLDLT::solve(const Eigen::VectorXd& b) const {
  return Eigen::VectorXd::Constant(b.size(), std::numeric_limits<double>::quiet_NaN());
}
std::string MultifrontalLDLT::failure() const {
  return "this build has no MUMPS";
}

#endif

}  // namespace knit::macro
