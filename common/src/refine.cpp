#include "knit/spline/refine.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "knit/spline/knot_vector.hpp"

namespace knit::spline {

namespace {

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

double binomial(int n, int k) {
  double b = 1.0;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

// Homogeneous coordinates of a curve: (w P, w) for a NURBS, P itself for a B-spline.
Eigen::MatrixXd to_homogeneous(const Eigen::MatrixXd& P, const Eigen::VectorXd& w, bool rational) {
  if (!rational) return P;
  Eigen::MatrixXd Pw(P.rows(), P.cols() + 1);
  Pw.leftCols(P.cols()) = P.array().colwise() * w.array();
  Pw.col(P.cols()) = w;
  return Pw;
}

SplineCurve curve_from_strip(int p, KnotStrip ks, int dim, bool rational) {
  BSplineBasis basis(p, std::move(ks.U));
  if (!rational) return SplineCurve(std::move(basis), std::move(ks.Pw));
  Eigen::VectorXd w = ks.Pw.col(dim);
  Eigen::MatrixXd P = ks.Pw.leftCols(dim).array().colwise() / w.array();
  return SplineCurve(std::move(basis), std::move(P), std::move(w));
}

// A surface's homogeneous net rearranged as a strip along `dir`: for dir = u, row i holds the
// homogeneous coordinates of P_{i,0}, P_{i,1}, ... side by side (D columns each).
Eigen::MatrixXd surface_to_strip(const SplineSurface& s, Direction dir) {
  const Eigen::MatrixXd H = to_homogeneous(s.control_points(), s.weights(), s.rational());
  const int D = static_cast<int>(H.cols());
  const int nu = s.size_u(), nv = s.size_v();
  const bool du = dir == Direction::kU;
  const int n = du ? nu : nv, other = du ? nv : nu;
  Eigen::MatrixXd M(n, static_cast<Eigen::Index>(other) * D);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int row = du ? i : j, blk = du ? j : i;
      M.block(row, static_cast<Eigen::Index>(blk) * D, 1, D) = H.row(i + nu * j);
    }
  return M;
}

SplineSurface surface_from_strip(const SplineSurface& s, Direction dir, int p_new, KnotStrip ks) {
  const int dim = s.dim();
  const int D = s.rational() ? dim + 1 : dim;
  const bool du = dir == Direction::kU;
  BSplineBasis bnew(p_new, std::move(ks.U));
  const int nu = du ? bnew.size() : s.size_u();
  const int nv = du ? s.size_v() : bnew.size();
  Eigen::MatrixXd H(static_cast<Eigen::Index>(nu) * nv, D);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int row = du ? i : j, blk = du ? j : i;
      H.row(i + nu * j) = ks.Pw.block(row, static_cast<Eigen::Index>(blk) * D, 1, D);
    }
  BSplineBasis bu = du ? std::move(bnew) : s.basis_u();
  BSplineBasis bv = du ? s.basis_v() : std::move(bnew);
  if (!s.rational()) return SplineSurface(std::move(bu), std::move(bv), std::move(H));
  Eigen::VectorXd w = H.col(dim);
  Eigen::MatrixXd P = H.leftCols(dim).array().colwise() / w.array();
  return SplineSurface(std::move(bu), std::move(bv), std::move(P), std::move(w));
}

void check_inside(const std::vector<double>& U, int p, double u, const char* what) {
  const int n = num_basis(U, p);
  if (!std::isfinite(u) || !(u > U[p] && u < U[n]))
    throw std::invalid_argument(std::string(what) + ": knot " + fmt(u) +
                                " is not strictly inside the domain (" + fmt(U[p]) + ", " +
                                fmt(U[n]) + ")");
}

}  // namespace

