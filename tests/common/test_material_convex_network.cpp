// The input-convex network of the energy-based law (knit/material/convex_network.hpp): the
// activation, the closed-form S and C against finite differences, convexity for any
// nonnegative weights, the fit's reverse-mode gradient against finite differences, the
// mirror-averaged law, and validation (its l-derivative: test_material_energy_law.cpp).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <catch2/catch.hpp>
#include <random>

#include "knit/material/energy_law.hpp"
#include "test_energy_util.hpp"

using namespace knit::material;

namespace {

std::vector<double> random_theta(const NetworkShape& sh, unsigned seed) {
  return testing::make_test_network_law(seed, 0.0, sh.h1, sh.h2).network.theta_at(5.0);
}

}  // namespace

namespace {

using Activation = void (*)(double, double&, double&, double&);

/// Over [lo, hi] in steps of 0.01: nondecreasing and convex, and the first and second
/// derivatives equal central differences of the value and the first derivative. tol_dds: a
/// step h that straddles a jump J of the third derivative errs by up to h |J|.
void check_activation(Activation f, double lo, double hi, double tol_dds) {
  for (double x = lo; x <= hi; x += 0.01) {
    double s, ds, dds;
    f(x, s, ds, dds);
    REQUIRE(ds >= 0.0);
    REQUIRE(dds >= 0.0);
    const double h = 1e-6;
    double sp, dsp, ddsp, sm, dsm, ddsm;
    f(x + h, sp, dsp, ddsp);
    f(x - h, sm, dsm, ddsm);
    REQUIRE(std::abs((sp - sm) / (2 * h) - ds) < 1e-8);
    REQUIRE(std::abs((dsp - dsm) / (2 * h) - dds) < tol_dds);
  }
}

}  // namespace

TEST_CASE("convex network: the activation is C2, convex and nondecreasing", "[unit]") {
  double s, ds, dds;
  // The pieces meet with equal value, slope and curvature at -1 and 1.
  for (double x0 : {-1.0, 1.0}) {
    double sl, dsl, ddsl, sr, dsr, ddsr;
    network_activation(x0 - 1e-12, sl, dsl, ddsl);
    network_activation(x0 + 1e-12, sr, dsr, ddsr);
    CHECK(std::abs(sl - sr) < 1e-11);
    CHECK(std::abs(dsl - dsr) < 1e-11);
    CHECK(std::abs(ddsl - ddsr) < 1e-11);
  }
  network_activation(-1.0, s, ds, dds);
  CHECK((s == 0.0 && ds == 0.0 && dds == 0.0));
  network_activation(2.5, s, ds, dds);
  CHECK((s == 2.5 && ds == 1.0 && dds == 0.0));
  // The third derivative, -3/2 x, jumps by 1.5 at -1 and 1.
  check_activation(network_activation, -1.5, 1.5, 1.5e-6);
  // The evaluator's form (reciprocals for the divisions) is the same function to round-off.
  check_activation(network_activation_impl<true>, -1.5, 1.5, 1.5e-6);
  for (double x = -1.5; x <= 1.5; x += 0.001) {
    double f, df, ddf;
    network_activation(x, s, ds, dds);
    network_activation_impl<true>(x, f, df, ddf);
    REQUIRE(std::abs(f - s) <= 4e-16 * (1.0 + std::abs(s)));
    REQUIRE(std::abs(df - ds) <= 4e-16);
    REQUIRE(ddf == dds);
  }
}

TEST_CASE("convex network: the stiffening activation is C2, convex and nondecreasing", "[unit]") {
  double s, ds, dds;
  network_stiffening_activation(-0.5, s, ds, dds);
  CHECK((s == 0.0 && ds == 0.0 && dds == 0.0));
  network_stiffening_activation(2.0, s, ds, dds);
  CHECK(s == Approx(8.0 / 6.0).epsilon(1e-15));
  CHECK(ds == 2.0);
  CHECK(dds == 2.0);
  // The third derivative jumps from 0 to 1 at 0.
  check_activation(network_stiffening_activation, -1.0, 2.0, 1e-6);
}

namespace {
/// The shapes the tests below run on: without stiffening units, with some in either layer,
/// and every unit of both layers stiffening.
NetworkShape shape_with(int h1, int h2, int variant) {
  NetworkShape sh;
  sh.h1 = h1;
  sh.h2 = h2;
  const int s1[] = {0, 2, 0, h1}, s2[] = {0, 0, 2, h2};
  sh.stiff1 = s1[variant];
  sh.stiff2 = s2[variant];
  return sh;
}
}  // namespace

