// Private k-refinement until knit/spline/refine.hpp is on main: the refined space contains
// the original one (degree raised by t, every breakpoint's multiplicity raised by t, knots
// inserted), so interpolating the homogeneous coordinates (w P, w) at the refined space's
// Greville abscissae reproduces the patch exactly (up to round-off).
#include "knit/macro/refinement.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "knit/spline/knot_vector.hpp"

namespace knit::macro {

namespace {

spline::BSplineBasis refined_basis(const spline::BSplineBasis& b, int p, int elements) {
  const int t = p - b.degree();
  const std::vector<double>& U = b.knots();
  const double a = b.lo(), c = b.hi();
  std::vector<double> V;
  for (double k : spline::unique_knots(U)) {
    const int m = spline::knot_multiplicity(U, k);
    const bool end = (k == a || k == c);
    const int mult = end ? p + 1 : m + t;
    for (int r = 0; r < mult; ++r) V.push_back(k);
  }
  const std::vector<double> bp = spline::unique_knots(U);
  for (int k = 1; k < elements; ++k) {
    const double x = a + (c - a) * k / elements;
    const bool present = std::any_of(bp.begin(), bp.end(),
                                     [&](double y) { return std::abs(x - y) <= 1e-10 * (c - a); });
    if (!present) V.push_back(x);
  }
  std::sort(V.begin(), V.end());
  return spline::BSplineBasis(p, V);
}

Eigen::MatrixXd collocation(const spline::BSplineBasis& b, const std::vector<double>& x) {
  Eigen::MatrixXd A(x.size(), b.size());
  for (size_t i = 0; i < x.size(); ++i) A.row(i) = b.eval_all(x[i]).transpose();
  return A;
}

}  // namespace

spline::SplineSurface refine_patch(const spline::SplineSurface& s, int p, int eu, int ev) {
  if (p < s.basis_u().degree() || p < s.basis_v().degree())
    throw std::invalid_argument("the refinement degree " + std::to_string(p) +
                                " is below the patch's degree");
  if (eu < 1 || ev < 1) throw std::invalid_argument("the number of elements must be at least 1");
  if (p == s.basis_u().degree() && p == s.basis_v().degree() && eu == 1 && ev == 1) return s;
  const spline::BSplineBasis bu = refined_basis(s.basis_u(), p, eu),
                             bv = refined_basis(s.basis_v(), p, ev);
  const std::vector<double> gu = bu.greville(), gv = bv.greville();
  const Eigen::MatrixXd Au = collocation(s.basis_u(), gu), Av = collocation(s.basis_v(), gv);
  const Eigen::PartialPivLU<Eigen::MatrixXd> Nu(collocation(bu, gu)), Nv(collocation(bv, gv));
  const int nu0 = s.size_u(), nv0 = s.size_v(), nu = bu.size(), nv = bv.size();
  const int dim = s.dim();
  Eigen::MatrixXd P(nu * nv, dim);
  Eigen::VectorXd w(nu * nv);
  for (int k = 0; k <= dim; ++k) {
    Eigen::MatrixXd C(nu0, nv0);  // homogeneous coordinate k of the control net
    for (int j = 0; j < nv0; ++j)
      for (int i = 0; i < nu0; ++i) {
        const int a = i + nu0 * j;
        C(i, j) = k < dim ? s.weights()(a) * s.control_points()(a, k) : s.weights()(a);
      }
    const Eigen::MatrixXd Vals = Au * C * Av.transpose();
    const Eigen::MatrixXd Cn = Nv.solve(Nu.solve(Vals).transpose()).transpose();
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        if (k < dim)
          P(i + nu * j, k) = Cn(i, j);
        else
          w(i + nu * j) = Cn(i, j);
      }
  }
  for (int a = 0; a < nu * nv; ++a) P.row(a) /= w(a);
  if (!s.rational()) return spline::SplineSurface(bu, bv, P);
  return spline::SplineSurface(bu, bv, P, w);
}

}  // namespace knit::macro
