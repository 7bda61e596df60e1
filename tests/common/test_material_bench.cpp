// Benchmark of the response-surface evaluation (hidden: run with "[.bench]").
// Target (issue #4): >= 1e6 evaluations of S and C per second per core.
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>

#include "knit/material/response_surface.hpp"
#include "test_material_util.hpp"

using namespace knit::material;

namespace {
/// CPU time of this thread (s): the machine is shared, wall time would count other processes.
double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
}  // namespace

TEST_CASE("bench: response-surface evaluations per second", "[.bench]") {
  const ResponseSurface rs(testing::make_test_surface());
  std::mt19937 gen(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> E;
  for (int k = 0; k < 4096; ++k) {
    const Eigen::Vector2d e = testing::fan_strain(u(gen), u(gen));
    E.emplace_back(e(0), e(1), 0.3 * (u(gen) - 0.5));
  }
  const int n = 2'000'000;
  double sink = 0.0;
  long iters = 0;
  const double c0 = thread_cpu_seconds();
  for (int k = 0; k < n; ++k) {
    const auto ev = rs.evaluate(E[k & 4095]);
    sink += ev.S(0) + ev.C(0, 0);
    iters += ev.iterations;
  }
  const double dt = thread_cpu_seconds() - c0;
  std::printf(
      "material evaluation: %.3g per second per core (target >= 1e6), mean Newton "
      "iterations %.2f [sink %g]\n",
      n / dt, static_cast<double>(iters) / n, sink);
  CHECK(n / dt > 0);
}

#include <filesystem>

#include "knit/material/database.hpp"

TEST_CASE("bench: loading the material database", "[.bench]") {
  // A database of the default size: 5 loop lengths x 13 paths x 20 steps, 11 x 11 surfaces.
  Database db;
  db.provenance = current_provenance();
  for (double l : {4.5, 5.0, 5.5, 6.0, 6.5}) {
    LoopLengthEntry e;
    e.loop_length = l;
    for (const auto& p : default_load_paths()) {
      RawPath r;
      r.path = p;
      // Near the identity (F11, F12, F21, F22): a converged step keeps det F > 0, which the
      // writer and reader check (session 53).
      r.F = RowMatrixX::Random(20, 4) * 0.1;
      r.F.col(0).array() += 1.0;
      r.F.col(3).array() += 1.0;
      r.P = RowMatrixX::Random(20, 4);
      testing::set_strain_and_stress(r);  // E and S of F and P (eq. 9)
      r.status.assign(20, 0);
      e.raw.push_back(r);
    }
    e.surface = testing::make_test_surface(4.5 / l);
    db.entries.push_back(e);
  }
  const auto file = std::filesystem::path(KNIT_BINARY_DIR) / "bench_database.h5";
  write_database(file, db);
  for (bool raw : {false, true}) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto fam = read_database(file, raw).family();
    const ResponseSurface rs(fam.at(5.25));
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("database load%s + family + one evaluator: %.1f ms (target <= 50 ms)\n",
                raw ? " (with raw data)" : "", ms);
    CHECK(rs.data().n1() == 11);
  }
}

#include "knit/material/energy_law.hpp"
#include "test_energy_util.hpp"

namespace {
/// W, S and C evaluations per second (CPU time, this thread) of `law` at l, strains uniform in
/// [-0.4, 0.5]^3 (e3 = 2 E12).
double energy_law_rate(const EnergyLaw& law, double l, double& sink,
                       LanesKernel kernel = LanesKernel::kAuto) {
  const EnergyLawAt at(law.data(), l, false, kernel);
  std::mt19937 gen(1);
  std::uniform_real_distribution<double> u(-0.4, 0.5);
  std::vector<Eigen::Vector3d> E;
  for (int k = 0; k < 4096; ++k) E.emplace_back(u(gen), u(gen), u(gen));
  const int n = 4'000'000;
  const double c0 = thread_cpu_seconds();
  for (int k = 0; k < n; ++k) {
    const EnergyResponse r = at.evaluate(E[k & 4095]);
    sink += r.W + r.S(0) + r.C(0, 1);
  }
  return n / (thread_cpu_seconds() - c0);
}
}  // namespace

namespace {
int nonzero_weights(const KnotWeights& w) {
  int n = 0;
  for (int k = 0; k < w.count; ++k) n += w.c[k] != 0.0;
  return n;
}
}  // namespace