TEST_CASE("convex network: S and C of the raw network equal finite differences", "[unit]") {
  const NetworkShape sh = shape_with(7, 5, GENERATE(0, 1, 2, 3));
  INFO("stiffening units " << sh.stiff1 << " and " << sh.stiff2);
  const std::vector<double> th = random_theta(sh, 3);
  std::mt19937 gen(2);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  const double h = 1e-6;
  double worst_S = 0.0, worst_C = 0.0, min_eig = 1e300;
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d e(u(gen), u(gen), u(gen));
    const NetworkResponse r = network_evaluate(sh, th.data(), e);
    REQUIRE(r.C == r.C.transpose());
    min_eig =
        std::min(min_eig, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(r.C).eigenvalues()(0));
    CHECK(network_evaluate(sh, th.data(), e, false).S == r.S);
    const auto [fd_S, fd_C] = testing::fd_errors(
        [&](const Eigen::Vector3d& x) { return network_evaluate(sh, th.data(), x); }, e, h);
    worst_S = std::max(worst_S, fd_S);
    worst_C = std::max(worst_C, fd_C);
  }
  INFO("FD(S) " << worst_S << ", FD(C) " << worst_C << ", min eig " << min_eig);
  CHECK(worst_S < 1e-7);
  CHECK(worst_C < 1e-6);
  // Convex for nonnegative V, w, w1 (the theorem the law relies on); -1e-12: round-off.
  CHECK(min_eig >= -1e-12);
}

TEST_CASE("convex network: the packed evaluation equals the reference network", "[unit]") {
  // NetworkLawAt (the law's fast path) against the mirror average of network_evaluate, the
  // formula of knit/material/convex_network.hpp written out. 12 / 6 and 16 / 8 take the
  // compiled-size path, 9 / 5 the general one.
  const int h1 = GENERATE(9, 12, 16);
  const NetworkShape sh = shape_with(h1, h1 == 9 ? 5 : h1 / 2, GENERATE(0, 1, 2, 3));
  INFO("units " << sh.h1 << " / " << sh.h2 << ", stiffening units " << sh.stiff1 << " and "
                << sh.stiff2);
  const std::vector<double> th = random_theta(sh, 12);
  const NetworkLawAt law(sh, th);
  const NetworkResponse z = network_evaluate(sh, th.data(), Eigen::Vector3d::Zero());
  const Eigen::Vector3d S0(z.S(0), z.S(1), 0.0);
  const Eigen::Matrix3d M = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  std::mt19937 gen(13);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d e(u(gen), u(gen), u(gen));
    const NetworkResponse a = network_evaluate(sh, th.data(), e),
                          b = network_evaluate(sh, th.data(), M * e);
    const double W = 0.5 * (a.W + b.W) - z.W - S0.dot(e);
    const Eigen::Vector3d S = 0.5 * (a.S + M * b.S) - S0;
    const Eigen::Matrix3d C = 0.5 * (a.C + M * b.C * M);
    const NetworkResponse r = law.evaluate(e);
    INFO("e = " << e.transpose());
    REQUIRE(std::abs(r.W - W) <= 1e-13 * (1 + std::abs(W)));
    REQUIRE((r.S - S).norm() <= 1e-13 * (1 + S.norm()));
    REQUIRE((r.C - C).norm() <= 1e-13 * (1 + C.norm()));
  }
}

namespace {
/// A reverse-mode gradient against central differences over theta: at 20 random strains e and
/// weights g, grad_of(th, e, g, grad) adds d f / d theta of f = value_of(th, e, g).
template <class Grad, class Value>
void check_theta_gradient(const NetworkShape& sh, unsigned seed, Grad grad_of, Value value_of) {
  INFO("stiffening units " << sh.stiff1 << " and " << sh.stiff2);
  std::vector<double> th = random_theta(sh, 9);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d e(u(gen), u(gen), u(gen)), g(u(gen), u(gen), u(gen));
    std::vector<double> grad(th.size(), 0.0);
    grad_of(th.data(), e, g, grad.data());
    for (std::size_t k = 0; k < th.size(); ++k) {
      const double h = 1e-6, keep = th[k];
      th[k] = keep + h;
      const double fp = value_of(th.data(), e, g);
      th[k] = keep - h;
      const double fm = value_of(th.data(), e, g);
      th[k] = keep;
      INFO("trial " << trial << ", parameter " << k);
      REQUIRE(std::abs((fp - fm) / (2 * h) - grad[k]) <= 1e-6 * (1 + std::abs(grad[k])));
    }
  }
}
}  // namespace

TEST_CASE("convex network: the fit's reverse-mode gradient equals finite differences", "[unit]") {
  // network_stress_gradient: f = g . S_N.
  const NetworkShape sh = shape_with(5, 3, GENERATE(0, 1, 2, 3));
  check_theta_gradient(
      sh, 4,
      [&](const double* th, const Eigen::Vector3d& e, const Eigen::Vector3d& g, double* grad) {
        network_stress_gradient(sh, th, e, g, grad);
      },
      [&](const double* th, const Eigen::Vector3d& e, const Eigen::Vector3d& g) {
        return g.dot(network_evaluate(sh, th, e, false).S);
      });
}