KnotStrip curve_knot_ins(int p, const std::vector<double>& UP, const Eigen::MatrixXd& Pw, double u,
                         int r) {
  // Algorithm A5.1 (CurveKnotIns), The NURBS Book p. 151. Book indices: np = n - 1 is the last
  // control point, k the span of u (UP[k] <= u < UP[k+1]), s the multiplicity of u.
  if (r < 0) throw std::invalid_argument("insert_knot: the number of insertions is negative");
  check_inside(UP, p, u, "insert_knot");
  const int n = num_basis(UP, p);
  KnotStrip out;
  if (r == 0) {
    out.U = UP;
    out.Pw = Pw;
    return out;
  }
  const int np = n - 1;
  const int mp = np + p + 1;
  const int k = find_span(n, p, u, UP);
  const int s = knot_multiplicity(UP, u);
  if (s + r > p)
    throw std::invalid_argument("insert_knot: knot " + fmt(u) + " has multiplicity " +
                                std::to_string(s) + "; inserting it " + std::to_string(r) +
                                " more times exceeds the degree " + std::to_string(p));
  out.U.resize(UP.size() + r);
  for (int i = 0; i <= k; ++i) out.U[i] = UP[i];
  for (int i = 1; i <= r; ++i) out.U[k + i] = u;
  for (int i = k + 1; i <= mp; ++i) out.U[i + r] = UP[i];
  const Eigen::Index C = Pw.cols();
  out.Pw.resize(n + r, C);
  for (int i = 0; i <= k - p; ++i) out.Pw.row(i) = Pw.row(i);
  for (int i = k - s; i <= np; ++i) out.Pw.row(i + r) = Pw.row(i);
  Eigen::MatrixXd Rw = Pw.middleRows(k - p, p - s + 1);
  int L = k - p;
  for (int j = 1; j <= r; ++j) {
    L = k - p + j;
    for (int i = 0; i <= p - j - s; ++i) {
      const double alpha = (u - UP[L + i]) / (UP[i + k + 1] - UP[L + i]);
      Rw.row(i) = alpha * Rw.row(i + 1) + (1.0 - alpha) * Rw.row(i);
    }
    out.Pw.row(L) = Rw.row(0);
    out.Pw.row(k + r - j - s) = Rw.row(p - j - s);
  }
  for (int i = L + 1; i < k - s; ++i) out.Pw.row(i) = Rw.row(i - L);
  return out;
}

KnotStrip refine_knot_vect(int p, const std::vector<double>& U, const Eigen::MatrixXd& Pw,
                           std::vector<double> X) {
  // Algorithm A5.4 (RefineKnotVectCurve), The NURBS Book p. 164, with the book's n = nb - 1
  // (last control point index), m = n + p + 1 (last knot index) and r = X.size() - 1.
  KnotStrip out;
  if (X.empty()) {
    out.U = U;
    out.Pw = Pw;
    return out;
  }
  std::sort(X.begin(), X.end());
  for (double x : X) check_inside(U, p, x, "insert_knots");
  for (size_t i = 0; i < X.size();) {
    size_t j = i;
    while (j < X.size() && X[j] == X[i]) ++j;
    const int mult = knot_multiplicity(U, X[i]) + static_cast<int>(j - i);
    if (mult > p)
      throw std::invalid_argument("insert_knots: knot " + fmt(X[i]) + " would get multiplicity " +
                                  std::to_string(mult) + ", more than the degree " +
                                  std::to_string(p));
    i = j;
  }
  const int nb = num_basis(U, p);
  const int n = nb - 1, m = n + p + 1;
  const int r = static_cast<int>(X.size()) - 1;
  const int a = find_span(nb, p, X[0], U);
  const int b = find_span(nb, p, X[r], U) + 1;
  out.U.assign(U.size() + X.size(), 0.0);
  out.Pw.resize(nb + r + 1, Pw.cols());
  std::vector<double>& Ubar = out.U;
  Eigen::MatrixXd& Qw = out.Pw;
  for (int j = 0; j <= a - p; ++j) Qw.row(j) = Pw.row(j);
  for (int j = b - 1; j <= n; ++j) Qw.row(j + r + 1) = Pw.row(j);
  for (int j = 0; j <= a; ++j) Ubar[j] = U[j];
  for (int j = b + p; j <= m; ++j) Ubar[j + r + 1] = U[j];
  int i = b + p - 1, k = b + p + r;
  for (int j = r; j >= 0; --j) {
    while (X[j] <= U[i] && i > a) {
      Qw.row(k - p - 1) = Pw.row(i - p - 1);
      Ubar[k] = U[i];
      --k;
      --i;
    }
    Qw.row(k - p - 1) = Qw.row(k - p);
    for (int l = 1; l <= p; ++l) {
      const int ind = k - p + l;
      double alfa = Ubar[k + l] - X[j];
      if (alfa == 0.0) {
        Qw.row(ind - 1) = Qw.row(ind);
      } else {
        alfa /= (Ubar[k + l] - U[i - p + l]);
        Qw.row(ind - 1) = alfa * Qw.row(ind - 1) + (1.0 - alfa) * Qw.row(ind);
      }
    }
    Ubar[k] = X[j];
    --k;
  }
  return out;
}

