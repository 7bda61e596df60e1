#include "knit/macro/reduced_tangent.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "knit/macro/thread_pool.hpp"
#include "sparse_cholmod.hpp"
#include "sparse_mumps.hpp"

namespace knit::macro {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

/// SparseLU with access to the diagonal of U (stored in the supernodes of L, as in
/// Eigen::SparseLU::absDeterminant()), for the pivot-based singularity check.
class PivotedSparseLU : public Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> {
 public:
  /// (min |u_jj|, max |u_jj|).
  std::pair<double, double> pivot_range() const {
    double lo = INFINITY, hi = 0.0;
    for (Eigen::Index j = 0; j < cols(); ++j) {
      double d = 0.0;
      for (SCMatrix::InnerIterator it(m_Lstore, j); it; ++it)
        if (it.index() == j) {
          d = std::abs(it.value());
          break;
        }
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    return {lo, hi};
  }
};

/// The sign of det K from the number of negative pivots of an LDLT (det K = det D: Sylvester).
int sign_of_inertia(int negative_pivots) {
  return negative_pivots % 2 ? -1 : 1;
}

/// Fills in the pivot ratio and the singularity verdict from the pivots d.
template <typename Vec>
Factorization from_pivots(const Vec& d, bool count_negative, const char* kind) {
  Factorization f;
  f.method = kind;
  const double hi = d.size() ? d.cwiseAbs().maxCoeff() : 0.0;
  const double lo = d.size() ? d.cwiseAbs().minCoeff() : 0.0;
  f.pivot_ratio = hi > 0.0 ? lo / hi : 0.0;
  if (count_negative) {
    f.negative_pivots = static_cast<int>((d.array() < 0.0).count());
    f.determinant_sign = sign_of_inertia(f.negative_pivots);
  }
  if (!(f.pivot_ratio > ReducedTangent::kSingularPivotRatio) || !d.allFinite()) {
    std::ostringstream o;
    o << "singular tangent stiffness (" << kind << ": smallest / largest pivot " << f.pivot_ratio
      << ")";
    f.why = o.str();
    return f;
  }
  f.ok = true;
  return f;
}

}  // namespace

struct ReducedTangent::Factors {
  Eigen::PartialPivLU<Eigen::MatrixXd> dense_lu;
  Eigen::LDLT<Eigen::MatrixXd, Eigen::Lower> dense_ldlt;
  PivotedSparseLU sparse_lu;
  Eigen::SimplicialLDLT<SpMat, Eigen::Lower> sparse_ldlt;
  bool ldlt_analyzed = false;
  SupernodalCholesky cholesky;
  bool cholesky_active = false;  ///< the last factorization was the supernodal Cholesky
  MultifrontalLDLT multifrontal;
  bool multifrontal_analyzed = false;
  bool multifrontal_active = false;  ///< the last factorization was the multifrontal LDLT
};

ReducedTangent::ReducedTangent(const ShellModel& m, const DofMap& dofs, bool symmetric, bool sparse,
                               bool supernodal, bool multifrontal)
    : n_(dofs.num_free()),
      symmetric_(symmetric),
      sparse_(sparse),
      supernodal_(symmetric && sparse && supernodal && SupernodalCholesky::available()),
      // Behind the supernodal Cholesky only (a build without CHOLMOD keeps the SimplicialLDLT
      // throughout, as docs/solver.md says).
      multifrontal_(supernodal_ && multifrontal && MultifrontalLDLT::available()),
      threads_(m.assembly_threads()),
      f_(std::make_unique<Factors>()) {
  const int ne = m.num_elements();
  const int nd =
      m.num_elements() > 0 ? 3 * static_cast<int>(m.element_control_points(0).size()) : 0;
  block_ = nd * nd;
  // Free index of each local DOF of each element.
  std::vector<int> g(static_cast<size_t>(ne) * nd);
  for (int e = 0; e < ne; ++e) {
    const Eigen::VectorXi& cp = m.element_control_points(e);
    for (int r = 0; r < nd; ++r) g[size_t(e) * nd + r] = dofs.free_index(3 * cp(r / 3) + r % 3);
  }
  auto wanted = [&](int gr, int gs) { return gr >= 0 && gs >= 0 && (!symmetric_ || gr >= gs); };
  map_.assign(static_cast<size_t>(ne) * block_, -1);
  if (!sparse_) {
    // Column-major n x n: entry (gr, gs) at gr + n gs.
    if (static_cast<double>(n_) * n_ > 2.0e9)
      throw std::invalid_argument("dense reduced tangent of " + std::to_string(n_) +
                                  " unknowns does not fit an int index");
    dense_.setZero(n_, n_);
    for (int e = 0; e < ne; ++e)
      for (int s = 0; s < nd; ++s)
        for (int r = 0; r < nd; ++r) {
          const int gr = g[size_t(e) * nd + r], gs = g[size_t(e) * nd + s];
          if (wanted(gr, gs)) map_[size_t(e) * block_ + r + size_t(nd) * s] = gr + n_ * gs;
        }
    compact_map(static_cast<long>(n_) * n_);
    return;
  }
  build_pattern(g, nd);
  if (supernodal_) {
    // CHOLMOD's fill-reducing ordering, then the pattern and the scatter map rebuilt in that
    // order: the Cholesky then takes the lower triangle as it is (natural ordering), without
    // the permuted transpose it would otherwise form at every factorization.
    perm_ = SupernodalCholesky::fill_reducing_ordering(sparse_matrix_, &ordering_);
    if (static_cast<int>(perm_.size()) == n_) {
      std::vector<int> inv(n_);
      for (int k = 0; k < n_; ++k) inv[perm_[k]] = k;
      for (int& x : g)
        if (x >= 0) x = inv[x];
      build_pattern(g, nd);
    } else {
      perm_.clear();
      ordering_ = "natural";
    }
  }
  // Symbolic analysis, once per run (the LDLT's only when the Cholesky needs a fallback).
  if (supernodal_ && n_ > 0 && !f_->cholesky.analyze(sparse_matrix_)) {
    supernodal_ = false;
    supernodal_failure_ = "the symbolic analysis: " + f_->cholesky.failure();
  }
  if (!symmetric_)
    f_->sparse_lu.analyzePattern(sparse_matrix_);
  else if (!supernodal_)
    analyze_ldlt();
  compact_map(sparse_matrix_.nonZeros());
}

void ReducedTangent::compact_map(long values) {
  const size_t ne = block_ > 0 ? map_.size() / static_cast<size_t>(block_) : 0;
  const int T = std::max(1, threads_);
  // The direct scatter: the first thread whose elements touch each value; an entry of a
  // later thread to that value is held back.
  {
    std::vector<int> first(values, T);
    for (int t = 0; t < T; ++t) {
      const auto [e0, e1] = ShellModel::element_range(static_cast<int>(ne), t, T);
      for (size_t k = size_t(e0) * block_; k < size_t(e1) * block_; ++k)
        if (map_[k] >= 0) first[map_[k]] = std::min(first[map_[k]], t);
    }
    direct_begin_.assign(ne + 1, 0);
    held_begin_.assign(ne + 1, 0);
    direct_src_.clear(), direct_dst_.clear(), held_src_.clear(), held_dst_.clear();
    for (int t = 0; t < T; ++t) {
      const auto [e0, e1] = ShellModel::element_range(static_cast<int>(ne), t, T);
      for (int e = e0; e < e1; ++e) {
        for (int k = 0; k < block_; ++k) {
          const int dst = map_[size_t(e) * block_ + k];
          if (dst < 0) continue;
          (first[dst] == t ? direct_src_ : held_src_).push_back(k);
          (first[dst] == t ? direct_dst_ : held_dst_).push_back(dst);
        }
        direct_begin_[e + 1] = direct_src_.size();
        held_begin_[e + 1] = held_src_.size();
      }
    }
    held_.assign(held_src_.size(), 0.0);
  }
  std::vector<int>().swap(map_);
}

void ReducedTangent::build_pattern(const std::vector<int>& g, int nd) {
  auto wanted = [&](int gr, int gs) { return gr >= 0 && gs >= 0 && (!symmetric_ || gr >= gs); };
  // Pattern: per column the sorted rows of every element that couples them.
  std::vector<std::vector<int>> cols(n_);
  std::vector<int> ge;
  const int ne = static_cast<int>(g.size() / std::max<size_t>(1, size_t(nd)));
  map_.assign(static_cast<size_t>(ne) * block_, -1);
  for (int e = 0; e < ne; ++e) {
    ge.assign(g.begin() + size_t(e) * nd, g.begin() + size_t(e + 1) * nd);
    std::sort(ge.begin(), ge.end());
    ge.erase(std::unique(ge.begin(), ge.end()), ge.end());
    for (int gs : ge)
      for (int gr : ge)
        if (wanted(gr, gs)) cols[gs].push_back(gr);
  }
  long nnz = 0;
  for (auto& c : cols) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    nnz += static_cast<long>(c.size());
  }
  SpMat& K = sparse_matrix_;
  K.resize(n_, n_);
  K.resizeNonZeros(nnz);
  K.outerIndexPtr()[0] = 0;
  for (int j = 0; j < n_; ++j) {
    std::copy(cols[j].begin(), cols[j].end(), K.innerIndexPtr() + K.outerIndexPtr()[j]);
    K.outerIndexPtr()[j + 1] = K.outerIndexPtr()[j] + static_cast<int>(cols[j].size());
    std::vector<int>().swap(cols[j]);
  }
  std::fill(K.valuePtr(), K.valuePtr() + nnz, 0.0);
  for (int e = 0; e < ne; ++e)
    for (int s = 0; s < nd; ++s)
      for (int r = 0; r < nd; ++r) {
        const int gr = g[size_t(e) * nd + r], gs = g[size_t(e) * nd + s];
        if (!wanted(gr, gs)) continue;
        const int* b = K.innerIndexPtr() + K.outerIndexPtr()[gs];
        const int* end = K.innerIndexPtr() + K.outerIndexPtr()[gs + 1];
        map_[size_t(e) * block_ + r + size_t(nd) * s] =
            static_cast<int>(std::lower_bound(b, end, gr) - K.innerIndexPtr());
      }
}

