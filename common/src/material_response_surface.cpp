// Response-surface evaluation (paper eqs. 16-18); see the header for the inversion and the
// extrapolation rules.
#include "knit/material/response_surface.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "knit/spline/basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::material {

namespace {

constexpr double kPi = std::numbers::pi;
/// Below this |xi2| the scaled column G = (dE/dxi1)/xi2 is replaced by its limit d2E/dxi1dxi2.
constexpr double kTauXi2 = 1e-7;
/// Tolerance for "inside [0, 1]" when classifying an evaluation as extrapolated.
constexpr double kInsideTol = 1e-9;

void check_knots(const std::vector<double>& U, int p, int n, const std::string& what) {
  try {
    spline::validate_knots(U, p, n);
  } catch (const std::exception& e) {
    throw std::invalid_argument("response surface: " + what + ": " + e.what());
  }
  if (std::abs(U.front()) > 1e-14 || std::abs(U.back() - 1.0) > 1e-14)
    throw std::invalid_argument("response surface: " + what + ": the domain must be [0, 1]");
}

/// Values N[0..p] and first derivatives D[0..p] of the non-zero B-splines at u (clamped to
/// the domain), via A2.2 at degrees p-1 and p and N'_{i,p} = p (N_{i,p-1}/(u_{i+p}-u_i) -
/// N_{i+1,p-1}/(u_{i+p+1}-u_{i+1})) (The NURBS Book eq. 2.9). Returns the first index.
inline int basis_d1(const spline::BSplineBasis& b, double u, double* N, double* D) {
  const int p = b.degree();
  const double* U = b.knots().data();
  const int span = b.find_span(u);
  // Algorithm A2.2 (BasisFuns) up to degree p-1, kept, then its last step to degree p.
  double left[spline::kMaxDegree + 1], right[spline::kMaxDegree + 1];
  double Nm[spline::kMaxDegree + 2];
  N[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    if (j == p)
      for (int r = 0; r < p; ++r) Nm[r] = N[r];
    left[j] = u - U[span + 1 - j];
    right[j] = U[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
  if (p == 0) {
    D[0] = 0.0;
    return span;
  }
  // Nm[r] = N_{span-p+1+r, p-1}, r = 0..p-1; N_{span-p, p-1} = N_{span+1, p-1} = 0.
  for (int r = 0; r <= p; ++r) {
    const int i = span - p + r;
    double d = 0.0;
    if (r >= 1) d += Nm[r - 1] / (U[i + p] - U[i]);
    if (r <= p - 1) d -= Nm[r] / (U[i + p + 1] - U[i + 1]);
    D[r] = p * d;
  }
  return span - p;
}

}  // namespace

void validate(const ResponseSurfaceData& d) {
  if (d.degree1 < 1 || d.degree2 < 1 || d.shear_degree < 1)
    throw std::invalid_argument("response surface: degrees must be >= 1");
  if (d.degree1 > spline::kMaxDegree || d.degree2 > spline::kMaxDegree ||
      d.shear_degree > spline::kMaxDegree)
    throw std::invalid_argument("response surface: degree above the supported maximum");
  const int n1 = d.n1(), n2 = d.n2();
  check_knots(d.knots1, d.degree1, -1, "knots_1");
  check_knots(d.knots2, d.degree2, -1, "knots_2");
  if (d.E_ctrl.rows() != n1 * n2 || d.E_ctrl.cols() != 2)
    throw std::invalid_argument("response surface: E_ctrl must be " + std::to_string(n1 * n2) +
                                " x 2, got " + std::to_string(d.E_ctrl.rows()) + " x " +
                                std::to_string(d.E_ctrl.cols()));
  if (d.S_ctrl.rows() != n1 * n2 || d.S_ctrl.cols() != 2)
    throw std::invalid_argument("response surface: S_ctrl must be " + std::to_string(n1 * n2) +
                                " x 2, got " + std::to_string(d.S_ctrl.rows()) + " x " +
                                std::to_string(d.S_ctrl.cols()));
  if (!d.E_ctrl.allFinite() || !d.S_ctrl.allFinite())
    throw std::invalid_argument("response surface: control points are not finite");
  const double escale = std::max(1e-300, d.E_ctrl.cwiseAbs().maxCoeff());
  const double sscale = std::max(1e-300, d.S_ctrl.cwiseAbs().maxCoeff());
  for (int i = 0; i < n1; ++i)
    if (d.E_ctrl.row(i).cwiseAbs().maxCoeff() > 1e-12 * escale ||
        d.S_ctrl.row(i).cwiseAbs().maxCoeff() > 1e-12 * sscale)
      throw std::invalid_argument(
          "response surface: the edge xi2 = 0 must be the stress-free origin (E = S = 0 at "
          "control point " +
          std::to_string(i) + " of row 0)");
  const int ns = static_cast<int>(d.shear_knots.size()) - d.shear_degree - 1;
  check_knots(d.shear_knots, d.shear_degree, -1, "shear_knots");
  if (d.E12_ctrl.size() != ns || d.S12_ctrl.size() != ns)
    throw std::invalid_argument("response surface: the shear curve needs " + std::to_string(ns) +
                                " control values");
  if (!d.E12_ctrl.allFinite() || !d.S12_ctrl.allFinite())
    throw std::invalid_argument("response surface: shear control values are not finite");
  if (d.E12_ctrl(0) != 0.0 || d.S12_ctrl(0) != 0.0)
    throw std::invalid_argument("response surface: the shear curve must start at E12 = S12 = 0");
  for (int k = 1; k < ns; ++k)
    if (!(d.E12_ctrl(k) > d.E12_ctrl(k - 1)))
      throw std::invalid_argument(
          "response surface: shear E12 control values must increase (the curve must be "
          "invertible)");
}

void ExtensionOptions::validate() const {
  if (!(blend_begin_deg >= 0.0) || !(blend_end_deg > blend_begin_deg) || !(blend_end_deg <= 90.0))
    throw std::invalid_argument(
        "response surface extension: need 0 <= blend_begin_deg < blend_end_deg <= 90");
  if (!(compression_scale > 0.0) || !(compression_scale <= 1.0))
    throw std::invalid_argument(
        "response surface extension: compression_scale must be in (0, 1] (never stiffer than "
        "the fan's initial stiffness)");
  if (!(compression_floor > 0.0) || !(compression_floor <= 1.0))
    throw std::invalid_argument("response surface extension: compression_floor must be in (0, 1]");
}

ResponseSurface::ResponseSurface(ResponseSurfaceData data, ExtensionOptions extension)
    : data_(std::move(data)) {
  validate(data_);
  extension.validate();
  b1_ = spline::BSplineBasis(data_.degree1, data_.knots1);
  b2_ = spline::BSplineBasis(data_.degree2, data_.knots2);
  bs_ = spline::BSplineBasis(data_.shear_degree, data_.shear_knots);
  const int n = data_.n1() * data_.n2();
  P_.resize(n);
  for (int a = 0; a < n; ++a)
    P_[a] << data_.E_ctrl(a, 0), data_.E_ctrl(a, 1), data_.S_ctrl(a, 0), data_.S_ctrl(a, 1);
  E12_max_ = data_.E12_ctrl(data_.E12_ctrl.size() - 1);
  {
    // E12(u) = u * E12_max exactly when the E12 control values sit at the Greville abscissae
    // (linear precision of B-splines): then no Newton is needed for the shear curve.
    const auto g = bs_.greville();
    shear_linear_ = true;
    for (std::size_t k = 0; k < g.size(); ++k)
      if (std::abs(data_.E12_ctrl(k) - g[k] * E12_max_) > 1e-14 * E12_max_) shear_linear_ = false;
  }

  // Initial-guess table along the outer edge xi2 = 1; the fan must turn counter-clockwise.
  const int m = 8 * (data_.n1() - 1) + 1;
  table_xi_.resize(m);
  phi_.resize(m);
  radius_.resize(m);
  slope1_.resize(m);
  Eigen::Matrix4d V;
  for (int k = 0; k < m; ++k) {
    const double x = static_cast<double>(k) / (m - 1);
    eval4({x, 1.0}, V);
    table_xi_[k] = x;
    double phi = std::atan2(V(1, 0), V(0, 0));
    if (k > 0) {
      while (phi < phi_[k - 1] - kPi) phi += 2 * kPi;
      while (phi > phi_[k - 1] + kPi) phi -= 2 * kPi;
    }
    phi_[k] = phi;
    radius_[k] = std::hypot(V(0, 0), V(1, 0));
    // Radial growth beyond the last step (the extension is linear in xi2 there).
    slope1_[k] = radius_[k] > 0.0 ? (V(0, 0) * V(0, 2) + V(1, 0) * V(1, 2)) / radius_[k] : 0.0;
    if (k > 0 && !(phi_[k] > phi_[k - 1]))
      throw std::invalid_argument(
          "response surface: the E-surface edge xi2 = 1 does not turn counter-clockwise at xi1 "
          "= " +
          std::to_string(x) + " (paths must be ordered by increasing angle; surface folded)");
    if (!(radius_[k] > 0.0))
      throw std::invalid_argument("response surface: the E-surface edge xi2 = 1 passes through 0");
  }
  if (phi_.back() - phi_.front() >= kPi)
    throw std::invalid_argument("response surface: the fan of paths spans 180 degrees or more");
  // Invertibility on a grid: det [G_E, E_2] > 0 (G = (dE/dxi1)/xi2, its limit on xi2 = 0).
  const int g1 = 4 * (data_.n1() - 1) + 1, g2 = 4 * (data_.n2() - 1) + 1;
  for (int j = 0; j < g2; ++j)
    for (int i = 0; i < g1; ++i) {
      const double x1 = static_cast<double>(i) / (g1 - 1), x2 = static_cast<double>(j) / (g2 - 1);
      eval4({x1, x2}, V);
      const Eigen::Vector2d G = x2 > kTauXi2 ? Eigen::Vector2d(V.block<2, 1>(0, 1) / x2)
                                             : Eigen::Vector2d(V.block<2, 1>(0, 3));
      // det [E_2, G] > 0: the fan turns counter-clockwise (E_2 radial, G tangential).
      const double det = V(0, 2) * G(1) - V(1, 2) * G(0);
      if (!(det > 0.0))
        throw std::invalid_argument(
            "response surface: the E-surface is not invertible near xi = (" + std::to_string(x1) +
            ", " + std::to_string(x2) + ") (Jacobian determinant " + std::to_string(det) + ")");
    }

  // C0: least squares over the edge directions, C0 * E_2(xi1, 0) ~ S_2(xi1, 0).
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero(), B = Eigen::Matrix2d::Zero();
  for (int k = 0; k < m; ++k) {
    eval4({table_xi_[k], 0.0}, V);
    const Eigen::Vector2d e = V.block<2, 1>(0, 2), s = V.block<2, 1>(2, 2);
    A += e * e.transpose();
    B += s * e.transpose();
  }
  C0_.setZero();
  C0_.topLeftCorner<2, 2>() = B * A.inverse();
  double S12, dS;
  std::uint8_t f = 0;
  shear(0.0, S12, dS, f);
  C0_(2, 2) = 0.5 * dS;

  // The fan's angular range: every path (the guess table) at every step, with the initial
  // tangent (xi2 = 0) and the end tangent (the direction of the continuation beyond xi2 = 1).
  {
    const double mid = 0.5 * (phi_.front() + phi_.back());
    auto unwrap = [&](double a) {
      while (a < mid - kPi) a += 2 * kPi;
      while (a > mid + kPi) a -= 2 * kPi;
      return a;
    };
    lo_ = phi_.front();
    hi_ = phi_.back();
    const int steps = 4 * (data_.n2() - 1);
    for (int k = 0; k < m; ++k)
      for (int j = 0; j <= steps + 1; ++j) {
        eval4({table_xi_[k], std::min(1.0, static_cast<double>(j) / steps)}, V);
        const Eigen::Vector2d e = j == 0 || j > steps ? Eigen::Vector2d(V.block<2, 1>(0, 2))
                                                      : Eigen::Vector2d(V.block<2, 1>(0, 0));
        const double a = unwrap(std::atan2(e(1), e(0)));
        lo_ = std::min(lo_, a);
        hi_ = std::max(hi_, a);
      }
    if (hi_ - lo_ >= kPi)
      throw std::invalid_argument(
          "response surface: the paths (with their initial and end tangents) span 180 degrees "
          "or more");
    // The two bands (beyond hi and below lo) must not overlap on the far side.
    const double half_gap = kPi - 0.5 * (hi_ - lo_);
    const double deg = kPi / 180.0;
    const double shrink = std::min(1.0, half_gap / (extension.blend_end_deg * deg));
    beta0_ = shrink * extension.blend_begin_deg * deg;
    beta1_ = shrink * extension.blend_end_deg * deg;
  }
  // K_c: the symmetric part of C0's tensile block, eigenvalues floored, scaled (SPD).
  {
    const Eigen::Matrix2d C2 = C0_.topLeftCorner<2, 2>();
    const Eigen::Matrix2d Cs = 0.5 * (C2 + C2.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(Cs);
    const double lmax = es.eigenvalues().maxCoeff();
    if (!(lmax > 0.0))
      throw std::invalid_argument(
          "response surface: the fan's initial stiffness has no positive eigenvalue (no "
          "compression stiffness can be derived)");
    const Eigen::Vector2d lam =
        extension.compression_scale * es.eigenvalues().cwiseMax(extension.compression_floor * lmax);
    Kc_ = es.eigenvectors() * lam.asDiagonal() * es.eigenvectors().transpose();
  }
}

void ResponseSurface::eval4(const Eigen::Vector2d& xi, Eigen::Matrix4d& V) const {
  const int p1 = data_.degree1, p2 = data_.degree2, n1 = data_.n1();
  const double c1 = std::clamp(xi(0), 0.0, 1.0), c2 = std::clamp(xi(1), 0.0, 1.0);
  const double d1 = xi(0) - c1, d2 = xi(1) - c2;
  double N0[spline::kMaxDegree + 1], N1[spline::kMaxDegree + 1];
  double M0[spline::kMaxDegree + 1], M1[spline::kMaxDegree + 1];
  const int i0 = basis_d1(b1_, c1, N0, N1);
  const int j0 = basis_d1(b2_, c2, M0, M1);
  Eigen::Vector4d V0 = Eigen::Vector4d::Zero(), V1 = V0, V2 = V0, V12 = V0;
  for (int b = 0; b <= p2; ++b) {
    Eigen::Vector4d r0 = Eigen::Vector4d::Zero(), r1 = r0;
    const Eigen::Vector4d* P = &P_[(j0 + b) * n1 + i0];
    for (int a = 0; a <= p1; ++a) {
      r0 += N0[a] * P[a];
      r1 += N1[a] * P[a];
    }
    V0 += M0[b] * r0;
    V1 += M0[b] * r1;
    V2 += M1[b] * r0;
    V12 += M1[b] * r1;
  }
  V.col(0) = V0 + V1 * d1 + V2 * d2 + V12 * (d1 * d2);
  V.col(1) = V1 + V12 * d2;
  V.col(2) = V2 + V12 * d1;
  V.col(3) = V12;
}

Eigen::Vector4d ResponseSurface::point(const Eigen::Vector2d& xi) const {
  Eigen::Matrix4d V;
  eval4(xi, V);
  return V.col(0);
}

Eigen::Vector2d ResponseSurface::shear_point(double u) const {
  const int p = data_.shear_degree;
  double buf[2 * (spline::kMaxDegree + 1)];
  Eigen::Map<Eigen::MatrixXd> N(buf, 2, p + 1);
  const int i0 = bs_.eval(std::clamp(u, 0.0, 1.0), 0, N.topRows(1));
  Eigen::Vector2d r = Eigen::Vector2d::Zero();
  for (int a = 0; a <= p; ++a)
    r += N(0, a) * Eigen::Vector2d(data_.E12_ctrl(i0 + a), data_.S12_ctrl(i0 + a));
  return r;
}

void ResponseSurface::shear(double E12, double& S12, double& dS, std::uint8_t& flags) const {
  const double sign = E12 < 0.0 ? -1.0 : 1.0;
  const double x = std::abs(E12);
  const int p = data_.shear_degree;
  auto curve = [&](double u, Eigen::Vector2d& c, Eigen::Vector2d& dc) {
    double N0[spline::kMaxDegree + 1], N1[spline::kMaxDegree + 1];
    const int i0 = basis_d1(bs_, u, N0, N1);
    c.setZero();
    dc.setZero();
    for (int a = 0; a <= p; ++a) {
      const Eigen::Vector2d P(data_.E12_ctrl(i0 + a), data_.S12_ctrl(i0 + a));
      c += N0[a] * P;
      dc += N1[a] * P;
    }
  };
  Eigen::Vector2d c, dc;
  if (x >= E12_max_) {
    curve(1.0, c, dc);
    S12 = sign * (c(1) + dc(1) / dc(0) * (x - E12_max_));
    dS = dc(1) / dc(0);
    if (x > E12_max_ * (1.0 + kInsideTol)) flags |= kBeyondShear;
    return;
  }
  double u = x / E12_max_;
  for (int it = 0; it < kMaxIterations && !shear_linear_; ++it) {
    curve(u, c, dc);
    const double r = c(0) - x;
    if (std::abs(r) <= kTolAbs + kTolRel * x) break;
    u = std::clamp(u - r / dc(0), 0.0, 1.0);
  }
  curve(u, c, dc);
  S12 = sign * c(1);
  dS = dc(1) / dc(0);
}

Eigen::Vector2d ResponseSurface::initial_guess(double rE, double phi) const {
  // phi is unwrapped around the fan's range, so it lies within beta1 < pi - half-range of it.
  const int m = static_cast<int>(phi_.size());
  double xi1, r, dr, dphi = 0.0;
  if (phi <= phi_.front()) {
    const double slope = (phi_[1] - phi_[0]) / (table_xi_[1] - table_xi_[0]);
    dphi = std::max(phi - phi_.front(), -1.3);
    xi1 = std::tan(dphi) / slope;
    r = radius_.front();
    dr = slope1_.front();
  } else if (phi >= phi_.back()) {
    const double slope = (phi_[m - 1] - phi_[m - 2]) / (table_xi_[m - 1] - table_xi_[m - 2]);
    dphi = std::min(phi - phi_.back(), 1.3);
    xi1 = 1.0 + std::tan(dphi) / slope;
    r = radius_.back();
    dr = slope1_.back();
  } else {
    // phi is finite and inside (phi_.front(), phi_.back()): upper_bound stays in the table.
    const int k = std::clamp(
        static_cast<int>(std::upper_bound(phi_.begin(), phi_.end(), phi) - phi_.begin()) - 1, 0,
        m - 2);
    const double w = (phi - phi_[k]) / (phi_[k + 1] - phi_[k]);
    xi1 = table_xi_[k] + w * (table_xi_[k + 1] - table_xi_[k]);
    r = radius_[k] + w * (radius_[k + 1] - radius_[k]);
    dr = slope1_[k] + w * (slope1_[k + 1] - slope1_[k]);
  }
  const double s = rE * std::cos(dphi);
  // Beyond the last step the paths continue with their end tangent: a scale-aware guess keeps
  // Newton's step count bounded for any |E|.
  if (s > r && dr > 0.0) return {xi1, 1.0 + (s - r) / dr};
  return {xi1, s / r};
}

ResponseSurface::FanSolution ResponseSurface::solve_fan(const Eigen::Vector2d& Et,
                                                        double psi) const {
  FanSolution out;
  const double rE = Et.norm();
  Eigen::Vector2d xi = initial_guess(rE, psi);
  Eigen::Matrix4d V;
  Eigen::Matrix2d J;
  const double tol = kTolAbs + kTolRel * rE;
  bool converged = false;
  int it = 0;
  eval4(xi, V);
  Eigen::Vector2d r = V.block<2, 1>(0, 0) - Et;
  double rnorm = r.norm();
  for (; it < kMaxIterations; ++it) {
    if (rnorm <= tol) {
      converged = true;
      break;
    }
    // Scaled Jacobian [G, E_2], G = E_1 / xi2 (regular on the collapsed edge).
    if (std::abs(xi(1)) > kTauXi2)
      J.col(0) = V.block<2, 1>(0, 1) / xi(1);
    else
      J.col(0) = V.block<2, 1>(0, 3);
    J.col(1) = V.block<2, 1>(0, 2);
    const Eigen::Vector2d step = J.partialPivLu().solve(-r);  // (xi2 * dxi1, dxi2)
    if (!step.allFinite()) break;
    // The xi2 step limit is relative (far outside the square xi2 is large: a fixed limit would
    // need |xi2| / limit iterations), and every step is backtracked until |E(xi) - E| drops.
    // xi2 stays positive (the fan chart); at most it shrinks tenfold per step.
    const double lim2 = 0.5 * std::max(1.0, xi(1));
    double lambda = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < kMaxBacktracking && !accepted; ++ls, lambda *= 0.5) {
      const double x2new = std::max(xi(1) + std::clamp(lambda * step(1), -lim2, lim2), 0.1 * xi(1));
      // Polar update: the tangential correction xi2*dxi1 over the new radius parameter.
      const double d1 = x2new > 0.0 ? std::clamp(lambda * step(0) / x2new, -0.5, 0.5) : 0.0;
      const Eigen::Vector2d trial(xi(0) + d1, x2new);
      if (!trial.allFinite()) continue;
      eval4(trial, V);
      const Eigen::Vector2d rt = V.block<2, 1>(0, 0) - Et;
      const double rtn = rt.norm();
      if (rtn < rnorm || rtn <= tol) {
        xi = trial;
        r = rt;
        rnorm = rtn;
        accepted = true;
      }
    }
    if (!accepted) {
      eval4(xi, V);
      break;
    }
  }
  out.iterations = it;
  if (!converged) out.flags |= kInversionFailed;
  out.xi = xi;
  if (xi(1) > 1.0 + kInsideTol) out.flags |= kBeyondPaths;
  if (xi(0) < -kInsideTol || xi(0) > 1.0 + kInsideTol) out.flags |= kOutsideFan;

  Eigen::Matrix2d JE, JS;
  if (std::abs(xi(1)) > kTauXi2) {
    JE.col(0) = V.block<2, 1>(0, 1) / xi(1);
    JS.col(0) = V.block<2, 1>(2, 1) / xi(1);
  } else {
    JE.col(0) = V.block<2, 1>(0, 3);
    JS.col(0) = V.block<2, 1>(2, 3);
  }
  JE.col(1) = V.block<2, 1>(0, 2);
  JS.col(1) = V.block<2, 1>(2, 2);
  out.S = V.block<2, 1>(2, 0);
  out.C = JS * JE.inverse();
  return out;
}

ResponseEvaluation ResponseSurface::evaluate(const Eigen::Vector3d& E) const {
  ResponseEvaluation out;
  // A non-finite strain never reaches the lookups: flagged, with non-finite S and C.
  if (!E.allFinite() || !std::isfinite(E.head<2>().norm())) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.S.setConstant(nan);
    out.C.setConstant(nan);
    out.xi.setConstant(nan);
    out.flags = kInversionFailed | kNonFiniteStrain;
    return out;
  }
  // Shear: S12(E12), E12 = (2E12)/2; C33 = dS12/d(2E12).
  double S12, dS;
  shear(0.5 * E(2), S12, dS, out.flags);
  out.S(2) = S12;
  out.C(2, 2) = 0.5 * dS;

  const Eigen::Vector2d Et = E.head<2>();
  const double rE2 = Et.squaredNorm();
  // The unloaded state, up to round-off: the initial tangent C0, inside the data. Its direction
  // is noise there (session 39's walkthrough: a paper-law run's extrapolation report listed
  // (E11, E22) = (-3.6e-16, 2.7e-16) as "biaxial compression (linear initial law)", and the
  // tangent of such a state switched between C0 and the compression law's Kc by the sign of
  // the round-off).
  constexpr double kOriginRadius = 1e-12;
  if (rE2 <= kOriginRadius * kOriginRadius) {
    out.C.topLeftCorner<2, 2>() = C0_.topLeftCorner<2, 2>();
    out.S.head<2>() = C0_.topLeftCorner<2, 2>() * Et;
    return out;
  }
  // The angle psi of (E11, E22) unwrapped around the fan's range, its distance beta beyond the
  // range, and the C1 blending weight w(beta) of the compression law.
  const double centre = 0.5 * (lo_ + hi_), half = 0.5 * (hi_ - lo_);
  double psi = std::atan2(Et(1), Et(0));
  while (psi <= centre - kPi) psi += 2 * kPi;
  while (psi > centre + kPi) psi -= 2 * kPi;
  const double beta = std::abs(psi - centre) - half;
  double w = 0.0, dw_dbeta = 0.0;
  if (beta >= beta1_) {
    w = 1.0;
  } else if (beta > beta0_) {
    const double x = (beta - beta0_) / (beta1_ - beta0_);
    w = x * x * (3.0 - 2.0 * x);
    dw_dbeta = 6.0 * x * (1.0 - x) / (beta1_ - beta0_);
  }
  out.blend = w;
  if (w == 1.0) {
    out.S.head<2>() = Kc_ * Et;
    out.C.topLeftCorner<2, 2>() = Kc_;
    out.flags |= kCompression;
    return out;
  }
  const FanSolution f = solve_fan(Et, psi);
  out.xi = f.xi;
  out.flags |= f.flags;
  out.iterations = f.iterations;
  if (w == 0.0) {
    out.S.head<2>() = f.S;
    out.C.topLeftCorner<2, 2>() = f.C;
    return out;
  }
  // dw/dE = dw/dbeta * sign(psi - centre) * dpsi/dE, dpsi/dE = (-E22, E11) / |E|^2.
  const Eigen::Vector2d Sc = Kc_ * Et;
  const Eigen::Vector2d dw_dE =
      dw_dbeta * (psi > centre ? 1.0 : -1.0) * Eigen::Vector2d(-Et(1), Et(0)) / rE2;
  out.S.head<2>() = (1.0 - w) * f.S + w * Sc;
  out.C.topLeftCorner<2, 2>() = (1.0 - w) * f.C + w * Kc_ + (Sc - f.S) * dw_dE.transpose();
  out.flags |= kCompression;
  return out;
}

}  // namespace knit::material
