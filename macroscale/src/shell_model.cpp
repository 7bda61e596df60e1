#include "knit/macro/shell_model.hpp"

#include <Eigen/Geometry>
#include <Eigen/StdVector>
#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "knit/macro/element_kernel.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::macro {

namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0, -a(2), a(1), a(2), 0, -a(0), -a(1), a(0), 0;
  return S;
}

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
  const int nqu = opt_.quadrature_points > 0 ? opt_.quadrature_points : pu + 1;
  const int nqv = opt_.quadrature_points > 0 ? opt_.quadrature_points : pv + 1;
  const auto su = spans(surface_.basis_u().knots()), sv = spans(surface_.basis_v().knots());
  const spline::QuadratureRule gu = spline::gauss_legendre(nqu), gv = spline::gauss_legendre(nqv);
  const int nel = static_cast<int>(su.size() * sv.size());
  elements_.resize(nel);
  points_.reserve(static_cast<size_t>(nel) * nqu * nqv);
  R_.resize(6, static_cast<Eigen::Index>(nloc_) * nel * nqu * nqv);
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
          R_.block(0, static_cast<Eigen::Index>(points_.size()) * nloc_, 6, nloc_) = sb.R;
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

void ShellModel::evaluate(const Eigen::VectorXd& u, bool tangent, Evaluation& out) const {
  const int ne = num_elements();
  out.fe.resize(3 * nloc_, ne);
  out.element_energy.resize(ne);
  if (tangent) {
    out.Ke.resize(elements_.size());
    for (auto& K : out.Ke) K.resize(3 * nloc_, 3 * nloc_);
  }
  const int nth = assembly_threads();
  bool ok = true;
  if (nth == 1) {
    ok = evaluate_range(0, ne, u, tangent, out);
  } else {
    std::vector<char> oks(nth, 1);
    std::vector<std::thread> pool;
    for (int k = 1; k < nth; ++k) {
      const int e0 = ne * k / nth, e1 = ne * (k + 1) / nth;
      pool.emplace_back([&, k, e0, e1] { oks[k] = evaluate_range(e0, e1, u, tangent, out); });
    }
    oks[0] = evaluate_range(0, ne / nth, u, tangent, out);
    for (auto& th : pool) th.join();
    for (char o : oks) ok = ok && o;
  }
  out.ok = ok;
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

double ShellModel::energy(const Eigen::VectorXd& u) const {
  Evaluation ev;
  evaluate(u, false, ev);
  return ev.ok ? ev.energy : std::numeric_limits<double>::quiet_NaN();
}

bool ShellModel::evaluate_range(int e0, int e1, const Eigen::VectorXd& u, bool tangent,
                                Evaluation& out) const {
  using Mat3 = Eigen::Matrix3d;
  using Vec3 = Eigen::Vector3d;
  using Mat15 = Eigen::Matrix<double, 15, 15>;
  const Eigen::MatrixXd& P = surface_.control_points();
  const int nl = nloc_;
  int maxq = 0;
  for (int e = e0; e < e1; ++e) maxq = std::max(maxq, elements_[e].num_points);
  // Workspace (allocated once per call and thread, never inside the point loop).
  Eigen::Matrix<double, Eigen::Dynamic, 3> xloc(nl, 3), fe(nl, 3);
  Eigen::Matrix<double, 6, 15> G = Eigen::Matrix<double, 6, 15>::Zero();
  std::vector<Mat15, Eigen::aligned_allocator<Mat15>> Hs(tangent ? maxq : 0);
  // W: the 9 products (H_q Phi)^T of the component pairs (i, j) stacked; KT = W Phi
  // (element_kernel.hpp). Zeroed once: the kernel reads padding rows it never writes.
  Eigen::MatrixXd W, KT;
  if (tangent) {
    W.setZero(kernel::workspace_rows(nl), 5 * maxq);
    KT.setZero(kernel::workspace_rows(nl), kernel::padded_functions(nl));
  }
  for (int e = e0; e < e1; ++e) {
    const Element& el = elements_[e];
    for (int l = 0; l < nl; ++l) {
      const int a = el.cp(l);
      xloc.row(l) = P.row(a) + u.segment<3>(3 * a).transpose();
    }
    fe.setZero();
    double energy = 0.0;
    bool symmetric = true;
    for (int q = 0; q < el.num_points; ++q) {
      const int pid = el.first_point + q;
      const Point& pt = points_[pid];
      const auto R = R_.block(0, static_cast<Eigen::Index>(pid) * nl, 6, nl);
      // dx = R xloc as a sum of outer products (contiguous columns of R, no GEMM call).
      Eigen::Matrix<double, 6, 1> d0 = Eigen::Matrix<double, 6, 1>::Zero(), d1 = d0, d2 = d0;
      for (int l = 0; l < nl; ++l) {
        const Eigen::Matrix<double, 6, 1> r = R.col(l);
        d0 += r * xloc(l, 0);
        d1 += r * xloc(l, 1);
        d2 += r * xloc(l, 2);
      }
      SurfaceDerivs dx;
      dx << d0, d1, d2;
      const CurrentPoint c = current_point(dx, pt.ref);
      if (!(c.j > 1e-12 * pt.ref.jacobian) || !c.eps.allFinite() || !c.kap.allFinite())
        return false;
      const Mat3& T = pt.ref.T;
      const SectionResponse sr = section(T * c.eps, T * c.kap, pt.ref.theta, pid);
      const Vec3 N = T.transpose() * sr.n, M = T.transpose() * sr.m;
      energy += pt.dA * sr.psi;
      // a3_,(l,i) = R1_l P1(:, i) + R2_l P2(:, i) with P_alpha = (I - a3 a3^T) Q_alpha / j,
      // Q1 e_i = e_i x a2, Q2 e_i = a1 x e_i.
      const Mat3 Q1 = -skew(c.a2), Q2 = skew(c.a1);
      const Mat3 Pr = Mat3::Identity() - c.a3 * c.a3.transpose();
      const Mat3 P1 = Pr * Q1 / c.j, P2 = Pr * Q2 / c.j;
      // Strain derivatives B(:, 3l+i) = sum_f Phi_f(l) G(:, 3f+i), Phi = (R_1, R_2, R_11, R_12,
      // R_22) (rows 1-5 of the basis), rows of B: eps11, eps22, 2eps12, kap11, kap22, 2kap12.
      G.block<1, 3>(0, 0) = c.a1.transpose();
      G.block<1, 3>(2, 0) = c.a2.transpose();
      G.block<1, 3>(1, 3) = c.a2.transpose();
      G.block<1, 3>(2, 3) = c.a1.transpose();
      G.block<1, 3>(3, 0) = -c.a11.transpose() * P1;
      G.block<1, 3>(4, 0) = -c.a22.transpose() * P1;
      G.block<1, 3>(5, 0) = -2.0 * c.a12.transpose() * P1;
      G.block<1, 3>(3, 3) = -c.a11.transpose() * P2;
      G.block<1, 3>(4, 3) = -c.a22.transpose() * P2;
      G.block<1, 3>(5, 3) = -2.0 * c.a12.transpose() * P2;
      G.block<1, 3>(3, 6) = -c.a3.transpose();
      G.block<1, 3>(5, 9) = -2.0 * c.a3.transpose();
      G.block<1, 3>(4, 12) = -c.a3.transpose();
      Eigen::Matrix<double, 6, 1> NM;
      NM << N, M;
      const Eigen::Matrix<double, 15, 1> g = pt.dA * (G.transpose() * NM);
      const Eigen::Map<const Eigen::Matrix<double, 3, 5>> gm(g.data());
      fe.noalias() += R.bottomRows(5).transpose().lazyProduct(gm.transpose());
      if (!tangent) continue;
      // Material part H = G^T D G with D the covariant section tangent.
      Eigen::Matrix<double, 6, 6> D;
      D.block<3, 3>(0, 0) = T.transpose() * sr.A * T;
      D.block<3, 3>(0, 3) = T.transpose() * sr.B * T;
      D.block<3, 3>(3, 0) = D.block<3, 3>(0, 3);
      D.block<3, 3>(3, 3) = T.transpose() * sr.D * T;
      if ((D - D.transpose()).cwiseAbs().maxCoeff() > 1e-12 * D.cwiseAbs().maxCoeff())
        symmetric = false;
      Mat15& H = Hs[q];
      // Coefficient-based products (a GEMM call with packing cost more at 15 x 6 x 15).
      const Eigen::Matrix<double, 6, 15> DG = (pt.dA * D).lazyProduct(G);
      H.noalias() = G.transpose().lazyProduct(DG);
      // Geometric part: n : eps_,rs + m : kappa_,rs (the variations listed in shell_model.hpp).
      const double c11 = M(0), c22 = M(1), c12 = 2.0 * M(2);
      const Vec3 v = c11 * c.a11 + c22 * c.a22 + c12 * c.a12;
      const double va3 = v.dot(c.a3);
      const Vec3 w = v - va3 * c.a3;
      const double ij = 1.0 / c.j;
      const Eigen::RowVector3d t1 = c.a3.transpose() * Q1, t2 = c.a3.transpose() * Q2;
      const Eigen::RowVector3d h1 = v.transpose() * P1, h2 = v.transpose() * P2;
      const Eigen::RowVector3d* tv[2] = {&t1, &t2};
      const Eigen::RowVector3d* hv[2] = {&h1, &h2};
      const Mat3* Qv[2] = {&Q1, &Q2};
      const Mat3* Pv[2] = {&P1, &P2};
      const Mat3 W = -skew(w);  // W(i, j) = eps_ijk w_k
      for (int al = 0; al < 2; ++al) {
        for (int be = 0; be < 2; ++be) {
          Mat3 Gab = ij * (tv[al]->transpose() * (*hv[be]) + hv[al]->transpose() * (*tv[be]) +
                           va3 * Qv[al]->transpose() * (*Pv[be]));
          const double Nab = al == be ? N(al) : N(2);
          Gab.diagonal().array() += Nab;
          if (al == 0 && be == 1) Gab -= ij * W;
          if (al == 1 && be == 0) Gab += ij * W;
          H.block<3, 3>(3 * al, 3 * be) += pt.dA * Gab;
        }
      }
      // m : (a_ab,r . a3_,s + a_ab,s . a3_,r): second-derivative functions f = 2, 3, 4.
      const double cf[3] = {c11, c12, c22};
      for (int f = 0; f < 3; ++f) {
        for (int be = 0; be < 2; ++be) {
          const Mat3 X = (-pt.dA * cf[f]) * (*Pv[be]);
          H.block<3, 3>(3 * (f + 2), 3 * be) += X;
          H.block<3, 3>(3 * be, 3 * (f + 2)) += X.transpose();
        }
      }
    }
    for (int l = 0; l < nl; ++l) out.fe.col(e).segment<3>(3 * l) = fe.row(l).transpose();
    out.element_energy(e) = energy;
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
    kin.PhiT = el.PhiT.data();
    kin.H = Hs[0].data();
    kin.pairs = pairs;
    kin.pi = pi;
    kin.pj = pj;
    kin.full = full;
    kernel::element_tangent_blocks(kin, W.data(), KT.data());
    Eigen::MatrixXd& Ke = out.Ke[e];
    // Ke(3 l + i, 3 m + j) = K_ij(l, m) = KT(p nl + m, l): written down Ke's columns (stride 3)
    // and, for a symmetric law, the mirror Ke(3 m + j, 3 l + i) likewise.
    const Eigen::Index ldw = KT.rows();
    const double* kt = KT.data();
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