void ReducedTangent::analyze_ldlt() {
  if (f_->ldlt_analyzed) return;
  f_->sparse_ldlt.analyzePattern(sparse_matrix_);
  f_->ldlt_analyzed = true;
}

ReducedTangent::~ReducedTangent() = default;

bool ReducedTangent::supernodal_available() {
  return SupernodalCholesky::available();
}

bool ReducedTangent::multifrontal_available() {
  return MultifrontalLDLT::available();
}

long ReducedTangent::stored_entries() const {
  return sparse_ ? static_cast<long>(sparse_matrix_.nonZeros()) : static_cast<long>(n_) * n_;
}

double* ReducedTangent::values() {
  return sparse_ ? sparse_matrix_.valuePtr() : dense_.data();
}

void ReducedTangent::begin_assembly(const ShellModel& model) {
  if (model.assembly_threads() != threads_)
    throw std::logic_error(
        "ReducedTangent::begin_assembly: the model's assembly threads changed since the "
        "reduced tangent was built");
  zero_values();
}

void ReducedTangent::zero_values() {
  const long nv = sparse_ ? static_cast<long>(sparse_matrix_.nonZeros()) : long(n_) * n_;
  std::fill(values(), values() + nv, 0.0);
}

void ReducedTangent::element(int e, int /*thread*/, const double* kt, const int* map) {
  double* v = values();
  const int* src = direct_src_.data();
  const int* dst = direct_dst_.data();
  if (map) {
    for (size_t i = direct_begin_[e]; i < direct_begin_[e + 1]; ++i) v[dst[i]] += kt[map[src[i]]];
    for (size_t i = held_begin_[e]; i < held_begin_[e + 1]; ++i) held_[i] = kt[map[held_src_[i]]];
  } else {
    for (size_t i = direct_begin_[e]; i < direct_begin_[e + 1]; ++i) v[dst[i]] += kt[src[i]];
    for (size_t i = held_begin_[e]; i < held_begin_[e + 1]; ++i) held_[i] = kt[held_src_[i]];
  }
}

