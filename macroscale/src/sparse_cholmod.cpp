// CHOLMOD adapter (sparse_cholmod.hpp): the only file that includes CHOLMOD's headers.
#include "sparse_cholmod.hpp"

#include "blas_threads.hpp"

#ifdef KNIT_HAVE_CHOLMOD
#include <cholmod.h>
#include <dlfcn.h>
#endif

#include <algorithm>
#include <limits>
#include <string>

namespace knit::macro {

#ifdef KNIT_HAVE_CHOLMOD

namespace {

/// Debian's CHOLMOD runs a few short loops of the supernodal factorization in OpenMP parallel
/// regions with a built-in thread count (num_threads(4)); on a busy 2-core machine waking
/// those threads cost more than the loops (a 1,440-unknown run: 5.2 s CPU with them limited
/// to one thread, 5.7-6.0 s without). The BLAS calls, where the work is, are serial anyway. A
/// max-active-levels of 0 makes every parallel region of the calling thread run on that
/// thread alone. Looked up at run time: present only when CHOLMOD brought libgomp along.
void serial_openmp_regions() {
  using SetLevels = void (*)(int);
  static const auto set_levels =
      reinterpret_cast<SetLevels>(::dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
  if (set_levels) set_levels(0);
}

/// A view of Eigen's compressed lower triangle as a CHOLMOD matrix (no copy; stype -1: only
/// the lower triangle is referenced).
cholmod_sparse view(const Eigen::SparseMatrix<double>& A) {
  cholmod_sparse s{};
  s.nrow = static_cast<size_t>(A.rows());
  s.ncol = static_cast<size_t>(A.cols());
  s.nzmax = static_cast<size_t>(A.nonZeros());
  s.p = const_cast<int*>(A.outerIndexPtr());
  s.i = const_cast<int*>(A.innerIndexPtr());
  s.x = const_cast<double*>(A.valuePtr());
  s.stype = -1;
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}

}  // namespace

/// How Impl orders the matrix.
enum class Ordering {
  kCholmod,  ///< CHOLMOD's default: AMD, METIS too when AMD's fill is high; postordered
  kNatural,  ///< the matrix's own order, postordered (the elimination tree's subtrees contiguous)
  kAsIs,     ///< the matrix's own order, not postordered (a matrix permuted already)
};

namespace {
/// CHOLMOD's status (cholmod_common::status) by name and in words; "" for OK and NOT_POSDEF.
std::string status_text(int status) {
  switch (status) {
    case CHOLMOD_OK:
    case CHOLMOD_NOT_POSDEF:
      return {};
    case CHOLMOD_NOT_INSTALLED:
      return "CHOLMOD_NOT_INSTALLED: a method CHOLMOD was built without";
    case CHOLMOD_OUT_OF_MEMORY:
      return "CHOLMOD_OUT_OF_MEMORY: the factor does not fit in memory";
    case CHOLMOD_TOO_LARGE:
      return "CHOLMOD_TOO_LARGE: the factor's size overflows an int index";
    case CHOLMOD_INVALID:
      return "CHOLMOD_INVALID: invalid input";
    case CHOLMOD_DSMALL:
      return "CHOLMOD_DSMALL: a diagonal entry of the factor is tiny";
    default:
      return "CHOLMOD status " + std::to_string(status);
  }
}
}  // namespace

struct SupernodalCholesky::Impl {
  cholmod_common c{};
  cholmod_factor* L = nullptr;
  std::string failure;  ///< status_text() of the last analyze or factorize
  explicit Impl(Ordering ordering) {
    cholmod_start(&c);
    c.supernodal = CHOLMOD_SUPERNODAL;
    c.print = 0;
    c.error_handler = nullptr;
    c.quick_return_if_not_posdef = 1;
    // Relaxed supernode amalgamation: CHOLMOD's defaults are nrelax = (4, 16, 48), zrelax =
    // (0.8, 0.1, 0.05). Larger supernodes (more explicit zeros, fewer and larger BLAS calls)
    // measured faster on the strips of the bench (16 x 100, p = 4, banded order: 129 -> 64
    // supernodes, factorization 32 -> 28 ms CPU; AMD order unchanged, 37.5 -> 36.6 ms), and
    // larger still slower (32, 64, 192 / 0.9, 0.8, 0.2: 32 ms).
    c.nrelax[0] = 16, c.nrelax[1] = 32, c.nrelax[2] = 96;
    c.zrelax[0] = 0.9, c.zrelax[1] = 0.8, c.zrelax[2] = 0.1;
    if (ordering != Ordering::kCholmod) {
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_NATURAL;
      c.postorder = ordering == Ordering::kNatural;
    }
  }
  ~Impl() {
    if (L) cholmod_free_factor(&L, &c);
    cholmod_finish(&c);
  }
};

bool SupernodalCholesky::available() {
  return true;
}

std::vector<int> SupernodalCholesky::fill_reducing_ordering(
    const Eigen::SparseMatrix<double>& lower, std::string* chosen) {
  // CHOLMOD's choice (AMD or METIS: the least fill) and the matrix's own order, the one with
  // fewer flops. The shell's DOFs are numbered along the patch's rows of control points: a
  // band of ~(p + 1) rows, which for a strip meshed along its short side is the better order
  // (16 x 100 elements, p = 4: 370 Mflop against AMD's 565 and METIS's 951; 8 x 40: 32 against
  // 54); for a strip meshed along its long side (the Sze cantilever) AMD is.
  std::vector<int> best;
  double best_flops = 0.0;
  for (const Ordering o : {Ordering::kCholmod, Ordering::kNatural}) {
    Impl impl(o);
    cholmod_sparse A = view(lower);
    impl.L = cholmod_analyze(&A, &impl.c);
    if (!impl.L || impl.c.status != CHOLMOD_OK) continue;
    if (!best.empty() && !(impl.c.fl < best_flops)) continue;
    const int* perm = static_cast<const int*>(impl.L->Perm);
    best.assign(perm, perm + impl.L->n);
    best_flops = impl.c.fl;
    if (chosen) {
      const int method = impl.c.method[impl.c.selected].ordering;
      *chosen = o == Ordering::kNatural     ? "natural"
                : method == CHOLMOD_METIS   ? "METIS"
                : method == CHOLMOD_NESDIS  ? "NESDIS"
                : method == CHOLMOD_NATURAL ? "natural"
                                            : "AMD";
    }
  }
  return best;
}

SupernodalCholesky::SupernodalCholesky() : impl_(std::make_unique<Impl>(Ordering::kAsIs)) {}
SupernodalCholesky::~SupernodalCholesky() = default;

bool SupernodalCholesky::analyze(const Eigen::SparseMatrix<double>& lower) {
  if (impl_->L) cholmod_free_factor(&impl_->L, &impl_->c);
  cholmod_sparse A = view(lower);
  impl_->L = cholmod_analyze(&A, &impl_->c);
  const bool ok = impl_->L != nullptr && impl_->c.status == CHOLMOD_OK;
  impl_->failure = ok ? std::string() : status_text(impl_->c.status);
  if (!ok && impl_->failure.empty()) impl_->failure = "the symbolic analysis failed";
  return ok;
}

std::string SupernodalCholesky::failure() const {
  return impl_->failure;
}

SupernodalCholesky::Status SupernodalCholesky::factorize(const Eigen::SparseMatrix<double>& lower) {
  if (!impl_->L) {
    impl_->failure = "no symbolic analysis";
    return Status::kFailed;
  }
  serial_openmp_regions();
  serial_blas();
  cholmod_sparse A = view(lower);
  cholmod_factorize(&A, impl_->L, &impl_->c);
  impl_->failure = status_text(impl_->c.status);
  if (impl_->c.status == CHOLMOD_NOT_POSDEF) return Status::kNotPositiveDefinite;
  if (impl_->c.status != CHOLMOD_OK || !impl_->L->is_super || !impl_->L->is_ll) {
    if (impl_->failure.empty()) impl_->failure = "the factor is not a supernodal L L^T";
    return Status::kFailed;
  }
  return Status::kOk;
}

Eigen::VectorXd SupernodalCholesky::pivots() const {
  const cholmod_factor* L = impl_->L;
  Eigen::VectorXd d(static_cast<Eigen::Index>(L->n));
  const int* super = static_cast<const int*>(L->super);
  const int* pi = static_cast<const int*>(L->pi);
  const int* px = static_cast<const int*>(L->px);
  const double* x = static_cast<const double*>(L->x);
  // Supernode s: columns super[s] .. super[s+1]-1, a dense column-major block of
  // pi[s+1] - pi[s] rows starting at x + px[s], its top square the diagonal block.
  for (size_t s = 0; s < L->nsuper; ++s) {
    const int nrow = pi[s + 1] - pi[s];
    for (int k = super[s]; k < super[s + 1]; ++k) {
      const int j = k - super[s];
      const double l = x[px[s] + j + static_cast<long>(j) * nrow];
      d(k) = l * l;
    }
  }
  return d;
}

Eigen::VectorXd SupernodalCholesky::solve(const Eigen::VectorXd& b) const {
  cholmod_dense B{};
  B.nrow = static_cast<size_t>(b.size());
  B.ncol = 1;
  B.nzmax = B.nrow;
  B.d = B.nrow;
  B.x = const_cast<double*>(b.data());
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  auto& c = const_cast<cholmod_common&>(impl_->c);
  cholmod_dense* X = cholmod_solve(CHOLMOD_A, impl_->L, &B, &c);
  Eigen::VectorXd x(b.size());
  if (X) {
    std::copy_n(static_cast<const double*>(X->x), b.size(), x.data());
    cholmod_free_dense(&X, &c);
  } else {
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return x;
}

#else  // without CHOLMOD: never used (available() is false)

struct SupernodalCholesky::Impl {};
bool SupernodalCholesky::available() {
  return false;
}
SupernodalCholesky::SupernodalCholesky() = default;
SupernodalCholesky::~SupernodalCholesky() = default;
std::vector<int> SupernodalCholesky::fill_reducing_ordering(const Eigen::SparseMatrix<double>&,
                                                            std::string*) {
  return {};
}
bool SupernodalCholesky::analyze(const Eigen::SparseMatrix<double>&) {
  return false;
}
SupernodalCholesky::Status SupernodalCholesky::factorize(const Eigen::SparseMatrix<double>&) {
  return Status::kFailed;
}
Eigen::VectorXd SupernodalCholesky::pivots() const {
  return {};
}
Eigen::VectorXd SupernodalCholesky::solve(const Eigen::VectorXd& b) const {
  return Eigen::VectorXd::Constant(b.size(), std::numeric_limits<double>::quiet_NaN());
}
std::string SupernodalCholesky::failure() const {
  return "this build has no CHOLMOD";
}

#endif

}  // namespace knit::macro