KnotStrip degree_elevate(int p, const std::vector<double>& U, const Eigen::MatrixXd& Pw, int t) {
  if (t < 0)
    throw std::invalid_argument(
        "elevate_degree: cannot lower the degree (t = " + std::to_string(t) + ")");
  const int nb = num_basis(U, p);
  KnotStrip out;
  if (t == 0) {
    out.U = U;
    out.Pw = Pw;
    return out;
  }
  // Interior knots of multiplicity p+1 (C^{-1} breaks) are outside A5.9's assumptions.
  for (int i = p + 1; i < nb; ++i)
    if (knot_multiplicity(U, U[i]) > p)
      throw std::invalid_argument(
          "elevate_degree: interior knot " + fmt(U[i]) + " has multiplicity " +
          std::to_string(knot_multiplicity(U, U[i])) + " > degree " + std::to_string(p) +
          " (a discontinuity); split the spline there first");
  if (p == 0) {
    // Here a single element: a constant, whose elevated Bezier form repeats the point.
    out.U.assign(t + 1, U.front());
    out.U.insert(out.U.end(), t + 1, U.back());
    out.Pw = Pw.row(0).replicate(t + 1, 1);
    return out;
  }
  // Algorithm A5.9 (DegreeElevateCurve), The NURBS Book p. 206. Book indices: n = nb - 1,
  // m = n + p + 1; ph = p + t the new degree.
  const int n = nb - 1, m = n + p + 1;
  const int ph = p + t, ph2 = ph / 2;
  const Eigen::Index C = Pw.cols();
  // Bezier degree elevation coefficients (eq. 5.36).
  Eigen::MatrixXd bezalfs = Eigen::MatrixXd::Zero(ph + 1, p + 1);
  bezalfs(0, 0) = bezalfs(ph, p) = 1.0;
  for (int i = 1; i <= ph2; ++i) {
    const double inv = 1.0 / binomial(ph, i);
    const int mpi = std::min(p, i);
    for (int j = std::max(0, i - t); j <= mpi; ++j)
      bezalfs(i, j) = inv * binomial(p, j) * binomial(t, i - j);
  }
  for (int i = ph2 + 1; i <= ph - 1; ++i) {
    const int mpi = std::min(p, i);
    for (int j = std::max(0, i - t); j <= mpi; ++j) bezalfs(i, j) = bezalfs(ph - i, p - j);
  }
  // Upper bounds for the output sizes: every distinct knot gains t copies.
  const int ndistinct = static_cast<int>(unique_knots(U).size());
  std::vector<double> Uh(U.size() + static_cast<size_t>(ndistinct) * t, 0.0);
  Eigen::MatrixXd Qw(nb + (ndistinct - 1) * t, C);
  Eigen::MatrixXd bpts(p + 1, C), ebpts(ph + 1, C), Nextbpts(std::max(p - 1, 1), C);
  std::vector<double> alfs(std::max(p - 1, 1));

  int mh = ph, kind = ph + 1;
  int r = -1, a = p, b = p + 1, cind = 1;
  double ua = U[0];
  Qw.row(0) = Pw.row(0);
  for (int i = 0; i <= ph; ++i) Uh[i] = ua;
  for (int i = 0; i <= p; ++i) bpts.row(i) = Pw.row(i);  // first Bezier segment
  while (b < m) {                                        // big loop through the knot vector
    const int i0 = b;
    while (b < m && U[b] == U[b + 1]) ++b;
    const int mul = b - i0 + 1;
    mh += mul + t;
    const double ub = U[b];
    const int oldr = r;
    r = p - mul;
    // Insert knot u(b) r times.
    const int lbz = oldr > 0 ? (oldr + 2) / 2 : 1;
    const int rbz = r > 0 ? ph - (r + 1) / 2 : ph;
    if (r > 0) {  // insert knots to get the Bezier segment
      const double numer = ub - ua;
      for (int k = p; k > mul; --k) alfs[k - mul - 1] = numer / (U[a + k] - ua);
      for (int j = 1; j <= r; ++j) {
        const int save = r - j, s = mul + j;
        for (int k = p; k >= s; --k)
          bpts.row(k) = alfs[k - s] * bpts.row(k) + (1.0 - alfs[k - s]) * bpts.row(k - 1);
        Nextbpts.row(save) = bpts.row(p);
      }
    }
    for (int i = lbz; i <= ph; ++i) {  // degree-elevate the Bezier segment
      ebpts.row(i).setZero();
      const int mpi = std::min(p, i);
      for (int j = std::max(0, i - t); j <= mpi; ++j) ebpts.row(i) += bezalfs(i, j) * bpts.row(j);
    }
    if (oldr > 1) {  // remove knot u = U[a] oldr times
      int first = kind - 2, last = kind;
      const double den = ub - ua;
      const double bet = (ub - Uh[kind - 1]) / den;
      for (int tr = 1; tr < oldr; ++tr) {  // knot removal loop
        int i = first, j = last, kj = j - kind + 1;
        while (j - i > tr) {  // new control points for one removal step
          if (i < cind) {
            const double alf = (ub - Uh[i]) / (ua - Uh[i]);
            Qw.row(i) = alf * Qw.row(i) + (1.0 - alf) * Qw.row(i - 1);
          }
          if (j >= lbz) {
            if (j - tr <= kind - ph + oldr) {
              const double gam = (ub - Uh[j - tr]) / den;
              ebpts.row(kj) = gam * ebpts.row(kj) + (1.0 - gam) * ebpts.row(kj + 1);
            } else {
              ebpts.row(kj) = bet * ebpts.row(kj) + (1.0 - bet) * ebpts.row(kj + 1);
            }
          }
          ++i;
          --j;
          --kj;
        }
        --first;
        ++last;
      }
    }
    if (a != p)  // load the knot ua
      for (int i = 0; i < ph - oldr; ++i) Uh[kind++] = ua;
    for (int j = lbz; j <= rbz; ++j) Qw.row(cind++) = ebpts.row(j);  // load control points
    if (b < m) {  // set up for the next pass through the loop
      for (int j = 0; j < r; ++j) bpts.row(j) = Nextbpts.row(j);
      for (int j = r; j <= p; ++j) bpts.row(j) = Pw.row(b - p + j);
      a = b;
      ++b;
      ua = ub;
    } else {
      for (int i = 0; i <= ph; ++i) Uh[kind + i] = ub;  // end knot
    }
  }
  const int nh = mh - ph - 1;  // book: index of the last new control point
  out.U.assign(Uh.begin(), Uh.begin() + mh + 1);
  out.Pw = Qw.topRows(nh + 1);
  return out;
}