void ReducedTangent::end_assembly() {
  // In thread order, each thread's elements in order (compact_map stored them so).
  double* v = values();
  for (size_t i = 0; i < held_.size(); ++i) v[held_dst_[i]] += held_[i];
}

void ReducedTangent::assemble(const std::vector<Eigen::MatrixXd>& Ke) {
  // The direct scatter's split, reading the stored tangents (map: the identity).
  zero_values();
  const int ne = std::min(static_cast<int>(direct_begin_.size()) - 1, static_cast<int>(Ke.size()));
  const int total = static_cast<int>(direct_begin_.size()) - 1;
  auto part = [&](int t) {
    const auto [e0, e1] = ShellModel::element_range(total, t, threads_);
    for (int e = e0; e < std::min(e1, ne); ++e) element(e, t, Ke[e].data(), nullptr);
  };
  if (threads_ <= 1)
    part(0);
  else
    ThreadPool::shared().run(threads_, part);
  end_assembly();
}

Factorization ReducedTangent::factorize() {
  if (n_ == 0) {
    Factorization f;
    f.ok = true;
    f.negative_pivots = symmetric_ ? 0 : -1;
    f.determinant_sign = 1;  // the empty product
    f.pivot_ratio = 1.0;
    return f;
  }
  if (!sparse_ && !symmetric_) {
    f_->dense_lu.compute(dense_);
    Factorization f = from_pivots(f_->dense_lu.matrixLU().diagonal(), false, "dense LU");
    if (f.ok) {
      // det K = det(P^-1) prod u_jj (P A = L U, L unit lower triangular).
      int sign = f_->dense_lu.permutationP().determinant() > 0 ? 1 : -1;
      for (double u : f_->dense_lu.matrixLU().diagonal()) sign = u < 0.0 ? -sign : sign;
      f.determinant_sign = sign;
    }
    return f;
  }
  if (!sparse_) {
    f_->dense_ldlt.compute(dense_);
    return from_pivots(f_->dense_ldlt.vectorD(), true, "dense LDLT");
  }
  if (symmetric_) {
    f_->cholesky_active = false;
    f_->multifrontal_active = false;
    if (supernodal_) {
      const auto st = f_->cholesky.factorize(sparse_matrix_);
      if (st == SupernodalCholesky::Status::kOk) {
        f_->cholesky_active = true;
        return from_pivots(f_->cholesky.pivots(), true, "supernodal Cholesky");
      }
      // Indefinite (or CHOLMOD failed): the LDLT below counts the negative pivots.
      if (st == SupernodalCholesky::Status::kFailed) {
        ++fallback_factorizations_;
        if (supernodal_failure_.empty())
          supernodal_failure_ = "a factorization: " + f_->cholesky.failure();
      }
    } else if (!supernodal_failure_.empty()) {
      ++fallback_factorizations_;  // the analysis failed: every factorization is the LDLT's
    }
    if (multifrontal_) {
      Factorization f;
      if (factorize_multifrontal(f)) return f;
    }
    analyze_ldlt();
    f_->sparse_ldlt.factorize(sparse_matrix_);
    if (f_->sparse_ldlt.info() != Eigen::Success) {
      Factorization f;
      f.why = "singular tangent stiffness (sparse LDLT: zero pivot)";
      return f;
    }
    return from_pivots(f_->sparse_ldlt.vectorD(), true, "sparse LDLT");
  }
  f_->sparse_lu.factorize(sparse_matrix_);
  if (f_->sparse_lu.info() != Eigen::Success) {
    Factorization f;
    f.why =
        "singular tangent stiffness (sparse LU failed: " + f_->sparse_lu.lastErrorMessage() + ")";
    return f;
  }
  const auto [lo, hi] = f_->sparse_lu.pivot_range();
  Eigen::Vector2d d(lo, hi);
  Factorization f = from_pivots(d, false, "sparse LU");
  // Eigen's signDeterminant: the signs of U's diagonal and of both permutations.
  if (f.ok) f.determinant_sign = f_->sparse_lu.signDeterminant() < 0.0 ? -1 : 1;
  return f;
}