TEST_CASE("convex network: the value's reverse-mode gradient equals finite differences", "[unit]") {
  // network_value_gradient (the exponential outer function's fit needs dN/dtheta): f = g_0 N.
  const NetworkShape sh = shape_with(5, 3, GENERATE(0, 1, 2, 3));
  check_theta_gradient(
      sh, 5,
      [&](const double* th, const Eigen::Vector3d& e, const Eigen::Vector3d& g, double* grad) {
        network_value_gradient(sh, th, e, g(0), grad);
      },
      [&](const double* th, const Eigen::Vector3d& e, const Eigen::Vector3d& g) {
        return g(0) * network_evaluate(sh, th, e, false).W;
      });
}

TEST_CASE("convex network: the exponential outer function keeps S = dW, C = dS, convexity",
          "[unit]") {
  // G = c g(N), g = exp up to the cap and its quadratic continuation beyond: g is C2 at the cap;
  // the packed law (mirror-averaged, normalized G) against the reference written out, S and C
  // of the law against finite differences of W and S, C positive semidefinite, on strains on
  // both sides of the cap (the cap is set to the median N of the samples).
  NetworkShape sh = shape_with(7, 5, GENERATE(0, 1, 3));
  INFO("stiffening units " << sh.stiff1 << " and " << sh.stiff2);
  std::vector<double> th = random_theta(sh, 21);
  // Output weights scaled down so that exp(N) stays moderate on the samples.
  for (int k = sh.w1(); k < sh.V(); ++k) th[static_cast<std::size_t>(k)] *= 0.1;
  for (int k = sh.w(); k < sh.size(); ++k) th[static_cast<std::size_t>(k)] *= 0.1;
  std::mt19937 gen(14);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<Eigen::Vector3d> es;
  std::vector<double> ns;
  for (int k = 0; k < 400; ++k) {
    es.emplace_back(u(gen), u(gen), u(gen));
    ns.push_back(network_evaluate(sh, th.data(), es.back(), false).W);
  }
  std::vector<double> sorted = ns;
  std::nth_element(sorted.begin(), sorted.begin() + 200, sorted.end());
  sh.outer = 1;
  sh.outer_scale = 2.5;
  sh.outer_cap = sorted[200];
  // g is C2 at the cap.
  double gl, dgl, ddgl, gr, dgr, ddgr;
  network_outer(sh.outer_cap - 1e-12, sh.outer_cap, gl, dgl, ddgl);
  network_outer(sh.outer_cap + 1e-12, sh.outer_cap, gr, dgr, ddgr);
  CHECK(std::abs(gl - gr) < 1e-10 * gr);
  CHECK(std::abs(dgl - dgr) < 1e-10 * gr);
  CHECK(std::abs(ddgl - ddgr) < 1e-10 * gr);
  const NetworkLawAt law(sh, th);
  const NetworkResponse z =
      network_compose_outer(sh, network_evaluate(sh, th.data(), Eigen::Vector3d::Zero()));
  const Eigen::Vector3d S0(z.S(0), z.S(1), 0.0);
  const Eigen::Matrix3d M = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  const NetworkResponse r0 = law.evaluate(Eigen::Vector3d::Zero());
  CHECK(std::abs(r0.W) <= 1e-14 * std::abs(z.W));
  CHECK(r0.S.norm() <= 1e-14 * (1 + z.S.norm()));
  int beyond = 0;
  double worst_S = 0.0, worst_C = 0.0, min_eig = 1e300;
  for (std::size_t k = 0; k < es.size(); ++k) {
    const Eigen::Vector3d& e = es[k];
    if (ns[k] > sh.outer_cap) ++beyond;
    const NetworkResponse a = network_compose_outer(sh, network_evaluate(sh, th.data(), e)),
                          b = network_compose_outer(sh, network_evaluate(sh, th.data(), M * e));
    const double W = 0.5 * (a.W + b.W) - z.W - S0.dot(e);
    const Eigen::Vector3d S = 0.5 * (a.S + M * b.S) - S0;
    const Eigen::Matrix3d C = 0.5 * (a.C + M * b.C * M);
    const NetworkResponse r = law.evaluate(e);
    INFO("e = " << e.transpose());
    REQUIRE(std::abs(r.W - W) <= 1e-12 * (1 + std::abs(W) + std::abs(z.W)));
    REQUIRE((r.S - S).norm() <= 1e-12 * (1 + S.norm() + z.S.norm()));
    REQUIRE((r.C - C).norm() <= 1e-12 * (1 + C.norm()));
    REQUIRE(r.C == r.C.transpose());
    min_eig =
        std::min(min_eig, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(r.C).eigenvalues()(0) /
                              (1 + r.C.norm()));
    const auto [fd_S, fd_C] =
        testing::fd_errors([&](const Eigen::Vector3d& x) { return law.evaluate(x); }, e, 1e-6);
    worst_S = std::max(worst_S, fd_S);
    worst_C = std::max(worst_C, fd_C);
  }
  INFO("beyond the cap " << beyond << " of " << es.size() << "; FD(S) " << worst_S << ", FD(C) "
                         << worst_C << ", min eig / (1 + |C|) " << min_eig);
  CHECK(beyond > 100);  // both pieces of g are exercised
  CHECK(worst_S < 1e-7);
  CHECK(worst_C < 1e-6);
  CHECK(min_eig >= -1e-12);
}

