// Knot insertion (A5.1, A5.3, A5.4), degree elevation (A5.9) and k-refinement leave curves and
// surfaces unchanged: checked pointwise at many parameters, for B-splines and NURBS, in 1-D to 4-D.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "knit/spline/knot_vector.hpp"
#include "knit/spline/refine.hpp"

using namespace knit::spline;

namespace {

// A random spline with the given degree and knots (interior knots possibly repeated).
SplineCurve random_curve(int p, std::vector<double> U, int dim, bool rational, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-1.0, 1.0), dw(0.3, 2.0);
  BSplineBasis b(p, std::move(U));
  Eigen::MatrixXd P(b.size(), dim);
  for (int i = 0; i < P.size(); ++i) P.data()[i] = d(gen);
  Eigen::VectorXd w;
  if (rational) {
    w.resize(b.size());
    for (int i = 0; i < w.size(); ++i) w(i) = dw(gen);
  }
  return SplineCurve(b, P, w);
}

SplineSurface random_surface(int pu, std::vector<double> U, int pv, std::vector<double> V, int dim,
                             bool rational, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-1.0, 1.0), dw(0.3, 2.0);
  BSplineBasis bu(pu, std::move(U)), bv(pv, std::move(V));
  const int n = bu.size() * bv.size();
  Eigen::MatrixXd P(n, dim);
  for (int i = 0; i < P.size(); ++i) P.data()[i] = d(gen);
  Eigen::VectorXd w;
  if (rational) {
    w.resize(n);
    for (int i = 0; i < n; ++i) w(i) = dw(gen);
  }
  return SplineSurface(bu, bv, P, w);
}

// Largest difference of values and first two derivatives (relative to their size) at 201 points
// spread over the domain, both ends included.
double curve_distance(const SplineCurve& a, const SplineCurve& b) {
  double e = 0.0;
  const double lo = a.basis().lo(), hi = a.basis().hi();
  for (int i = 0; i <= 200; ++i) {
    const double u = lo + (hi - lo) * i / 200.0;
    e = std::max(e, (a.eval(u) - b.eval(u)).cwiseAbs().maxCoeff());
  }
  return e;
}

double surface_distance(const SplineSurface& a, const SplineSurface& b) {
  double e = 0.0;
  for (int i = 0; i <= 30; ++i)
    for (int j = 0; j <= 30; ++j) {
      const double u = a.basis_u().lo() + (a.basis_u().hi() - a.basis_u().lo()) * i / 30.0;
      const double v = a.basis_v().lo() + (a.basis_v().hi() - a.basis_v().lo()) * j / 30.0;
      e = std::max(e, (a.eval(u, v) - b.eval(u, v)).cwiseAbs().maxCoeff());
    }
  return e;
}

const std::vector<double> kU3 = {0,   0,   0, 0, 0.2, 0.5,
                                 0.5, 0.7, 1, 1, 1,   1};  // p = 3, a double knot

}  // namespace

TEST_CASE("knot insertion (A5.1) reproduces curves", "[unit][spline][refine]") {
  const int dim = GENERATE(1, 3, 4);
  const bool rational = GENERATE(false, true);
  const SplineCurve c = random_curve(3, kU3, dim, rational, 7 + dim);
  for (auto [u, times] : {std::pair{0.1, 1}, {0.2, 2}, {0.5, 1}, {0.63, 3}, {0.99, 2}}) {
    const SplineCurve r = insert_knot(c, u, times);
    CHECK(r.size() == c.size() + times);
    CHECK(r.rational() == rational);
    CHECK(knot_multiplicity(r.knots(), u) == knot_multiplicity(c.knots(), u) + times);
    CHECK(curve_distance(c, r) < 1e-12);
  }
  CHECK_THROWS_AS(insert_knot(c, 0.5, 2), std::invalid_argument);  // 2 + 2 > p
  CHECK_THROWS_AS(insert_knot(c, 0.0), std::invalid_argument);     // domain end
  CHECK_THROWS_AS(insert_knot(c, 1.5), std::invalid_argument);     // outside
}