bool ReducedTangent::factorize_multifrontal(Factorization& f) {
  MultifrontalLDLT& m = f_->multifrontal;
  if (!f_->multifrontal_analyzed) {
    f_->multifrontal_analyzed = true;
    // The supernodal path's matrix is in its fill-reducing order already.
    if (!m.analyze(sparse_matrix_, !perm_.empty())) {
      multifrontal_ = false;
      multifrontal_failure_ = "the symbolic analysis: " + m.failure();
      m.release();
      return false;
    }
  }
  const auto st = m.factorize(sparse_matrix_);
  if (st == MultifrontalLDLT::Status::kFailed) {
    // MUMPS failed (memory, workspace): this and every later factorization by the LDLT, with
    // MUMPS's memory freed first.
    multifrontal_ = false;
    multifrontal_failure_ = "a factorization: " + m.failure();
    m.release();
    return false;
  }
  ++multifrontal_factorizations_;
  f.method = "multifrontal LDLT";
  f.negative_pivots = m.negative_pivots();
  if (f.negative_pivots >= 0) f.determinant_sign = sign_of_inertia(f.negative_pivots);
  if (st == MultifrontalLDLT::Status::kSingular) {
    f.pivot_ratio = 0.0;
    f.why =
        m.null_pivots() < 0
            ? "singular tangent stiffness (multifrontal LDLT: numerically singular)"
            : "singular tangent stiffness (multifrontal LDLT: " + std::to_string(m.null_pivots()) +
                  " null pivots, |pivot| <= 1e-14 of the matrix's norm)";
    return true;
  }
  f.pivot_ratio = 1.0;  // not available: no null pivot, so above the threshold
  f.ok = true;
  f_->multifrontal_active = true;
  return true;
}

