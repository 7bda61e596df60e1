#include "knit/macro/shell_model.hpp"

#include <Eigen/Geometry>
#include <Eigen/StdVector>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <thread>

#include "knit/macro/element_kernel.hpp"
#include "knit/macro/thread_pool.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::macro {

namespace {

/// Gauss points of every non-empty span of U, as (span start, span end) pairs.
std::vector<std::pair<double, double>> spans(const std::vector<double>& U) {
  std::vector<std::pair<double, double>> s;
  for (size_t i = 0; i + 1 < U.size(); ++i)
    if (U[i + 1] > U[i]) s.emplace_back(U[i], U[i + 1]);
  return s;
}

}  // namespace

ShellModel::ShellModel(spline::SplineSurface surface, double thickness,
                       std::shared_ptr<Material> material, ShellOptions options)
    : surface_(std::move(surface)), t_(thickness), material_(std::move(material)), opt_(options) {
  const int pu = surface_.basis_u().degree(), pv = surface_.basis_v().degree();
  nloc_ = (pu + 1) * (pv + 1);
  const Eigen::MatrixXd& P = surface_.control_points();
  scale_ = (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm();
  if (!(scale_ > 0)) scale_ = 1.0;
  const int extra = std::max(0, opt_.extra_quadrature_points);
  const int nqu = opt_.quadrature_points > 0 ? opt_.quadrature_points : pu + 1 + extra;
  const int nqv = opt_.quadrature_points > 0 ? opt_.quadrature_points : pv + 1 + extra;
  const auto su = spans(surface_.basis_u().knots()), sv = spans(surface_.basis_v().knots());
  const spline::QuadratureRule gu = spline::gauss_legendre(nqu), gv = spline::gauss_legendre(nqv);
  const int nel = static_cast<int>(su.size() * sv.size());
  elements_.resize(nel);
  points_.reserve(static_cast<size_t>(nel) * nqu * nqv);
  R_.resize(1, static_cast<Eigen::Index>(nloc_) * nel * nqu * nqv);
  spline::SurfaceBasis sb;
  std::vector<Eigen::Vector2d> thetas;
  int e = 0;
  for (const auto& [v0, v1] : sv) {
    for (const auto& [u0, u1] : su) {
      Element& el = elements_[e++];
      el.first_point = static_cast<int>(points_.size());
      for (int b = 0; b < nqv; ++b) {
        for (int a = 0; a < nqu; ++a) {
          const double u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * gu.points[a];
          const double v = 0.5 * (v0 + v1) + 0.5 * (v1 - v0) * gv.points[b];
          const double w = gu.weights[a] * gv.weights[b] * 0.25 * (u1 - u0) * (v1 - v0);
          surface_.basis(u, v, 2, sb);
          if (el.cp.size() == 0) el.cp = sb.index;
          SurfaceDerivs dX = SurfaceDerivs::Zero();
          for (int l = 0; l < nloc_; ++l) dX += sb.R.col(l) * P.row(sb.index(l));
          Point pt;
          pt.ref = reference_point(dX, Eigen::Vector2d(u, v), scale_);
          pt.dA = w * pt.ref.jacobian;
          R_.block(0, static_cast<Eigen::Index>(points_.size()) * nloc_, 1, nloc_) = sb.R.row(0);
          el.PhiT.conservativeResize(kernel::padded_functions(nloc_), el.PhiT.cols() + 5);
          el.PhiT.rightCols(5).setZero();
          el.PhiT.rightCols(5).topRows(nloc_) = sb.R.bottomRows(5).transpose();
          points_.push_back(pt);
          thetas.emplace_back(u, v);
        }
      }
      el.num_points = static_cast<int>(points_.size()) - el.first_point;
    }
  }
  material_->bind_points(thetas);
  nqu_ = nqu, nqv_ = nqv;
  for (const Element& el : elements_) max_points_ = std::max(max_points_, el.num_points);
  factorize_elements(su, sv, gu, gv);
  share_phis();
  // Ke(3 l + i, 3 m + j) = K_ij(l, m) = KT(p nl + m, l) for pair p = (i, j); symmetric layout:
  // pairs (0,1), (0,2), (1,2), (0,0), (1,1), (2,2), K_ij(l, m) = K_ji(m, l) for i > j, and a
  // diagonal pair's K(l, m) = K(m, l) read where l >= m (all that evaluate_range's copy reads).
  const int nl = nloc_, nd = 3 * nl, ldw = kernel::workspace_rows(nl);
  constexpr int kSymPair[3][3] = {{3, 0, 1}, {0, 4, 2}, {1, 2, 5}};
  for (const bool sym : {false, true}) {
    std::vector<int>& map = kt_map_[sym];
    map.resize(static_cast<size_t>(nd) * nd);
    for (int m = 0; m < nl; ++m)
      for (int j = 0; j < 3; ++j)
        for (int l = 0; l < nl; ++l)
          for (int i = 0; i < 3; ++i) {
            int at = l * ldw + (3 * i + j) * nl + m;
            if (sym) {
              const int p = kSymPair[i][j];
              at = (i < j || (i == j && l >= m)) ? l * ldw + p * nl + m : m * ldw + p * nl + l;
            }
            map[(3 * l + i) + static_cast<size_t>(nd) * (3 * m + j)] = at;
          }
  }
}

void ShellModel::factorize_elements(const std::vector<std::pair<double, double>>& su,
                                    const std::vector<std::pair<double, double>>& sv,
                                    const spline::QuadratureRule& gu,
                                    const spline::QuadratureRule& gv) {
  // Phi_f(lu + nu lv, qu + nqu qv) = a_du(lu, qu) b_dv(lv, qv) for a B-spline surface (the
  // local functions u fastest, the points u fastest); a rational surface or another ordering
  // fails the check below and keeps the direct product.
  const int nu = surface_.basis_u().degree() + 1, nv = surface_.basis_v().degree() + 1;
  if (!kernel::sum_factorized(nu, nv)) return;
  constexpr int kDu[5] = {1, 0, 2, 1, 0}, kDv[5] = {0, 1, 0, 1, 2};
  const int nqu = nqu_, nqv = nqv_;
  Eigen::MatrixXd du(3, nu), dv(3, nv);
  double err = 0.0, big = 0.0;
  int e = 0;
  for (const auto& [v0, v1] : sv) {
    for (const auto& [u0, u1] : su) {
      Element& el = elements_[e++];
      el.Au.assign(static_cast<size_t>(3) * nqu * nu, 0.0);
      el.Bk.assign(static_cast<size_t>(5) * nqv * nv, 0.0);
      for (int a = 0; a < nqu; ++a) {
        surface_.basis_u().eval(0.5 * (u0 + u1) + 0.5 * (u1 - u0) * gu.points[a], 2, du);
        for (int d = 0; d < 3; ++d)
          for (int lu = 0; lu < nu; ++lu) el.Au[(d * nqu + a) * nu + lu] = du(d, lu);
      }
      for (int b = 0; b < nqv; ++b) {
        surface_.basis_v().eval(0.5 * (v0 + v1) + 0.5 * (v1 - v0) * gv.points[b], 2, dv);
        for (int f = 0; f < 5; ++f)
          for (int lv = 0; lv < nv; ++lv) el.Bk[(5 * b + f) * nv + lv] = dv(kDv[f], lv);
      }
      for (int b = 0; b < nqv; ++b)
        for (int a = 0; a < nqu; ++a)
          for (int f = 0; f < 5; ++f)
            for (int lv = 0; lv < nv; ++lv)
              for (int lu = 0; lu < nu; ++lu) {
                const double phi = el.PhiT(lu + nu * lv, 5 * (a + nqu * b) + f);
                const double t = el.Au[(kDu[f] * nqu + a) * nu + lu] * el.Bk[(5 * b + f) * nv + lv];
                err = std::max(err, std::abs(phi - t));
                big = std::max(big, std::abs(phi));
              }
    }
  }
  factorized_ = err <= 1e-12 * big;
  if (!factorized_)
    for (Element& el : elements_) el.Au.clear(), el.Bk.clear();
}

void ShellModel::share_phis() {
  // Elements whose basis derivatives at their points agree (uniform knot spans away from the
  // patch's edges: at p = 4, 16 x 100 elements, 49 distinct of 1,600) share one PhiT; the
  // elements' 32 KB each (p = 4) were read by every residual and tangent pass (51 MB at
  // 16 x 100). A candidate is found by its entries rounded to 1e-9 of its largest and taken
  // when it agrees to 1e-13 (round-off of the basis evaluation at shifted knots); otherwise the
  // element keeps its own.
  std::map<std::vector<long long>, int> seen;
  std::vector<long long> key;
  for (Element& el : elements_) {
    const Eigen::MatrixXd& P = el.PhiT;
    const double big = P.size() > 0 ? P.cwiseAbs().maxCoeff() : 0.0;
    key.resize(static_cast<size_t>(P.size()));
    for (Eigen::Index k = 0; k < P.size(); ++k)
      key[k] = big > 0.0 ? std::llround(P.data()[k] / big * 1e9) : 0;
    const auto it = opt_.share_bases ? seen.find(key) : seen.end();
    if (it != seen.end() && phis_[it->second].cols() == P.cols() &&
        (phis_[it->second] - P).cwiseAbs().maxCoeff() <= 1e-13 * big) {
      el.phi = it->second;
    } else {
      el.phi = static_cast<int>(phis_.size());
      phis_.push_back(P);
      seen.emplace(key, el.phi);
    }
    el.PhiT.resize(0, 0);
  }
}

SectionResponse ShellModel::section(const Eigen::Vector3d& Ec, const Eigen::Vector3d& Kc,
                                    const Eigen::Vector2d& theta, int point_id) const {
  MaterialPoint where;
  where.theta = theta;
  where.point_id = point_id;
  return integrate_section(*material_, opt_.integration, t_, Ec, Kc, where);
}

int ShellModel::assembly_threads() const {
  int n = opt_.threads;
  if (n == 0) {
    const double work = double(num_quadrature_points()) * (3.0 * nloc_) * (3.0 * nloc_);
    n = work >= kAutoThreadWork ? static_cast<int>(std::thread::hardware_concurrency()) : 1;
  }
  return std::max(1, std::min(n, num_elements()));
}

/// Workspace of one thread (no allocation in evaluate_range): the element's control point
/// positions and forces, the point matrices H, and the kernel's W, KT, Y (element_kernel.hpp;
/// zeroed whenever their layout changes: the kernel reads padding rows it never writes).
struct ShellModel::Workspace {
  std::vector<double> xloc, fe, H, W, KT, Y;
  PointState local;
  int nl = -1, maxq = -1;
  bool factorized = false;
};

ShellModel::Workspace& ShellModel::workspace() const {
  // Per thread and kept for the life of the thread: the assembly threads are a persistent
  // pool and the caller's thread lives on, so the next evaluation (of this or another model
  // of no larger elements) finds its memory mapped already (the design's many small models).
  thread_local Workspace w;
  const int nl = nloc_;
  if (w.nl != nl || w.maxq != max_points_ || w.factorized != factorized_) {
    const size_t rows = kernel::workspace_rows(nl);
    w.xloc.assign(3 * kernel::padded_functions(nl), 0.0);
    w.fe.assign(3 * kernel::padded_functions(nl), 0.0);
    w.H.assign(size_t(225) * max_points_, 0.0);
    w.W.assign(rows * 5 * max_points_, 0.0);
    w.KT.assign(rows * kernel::padded_functions(nl), 0.0);
    w.Y.assign(factorized_ ? rows * 5 * nqv_ * (surface_.basis_u().degree() + 1) : 0, 0.0);
    w.nl = nl, w.maxq = max_points_, w.factorized = factorized_;
  }
  return w;
}

bool ShellModel::run_ranges(const Eigen::VectorXd* u, Pass pass, const Evaluation* from,
                            Evaluation& out, ElementTangentSink* sink) const {
  const int nth = assembly_threads();
  if (nth == 1) return evaluate_range(0, 1, u, pass, from, out, sink, workspace());
  // The process-wide pool: threads started once, not per call.
  std::vector<char> oks(nth, 1);
  ThreadPool::shared().run(
      nth, [&](int k) { oks[k] = evaluate_range(k, nth, u, pass, from, out, sink, workspace()); });
  bool ok = true;
  for (int k = 0; k < nth; ++k) ok = ok && oks[k];
  return ok;
}

namespace {
void allocate_tangents(std::vector<Eigen::MatrixXd>& Ke, int ne, int n) {
  Ke.resize(ne);
  for (auto& K : Ke) K.resize(n, n);
}
}  // namespace

void ShellModel::evaluate(const Eigen::VectorXd& u, bool tangent, Evaluation& out, bool keep_points,
                          ElementTangentSink* sink) const {
  const int ne = num_elements();
  out.fe.resize(3 * nloc_, ne);
  out.element_energy.resize(ne);
  if (!tangent) sink = nullptr;
  if (tangent && !sink) allocate_tangents(out.Ke, ne, 3 * nloc_);
  if (sink) out.Ke.clear();
  const bool keep = keep_points && !tangent;
  if (keep) out.points.resize(points_.size());
  out.has_points = false;
  const bool ok =
      run_ranges(&u, tangent ? Pass::kTangent : (keep ? Pass::kResidualKeep : Pass::kResidual),
                 nullptr, out, sink);
  out.ok = ok;
  out.has_points = ok && keep;
  out.fint.setZero(num_dofs());
  out.energy = material_->hyperelastic() ? 0.0 : std::numeric_limits<double>::quiet_NaN();
  if (!ok) return;
  // Sum in element order (independent of the thread split).
  for (int e = 0; e < ne; ++e) {
    const Eigen::VectorXi& cp = elements_[e].cp;
    for (int l = 0; l < nloc_; ++l)
      out.fint.segment<3>(3 * cp(l)) += out.fe.col(e).segment<3>(3 * l);
    out.energy += out.element_energy(e);
  }
}

void ShellModel::tangent_from(const Evaluation& from, Evaluation& out,
                              ElementTangentSink* sink) const {
  if (!from.ok || !from.has_points)
    throw std::logic_error("ShellModel::tangent_from: the evaluation kept no point states");
  out.fint = from.fint;
  out.energy = from.energy;
  out.has_points = false;
  if (sink)
    out.Ke.clear();
  else
    allocate_tangents(out.Ke, num_elements(), 3 * nloc_);
  out.ok = run_ranges(nullptr, Pass::kTangentFromStates, &from, out, sink);
}

double ShellModel::energy(const Eigen::VectorXd& u) const {
  Evaluation ev;
  evaluate(u, false, ev);
  return ev.ok ? ev.energy : std::numeric_limits<double>::quiet_NaN();
}

namespace {

inline void copy3(const Eigen::Vector3d& v, double* d) {
  d[0] = v(0), d[1] = v(1), d[2] = v(2);
}
}  // namespace

bool ShellModel::residual_point(int pid, const double* Phi, const double* xT, PointState& s,
                                double& energy, double* feT) const {
  const int nl = nloc_;
  const Point& pt = points_[pid];
  // dx = R x over contiguous vectors of the element's functions (element_kernel.cpp, built for
  // each instruction set).
  SurfaceDerivs dx;  // 6 x 3 column-major: dx(r, i) at 6 i + r (row 0 not computed)
  kernel::current_derivatives(Phi, xT, nl, dx.data());
  const CurrentPoint c = current_point(dx, pt.ref);
  if (!(c.j > 1e-12 * pt.ref.jacobian) || !c.eps.allFinite() || !c.kap.allFinite()) return false;
  const Eigen::Matrix3d& T = pt.ref.T;
  const SectionResponse sr = section(T * c.eps, T * c.kap, pt.ref.theta, pid);
  const Eigen::Vector3d N = T.transpose() * sr.n, M = T.transpose() * sr.m;
  energy += pt.dA * sr.psi;
  copy3(c.a1, s.a1), copy3(c.a2, s.a2), copy3(c.a3, s.a3);
  copy3(c.a11, s.a11), copy3(c.a22, s.a22), copy3(c.a12, s.a12);
  copy3(N, s.N), copy3(M, s.M);
  s.j = c.j;
  for (int k = 0; k < 9; ++k)
    s.A[k] = sr.A.data()[k], s.B[k] = sr.B.data()[k], s.D[k] = sr.D.data()[k];
  // g = dA G^T (N, M) (G: point_matrix), per function f = R_1, R_2, R_11, R_12, R_22:
  //   g_1 = N11 a1 + N12 a2 + a3_,1 term,  a3_,(l,i) . v summed: -P_alpha^T v = -Q_alpha^T w / j
  //   with Q1^T w = a2 x w, Q2^T w = w x a1; g_11 = -M11 a3, g_12 = -2 M12 a3, g_22 = -M22 a3.
  double v[3], w[3], q1[3], q2[3], g[15];
  kernel::bending_vector(s, v, w);
  kernel::cross3(s.a2, w, q1);
  kernel::cross3(w, s.a1, q2);
  const double ij = 1.0 / s.j, dA = pt.dA;
  for (int i = 0; i < 3; ++i) {
    g[i] = dA * (N(0) * s.a1[i] + N(2) * s.a2[i] - ij * q1[i]);
    g[3 + i] = dA * (N(1) * s.a2[i] + N(2) * s.a1[i] - ij * q2[i]);
    g[6 + i] = -dA * M(0) * s.a3[i];
    g[9 + i] = -dA * 2.0 * M(2) * s.a3[i];
    g[12 + i] = -dA * M(1) * s.a3[i];
  }
  kernel::add_point_forces(Phi, g, nl, feT);
  return true;
}

void ShellModel::point_matrix(int pid, const PointState& s, double* H, bool& symmetric) const {
  const Point& pt = points_[pid];
  kernel::point_matrix(s, pt.ref.T.data(), pt.dA, H, symmetric);
}

bool ShellModel::evaluate_range(int thread, int threads, const Eigen::VectorXd* u, Pass pass,
                                const Evaluation* from, Evaluation& out, ElementTangentSink* sink,
                                Workspace& ws) const {
  const auto [e0, e1] = element_range(num_elements(), thread, threads);
  const Eigen::MatrixXd& P = surface_.control_points();
  const int nl = nloc_;
  const bool tangent = pass == Pass::kTangent || pass == Pass::kTangentFromStates;
  const bool stored = pass == Pass::kTangentFromStates;
  // The thread's workspace (Workspace: sized once per model, never allocated here). xT and feT:
  // the element's control points and forces, component-major with padded_functions(nl) rows
  // (the kernel's layout; the padding stays zero).
  const int nlp = kernel::padded_functions(nl);
  std::vector<double>& xT = ws.xloc;
  std::vector<double>& feT = ws.fe;
  double* Hs = ws.H.data();
  PointState& local = ws.local;
  for (int e = e0; e < e1; ++e) {
    const Element& el = elements_[e];
    bool symmetric = true;
    if (!stored) {
      for (int l = 0; l < nl; ++l) {
        const int a = el.cp(l);
        for (int i = 0; i < 3; ++i) xT[i * nlp + l] = P(a, i) + (*u)(3 * a + i);
      }
      std::fill(feT.begin(), feT.end(), 0.0);
      double energy = 0.0;
      for (int q = 0; q < el.num_points; ++q) {
        const int pid = el.first_point + q;
        PointState& s = pass == Pass::kResidualKeep ? out.points[pid] : local;
        const double* Phi = phis_[el.phi].data() + 5L * q * nlp;
        if (!residual_point(pid, Phi, xT.data(), s, energy, feT.data())) return false;
        if (tangent) point_matrix(pid, s, Hs + 225 * q, symmetric);
      }
      double* fe = out.fe.col(e).data();
      for (int l = 0; l < nl; ++l)
        for (int i = 0; i < 3; ++i) fe[3 * l + i] = feT[i * nlp + l];
      out.element_energy(e) = energy;
    } else {
      for (int q = 0; q < el.num_points; ++q) {
        const int pid = el.first_point + q;
        point_matrix(pid, from->points[pid], Hs + 225 * q, symmetric);
      }
    }
    if (!tangent) continue;
    // K(3l+i, 3m+j) = sum_q sum_fk Phi_f(l) H_q(3f+i, 3k+j) Phi_k(m): per pair (i, j) the
    // columns (H Phi)^T, then all pairs in one product (element_kernel.hpp: plain loops, an
    // AVX2/FMA version chosen at run time).
    // Symmetric: the off-diagonal pairs (0,1), (0,2), (1,2) first, then the diagonal ones,
    // whose blocks are symmetric: only their lower triangles are computed.
    int pairs = 0;
    int pi[9], pj[9];
    for (int i = 0; i < 3; ++i)
      for (int j = symmetric ? i + 1 : 0; j < 3; ++j) {
        pi[pairs] = i;
        pj[pairs++] = j;
      }
    const int full = pairs;  // pairs computed as full blocks
    if (symmetric)
      for (int i = 0; i < 3; ++i) {
        pi[pairs] = i;
        pj[pairs++] = i;
      }
    kernel::ElementTangentInput kin;
    kin.nl = nl;
    kin.nq = el.num_points;
    kin.PhiT = phis_[el.phi].data();
    kin.H = Hs;
    kin.pairs = pairs;
    kin.pi = pi;
    kin.pj = pj;
    kin.full = full;
    if (factorized_) {
      kin.Au = el.Au.data();
      kin.Bk = el.Bk.data();
      kin.nu = surface_.basis_u().degree() + 1;
      kin.nv = surface_.basis_v().degree() + 1;
      kin.nqu = nqu_;
      kin.nqv = nqv_;
      kin.Y = ws.Y.data();
    }
    kernel::element_tangent_blocks(kin, ws.W.data(), ws.KT.data());
    if (sink) {
      sink->element(e, thread, ws.KT.data(), kt_map_[symmetric].data());
      continue;
    }
    Eigen::MatrixXd& Ke = out.Ke[e];
    // Ke(3 l + i, 3 m + j) = K_ij(l, m) = KT(p nl + m, l): written down Ke's columns (stride 3)
    // and, for a symmetric law, the mirror Ke(3 m + j, 3 l + i) likewise.
    const Eigen::Index ldw = kernel::workspace_rows(nl);
    const double* kt = ws.KT.data();
    for (int p = 0; p < pairs; ++p) {
      const int i = pi[p], j = pj[p];
      const bool tri = p >= full;  // symmetric diagonal block from its lower triangle
      for (int m = 0; m < nl; ++m) {
        double* col = Ke.data() + (3 * m + j) * Ke.rows() + i;  // col[3 l] = Ke(3 l + i, 3 m + j)
        for (int l = tri ? m : 0; l < nl; ++l) col[3 * l] = kt[l * ldw + p * nl + m];
      }
      if (!symmetric) continue;
      for (int l = 0; l < nl; ++l) {
        double* col = Ke.data() + (3 * l + i) * Ke.rows() + j;  // col[3 m] = Ke(3 m + j, 3 l + i)
        const double* Kl = kt + l * ldw + p * nl;               // Kl[m] = K_ij(l, m)
        for (int m = 0; m < (tri ? l : nl); ++m) col[3 * m] = Kl[m];
      }
    }
  }
  return true;
}

Eigen::Vector3d ShellModel::displacement(const Eigen::VectorXd& u,
                                         const Eigen::Vector2d& theta) const {
  spline::SurfaceBasis sb;
  surface_.basis(theta(0), theta(1), 0, sb);
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (int l = 0; l < sb.index.size(); ++l) d += sb.R(0, l) * u.segment<3>(3 * sb.index(l));
  return d;
}

ShellSample ShellModel::sample(const Eigen::VectorXd& u, const Eigen::Vector2d& theta) const {
  spline::SurfaceBasis sb;
  surface_.basis(theta(0), theta(1), 2, sb);
  SurfaceDerivs dX = SurfaceDerivs::Zero(), dx = SurfaceDerivs::Zero();
  const Eigen::MatrixXd& P = surface_.control_points();
  for (int l = 0; l < sb.index.size(); ++l) {
    const int a = sb.index(l);
    dX += sb.R.col(l) * P.row(a);
    dx += sb.R.col(l) * (P.row(a) + u.segment<3>(3 * a).transpose());
  }
  ShellSample s;
  s.X = dX.row(0).transpose();
  s.x = dx.row(0).transpose();
  s.u = s.x - s.X;
  const ReferencePoint ref = reference_point(dX, theta, scale_);
  const CurrentPoint c = current_point(dx, ref);
  s.E = ref.T * c.eps;
  s.kappa = ref.T * c.kap;
  const SectionResponse sr = section(s.E, s.kappa, theta, -1);
  s.n = sr.n;
  s.m = sr.m;
  return s;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> ShellModel::normals(
    const Eigen::VectorXd& u, const Eigen::Vector2d& theta) const {
  thread_local spline::SurfaceBasis sb;  // kept: called per element corner and converged step
  surface_.basis(theta(0), theta(1), 1, sb);
  Eigen::Vector3d A1 = Eigen::Vector3d::Zero(), A2 = A1, a1 = A1, a2 = A1;
  const Eigen::MatrixXd& P = surface_.control_points();
  for (int l = 0; l < sb.index.size(); ++l) {
    const int a = sb.index(l);
    const Eigen::Vector3d X = P.row(a).transpose(), x = X + u.segment<3>(3 * a);
    A1 += sb.R(1, l) * X, A2 += sb.R(2, l) * X;
    a1 += sb.R(1, l) * x, a2 += sb.R(2, l) * x;
  }
  const Eigen::Vector3d N = A1.cross(A2), n = a1.cross(a2);
  return {n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero(),
          N.norm() > 0 ? Eigen::Vector3d(N.normalized()) : Eigen::Vector3d::Zero()};
}

Eigen::VectorXd ShellModel::point_force(const Eigen::Vector2d& theta,
                                        const Eigen::Vector3d& F) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  spline::SurfaceBasis sb;
  surface_.basis(theta(0), theta(1), 0, sb);
  for (int l = 0; l < sb.index.size(); ++l) f.segment<3>(3 * sb.index(l)) += sb.R(0, l) * F;
  return f;
}

Eigen::VectorXd ShellModel::edge_force(Edge edge, const Eigen::Vector3d& q) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  const bool along_u = edge == Edge::kV0 || edge == Edge::kV1;
  const spline::BSplineBasis& b = along_u ? surface_.basis_u() : surface_.basis_v();
  const double fixed = (edge == Edge::kU1 || edge == Edge::kV1) ? 1.0 : 0.0;
  const spline::QuadratureRule g = spline::gauss_legendre_on_spans(b.degree() + 2, b.knots());
  spline::SurfaceBasis sb;
  const Eigen::MatrixXd& P = surface_.control_points();
  for (size_t k = 0; k < g.points.size(); ++k) {
    const double s = g.points[k];
    const double u = along_u ? s : fixed, v = along_u ? fixed : s;
    surface_.basis(u, v, 1, sb);
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (int l = 0; l < sb.index.size(); ++l)
      d += sb.R(along_u ? 1 : 2, l) * P.row(sb.index(l)).transpose();
    const double ds = d.norm() * g.weights[k];
    for (int l = 0; l < sb.index.size(); ++l)
      f.segment<3>(3 * sb.index(l)) += (sb.R(0, l) * ds) * q;
  }
  return f;
}

Eigen::VectorXd ShellModel::area_force(const Eigen::Vector3d& q) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  for (const Element& el : elements_) {
    for (int k = 0; k < el.num_points; ++k) {
      const int pid = el.first_point + k;
      const auto R = R_.block(0, static_cast<Eigen::Index>(pid) * nloc_, 1, nloc_);
      for (int l = 0; l < nloc_; ++l) f.segment<3>(3 * el.cp(l)) += (R(0, l) * points_[pid].dA) * q;
    }
  }
  return f;
}

}  // namespace knit::macro
