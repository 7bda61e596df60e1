#include "knit/spline/surface.hpp"

#include <stdexcept>

#include "knit/spline/basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::spline {

SplineSurface::SplineSurface(BSplineBasis bu, BSplineBasis bv, Eigen::MatrixXd P, Eigen::VectorXd w)
    : bu_(std::move(bu)), bv_(std::move(bv)), P_(std::move(P)), w_(std::move(w)) {
  const int n = bu_.size() * bv_.size();
  if (P_.rows() != n)
    throw KnotVectorError(KnotError::kCountMismatch,
                          "surface: " + std::to_string(P_.rows()) +
                              " control points but the knot vectors define " +
                              std::to_string(bu_.size()) + " x " + std::to_string(bv_.size()) +
                              " = " + std::to_string(n) + " basis functions");
  rational_ = w_.size() > 0;
  if (!rational_) {
    w_ = Eigen::VectorXd::Ones(n);
  } else {
    if (w_.size() != n)
      throw std::invalid_argument("surface: " + std::to_string(w_.size()) + " weights for " +
                                  std::to_string(n) + " control points");
    for (int i = 0; i < n; ++i)
      if (!(w_(i) > 0.0))
        throw std::invalid_argument("surface: weight " + std::to_string(i) + " is not positive");
  }
}

void SplineSurface::basis(double u, double v, int nder, SurfaceBasis& out) const {
  if (nder < 0 || nder > 2)
    throw std::invalid_argument("surface: derivative order " + std::to_string(nder) +
                                " outside 0..2");
  const int pu = bu_.degree(), pv = bv_.degree();
  const int nloc = (pu + 1) * (pv + 1);
  if (out.R.cols() != nloc) out.R.resize(6, nloc);
  if (out.index.size() != nloc) out.index.resize(nloc);
  out.nderiv = nder;
  // Stack storage for the 1-D derivatives (no heap allocation in quadrature loops).
  double bufu[3 * (kMaxDegree + 1)], bufv[3 * (kMaxDegree + 1)];
  Eigen::Map<Eigen::MatrixXd> Nu(bufu, nder + 1, pu + 1), Nv(bufv, nder + 1, pv + 1);
  const int iu0 = bu_.eval(u, nder, Nu);
  const int iv0 = bv_.eval(v, nder, Nv);
  const int nu = bu_.size();
  // Tensor products: rows 0 N, 1 N_u, 2 N_v, 3 N_uu, 4 N_uv, 5 N_vv.
  for (int b = 0; b <= pv; ++b) {
    for (int a = 0; a <= pu; ++a) {
      const int l = a + (pu + 1) * b;
      out.index(l) = (iu0 + a) + nu * (iv0 + b);
      out.R(0, l) = Nu(0, a) * Nv(0, b);
      if (nder >= 1) {
        out.R(1, l) = Nu(1, a) * Nv(0, b);
        out.R(2, l) = Nu(0, a) * Nv(1, b);
      }
      if (nder >= 2) {
        out.R(3, l) = Nu(2, a) * Nv(0, b);
        out.R(4, l) = Nu(1, a) * Nv(1, b);
        out.R(5, l) = Nu(0, a) * Nv(2, b);
      }
    }
  }
  if (!rational_) return;
  const int rows = nder == 0 ? 1 : (nder == 1 ? 3 : 6);
  double W[6] = {0, 0, 0, 0, 0, 0};
  for (int l = 0; l < nloc; ++l) {
    const double wl = w_(out.index(l));
    for (int r = 0; r < rows; ++r) {
      out.R(r, l) *= wl;
      W[r] += out.R(r, l);
    }
  }
  const double iW = 1.0 / W[0];
  for (int l = 0; l < nloc; ++l) {
    const double R = out.R(0, l) * iW;
    out.R(0, l) = R;
    if (nder >= 1) {
      const double Ru = (out.R(1, l) - R * W[1]) * iW;
      const double Rv = (out.R(2, l) - R * W[2]) * iW;
      if (nder >= 2) {
        out.R(3, l) = (out.R(3, l) - 2.0 * Ru * W[1] - R * W[3]) * iW;
        out.R(4, l) = (out.R(4, l) - Ru * W[2] - Rv * W[1] - R * W[4]) * iW;
        out.R(5, l) = (out.R(5, l) - 2.0 * Rv * W[2] - R * W[5]) * iW;
      }
      out.R(1, l) = Ru;
      out.R(2, l) = Rv;
    }
  }
}

Eigen::MatrixXd SplineSurface::derivatives(double u, double v, int nder) const {
  SurfaceBasis sb;
  basis(u, v, nder, sb);
  const int rows = nder == 0 ? 1 : (nder == 1 ? 3 : 6);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(rows, dim());
  for (int l = 0; l < sb.index.size(); ++l)
    for (int r = 0; r < rows; ++r) out.row(r) += sb.R(r, l) * P_.row(sb.index(l));
  return out;
}

Eigen::VectorXd SplineSurface::eval(double u, double v) const {
  return derivatives(u, v, 0).row(0).transpose();
}

}  // namespace knit::spline