TEST_CASE("convex network: the law is stress-free at 0, even in E12, convex", "[unit]") {
  const EnergyLaw law(testing::make_test_network_law(5, 0.03));
  std::mt19937 gen(8);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  for (double l : {4.5, 5.0, 5.5, 6.1, 6.5}) {
    const EnergyLawAt at = law.at(l);
    const EnergyResponse r0 = at.evaluate(Eigen::Vector3d::Zero());
    CHECK(r0.W == 0.0);
    CHECK(r0.S.norm() == 0.0);
    for (int k = 0; k < 500; ++k) {
      const Eigen::Vector3d e(u(gen), u(gen), u(gen)), m(e(0), e(1), -e(2));
      const EnergyResponse a = at.evaluate(e), b = at.evaluate(m);
      REQUIRE(std::abs(a.W - b.W) <= 1e-13 * (1 + std::abs(a.W)));
      REQUIRE(std::abs(a.S(1) - b.S(1)) <= 1e-13 * (1 + a.S.norm()));
      REQUIRE(std::abs(a.S(2) + b.S(2)) <= 1e-13 * (1 + a.S.norm()));
      REQUIRE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(a.C).eigenvalues()(0) >=
              0.03 * (1 - 1e-9));
    }
  }
}

TEST_CASE("convex network: validation refuses bad data", "[unit]") {
  const EnergyLawData good = testing::make_test_network_law();
  CHECK_NOTHROW(validate(good));
  auto refuses = [&](auto&& change, const std::string& what) {
    EnergyLawData d = good;
    change(d);
    CHECK_THROWS_WITH(validate(d), Catch::Contains(what));
  };
  const NetworkShape& sh = good.network.shape;
  refuses([&](EnergyLawData& d) { d.network.theta(1, sh.V() + 2) = -1e-9; }, "must be >= 0");
  refuses([&](EnergyLawData& d) { d.network.theta(0, sh.w()) = -1.0; }, "must be >= 0");
  refuses([&](EnergyLawData& d) { d.network.theta(2, sh.w1()) = -0.5; }, "must be >= 0");
  refuses([&](EnergyLawData& d) { d.network.theta(0, 0) = std::nan(""); }, "finite");
  refuses([&](EnergyLawData& d) { d.network.l_knots = {4.5, 4.5, 6.5}; }, "strictly increasing");
  refuses([&](EnergyLawData& d) { d.network.l_knots = {4.6, 5.5, 6.5}; }, "cover");
  // Knots beyond the range (found by fuzzing a database: they "covered" it).
  refuses([&](EnergyLawData& d) { d.network.l_knots = {4.5, 5.5, 1e308}; }, "run from l_min");
  refuses([&](EnergyLawData& d) { d.network.l_knots = {1e-300, 5.5, 6.5}; }, "run from l_min");
  refuses([&](EnergyLawData& d) { d.network.theta.conservativeResize(3, sh.size() - 1); },
          "theta must be");
  refuses([&](EnergyLawData& d) { d.network.shape.h1 = 0; }, "hidden layer sizes");
  refuses([&](EnergyLawData& d) { d.network.shape.stiff2 = d.network.shape.h2 + 1; },
          "stiffening units");
  refuses([&](EnergyLawData& d) { d.network.shape.stiff1 = -1; }, "stiffening units");
  refuses([&](EnergyLawData& d) { d.network.shape.outer = 2; }, "outer must be");
  refuses(
      [&](EnergyLawData& d) {
        d.network.shape.outer = 1;
        d.network.shape.outer_scale = 0.0;
      },
      "outer_scale");
  refuses(
      [&](EnergyLawData& d) {
        d.network.shape.outer = 1;
        d.network.shape.outer_cap = std::nan("");
      },
      "outer_cap");
  // Negative entries where no sign is required are fine (biases, first-layer weights, L).
  EnergyLawData ok = good;
  ok.network.theta(0, sh.b0()) = -3.0;
  ok.network.theta(0, sh.L()) = -2.0;
  CHECK_NOTHROW(validate(ok));
}