// --- Curves -----------------------------------------------------------------------------------

SplineCurve insert_knot(const SplineCurve& c, double u, int times) {
  const Eigen::MatrixXd Pw = to_homogeneous(c.control_points(), c.weights(), c.rational());
  return curve_from_strip(c.degree(), curve_knot_ins(c.degree(), c.knots(), Pw, u, times), c.dim(),
                          c.rational());
}

SplineCurve insert_knots(const SplineCurve& c, const std::vector<double>& X) {
  const Eigen::MatrixXd Pw = to_homogeneous(c.control_points(), c.weights(), c.rational());
  return curve_from_strip(c.degree(), refine_knot_vect(c.degree(), c.knots(), Pw, X), c.dim(),
                          c.rational());
}

SplineCurve elevate_degree(const SplineCurve& c, int t) {
  const Eigen::MatrixXd Pw = to_homogeneous(c.control_points(), c.weights(), c.rational());
  return curve_from_strip(c.degree() + t, degree_elevate(c.degree(), c.knots(), Pw, t), c.dim(),
                          c.rational());
}

std::vector<double> missing_uniform_breakpoints(const BSplineBasis& basis, int elements) {
  if (elements < 1)
    throw std::invalid_argument("refine: the number of elements must be at least 1, got " +
                                std::to_string(elements));
  const double a = basis.lo(), b = basis.hi();
  const double tol = 1e-10 * (b - a);
  const std::vector<double> have = basis.breakpoints();
  std::vector<double> X;
  for (int k = 1; k < elements; ++k) {
    const double x = a + (b - a) * static_cast<double>(k) / elements;
    const bool present =
        std::any_of(have.begin(), have.end(), [&](double y) { return std::abs(x - y) <= tol; });
    if (!present) X.push_back(x);
  }
  return X;
}