TEST_CASE("knot refinement (A5.4) equals repeated single insertion", "[unit][spline][refine]") {
  const bool rational = GENERATE(false, true);
  const SplineCurve c = random_curve(4, uniform_knots(4, 3), 3, rational, 11);
  const std::vector<double> X = {0.9, 0.05, 0.5, 0.5, 1.0 / 3.0, 0.6};
  const SplineCurve r = insert_knots(c, X);
  SplineCurve s = c;
  for (double x : X) s = insert_knot(s, x);
  REQUIRE(r.knots().size() == s.knots().size());
  for (size_t i = 0; i < r.knots().size(); ++i) CHECK(r.knots()[i] == s.knots()[i]);
  CHECK((r.control_points() - s.control_points()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((r.weights() - s.weights()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(curve_distance(c, r) < 1e-12);
}

TEST_CASE("degree elevation (A5.9) reproduces curves and keeps continuity",
          "[unit][spline][refine]") {
  const int dim = GENERATE(1, 3, 4);
  const bool rational = GENERATE(false, true);
  for (int p : {1, 2, 3}) {
    std::vector<double> U(p + 1, 0.0);
    for (double k : {0.25, 0.25, 0.4, 0.8}) U.push_back(k);
    if (p == 1) U = {0, 0, 0.25, 0.4, 0.8};  // p = 1 allows no double knot
    U.insert(U.end(), p + 1, 1.0);
    const SplineCurve c = random_curve(p, U, dim, rational, 3 + p);
    for (int t : {1, 2, 3}) {
      const SplineCurve e = elevate_degree(c, t);
      CHECK(e.degree() == p + t);
      // Every distinct knot's multiplicity grows by t.
      for (double k : unique_knots(c.knots()))
        CHECK(knot_multiplicity(e.knots(), k) == knot_multiplicity(c.knots(), k) + t);
      CHECK(curve_distance(c, e) < 1e-12);
    }
  }
}

TEST_CASE("degree elevation of a single Bezier segment and of a constant",
          "[unit][spline][refine]") {
  const SplineCurve c = random_curve(2, {0, 0, 0, 1, 1, 1}, 2, true, 5);
  const SplineCurve e = elevate_degree(c, 2);
  CHECK(e.size() == 5);
  CHECK(curve_distance(c, e) < 1e-12);
  Eigen::MatrixXd P(1, 2);
  P << 0.3, -0.7;
  const SplineCurve k(BSplineBasis(0, {0.0, 2.0}), P);
  const SplineCurve ke = elevate_degree(k, 3);
  CHECK(ke.degree() == 3);
  CHECK(curve_distance(k, ke) < 1e-15);
  // A C^{-1} break cannot be elevated by A5.9.
  const SplineCurve d = random_curve(1, {0, 0, 0.5, 0.5, 1, 1}, 2, false, 1);
  CHECK_THROWS_AS(elevate_degree(d, 1), std::invalid_argument);
}

TEST_CASE("refine(curve, p, elements) keeps the geometry", "[unit][spline][refine]") {
  const bool rational = GENERATE(false, true);
  // The exact quarter circle, refined to a quartic with 7 elements, stays a circle.
  Eigen::MatrixXd P(3, 2);
  P << 1, 0, 1, 1, 0, 1;
  Eigen::VectorXd w(3);
  w << 1, std::sqrt(0.5), 1;
  const SplineCurve circle(BSplineBasis(2, {0, 0, 0, 1, 1, 1}), P, w);
  const SplineCurve r = refine(circle, 4, 7);
  CHECK(r.degree() == 4);
  CHECK(r.basis().num_elements() == 7);
  CHECK(r.size() == 4 + 7);
  for (int i = 0; i <= 100; ++i) CHECK(std::abs(r.eval(i / 100.0).norm() - 1.0) < 1e-14);
  // Existing breakpoints are kept; the uniform ones are added.
  const SplineCurve c = random_curve(2, {0, 0, 0, 0.3, 1, 1, 1}, 3, rational, 9);
  const SplineCurve rc = refine(c, 3, 4);
  CHECK(rc.degree() == 3);
  CHECK(rc.basis().breakpoints() == std::vector<double>{0, 0.25, 0.3, 0.5, 0.75, 1});
  CHECK(curve_distance(c, rc) < 1e-12);
  CHECK_THROWS_AS(refine(rc, 2, 4), std::invalid_argument);  // degree reduction
  CHECK_THROWS_AS(refine(rc, 3, 0), std::invalid_argument);
  // Already at the requested degree and elements: nothing changes.
  const SplineCurve same = refine(rc, 3, 2);
  CHECK(same.size() == rc.size());
}

TEST_CASE("surface knot insertion (A5.3) and refinement in both directions",
          "[unit][spline][refine]") {
  const int dim = GENERATE(1, 3, 4);
  const bool rational = GENERATE(false, true);
  const SplineSurface s =
      random_surface(2, {0, 0, 0, 0.4, 1, 1, 1}, 3, kU3, dim, rational, 21 + dim);
  const SplineSurface su = insert_knot_u(s, 0.7, 2);
  CHECK(su.size_u() == s.size_u() + 2);
  CHECK(su.size_v() == s.size_v());
  CHECK(surface_distance(s, su) < 1e-12);
  const SplineSurface sv = insert_knot_v(s, 0.5);
  CHECK(sv.size_v() == s.size_v() + 1);
  CHECK(surface_distance(s, sv) < 1e-12);
  const SplineSurface sx = insert_knots(s, Direction::kV, {0.1, 0.1, 0.9});
  CHECK(surface_distance(s, sx) < 1e-12);
  CHECK_THROWS_AS(insert_knot_v(s, 0.5, 2), std::invalid_argument);
}

TEST_CASE("surface degree elevation and refine(surface, p, eu, ev)", "[unit][spline][refine]") {
  const bool rational = GENERATE(false, true);
  const SplineSurface s =
      random_surface(2, {0, 0, 0, 0.4, 1, 1, 1}, 1, {0, 0, 0.5, 1, 1}, 3, rational, 33);
  const SplineSurface e = elevate_degree(s, 1, 2);
  CHECK(e.basis_u().degree() == 3);
  CHECK(e.basis_v().degree() == 3);
  CHECK(surface_distance(s, e) < 1e-12);
  const SplineSurface r = refine(s, 3, 5, 4);
  CHECK(r.basis_u().degree() == 3);
  CHECK(r.basis_v().degree() == 3);
  CHECK(r.basis_u().breakpoints() == std::vector<double>{0, 0.2, 0.4, 0.6, 0.8, 1});
  CHECK(r.basis_v().num_elements() == 4);
  CHECK(surface_distance(s, r) < 1e-12);
  // A single-element surface ends with exactly the requested elements: (p + e) functions each way.
  const SplineSurface b = random_surface(1, {0, 0, 1, 1}, 1, {0, 0, 1, 1}, 3, rational, 2);
  const SplineSurface rb = refine(b, 3, 11, 11);
  CHECK(rb.size_u() == 14);
  CHECK(rb.size_v() == 14);
  CHECK(surface_distance(b, rb) < 1e-12);
  CHECK_THROWS_AS(refine(r, 2, 4, 4), std::invalid_argument);
}
