// Point-to-curve contact with friction: see knit/meso/contact/pair.hpp.
#include "knit/meso/contact/pair.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "knit/spline/basis.hpp"

namespace knit::meso::contact {

namespace {

/// y = sum_j N(i, j) Q(j, :) for one row i of N, summed in the order of Eigen's row-major GEMV
/// kernel with 2-wide packets (SSE2, the build's x86-64 target), which the former expression
/// `(N.row(i) * Q).transpose()` called: even and odd j in two lanes, the lanes added, then the
/// odd tail. Bit for bit the same numbers, without the kernel's call and copy overhead for
/// these 1 x (p+1) x 3 products (a third of the closest-point search's time).
/// The number of rows n is an int or a std::integral_constant (unrolled loops, the same sums).
template <class NMat, class QBlock, class Rows>
Eigen::Vector3d row_times_n(const NMat& N, int i, const QBlock& Q, Rows n) {
  Eigen::Vector3d y;
  for (int c = 0; c < 3; ++c) {
    double s0 = 0.0, s1 = 0.0;
    int j = 0;
    for (; j + 2 <= n; j += 2) {
      s0 = s0 + N(i, j) * Q(j, c);
      s1 = s1 + N(i, j + 1) * Q(j + 1, c);
    }
    double cc = s0 + s1;
    for (; j < n; ++j) cc += N(i, j) * Q(j, c);
    y(c) = 0.0 + cc;
  }
  return y;
}

template <class NMat, class QBlock>
Eigen::Vector3d row_times(const NMat& N, int i, const QBlock& Q) {
  const int n = static_cast<int>(Q.rows());
  if (n == 5) return row_times_n(N, i, Q, std::integral_constant<int, 5>{});  // quartic yarns
  return row_times_n(N, i, Q, n);
}

// The chain at u in copy k: N (3 x (p+1): N, N_u, N_uu) and x, x_u, x_uu. N is a dynamic-size
// matrix or a Map of one over caller storage (project() evaluates into a stack buffer: no heap
// allocation per Newton step of the closest-point search).
template <class NMat>
int eval_chain_at(const Chain& c, double u, int k, NMat& N, Eigen::Vector3d& x,
                  Eigen::Vector3d& x_u, Eigen::Vector3d& x_uu) {
  const int p = c.basis->degree();
  const double ut = std::clamp(u - k, c.basis->lo(), c.basis->hi());
  const int first = c.basis->eval(ut, std::min(2, p), N.topRows(std::min(2, p) + 1));
  if (p < 2) N.row(2).setZero();
  const auto Q = c.Q->middleRows(first, p + 1);
  x = row_times(N, 0, Q) + k * c.a1 + c.t;
  x_u = row_times(N, 1, Q);
  x_uu = row_times(N, 2, Q);
  return first;
}

}  // namespace

ChainPoint eval_chain(const Chain& c, double u, int k) {
  const int p = c.basis->degree();
  ChainPoint cp;
  cp.u = u;
  cp.k = k;
  cp.N.resize(3, p + 1);
  cp.first = eval_chain_at(c, u, k, cp.N, cp.x, cp.x_u, cp.x_uu);
  return cp;
}

Projection project(const Chain& c, const Eigen::Vector3d& xs, int k, double lo, double hi,
                   double u0) {
  Projection pr;
  pr.k = k;
  double u = std::clamp(u0, lo, hi);
  double buf[3 * (spline::kMaxDegree + 1)];
  Eigen::Map<Eigen::MatrixXd> N(buf, 3, c.basis->degree() + 1);
  ChainPoint cp;  // x, x_u, x_uu only (N lives in buf)
  eval_chain_at(c, u, k, N, cp.x, cp.x_u, cp.x_uu);
  double f = (xs - cp.x).squaredNorm();
  for (int it = 0; it < 30; ++it) {
    pr.iterations = it + 1;
    const Eigen::Vector3d r = xs - cp.x;
    const double phi = r.dot(cp.x_u);
    const double phiu = -cp.x_u.squaredNorm() + r.dot(cp.x_uu);
    // d(|r|^2)/du = -2 phi: a descent direction is sign(phi).
    double du = (phiu < 0) ? -phi / phiu : (phi > 0 ? 1 : -1) * 0.25 * (hi - lo);
    const double lim = 0.5 * (hi - lo);
    du = std::clamp(du, -lim, lim);
    double un = std::clamp(u + du, lo, hi);
    // A step that moves away from xs is halved (session 34: a full Newton step from where the
    // curve bends could jump over the nearest minimum to a farther one; the relative 1e-12
    // keeps round-off at convergence from halving).
    eval_chain_at(c, un, k, N, cp.x, cp.x_u, cp.x_uu);
    double fn = (xs - cp.x).squaredNorm();
    for (int h = 0; h < 40 && fn > f * (1.0 + 1e-12); ++h) {
      du *= 0.5;
      un = std::clamp(u + du, lo, hi);
      eval_chain_at(c, un, k, N, cp.x, cp.x_u, cp.x_uu);
      fn = (xs - cp.x).squaredNorm();
    }
    const double step = std::abs(un - u);
    u = un;
    f = fn;
    if (step < 1e-14 * std::max(1.0, std::abs(u))) break;
  }
  const Eigen::Vector3d r = xs - cp.x;
  pr.u = u;
  pr.distance = r.norm();
  const double phi = r.dot(cp.x_u);
  pr.ok = std::abs(phi) <= 1e-9 * std::max(1e-12, r.norm() * cp.x_u.norm()) &&
          (-cp.x_u.squaredNorm() + r.dot(cp.x_uu)) < 0;
  return pr;
}

PairResult evaluate_pair(const Eigen::Vector3d& xs, const Chain& c, const Projection& pr, double d,
                         const PenaltyLaw& law, const FrictionLaw& fr, const PairHistory& hist,
                         bool want_jac) {
  using Eigen::Matrix3d;
  using Eigen::MatrixXd;
  using Eigen::Vector3d;
  PairResult out;
  const ChainPoint cp = eval_chain(c, pr.u, pr.k);
  const int p = c.basis->degree();
  const int nz = 3 + 3 * (p + 1);
  out.u = pr.u;
  out.master_first = cp.first;
  out.Nm = cp.N.topRows(2);
  out.u_anchor_new = hist.u_anchor;
  const Vector3d r = xs - cp.x;
  const double rho = r.norm();
  out.gap = rho - d;
  if (want_jac) {
    out.df_dz = MatrixXd::Zero(3, nz);
    out.dm_dz = MatrixXd::Zero(3, nz);
  }
  if (out.gap >= 0 || !(rho > 0)) {
    out.u_anchor_new = pr.u;  // contact released: the anchor follows
    return out;
  }
  auto nv = law.eval(out.gap);
  bool tie = false;  // the soft bilateral tie of a reference pair that opened (no friction)
  if (hist.g_ref < 0) {
    // Stress-free reference (contact_set.hpp): measured from the reference overlap g_r,
    //   g <= g_r:     p(g) - p(g_r),  energy Pi(g) - Pi(g_r) - p(g_r) (g_r - g);
    //   g_r < g < 0:  the tie p = -k_0 (g - g_r) g / g_r (>= -k_0 |g_r| / 4, adhesive), C0 at
    //                 g_r and 0, slope -k_0 at g_r: opened sections stay weakly coupled, as
    //                 the plain law's soft branch keeps touching yarns coupled;
    //                 energy k_0 / g_r (g^3/3 - g_r g^2/2 + g_r^3/6).
    const double gr = hist.g_ref, g = out.gap;
    if (g > gr) {
      const double k0 = law.k_0;
      if (k0 <= 0) {
        out.u_anchor_new = pr.u;
        return out;
      }
      tie = true;
      nv.p = -k0 * (g - gr) * g / gr;
      nv.dp_dg = -k0 * (2.0 * g - gr) / gr;
      nv.energy = k0 / gr * (g * g * g / 3.0 - gr * g * g / 2.0 + gr * gr * gr / 6.0);
    } else {
      const auto r = law.eval(gr);
      nv.p -= r.p;
      nv.energy -= r.energy + r.p * (gr - g);
    }
  } else if (nv.p <= 0) {  // within the allowance g0: no force, no friction, the anchor follows
    out.u_anchor_new = pr.u;
    return out;
  }
  out.active = true;
  const Vector3d n = r / rho;
  const double ell = cp.x_u.norm();
  const Vector3d tau = cp.x_u / ell;
  out.n = n;
  out.tau = tau;
  out.p = nv.p;
  // Friction: return mapping from the anchor of the last converged state.
  const double e = ell * (pr.u - hist.u_anchor);
  out.e = e;
  // The slave's own slip relative to the master is 1 - q times the closest point's arc,
  // q = r . x_m,uu / |x_m,u|^2 (the closest point's phi_u = -|x_m,u|^2 (1 - q)): the friction
  // force f_T = -k_T e works on (1 - q) de. Both the friction work (slip, below) and the elastic
  // stick energy are counted on that slip (session 56's red team; the stick term since session
  // 57): for a fixed q the stick force is the derivative of (1 - q) k_T e^2 / 2 along the slip.
  // Bookkeeping only: the forces and their tangent do not depend on it.
  const double one_q = 1.0 - r.dot(cp.x_uu) / (ell * ell);
  const double ftr = -fr.k_T * e;
  const double lim = fr.mu * nv.p;
  const double sgn = e >= 0 ? 1.0 : -1.0;
  if (tie) {  // no friction on the tie: the anchor follows
    out.f_T = 0;
    out.u_anchor_new = pr.u;
    out.energy = nv.energy;
  } else if (std::abs(ftr) <= lim) {
    out.f_T = ftr;
    out.energy = nv.energy + 0.5 * one_q * fr.k_T * e * e;
  } else {
    out.slip = true;
    out.f_T = -lim * sgn;
    out.u_anchor_new = pr.u - sgn * lim / (fr.k_T * ell);
    // Friction work of this increment: |f_T| times the slip, |anchor shift| ell (1 - q). The
    // anchor shift is an arc of the closest point along the master's centerline; the slave, at
    // r from it, slides 1 - q times as far, q = r . x_m,uu / |x_m,u|^2 (the closest point's
    // phi_u = -|x_m,u|^2 (1 - q)), and that slip is what f_T works on. Interlocked loops touch
    // inside each other's bends, q ~ 0.5: without the factor the dissipation was about twice the
    // net work of closed strain loops (session 56's red team: 0.0921 against 0.0442 N mm).
    out.dissipation = lim * ell * one_q * std::abs(out.u_anchor_new - hist.u_anchor);
    out.energy = nv.energy + 0.5 * one_q * lim * lim / fr.k_T;
  }
  out.f = out.p * n + out.f_T * tau;
  const Vector3d nxt = n.cross(tau);
  out.m = -0.5 * d * out.f_T * nxt;
  if (!want_jac) return out;

  // ---- linearization ----
  MatrixXd Dxs = MatrixXd::Zero(3, nz), Dxm = MatrixXd::Zero(3, nz), Dxmu = MatrixXd::Zero(3, nz);
  Dxs.leftCols(3).setIdentity();
  for (int b = 0; b <= p; ++b) {
    Dxm.block(0, 3 + 3 * b, 3, 3) = cp.N(0, b) * Matrix3d::Identity();
    Dxmu.block(0, 3 + 3 * b, 3, 3) = cp.N(1, b) * Matrix3d::Identity();
  }
  const double phiu = -cp.x_u.squaredNorm() + r.dot(cp.x_uu);
  const Eigen::RowVectorXd du =
      -(cp.x_u.transpose() * Dxs - cp.x_u.transpose() * Dxm + r.transpose() * Dxmu) / phiu;
  const MatrixXd dr = Dxs - Dxm - cp.x_u * du;
  const Eigen::RowVectorXd drho = n.transpose() * dr;
  const MatrixXd dn = (Matrix3d::Identity() - n * n.transpose()) / rho * dr;
  const MatrixXd dxu = Dxmu + cp.x_uu * du;  // total derivative of x_m,u
  const Eigen::RowVectorXd dell = tau.transpose() * dxu;
  const MatrixXd dtau = (Matrix3d::Identity() - tau * tau.transpose()) / ell * dxu;
  const Eigen::RowVectorXd dp = nv.dp_dg * drho;
  Eigen::RowVectorXd dfT;
  if (tie) {
    dfT = Eigen::RowVectorXd::Zero(nz);
  } else if (!out.slip) {
    const Eigen::RowVectorXd de = ell * du + (pr.u - hist.u_anchor) * dell;
    dfT = -fr.k_T * de;
  } else {
    dfT = -fr.mu * sgn * dp;
  }
  out.df_dz = n * dp + out.p * dn + tau * dfT + out.f_T * dtau;
  // m = -(d/2) f_T (n x tau)
  MatrixXd dnxt(3, nz);
  for (int j = 0; j < nz; ++j)
    dnxt.col(j) = Vector3d(dn.col(j)).cross(tau) + n.cross(Vector3d(dtau.col(j)));
  out.dm_dz = -0.5 * d * (nxt * dfT + out.f_T * dnxt);
  out.du_dz = du;
  return out;
}

}  // namespace knit::meso::contact