Eigen::VectorXd ReducedTangent::solve(const Eigen::VectorXd& b) const {
  if (n_ == 0) return Eigen::VectorXd(0);
  if (!sparse_)
    return symmetric_ ? Eigen::VectorXd(f_->dense_ldlt.solve(b))
                      : Eigen::VectorXd(f_->dense_lu.solve(b));
  if (perm_.empty()) return solve_stored(b);
  // Stored order k holds the unknown perm_[k].
  Eigen::VectorXd bp(n_), x(n_);
  for (int k = 0; k < n_; ++k) bp(k) = b(perm_[k]);
  const Eigen::VectorXd xp = solve_stored(bp);
  for (int k = 0; k < n_; ++k) x(perm_[k]) = xp(k);
  return x;
}

Eigen::VectorXd ReducedTangent::solve_stored(const Eigen::VectorXd& b) const {
  if (f_->cholesky_active) return f_->cholesky.solve(b);
  if (f_->multifrontal_active) return f_->multifrontal.solve(b);
  return symmetric_ ? Eigen::VectorXd(f_->sparse_ldlt.solve(b))
                    : Eigen::VectorXd(f_->sparse_lu.solve(b));
}

Eigen::VectorXd ReducedTangent::multiply(const Eigen::VectorXd& x) const {
  if (sparse_ && !perm_.empty()) {
    Eigen::VectorXd xp(n_), y(n_);
    for (int k = 0; k < n_; ++k) xp(k) = x(perm_[k]);
    const Eigen::VectorXd yp = sparse_matrix_.selfadjointView<Eigen::Lower>() * xp;
    for (int k = 0; k < n_; ++k) y(perm_[k]) = yp(k);
    return y;
  }
  if (sparse_)
    return symmetric_ ? Eigen::VectorXd(sparse_matrix_.selfadjointView<Eigen::Lower>() * x)
                      : Eigen::VectorXd(sparse_matrix_ * x);
  return symmetric_ ? Eigen::VectorXd(dense_.selfadjointView<Eigen::Lower>() * x)
                    : Eigen::VectorXd(dense_ * x);
}

}  // namespace knit::macro