TEST_CASE("bench: energy-law evaluations per second", "[.bench]") {
  // Issue 11 target: >= 2e6 evaluations of W, S and C per second on one core. Both families:
  // the ridge law (default directions: 24 ridges, cubic f'', 8 spans) and the network law of
  // the default fit (hidden layers 12 and 6; mirror-averaged: two network passes). With
  // KNIT_BENCH_DATABASE=FILE also the law stored in that material database, at its middle
  // loop length (a fitted law: its units are curved where the data put them) and between its
  // two middle knots (with l_interpolation "energy" there: two laws, four network passes; with
  // l_blend, session 44, the middle knot lies in a rounding window: three laws, six passes;
  // one six-lane pass with AVX-512, a four-lane and a two-lane pass without it).
  for (const int kind : {0, 1, 2}) {
    EnergyLawData d = kind == 0 ? testing::make_test_energy_law()
                                : testing::make_test_network_law(7, 0.02, 12, 6);
    if (kind == 2) d.network.l_interpolation = LInterpolation::kEnergy;
    const EnergyLaw law(d);
    double sink = 0.0;
    const double rate = energy_law_rate(law, 5.3, sink);  // between the knots 4.5 and 5.5
    std::printf(
        "energy-law evaluation (%s): %.3g per second per core (W, S, C; target >= 2e6) [sink %g]\n",
        kind == 0   ? "ridge"
        : kind == 1 ? "network 12/6, theta interpolated in l"
                    : "network 12/6, W interpolated in l, between knots",
        rate, sink);
    CHECK(rate > 0);
  }
  if (const char* file = std::getenv("KNIT_BENCH_DATABASE")) {
    const Database db = read_database(file, false);
    const EnergyLaw law(require_energy_law(db, file));
    const std::size_t n = db.entries.size(), m = n / 2;
    const double l_mid = 0.5 * (db.entries.front().loop_length + db.entries.back().loop_length);
    const double l_between =
        n > 1 ? 0.5 * (db.entries[m == 0 ? 0 : m - 1].loop_length + db.entries[m].loop_length)
              : l_mid;
    // And at the first loop length, an end knot: one law, two passes (session 50).
    // Each also with the AVX2 kernels forced (session 53): on a processor with AVX-512 the
    // rate that one without it, but with AVX2 and FMA, would see (the same on other ones).
    for (const double l : {l_mid, l_between, db.entries.front().loop_length})
      for (const LanesKernel kernel : {LanesKernel::kAuto, LanesKernel::kAvx2}) {
        double sink = 0.0;
        const double rate = energy_law_rate(law, l, sink, kernel);
        const EnergyLawData& d = law.data();
        const int laws = d.family == EnergyFamily::kNetwork &&
                                 d.network.l_interpolation == LInterpolation::kEnergy
                             ? nonzero_weights(d.network.weights(l))
                             : 1;
        std::printf(
            "energy-law evaluation (%s, l = %g mm, %d knot law%s%s): %.3g per second per core "
            "(W, S, C; target >= 2e6) [sink %g]\n",
            file, l, laws, laws == 1 ? "" : "s",
            kernel == LanesKernel::kAvx2 ? ", AVX2 kernels" : "", rate, sink);
        CHECK(rate > 0);
      }
  }
}

#include "knit/material/network_lanes.hpp"

TEST_CASE("bench: six-lane kernels", "[.bench]") {
  // The six-lane pass of a rounding window (three knot laws) by each kernel this processor has,
  // so that a machine with AVX-512 also measures the AVX2 kernel that processors without it run
  // (session 53). The knot laws of KNIT_BENCH_DATABASE at its middle loop length, else the test
  // network law's theta three times.
  std::vector<std::vector<double>> th;
  NetworkShape shape;
  Eigen::Vector3d c(0.25, 0.5, 0.25);
  const char* file = std::getenv("KNIT_BENCH_DATABASE");
  if (file) {
    const Database db = read_database(file, false);
    const EnergyLawData d = require_energy_law(db, file);
    const double l_mid = 0.5 * (db.entries.front().loop_length + db.entries.back().loop_length);
    const KnotWeights w = d.network.weights(l_mid);
    if (w.count == 3) {
      shape = d.network.shape;
      for (int k = 0; k < 3; ++k) th.push_back(d.network.theta_row(w.j[k]));
      c = Eigen::Vector3d(w.c[0], w.c[1], w.c[2]);
    }
  }
  if (th.empty()) {
    const EnergyLawData d = testing::make_test_network_law(7, 0.02, 12, 6);
    shape = d.network.shape;
    for (int k = 0; k < 3; ++k) th.push_back(d.network.theta_row(std::min(k, 1)));
  }
  std::mt19937 gen(1);
  std::uniform_real_distribution<double> u(-0.4, 0.5);
  std::vector<Eigen::Vector3d> E;
  for (int k = 0; k < 4096; ++k) E.emplace_back(u(gen), u(gen), u(gen));
  for (const LanesKernel kernel :
       {LanesKernel::kAuto, LanesKernel::kAvx2, LanesKernel::kPortable}) {
    const NetworkLanesAt lanes(shape, th[0], th[1], th[2], c, kernel);
    const int n = 2'000'000;
    double sink = 0.0;
    const double c0 = thread_cpu_seconds();
    for (int k = 0; k < n; ++k) {
      const NetworkResponse r = lanes.evaluate(E[k & 4095]);
      sink += r.W + r.S(0) + r.C(0, 1);
    }
    const double rate = n / (thread_cpu_seconds() - c0);
    std::printf("six-lane kernel (%s%s): %.3g passes per second per core [sink %g]\n",
                kernel == LanesKernel::kAuto   ? "auto"
                : kernel == LanesKernel::kAvx2 ? "AVX2"
                                               : "portable",
                lanes.wide() ? "" : ", portable code", rate, sink);
    CHECK(rate > 0);
  }
}