namespace {
int elevation_needed(int have, int p, const char* what) {
  if (p < 0)
    throw std::invalid_argument(std::string("refine: target degree ") + std::to_string(p) +
                                " is negative");
  if (have > p)
    throw std::invalid_argument(std::string("refine: the ") + what + " has degree " +
                                std::to_string(have) + ", higher than the requested degree " +
                                std::to_string(p) + " (degree reduction is not supported)");
  return p - have;
}
}  // namespace

SplineCurve refine(const SplineCurve& c, int p, int elements) {
  const SplineCurve e = elevate_degree(c, elevation_needed(c.degree(), p, "curve"));
  return insert_knots(e, missing_uniform_breakpoints(e.basis(), elements));
}

// --- Surfaces ---------------------------------------------------------------------------------

SplineSurface insert_knot(const SplineSurface& s, Direction dir, double u, int times) {
  const BSplineBasis& b = dir == Direction::kU ? s.basis_u() : s.basis_v();
  return surface_from_strip(
      s, dir, b.degree(),
      curve_knot_ins(b.degree(), b.knots(), surface_to_strip(s, dir), u, times));
}

SplineSurface insert_knots(const SplineSurface& s, Direction dir, const std::vector<double>& X) {
  const BSplineBasis& b = dir == Direction::kU ? s.basis_u() : s.basis_v();
  return surface_from_strip(s, dir, b.degree(),
                            refine_knot_vect(b.degree(), b.knots(), surface_to_strip(s, dir), X));
}

SplineSurface elevate_degree(const SplineSurface& s, int tu, int tv) {
  SplineSurface r = s;
  if (tu != 0) {
    const BSplineBasis& b = r.basis_u();
    r = surface_from_strip(
        r, Direction::kU, b.degree() + tu,
        degree_elevate(b.degree(), b.knots(), surface_to_strip(r, Direction::kU), tu));
  }
  if (tv != 0) {
    const BSplineBasis& b = r.basis_v();
    r = surface_from_strip(
        r, Direction::kV, b.degree() + tv,
        degree_elevate(b.degree(), b.knots(), surface_to_strip(r, Direction::kV), tv));
  }
  return r;
}

SplineSurface refine(const SplineSurface& s, int p, int elements_u, int elements_v) {
  const int tu = elevation_needed(s.basis_u().degree(), p, "surface (u direction)");
  const int tv = elevation_needed(s.basis_v().degree(), p, "surface (v direction)");
  SplineSurface e = elevate_degree(s, tu, tv);
  e = insert_knots(e, Direction::kU, missing_uniform_breakpoints(e.basis_u(), elements_u));
  return insert_knots(e, Direction::kV, missing_uniform_breakpoints(e.basis_v(), elements_v));
}

}  // namespace knit::spline
