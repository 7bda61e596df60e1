// The lane evaluator of the network law (knit/material/network_lanes.hpp) against the
// reference pass by pass (NetworkLawAt, itself tested against the formula written out in
// test_material_convex_network.cpp): two lanes = the mirror-averaged law at one theta, four
// lanes = the convex combination of two knots' laws, six = of three (every kernel: AVX-512,
// AVX2 with FMA and portable, where the processor has them); on the compiled sizes (12 / 6) and the
// general path (9 / 5, 16 / 8), with stiffening units and the exponential outer function.
#include <catch2/catch.hpp>
#include <random>

#include "knit/material/network_lanes.hpp"
#include "test_energy_util.hpp"

using namespace knit::material;

namespace {

NetworkShape lanes_shape(int h1, int h2, int stiff1, int stiff2, bool outer) {
  NetworkShape sh;
  sh.h1 = h1;
  sh.h2 = h2;
  sh.stiff1 = stiff1;
  sh.stiff2 = stiff2;
  if (outer) {
    sh.outer = 1;
    sh.outer_scale = 2.5;
    sh.outer_cap = 0.5;  // samples on both sides of the cap
  }
  return sh;
}

/// A parameter set with moderate output weights (exp(N) stays moderate with the outer function).
std::vector<double> lanes_theta(const NetworkShape& sh, unsigned seed) {
  std::vector<double> th =
      testing::make_test_network_law(seed, 0.0, sh.h1, sh.h2).network.theta_at(5.0);
  for (int k = sh.w1(); k < sh.V(); ++k) th[static_cast<std::size_t>(k)] *= 0.1;
  for (int k = sh.w(); k < sh.size(); ++k) th[static_cast<std::size_t>(k)] *= 0.1;
  return th;
}

void require_close(const NetworkResponse& r, const NetworkResponse& ref) {
  const double tol = 1e-13;
  REQUIRE(std::abs(r.W - ref.W) <= tol * (1 + std::abs(ref.W)));
  REQUIRE((r.S - ref.S).norm() <= tol * (1 + ref.S.norm()));
  REQUIRE((r.C - ref.C).norm() <= tol * (1 + ref.C.norm()));
  REQUIRE(r.C == r.C.transpose());
}

}  // namespace

TEST_CASE("network lanes: two lanes equal the mirror-averaged law, four its blend", "[unit]") {
  const auto [h1, h2] = GENERATE(std::pair{12, 6}, std::pair{9, 5}, std::pair{16, 8});
  const int variant = GENERATE(0, 1, 2);
  const bool outer = GENERATE(false, true);
  const int s1[] = {0, 2, h1}, s2[] = {0, 1, h2};
  const NetworkShape sh = lanes_shape(h1, h2, s1[variant], s2[variant], outer);
  INFO("units " << h1 << " / " << h2 << ", stiffening " << sh.stiff1 << " and " << sh.stiff2
                << ", outer " << sh.outer);
  const std::vector<double> ta = lanes_theta(sh, 31), tb = lanes_theta(sh, 32),
                            tc = lanes_theta(sh, 33);
  const NetworkLawAt ref_a(sh, ta), ref_b(sh, tb), ref_c(sh, tc);
  const NetworkLanesAt two(sh, ta);
  CHECK(two.lanes() == 2);
  const double t = GENERATE(0.0, 0.3, 1.0);
  // Every kernel: the widest the processor has (kAuto), AVX2 (where it has it), portable.
  const LanesKernel kernel =
      GENERATE(LanesKernel::kAuto, LanesKernel::kAvx2, LanesKernel::kPortable);
  const NetworkLanesAt four(sh, ta, tb, t, kernel);
  // Six lanes: weights of a rounding window (1 - s)^2 / 2, ..., here with s = t.
  const Eigen::Vector3d c(0.5 * (1 - t) * (1 - t), 0.5 + t * (1 - t), 0.5 * t * t);
  const NetworkLanesAt six(sh, ta, tb, tc, c, kernel);
  CHECK(four.lanes() == 4);
  CHECK(six.lanes() == 6);
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"),
             avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  const bool wide = kernel == LanesKernel::kAuto   ? avx2 || avx512
                    : kernel == LanesKernel::kAvx2 ? avx2
                                                   : false;
  CHECK(four.wide() == wide);
  CHECK(six.wide() == wide);  // AVX-512's eight-lane vectors, or AVX2's split
  CHECK_FALSE(two.wide());
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  int beyond_cap = 0;
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3d e(u(gen), u(gen), u(gen));
    INFO("e = " << e.transpose() << ", t = " << t);
    const NetworkResponse a = ref_a.evaluate(e), b = ref_b.evaluate(e);
    require_close(two.evaluate(e), a);
    NetworkResponse blend;
    blend.W = (1 - t) * a.W + t * b.W;
    blend.S = (1 - t) * a.S + t * b.S;
    blend.C = (1 - t) * a.C + t * b.C;
    require_close(four.evaluate(e), blend);
    const NetworkResponse cc = ref_c.evaluate(e);
    blend.W = c(0) * a.W + c(1) * b.W + c(2) * cc.W;
    blend.S = c(0) * a.S + c(1) * b.S + c(2) * cc.S;
    blend.C = c(0) * a.C + c(1) * b.C + c(2) * cc.C;
    require_close(six.evaluate(e), blend);
    if (network_evaluate(sh, ta.data(), e, false).W > sh.outer_cap) ++beyond_cap;
  }
  if (outer) CHECK(beyond_cap > 10);  // both pieces of the outer function are exercised
}

TEST_CASE("network lanes: stress-free at 0 and even in E12", "[unit]") {
  const NetworkShape sh = lanes_shape(12, 6, 0, 0, true);
  const LanesKernel kernel =
      GENERATE(LanesKernel::kAuto, LanesKernel::kAvx2, LanesKernel::kPortable);
  const bool six_lanes = GENERATE(false, true);
  const NetworkLanesAt law =
      six_lanes ? NetworkLanesAt(sh, lanes_theta(sh, 41), lanes_theta(sh, 42), lanes_theta(sh, 43),
                                 Eigen::Vector3d(0.2, 0.5, 0.3), kernel)
                : NetworkLanesAt(sh, lanes_theta(sh, 41), lanes_theta(sh, 42), 0.6, kernel);
  const NetworkResponse r0 = law.evaluate(Eigen::Vector3d::Zero());
  CHECK(std::abs(r0.W) <= 1e-14);
  CHECK(r0.S.norm() <= 1e-14);
  std::mt19937 gen(43);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d e(u(gen), u(gen), u(gen)), me(e(0), e(1), -e(2));
    const NetworkResponse p = law.evaluate(e), m = law.evaluate(me);
    REQUIRE(std::abs(p.W - m.W) <= 1e-13 * (1 + std::abs(p.W)));
    REQUIRE(std::abs(p.S(0) - m.S(0)) <= 1e-13 * (1 + p.S.norm()));
    REQUIRE(std::abs(p.S(2) + m.S(2)) <= 1e-13 * (1 + p.S.norm()));
  }
}

TEST_CASE("network lanes: a theta of the wrong size or a bad shape is refused", "[unit]") {
  const NetworkShape sh = lanes_shape(12, 6, 0, 0, false);
  std::vector<double> th = lanes_theta(sh, 51);
  th.pop_back();
  CHECK_THROWS_AS(NetworkLanesAt(sh, th), std::invalid_argument);
  NetworkShape bad = sh;
  bad.h1 = 0;
  CHECK_THROWS_AS(NetworkLanesAt(bad, lanes_theta(sh, 51)), std::invalid_argument);
}
