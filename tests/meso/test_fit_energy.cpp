// Fit of the energy-based law (knit/meso/fit/energy_fit.hpp) on synthetic data of a known
// hyperelastic law (knit/meso/fit/synthetic.hpp: W = k(l) (a1/2 E1^2 + a12 E1 E2 + a2/2 E2^2 +
// b1/4 E1^4 + b2/4 E2^4 + g/4 (2E12)^2 + h/32 (2E12)^4), exactly a sum of ridge functions of
// the default directions), its held-out errors, and its refusals.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "knit/core/errors.hpp"
#include "knit/material/energy_law.hpp"
#include "knit/meso/fit/energy_fit.hpp"
#include "knit/meso/fit/response_fit.hpp"
#include "knit/meso/fit/synthetic.hpp"

using namespace knit::meso::fit;
using knit::material::Database;
namespace material = knit::material;

namespace {

/// The paper's paths and the synthetic coverage paths of `steps` steps; with uniaxial_steps > 0
/// also the synthetic law's own uniaxial-stress paths (course and wale, to 0.4).
Database synthetic_coverage_db(std::vector<double> ls = {4.5, 5.5, 6.5}, int steps = 8,
                               int uniaxial_steps = 0) {
  SyntheticOptions so;
  so.loop_lengths = std::move(ls);
  so.paths = knit::material::default_load_paths(steps);
  for (const auto& p : synthetic_coverage_paths(steps)) so.paths.push_back(p);
  for (int axis = 0; axis < 2 && uniaxial_steps > 0; ++axis) {
    material::LoadPath u;
    u.kind = material::PathKind::kUniaxial;
    u.axis = axis;
    u.target(0) = 0.4;  // the axial strain, along `axis` (load_paths.hpp); session 33: the
                        // wale path had target(1) = 0.4 and zero strain at every step
    u.steps = uniaxial_steps;
    u.set = "coverage";
    so.paths.push_back(u);
  }
  return synthetic_database(so);
}

/// The ridge family's fit (fast; the diagnostics do not depend on the family).
EnergyFitOptions ridge_options() {
  EnergyFitOptions o;
  o.family = "ridge";
  return o;
}
EnergyFitSummary fit_ridge(const Database& db) {
  EnergyFitSummary s = fit_energy_law(db, ridge_options());
  INFO(s.reason);
  REQUIRE(s.ok());
  return s;
}

/// A raw path of `n` converged steps, all numbers zero (the test fills E and S).
material::RawPath zero_path(material::PathKind kind, const std::string& set, int n, int axis = 0) {
  material::RawPath r;
  r.path.kind = kind;
  r.path.axis = axis;
  r.path.set = set;
  r.E = material::RowMatrixX::Zero(n, 3);
  r.S = material::RowMatrixX::Zero(n, 3);
  r.F = r.P = material::RowMatrixX::Zero(n, 4);
  r.status.assign(static_cast<std::size_t>(n), 0);
  return r;
}

/// A network fit of `db` (Ceres L-BFGS, `iterations` iterations from `seed`), required to succeed.
EnergyFitSummary fit_network(const Database& db, int iterations, int seed = 1) {
  EnergyFitOptions o;
  o.family = "network";
  o.network_iterations = iterations;
  o.seed = seed;
  EnergyFitSummary s = fit_energy_law(db, o);
  INFO(s.reason);
  REQUIRE(s.ok());
  REQUIRE(s.law.family == material::EnergyFamily::kNetwork);
  return s;
}

/// Network-family options of a small network (h1 and h2 units) fitted for `iterations`.
EnergyFitOptions small_network(int h1, int h2, int iterations) {
  EnergyFitOptions o;
  o.hidden1 = h1;
  o.hidden2 = h2;
  o.network_iterations = iterations;
  return o;
}

/// The first coverage path of the first loop length with at least `steps` steps (the number
/// of paths if none).
std::size_t first_coverage_path(const Database& db, int steps) {
  const auto& raw = db.entries[0].raw;
  std::size_t q = 0;
  while (q < raw.size() && (raw[q].path.set != "coverage" || raw[q].steps() < steps)) ++q;
  return q;
}

}  // namespace

TEST_CASE("energy fit: recovers the synthetic hyperelastic law within 0.3 % of the range",
          "[unit]") {
  const Database db = synthetic_coverage_db();
  const EnergyFitSummary s = fit_ridge(db);
  std::printf("%s", energy_fit_report(s).c_str());
  const auto& d = s.diagnostics;
  REQUIRE(d.per_loop.size() == 3);
  // Stated error: the synthetic law is a polynomial of degree 4 in e (f'' quadratic: exact in
  // the cubic s-splines; with 3 loop lengths the quadratic l-spline interpolates k(l)); only
  // the smoothing penalty leaves a small bias. Measured with the exact (active-set) solve:
  // max 0.05-0.12 %, rms 0.006-0.012 % of the stress range. Ceres' bounded trust region
  // (until session 14) stopped short of the optimum at max 1.9-2.4 %, rms 0.23-0.26 %: these
  // bounds fail it.
  for (const auto& p : d.per_loop) {
    INFO("l = " << p.loop_length);
    CHECK(p.max_relative < 0.003);
    CHECK(p.rms_relative < 0.0005);
  }
  // Held out: 24 quasi-random states per loop length that did not enter the fit, within 5 %
  // of the range (measured: largest error 0.0045 %; with Ceres' solve 0.63-0.65 %).
  CHECK(d.holdout_points == 3 * 24);
  CHECK(d.holdout_within_5_percent == d.holdout_points);
  // Per held-out run (one state each here): every run counted, all within 5 %.
  CHECK(d.holdout_runs == 3 * 24);
  CHECK(d.holdout_runs_within_5_percent == d.holdout_runs);
  CHECK(d.holdout_run_ends_within_5_percent == d.holdout_runs);
  CHECK(d.holdout_max_relative < 0.001);
  // Convex at every l by construction; the floor is the smallest eigenvalue.
  CHECK((s.law.coefficients.array() >= 0.0).all());
  CHECK(d.min_eigenvalue >= s.law.floor * (1 - 1e-12));
  CHECK(s.law.floor > 0.0);
  // Midway between the fitted loop lengths the law still follows the known one.
  const knit::material::EnergyLaw law(s.law);
  const SyntheticLaw truth;
  for (double l : {5.0, 6.0}) {
    const auto at = law.at(l);
    double worst = 0.0;
    for (double e1 : {-0.1, 0.0, 0.15, 0.3})
      for (double e2 : {-0.1, 0.0, 0.15, 0.3})
        for (double g : {0.0, 0.2}) {
          const Eigen::Vector3d S = at.evaluate({e1, e2, g}).S;
          const Eigen::Vector3d T = truth.stress({e1, e2, 0.5 * g}, l);
          worst = std::max(worst, (S - T).cwiseAbs().maxCoeff());
        }
    const double range = d.per_loop[1].stress_range;
    INFO("l = " << l << ": worst error " << worst << " MPa of range " << range);
    CHECK(worst < 0.02 * range);
  }
}

// The accuracy of the network fit needs its 1,500 iterations (~35 s under ASan + UBSan, the
// slowest test of the sanitizer run): a [verification] test (Release only). The sanitizer run
// covers the same fit code with the determinism test below.
TEST_CASE("energy fit: the network family recovers the synthetic law", "[verification]") {
  const EnergyFitSummary s = fit_network(synthetic_coverage_db(), 1500);
  std::printf("%s", energy_fit_report(s).c_str());
  CHECK(s.law.network.l_knots == std::vector<double>{4.5, 5.5, 6.5});
  const auto& d = s.diagnostics;
  // Stated error (not exact: the synthetic quartic is not a network; 1,500 L-BFGS iterations):
  // measured max 2.5 / 2.8 / 3.1 %, rms 0.30 / 0.31 / 0.33 % of the range; held out largest
  // 0.51 %.
  for (const auto& p : d.per_loop) {
    INFO("l = " << p.loop_length);
    CHECK(p.max_relative < 0.05);
    CHECK(p.rms_relative < 0.01);
  }
  CHECK(d.holdout_within_5_percent == d.holdout_points);
  CHECK(d.holdout_max_relative < 0.02);
  CHECK(d.min_eigenvalue >= s.law.floor * (1 - 1e-9));
}

TEST_CASE("energy fit: the network fit gives the same law from the same seed", "[unit]") {
  // The initial parameters are drawn from the seed; every L-BFGS iteration is deterministic, so
  // a short fit shows a difference as well as a long one.
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const EnergyFitSummary s = fit_network(db, 100);
  CHECK(s.diagnostics.min_eigenvalue >= s.law.floor * (1 - 1e-9));
  CHECK(fit_network(db, 100).law.network.theta == s.law.network.theta);
  CHECK(fit_network(db, 100, 2).law.network.theta != s.law.network.theta);
}

TEST_CASE("energy fit: the network fit gives the same law for every thread count", "[unit]") {
  // Each knot's points go to one thread, in order, and the objective's terms are summed in the
  // serial order (mesoscale/src/fit_network.cpp), so the threads change no floating-point
  // operation: the law is the same to the last bit. Three knots, so that two threads get
  // unequal shares; the outer function and a tube, so that every term of the objective is there.
  const Database db = synthetic_coverage_db({4.5, 5.5, 6.5}, 6);
  EnergyFitOptions o = small_network(4, 3, 150);
  o.outer = "exp";
  o.tube = 0.01;
  o.threads = 1;
  const EnergyFitSummary one = fit_energy_law(db, o);
  REQUIRE(one.ok());
  for (int threads : {2, 3, 0}) {
    INFO("threads " << threads);
    o.threads = threads;
    const EnergyFitSummary many = fit_energy_law(db, o);
    REQUIRE(many.ok());
    CHECK(many.law.network.theta == one.law.network.theta);
    CHECK(many.ceres_iterations == one.ceres_iterations);
  }
  o.threads = -1;
  CHECK(o.validate() == "threads must be >= 0 (0: all cores)");
}

// Session 57: the default law's largest fit error at 6.5 mm was 4.5-7.1 % over seeds 1-6, and
// the seed with the smallest final objective was the one within 5 % (docs/law-experiments.md,
// "Multi-start"). starts = K runs the fit from seeds seed ... seed + K - 1 and keeps the start
// of least objective: the same law, to the last bit, as a single fit from that seed, for every
// thread count (starts side by side, threads / starts each), with every start's iterations counted.
TEST_CASE("energy fit: multi-start keeps the start of least objective", "[unit]") {
  const Database db = synthetic_coverage_db({4.5, 5.5, 6.5}, 6);
  EnergyFitOptions o = small_network(4, 3, 150);
  o.outer = "exp";
  o.tube = 0.01;
  o.seed = 3;
  std::vector<EnergyFitSummary> single;
  for (int seed = 3; seed < 6; ++seed) {
    o.seed = seed;
    single.push_back(fit_energy_law(db, o));
    REQUIRE(single.back().ok());
    CHECK(single.back().seed == seed);
    CHECK(std::isfinite(single.back().objective));
  }
  std::size_t least = 0;
  for (std::size_t k = 1; k < single.size(); ++k)
    if (single[k].objective < single[least].objective) least = k;
  // The draws must differ, or the choice is not tested.
  REQUIRE(single[0].objective != single[1].objective);
  REQUIRE(single[1].objective != single[2].objective);
  o.seed = 3;
  o.starts = 3;
  for (int threads : {1, 2, 7, 0}) {  // 7: two threads for each of the three starts
    INFO("threads " << threads);
    o.threads = threads;
    const EnergyFitSummary multi = fit_energy_law(db, o);
    REQUIRE(multi.ok());
    CHECK(multi.seed == single[least].seed);
    CHECK(multi.objective == single[least].objective);
    CHECK(multi.law.network.theta == single[least].law.network.theta);
    REQUIRE(multi.diagnostics.per_loop.size() == single[least].diagnostics.per_loop.size());
    for (std::size_t k = 0; k < multi.diagnostics.per_loop.size(); ++k)
      CHECK(multi.diagnostics.per_loop[k].max_relative ==
            single[least].diagnostics.per_loop[k].max_relative);
    CHECK(multi.ceres_iterations ==
          single[0].ceres_iterations + single[1].ceres_iterations + single[2].ceres_iterations);
  }
  o.starts = 0;
  CHECK(o.validate() == "starts must be in 1..64");
  o.starts = 65;
  CHECK(o.validate() == "starts must be in 1..64");
  o.starts = 2;
  o.seed = 2147483647;
  CHECK(o.validate() == "seed + starts - 1 must fit an int");
}

// Session 55's red team: the default law's pure-shear stiffness was ordered wrongly in l (the
// paper's shear path, one of 13 paths at weight_paper, is all the pure-shear data). weight_shear
// weights the pure-shear paths' states alone: here the shear path's stresses are scaled by 1.5
// (data the rest of the paths contradict), and the law follows them the more, the larger
// weight_shear; weight_paper no longer reaches them.
TEST_CASE("energy fit: weight_shear weights the pure-shear paths' states", "[unit]") {
  Database db = synthetic_coverage_db({4.5, 6.5}, 4);
  int shear_paths = 0;
  for (auto& entry : db.entries)
    for (auto& r : entry.raw)
      if (r.path.kind == material::PathKind::kShear) {
        ++shear_paths;
        r.S *= 1.5;
        r.P *= 1.5;
      }
  REQUIRE(shear_paths == 2);  // the paper's shear path at each loop length
  // The largest |S_law - S_data| over the shear paths' states, and over the others.
  auto misses = [&](const EnergyFitOptions& o) {
    const EnergyFitSummary s = fit_energy_law(db, o);
    INFO(s.reason);
    REQUIRE(s.ok());
    const material::EnergyLaw law(s.law);
    std::pair<double, double> worst{0.0, 0.0};
    for (const auto& entry : db.entries)
      for (const auto& r : entry.raw)
        for (int k = 0; k < r.steps(); ++k) {
          const Eigen::Vector3d e(r.E(k, 0), r.E(k, 1), 2.0 * r.E(k, 2));
          const double miss = (law.at(entry.loop_length).evaluate(e).S - r.S.row(k).transpose())
                                  .cwiseAbs()
                                  .maxCoeff();
          double& w = r.path.kind == material::PathKind::kShear ? worst.first : worst.second;
          w = std::max(w, miss);
        }
    return worst;
  };
  EnergyFitOptions low = ridge_options(), high = ridge_options(), paper = ridge_options();
  low.weight_shear = 0.01;
  high.weight_shear = 1000.0;
  paper.weight_shear = 0.01;
  paper.weight_paper = 1000.0;
  const auto l = misses(low), h = misses(high), p = misses(paper);
  INFO("shear paths: " << l.first << " / " << h.first << " / " << p.first << " MPa; others "
                       << l.second << " / " << h.second << " / " << p.second);
  CHECK(h.first < 0.5 * l.first);
  CHECK(p.first > 0.9 * l.first);  // weight_paper does not weight the shear path any more
  CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"weight_shear": 0})", "f.json"),
                    Catch::Contains("weight_shear must be -1 (the path set's weight) or in (0, "
                                    "1000]"));
  // -1, the default: the set's weight, as before the option (the review of session 55: a
  // refit from options recorded without the key must weight as they were fitted).
  EnergyFitOptions as_set = ridge_options(), explicit_paper = ridge_options();
  as_set.weight_paper = explicit_paper.weight_paper = 7.0;
  explicit_paper.weight_shear = 7.0;
  CHECK(EnergyFitOptions{}.weight_shear == -1.0);
  CHECK(misses(as_set) == misses(explicit_paper));
}

TEST_CASE("energy fit: a floor or weights large enough to overflow are refused", "[unit]") {
  // floor 1e308 ended in "Initial cost and jacobian evaluation failed", naming no option.
  EnergyFitOptions o;
  CHECK(o.validate().empty());
  o.floor = 1e308;
  CHECK(o.validate().find("floor must be <= 1000 MPa") == 0);
  o.floor = 1e3;
  CHECK(o.validate().empty());
  o.floor = -1.0;
  o.smoothing = 1e308;
  CHECK(o.validate() == "smoothing must be in [0, 1000]");
  o.smoothing = 1e-9;
  o.loss_scale = 1e308;
  CHECK(o.validate() == "loss_scale must be in (0, 1000]");
  // From a file: named by the option's JSON pointer (session 29: the key in prose only).
  CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"floor": 1e308})", "o.json"),
                    Catch::StartsWith("o.json: /floor: floor must be <= 1000 MPa"));
  CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"tube_weight": -1})", "o.json"),
                    Catch::StartsWith("o.json: /tube_weight: "));
  // An integer option written as 12.0 is the integer 12, as JSON Schema counts it (session 39:
  // the sweep input's schema accepted it and the reader refused it); 12.5 and 2^31 are refused.
  CHECK(EnergyFitOptions::from_json(R"({"s_spans": 12.0})", "o.json").s_spans == 12);
  CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"s_spans": 12.5})", "o.json"),
                    "o.json: /s_spans: must be an integer");
  CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"s_spans": 2147483648.0})", "o.json"),
                    "o.json: /s_spans: must fit a 32-bit integer, got 2147483648.0");
}

TEST_CASE("energy fit: the monotonicity bound of the data", "[unit]") {
  // The gradient of a convex quadratic is monotone: no convex law need miss anything.
  Eigen::Matrix3d C;
  C << 4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0;
  std::vector<Eigen::Vector3d> e, S;
  for (int i = 0; i < 40; ++i) {
    e.push_back(Eigen::Vector3d(std::sin(1.3 * i), std::cos(0.7 * i), std::sin(0.4 * i + 1)));
    S.push_back(C * e.back());
  }
  CHECK(monotonicity_bound(e, S, 1.0) == 0.0);
  // One state whose S11 falls as E11 rises from the origin: -(S_i - S_j).(e_i - e_j) = 1 over
  // 2 range |de|_1 = 2 x 2 x 1: 0.25.
  CHECK(monotonicity_bound({Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0)},
                           {Eigen::Vector3d::Zero(), Eigen::Vector3d(-1, 0, 0)},
                           2.0) == Approx(0.25).epsilon(1e-15));
  CHECK(std::isnan(monotonicity_bound(e, S, 0.0)));
  // In the fit's diagnostics: the synthetic law is convex and the cell is not involved.
  const EnergyFitSummary s = fit_network(synthetic_coverage_db({4.5, 6.5}, 6), 50);
  for (const auto& p : s.diagnostics.per_loop) CHECK(p.monotonicity_bound < 1e-12);
}

TEST_CASE("energy fit: the tube bounds the network's largest error", "[unit]") {
  // A network too small for the synthetic law (2 and 1 units) misses some states by far more
  // than it misses most; the tube (EnergyFitOptions::tube) trades the rms for the largest error.
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  EnergyFitOptions o = small_network(2, 1, 400);
  auto largest = [](const EnergyFitSummary& s) {
    double m = 0.0;
    for (const auto& p : s.diagnostics.per_loop) m = std::max(m, p.max_relative);
    return m;
  };
  const EnergyFitSummary plain = fit_energy_law(db, o);
  REQUIRE(plain.ok());
  o.tube = 0.5 * largest(plain);
  o.tube_weight = 1e4;
  const EnergyFitSummary tube = fit_energy_law(db, o);
  REQUIRE(tube.ok());
  std::printf("tube: largest error %.2f %% of the range without, %.2f %% with a tube of %.2f %%\n",
              100 * largest(plain), 100 * largest(tube), 100 * o.tube);
  CHECK(largest(tube) < 0.8 * largest(plain));
  CHECK(tube.diagnostics.min_eigenvalue >= tube.law.floor * (1 - 1e-9));
  // The tube on the uniaxial states alone: a width < 0 there means "the same as tube".
  o.tube_uniaxial = -1.0;
  CHECK(EnergyFitOptions::from_json(o.to_json()).to_json() == o.to_json());
}

TEST_CASE("energy fit: a heavier uniaxial tube brings the uniaxial curves closer", "[unit]") {
  // A narrow tube on the uniaxial-stress states (1 % of their own axial stress) with a heavier
  // penalty there (tube_uniaxial_weight) brings the law's uniaxial curves closer to the data
  // (the synthetic law's own uniaxial-stress paths, course and wale, added to the data). The
  // network of the test above (2 and 1 units) lands in a different local minimum for every
  // seed and tube width (one seed ends at 100 % either way); so the check is on the median
  // over six seeds.
  const Database with_uniaxial = synthetic_coverage_db({4.5, 6.5}, 6, 8);
  EnergyFitOptions o = small_network(2, 1, 400);
  o.tube = 0.13;
  o.tube_weight = 1e4;
  o.tube_uniaxial = 0.01;
  auto uniaxial = [&](double weight, int seed) {
    o.tube_uniaxial_weight = weight;
    o.seed = seed;
    const EnergyFitSummary s = fit_energy_law(with_uniaxial, o);
    REQUIRE(s.ok());
    double m = 0.0;
    for (const auto& p : s.diagnostics.per_loop) m = std::max(m, p.uniaxial_max_relative);
    return m;
  };
  std::vector<double> alike, heavy;
  for (int seed = 1; seed <= 6; ++seed) {
    alike.push_back(uniaxial(1.0, seed));
    heavy.push_back(uniaxial(100.0, seed));
    std::printf("tube: seed %d, largest uniaxial error %.2f %% alike, %.2f %% x 100\n", seed,
                100 * alike.back(), 100 * heavy.back());
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  CHECK(median(heavy) < 0.5 * median(alike));
  CHECK(EnergyFitOptions::from_json(o.to_json()).to_json() == o.to_json());
}

TEST_CASE("energy fit: the network fit says how far it is", "[unit]") {
  // Session 44's red team: knit-meso fit ran 45 s with nothing on stderr, and the sweep's bar
  // stood at 100 % through its fit. EnergyFitOptions::progress gets one line every
  // progress_seconds (here 0: every iteration); the law is the same with or without it.
  const Database db = synthetic_coverage_db({4.5, 6.5}, 4);
  EnergyFitOptions o = small_network(4, 3, 20);
  const EnergyFitSummary quiet = fit_energy_law(db, o);
  REQUIRE(quiet.ok());
  std::FILE* f = std::tmpfile();
  REQUIRE(f);
  o.progress = f;
  o.progress_seconds = 0.0;
  const EnergyFitSummary loud = fit_energy_law(db, o);
  REQUIRE(loud.ok());
  std::rewind(f);
  std::string text;
  for (int c; (c = std::fgetc(f)) != EOF;) text += static_cast<char>(c);
  std::fclose(f);
  CHECK_THAT(text, Catch::StartsWith("energy fit: L-BFGS iteration ") &&
                       Catch::Contains(" of 20 (") && Catch::Contains("objective"));
  CHECK(std::count(text.begin(), text.end(), '\n') >= 5);
  CHECK(loud.law.network.theta == quiet.law.network.theta);
}

TEST_CASE("energy fit: the softness prior pulls the network towards the slack cell", "[unit]") {
  // EnergyFitOptions::prior_points: quasi-random states of the data's box with the target
  // S = floor e. A dominant prior (weight 10 x the mean data weight) must make the law softer
  // across the box than the same fit without it; the prior states are not fit data (the
  // diagnostics count the same states).
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  EnergyFitOptions o = small_network(4, 3, 300);
  const EnergyFitSummary plain = fit_energy_law(db, o);
  REQUIRE(plain.ok());
  o.prior_points = 100;
  o.prior_weight = 10.0;
  const EnergyFitSummary prior = fit_energy_law(db, o);
  REQUIRE(prior.ok());
  // The mean of |S - floor e| (MPa) over a grid of the box of the synthetic paths.
  auto excess = [](const EnergyFitSummary& s, double l) {
    const material::EnergyLawAt at = material::EnergyLaw(s.law).at(l);
    double sum = 0.0;
    int n = 0;
    for (double e1 = -0.1; e1 <= 0.301; e1 += 0.05)
      for (double e2 = -0.1; e2 <= 0.301; e2 += 0.05)
        for (double g : {0.0, 0.15, 0.3}) {
          const Eigen::Vector3d e(e1, e2, g);
          sum += (at.evaluate(e).S - s.law.floor * e).norm();
          ++n;
        }
    return sum / n;
  };
  for (double l : {4.5, 6.5}) {
    INFO("l = " << l << " mm: mean |S - floor e| " << excess(plain, l) << " MPa without the prior, "
                << excess(prior, l) << " with it");
    CHECK(excess(prior, l) < 0.5 * excess(plain, l));
  }
  REQUIRE(prior.diagnostics.per_loop.size() == plain.diagnostics.per_loop.size());
  for (std::size_t k = 0; k < plain.diagnostics.per_loop.size(); ++k)
    CHECK(prior.diagnostics.per_loop[k].points == plain.diagnostics.per_loop[k].points);
  CHECK(prior.diagnostics.min_eigenvalue >= prior.law.floor * (1 - 1e-9));
  CHECK(EnergyFitOptions::from_json(o.to_json()).to_json() == o.to_json());
  o.prior_points = -1;
  CHECK_FALSE(o.validate().empty());
}

TEST_CASE("energy fit: stiffening units are fitted, stored and keep the law convex", "[unit]") {
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  EnergyFitOptions o = small_network(4, 3, 300);
  o.stiff1 = 1;
  o.stiff2 = 2;
  const EnergyFitSummary s = fit_energy_law(db, o);
  REQUIRE(s.ok());
  CHECK(s.law.network.shape.stiff1 == 1);
  CHECK(s.law.network.shape.stiff2 == 2);
  CHECK(s.diagnostics.min_eigenvalue >= s.law.floor * (1 - 1e-9));
  for (const auto& p : s.diagnostics.per_loop) CHECK(p.rms_relative < 0.05);
}

TEST_CASE("energy fit: the exponential outer function is fitted, stored and keeps the law convex",
          "[unit]") {
  // outer "exp" (W from exp(N), session 15): the fit's gradient then runs through g'(N) S_N
  // (network_value_gradient); the stored law (outer_scale, outer_cap) must reproduce the fitted
  // one, so its diagnostics, evaluated by the stored law, show the fit's accuracy.
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  EnergyFitOptions o = small_network(4, 3, 300);
  o.outer = "exp";
  const EnergyFitSummary s = fit_energy_law(db, o);
  REQUIRE(s.ok());
  std::printf("%s", energy_fit_report(s).c_str());
  const auto& sh = s.law.network.shape;
  CHECK(sh.outer == 1);
  CHECK(sh.outer_scale > 0.0);
  CHECK(s.diagnostics.min_eigenvalue >= s.law.floor * (1 - 1e-9));
  // Measured: rms 2.5 %, largest 10.3-10.8 % of the range (4 / 3 units, 300 iterations). With
  // the value's gradient left out of the fit's gradient: rms 5.5 %, largest 24.6-24.9 %.
  for (const auto& p : s.diagnostics.per_loop) {
    INFO("l = " << p.loop_length << ": rms " << p.rms_relative << ", max " << p.max_relative);
    CHECK(p.rms_relative < 0.035);
    CHECK(p.max_relative < 0.15);
  }
  // The interpolation in l (session 16): energy by default. The fit sees the knots only, so
  // the other interpolation gives the same parameters, to the last bit.
  CHECK(s.law.network.l_interpolation == knit::material::LInterpolation::kEnergy);
  o.l_interpolation = "parameters";
  const EnergyFitSummary t = fit_energy_law(db, o);
  REQUIRE(t.ok());
  CHECK(t.law.network.l_interpolation == knit::material::LInterpolation::kParameters);
  CHECK(t.law.network.theta == s.law.network.theta);
}

TEST_CASE("energy fit: states where the cell gives way are left out of the fit", "[unit]") {
  // On the synthetic law (convex: dS . de > 0 on every step) nothing is left out. Then one
  // coverage path's stress falls at its third step (the cell "gives way": dS . de < 0): that
  // step and the rest of the path leave the fit and its diagnostics, and the report names
  // them; with stable_min_cos below -1 they are kept, and the law misses the fallen states.
  Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  EnergyFitOptions o;
  o.family = "ridge";
  const EnergyFitSummary clean = fit_energy_law(db, o);
  REQUIRE(clean.ok());
  CHECK(clean.gave_way.empty());
  {
    // Held-out paths none of which converged: the report does not claim there is no held-out
    // path (session 47's red team: "none (no path with set "holdout")").
    Database unconverged = db;
    int held = 0;
    for (auto& e : unconverged.entries)
      for (auto& p : e.raw)
        if (p.path.set == "holdout") {
          std::fill(p.status.begin(), p.status.end(), 1);
          ++held;
        }
    REQUIRE(held > 0);
    const EnergyFitSummary none = fit_energy_law(unconverged, o);
    REQUIRE(none.ok());
    CHECK(none.diagnostics.holdout_points == 0);
    CHECK(energy_fit_report(none).find("held out: no converged state (no path with set "
                                       "\"holdout\", or none of them converged)") !=
          std::string::npos);
  }
  const std::size_t q = first_coverage_path(db, 6);
  REQUIRE(q < db.entries[0].raw.size());
  auto& r = db.entries[0].raw[q];
  for (int s = 2; s < r.steps(); ++s) r.S.row(s) = 0.3 * r.S.row(1);  // falls, then stays
  const EnergyFitSummary cut = fit_energy_law(db, o);
  REQUIRE(cut.ok());
  REQUIRE(cut.gave_way.size() == 1);
  CHECK(cut.gave_way[0] == knit::material::raw_path_location(0, q) + " from step 3");
  CHECK(cut.diagnostics.points_skipped == clean.diagnostics.points_skipped + r.steps() - 2);
  CHECK(cut.diagnostics.per_loop[0].points == clean.diagnostics.per_loop[0].points - 4);
  CHECK(energy_fit_report(cut).find("gave way") != std::string::npos);
  // The law fitted without the fallen states follows the rest as before.
  CHECK(cut.diagnostics.per_loop[0].max_relative < 0.03);
  o.stable_min_cos = -2.0;
  const EnergyFitSummary kept = fit_energy_law(db, o);
  REQUIRE(kept.ok());
  CHECK(kept.gave_way.empty());
  CHECK(kept.diagnostics.points_skipped == clean.diagnostics.points_skipped);
  CHECK(kept.diagnostics.per_loop[0].max_relative > 0.1);
  // Validation.
  o.stable_min_cos = 1.5;
  CHECK(o.validate().find("stable_min_cos") != std::string::npos);
  o.stable_min_cos = std::nan("");
  CHECK(o.validate().find("stable_min_cos") != std::string::npos);
}

TEST_CASE("energy fit: a robust loss and custom directions also fit", "[unit]") {
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  EnergyFitOptions o = EnergyFitOptions::from_json(
      R"({"family": "ridge", "loss": "huber", "loss_scale": 0.01, "loss_rounds": 2, "s_spans": 6,
          "directions": [[1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]]})");
  const EnergyFitSummary s = fit_energy_law(db, o);
  REQUIRE(s.ok());
  CHECK(s.law.directions.d.rows() == 9);  // 6 + 3 mirrors
  for (const auto& p : s.diagnostics.per_loop) CHECK(p.max_relative < 0.03);
}

TEST_CASE("energy fit: the uniaxial-stress diagnostic compares the law driven like the cell",
          "[unit]") {
  Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const EnergyFitSummary s = fit_ridge(db);
  const material::EnergyLawAt at = material::EnergyLaw(s.law).at(6.5);
  // A wale-wise uniaxial path made of the law's own uniaxial response: the ratio must be 1;
  // the same path with the cell's stress scaled by 1.5 must give 1 / 1.5.
  for (const double scale : {1.0, 1.5}) {
    const int n = 5;
    material::RawPath r = zero_path(material::PathKind::kUniaxial, "coverage", n, 1);
    r.path.target << 0.05 * n, 0.0;  // wale-wise tension to E22 = 0.25
    double lateral = 0.0;
    for (int k = 0; k < n; ++k) {
      const double e2 = 0.05 * (k + 1);
      const double s2 = uniaxial_axial_stress(at, 1, e2, lateral);
      REQUIRE(std::isfinite(s2));
      // recover the lateral strain the solve found: its lateral stress vanishes there
      double lo = -0.6, hi = 0.6;
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        (at.evaluate({mid, e2, 0.0}).S(0) > 0.0 ? hi : lo) = mid;
      }
      lateral = 0.5 * (lo + hi);
      CHECK(at.evaluate({lateral, e2, 0.0}).S(1) == Approx(s2).epsilon(1e-8));
      r.E.row(k) << lateral, e2, 0.0;
      r.S.row(k) << 0.0, scale * s2, 0.0;
    }
    db.entries[1].raw.push_back(r);
    const auto dg = diagnose_energy_law(s.law, db);
    // A path that stopped (the cell jammed): its end is its last converged step (session 33,
    // a helper's audit: the end ratio was NaN then and the report said "no path").
    // The cell's stress there doubled: the end ratio is 1 / (2 scale), not the first step's.
    db.entries[1].raw.back().status.back() = 1;
    db.entries[1].raw.back().S.bottomRows(1).setConstant(99.0);  // not data
    db.entries[1].raw.back().S(n - 2, 1) *= 2.0;
    const auto stopped = diagnose_energy_law(s.law, db);
    CHECK(stopped.per_loop[1].uniaxial_end_ratio(1) == Approx(0.5 / scale).epsilon(1e-6));
    db.entries[1].raw.pop_back();
    CHECK(dg.per_loop[1].uniaxial_end_ratio(1) == Approx(1.0 / scale).epsilon(1e-6));
    CHECK(dg.per_loop[1].uniaxial_max_relative == Approx(1.0 - 1.0 / scale).margin(1e-6));
    CHECK(std::isnan(dg.per_loop[1].uniaxial_end_ratio(0)));
    // The curve stored for knit-macro (session 41): the path's steps, the law's own stress
    // beside the cell's; no course-wise curve, none at the other loop length.
    const material::UniaxialCurve& c = dg.per_loop[1].uniaxial[1];
    REQUIRE(c.strain.size() == static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      const auto i = static_cast<std::size_t>(k);
      CHECK(c.strain[i] == r.E(k, 1));
      CHECK(c.cell[i] == r.S(k, 1));
      CHECK(c.law[i] == Approx(c.cell[i] / scale).epsilon(1e-6));
    }
    CHECK(dg.per_loop[1].uniaxial[0].empty());
    CHECK(dg.per_loop[0].uniaxial[1].empty());
    // The stopped path's curve holds its converged steps only.
    CHECK(stopped.per_loop[1].uniaxial[1].strain.size() == static_cast<std::size_t>(n - 1));
    // A compression path along the same axis (to E22 = -0.2, its law 3 times the cell) counts
    // in the largest departure but is not stored: it replaced the tension curve (session 41's
    // review), which turned the wale-wise warning off.
    db.entries[1].raw.push_back(r);
    material::RawPath q = zero_path(material::PathKind::kUniaxial, "coverage", 4, 1);
    q.path.target << -0.2, 0.0;
    for (int k = 0; k < 4; ++k) {
      const double e2 = -0.05 * (k + 1);
      q.E.row(k) << 0.0, e2, 0.0;
      q.S.row(k) << 0.0, uniaxial_axial_stress(at, 1, e2, 0.0) / 3.0, 0.0;
    }
    db.entries[1].raw.push_back(q);
    const auto both = diagnose_energy_law(s.law, db);
    db.entries[1].raw.resize(db.entries[1].raw.size() - 2);
    CHECK(both.per_loop[1].uniaxial[1].strain == c.strain);
    CHECK(both.per_loop[1].uniaxial_max_relative == Approx(2.0).epsilon(1e-6));
    // The report says so for the course (no course-wise path here) instead of "nan".
    EnergyFitSummary with = s;
    with.diagnostics = dg;
    const std::string report = energy_fit_report(with);
    CHECK(report.find("course no path, wale ") != std::string::npos);
    CHECK(report.find("nan") == std::string::npos);
  }
}

TEST_CASE("energy fit: a law that misses its data by more than their range fails", "[unit]") {
  // Session 41's red team: network_iterations 5 with a floor of 1000 MPa was written with a
  // largest error of 25,214 % of the stress range, exit 0.
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const EnergyFitSummary bad =
      fit_energy_law(db, EnergyFitOptions::from_json(R"({"family": "ridge", "floor": 1000})"));
  CHECK(bad.status == FitStatus::kSolverFailed);
  CHECK_THAT(bad.reason, Catch::StartsWith("the law misses its own fit data at l = ") &&
                             Catch::Contains("(more than 100 % or an RMS of 25 %)"));
  // The same family with its own floor fits (within a few % of the range).
  const EnergyFitSummary good =
      fit_energy_law(db, EnergyFitOptions::from_json(R"({"family": "ridge"})"));
  REQUIRE(good.ok());
  for (const auto& p : good.diagnostics.per_loop) CHECK(p.max_relative < kMaxFitErrorRelative);
}

TEST_CASE("energy fit: refusals name the HDF5 path and the reason", "[unit]") {
  SECTION("non-finite data in a converged step") {
    Database db = synthetic_coverage_db({4.5, 6.5}, 4);
    db.entries[1].raw[3].S(2, 1) = NAN;
    const auto s = fit_energy_law(db, {});
    CHECK(s.status == FitStatus::kRefused);
    CHECK_THAT(s.reason,
               Catch::Contains("/loop_1/raw/path_03: step 3") && Catch::Contains("not finite"));
  }
  SECTION("data so large that the law's errors overflow") {
    // One stress of 1e308 MPa: the fit once "succeeded" with a floor of 1.6e306 MPa and an rms
    // error of inf. A law whose errors against its own data are not finite is no result.
    Database db = synthetic_coverage_db({4.5, 6.5}, 4);
    db.entries[1].raw[3].S(2, 1) = 1e308;
    EnergyFitOptions ridge;
    ridge.family = "ridge";
    const auto s = fit_energy_law(db, ridge);
    CHECK_FALSE(s.ok());
    CHECK_THAT(s.reason, Catch::Contains("the normal matrix is not finite"));
    const auto n = fit_energy_law(db, small_network(4, 3, 50));
    CHECK_FALSE(n.ok());
    CHECK_THAT(n.reason, Catch::Contains("the law's errors against the data are not finite") &&
                             Catch::Contains("1e+308 MPa at 6.5 mm"));
    // The same in a held-out state: the fit is fine, its held-out errors are not.
    Database h = synthetic_coverage_db({4.5, 6.5}, 4);
    const auto held =
        std::find_if(h.entries[1].raw.begin(), h.entries[1].raw.end(),
                     [](const material::RawPath& r) { return r.path.set == "holdout"; });
    REQUIRE(held != h.entries[1].raw.end());
    held->S(0, 0) = 1e308;  // held-out paths are single states
    const auto hs = fit_energy_law(h, ridge);
    CHECK_FALSE(hs.ok());
    CHECK_THAT(hs.reason, Catch::Contains("the law's errors against the held-out data are not "
                                          "finite"));
  }
  SECTION("a loop length without usable data") {
    Database db = synthetic_coverage_db({4.5, 6.5}, 4);
    for (auto& r : db.entries[0].raw) std::fill(r.status.begin(), r.status.end(), 1);
    const auto s = fit_energy_law(db, {});
    CHECK(s.status == FitStatus::kRefused);
    CHECK_THAT(s.reason, Catch::Contains("/loop_0/raw: only 0 converged steps"));
  }
  SECTION("a ridge law too large to solve in minutes") {
    // Session 52's red team: s_spans 200 (inside the schema's bound) would have run for hours
    // without a word. 24 default directions make 15 functions; 2 loop lengths; s_spans 60 +
    // s_degree 5: 15 x 2 x 65 = 1950 coefficients (about two minutes) pass the check, 61 + 5
    // (1980) too, 62 + 5 (2010) does not.
    Database db = synthetic_coverage_db({4.5, 6.5}, 4);
    EnergyFitOptions ridge;
    ridge.family = "ridge";
    ridge.s_degree = 5;
    ridge.s_spans = 62;
    const auto s = fit_energy_law(db, ridge);
    CHECK(s.status == FitStatus::kRefused);
    CHECK_THAT(s.reason, Catch::Contains("the ridge law would have 2010 coefficients (15 "
                                         "functions x 2 l control points") &&
                             Catch::Contains("lower s_spans"));
    // Where a refusal points: the factor farthest above the defaults' (the review of session
    // 54: always /s_spans, also when the directions were the cause).
    CHECK(ridge.ridge_size_key(2) == "/s_spans");  // 62 / 12 against (5 + 1) / (3 + 1)
    ridge.s_spans = 12;
    ridge.s_degree = 5;
    CHECK(ridge.ridge_size_key(2) == "/s_degree");
    ridge.s_degree = 3;
    for (int k = 0; k < 80; ++k)  // 80 directions on a spiral of the half sphere
      ridge.directions.emplace_back(std::cos(0.7 * k), std::sin(0.7 * k), 0.1 + k / 80.0);
    INFO(ridge.ridge_size_refusal(2));
    CHECK_FALSE(ridge.ridge_size_refusal(2).empty());
    CHECK(ridge.ridge_size_key(2) == "/directions");
    ridge.directions.clear();
    ridge.l_control_points = 40;
    CHECK(ridge.ridge_size_key(40) == "/l_control_points");
    // The s factor as a whole: s_spans 24 + s_degree 3 is 27 / 15 = 1.8 times the default's
    // size, below directions 1.9 times as many (the review of session 55: s_spans alone read 2).
    // 29 directions off the E12 = 0 plane (each with its mirror, one function): 29 / 15 = 1.93.
    ridge.l_control_points = 5;
    ridge.s_spans = 24;
    for (int k = 0; k < 29; ++k)
      ridge.directions.emplace_back(std::cos(0.9 * k), std::sin(0.9 * k), 0.2 + k / 100.0);
    CHECK(ridge.ridge_size_key(2) == "/directions");
    ridge.s_spans = 30;  // 33 / 15 = 2.2: now the s factor
    CHECK(ridge.ridge_size_key(2) == "/s_spans");
  }
  SECTION("no loop length") {
    const auto s = fit_energy_law(Database{}, {});
    CHECK(s.status == FitStatus::kRefused);
    CHECK_THAT(s.reason, Catch::Contains("/loop_lengths"));
  }
  SECTION("bad options") {
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"s_spans": 0})", "f.json", "/energy_fit"),
                      Catch::Contains("f.json: /energy_fit/s_spans: s_spans"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"floor_relative": "x"})", "f.json"),
                      Catch::Contains("f.json: /floor_relative: must be a number"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"weight_relative": -1})", "f.json"),
                      Catch::Contains("weight_relative must be in [0, 100]"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"weight_uniaxial": 0})", "f.json"),
                      Catch::Contains("weight_uniaxial"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"family": "spline"})", "f.json"),
                      Catch::Contains("family must be"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"tube": 2})", "f.json"),
                      Catch::Contains("tube must be in [0, 1]"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"max_iterations": 100001})", "f.json"),
                      Catch::Contains("max_iterations must be in 1..100000"));
    CHECK(EnergyFitOptions::from_json(R"({"max_iterations": 100000})").max_iterations == 100000);
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"tube_weight": -1})", "f.json"),
                      Catch::Contains("tube_weight"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"hidden1": 0})", "f.json"),
                      Catch::Contains("f.json: /hidden1: hidden1 must be in 1..64"));
    // Each option at its own pointer (session 44's red team: these were named at no field).
    for (const char* h2 : {"0", "65"})
      CHECK_THROWS_WITH(
          EnergyFitOptions::from_json(std::string(R"({"hidden2": )") + h2 + "}", "f.json"),
          "f.json: /hidden2: hidden2 must be in 1..64");
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"hidden2": 4, "stiff2": 5})", "f.json"),
                      "f.json: /stiff2: stiff2 must be in 0..hidden2 (here 0..4)");
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"stiff1": 13})", "f.json"),
                      "f.json: /stiff1: stiff1 must be in 0..hidden1 (here 0..12)");
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"outer": "log"})", "f.json"),
                      Catch::Contains("outer must be"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"outer": 1})", "f.json"),
                      Catch::Contains("f.json: /outer"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"l_interpolation": "spline"})", "f.json"),
                      Catch::Contains("l_interpolation must be"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"l_interpolation": 0})", "f.json"),
                      Catch::Contains("f.json: /l_interpolation"));
    CHECK(EnergyFitOptions::from_json(R"({"l_interpolation": "parameters"})", "f.json")
              .l_interpolation == "parameters");
    // The rounding of the knots' kinks (session 44): a fraction up to 0.5, energy interpolation.
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"l_blend": 0.6})", "f.json"),
                      Catch::Contains("l_blend must be in [0, 0.5]"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(
                          R"({"l_blend": 0.1, "l_interpolation": "parameters"})", "f.json"),
                      Catch::Contains("l_blend needs l_interpolation"));
    CHECK(EnergyFitOptions::from_json(R"({"l_blend": 0.1})", "f.json").l_blend == 0.1);
    // The loss is read by the helper the paper's fit shares (fit_options_json.hpp).
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"loss": "l1"})", "f.json", "/energy_fit"),
                      Catch::Contains("f.json: /energy_fit/loss: must be \"none\""));
    CHECK(EnergyFitOptions::from_json(R"({"loss": "cauchy"})", "f.json").loss == Loss::kCauchy);
    // Range before narrowing: 2^32 + 12 was read as 12 (the same check as the eq. 17 fit's).
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"hidden1": 4294967308})", "f.json"),
                      Catch::Contains("/hidden1") && Catch::Contains("32-bit"));
    CHECK_THROWS_WITH(FitOptions::from_json(R"({"degree_1": 4294967299})", "f.json"),
                      Catch::Contains("/degree_1") && Catch::Contains("32-bit"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"smooth": 1})", "f.json"),
                      Catch::Contains("/smooth: unknown energy-fit option"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"seeed": 1})", "f.json"),
                      Catch::Contains("/seeed: unknown energy-fit option (did you mean \"seed\"?"));
    CHECK_THROWS_WITH(EnergyFitOptions::from_json(R"({"directions": [[1, 0]]})", "f.json"),
                      Catch::Contains("/directions/0"));
    // Parallel directions, and one whose length overflows, are refused with the options (a
    // sweep refused them only when it laid out the law, after every case: session 36).
    CHECK_THROWS_WITH(
        EnergyFitOptions::from_json(R"({"directions": [[1, 0, 0], [-2, 0, 0]]})", "f.json"),
        "f.json: /directions: directions must not hold parallel ones (with their mirrors, (a, "
        "b, -c)): two directions are parallel");
    CHECK_THROWS_WITH(
        EnergyFitOptions::from_json(R"({"directions": [[0, 1, 1], [0, 1, -1]]})", "f.json"),
        Catch::Contains("/directions: directions must not hold parallel ones"));
    CHECK_THROWS_WITH(
        EnergyFitOptions::from_json(R"({"directions": [[1e308, 1e308, 1e308]]})", "f.json"),
        "f.json: /directions: directions must be finite and non-zero, with a length that can be "
        "normalized (not below about 1e-150 or above 1e150)");
    // Session 54's red team: 1e-160 passed (its norm underflowed to a finite subnormal) and the
    // sweep ended after all its cases with "direction 0 is not a unit vector".
    CHECK_THROWS_WITH(
        EnergyFitOptions::from_json(R"({"directions": [[1e-160, 0, 0], [0, 1, 0]]})", "f.json"),
        Catch::StartsWith("f.json: /directions: directions must be finite and non-zero"));
    CHECK_NOTHROW(
        EnergyFitOptions::from_json(R"({"directions": [[1e150, 0, 1], [0, 1, 1]]})", "f.json"));
    EnergyFitOptions o;
    o.family = "ridge";
    o.directions = {{1, 0, 0}, {2, 0, 0}};
    const auto s = fit_energy_law(synthetic_coverage_db({4.5}, 4), o);
    CHECK(s.status == FitStatus::kRefused);
    CHECK_THAT(s.reason, Catch::Contains("parallel"));
  }
}

TEST_CASE("energy fit: the options round-trip through JSON", "[unit]") {
  EnergyFitOptions o;
  o.s_spans = 5;
  o.floor = 0.01;
  o.loss = Loss::kCauchy;
  o.directions = {{1, 0, 0}, {0, 1, 0.5}};
  o.family = "ridge";
  o.hidden2 = 4;
  o.stiff1 = 0;
  o.stiff2 = 2;
  o.l_coupling = 0.5;
  o.seed = 3;
  o.tube = 0.04;
  o.tube_weight = 300;
  o.tube_uniaxial = 0.01;
  o.outer = "exp";
  const EnergyFitOptions b = EnergyFitOptions::from_json(o.to_json());
  CHECK(b.to_json() == o.to_json());
  CHECK(b.stiff2 == 2);
  CHECK(b.outer == "exp");
}

TEST_CASE("energy fit: held-out states and runs are counted against 5 % of the stress range",
          "[unit]") {
  // Issue 11's held-out figure (docs/law-experiments.md): a state is within when its largest
  // stress error is <= 5 % of its loop length's stress range; a run is within when every
  // converged state is, and its end is its last converged state. A held-out run of three
  // states at 6.5 mm whose S is the law's own response, but 8 % of the range off in S11 at the
  // middle state and 4 % off in S12 at the last, a sheared one (the strain is e = (E11, E22,
  // 2 E12)). Session 33, a helper's audit: a threshold of 50 %, a run judged by its last state
  // only and the held-out strain built with E12 instead of 2 E12 each passed the suite.
  Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const EnergyFitSummary s = fit_ridge(db);
  const auto base = diagnose_energy_law(s.law, db);
  const double range = base.per_loop[1].stress_range;
  REQUIRE(range > 0.0);
  const material::EnergyLawAt at = material::EnergyLaw(s.law).at(6.5);
  const int n = 3;
  material::RawPath r = zero_path(material::PathKind::kGradient, "holdout", n);
  for (int k = 0; k < n; ++k) {
    const double t = 0.1 * (k + 1);
    r.E.row(k) << 0.5 * t, 0.3 * t, 0.8 * t;  // tensor E12: e3 = 2 E12 = 1.6 t
    const Eigen::Vector3d e(0.5 * t, 0.3 * t, 1.6 * t);
    r.S.row(k) = at.evaluate(e).S.transpose();
  }
  r.S(1, 0) += 0.08 * range;
  r.S(2, 2) += 0.04 * range;
  db.entries[1].raw.push_back(r);
  const auto dg = diagnose_energy_law(s.law, db);
  CHECK(dg.holdout_points == base.holdout_points + 3);
  CHECK(dg.holdout_within_5_percent == base.holdout_within_5_percent + 2);
  CHECK(dg.holdout_max_relative == Approx(std::max(base.holdout_max_relative, 0.08)).epsilon(1e-6));
  CHECK(dg.holdout_runs == base.holdout_runs + 1);
  CHECK(dg.holdout_runs_within_5_percent == base.holdout_runs_within_5_percent);
  CHECK(dg.holdout_run_ends_within_5_percent == base.holdout_run_ends_within_5_percent + 1);
}

TEST_CASE("energy fit: the per-loop-length figures equal their definitions", "[unit]") {
  // Recomputed here from the converged steps of the fit's paths (not held out): per loop length
  // the largest and the RMS error per component, the stress range (the largest spread of a
  // component), max_relative and rms_relative (the largest component over the range), and the
  // smallest eigenvalue of C over all these states. Session 33, the fit audit: rms_relative as
  // a mean of components, max_relative the same, and the middle eigenvalue passed the suite.
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const EnergyFitSummary s = fit_ridge(db);
  const auto& dg = s.diagnostics;
  REQUIRE(dg.per_loop.size() == 2);
  const material::EnergyLaw law(s.law);
  double min_eig = 1e300;
  for (std::size_t k = 0; k < 2; ++k) {
    const material::EnergyLawAt at = law.at(db.entries[k].loop_length);
    Eigen::Vector3d mx = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    int n = 0;
    for (const auto& r : db.entries[k].raw) {
      if (r.path.set == "holdout") continue;
      for (int i = 0; i < r.steps(); ++i) {
        if (r.status[static_cast<std::size_t>(i)] != 0) continue;
        const Eigen::Vector3d e(r.E(i, 0), r.E(i, 1), 2.0 * r.E(i, 2));
        const Eigen::Vector3d S = r.S.row(i).transpose();
        const material::EnergyResponse v = at.evaluate(e);
        const Eigen::Vector3d err = (v.S - S).cwiseAbs();
        mx = mx.cwiseMax(err);
        sq += err.cwiseProduct(err);
        lo = lo.cwiseMin(S);
        hi = hi.cwiseMax(S);
        min_eig = std::min(
            min_eig, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(v.C).eigenvalues().minCoeff());
        ++n;
      }
    }
    const auto& p = dg.per_loop[k];
    INFO("l = " << p.loop_length);
    CHECK(p.points == n);
    const double range = (hi - lo).maxCoeff();
    const Eigen::Vector3d rms = (sq / n).cwiseSqrt();
    CHECK(p.stress_range == Approx(range).epsilon(1e-12));
    CHECK((p.max - mx).norm() <= 1e-12 * (1 + mx.norm()));
    CHECK((p.rms - rms).norm() <= 1e-12 * (1 + rms.norm()));
    CHECK(p.max_relative == Approx(mx.maxCoeff() / range).epsilon(1e-12));
    CHECK(p.rms_relative == Approx(rms.maxCoeff() / range).epsilon(1e-12));
    // the components differ, so a mean or a smallest one would not pass
    CHECK(mx.minCoeff() < 0.9 * mx.maxCoeff());
  }
  CHECK(dg.min_eigenvalue == Approx(min_eig).epsilon(1e-10));
}

TEST_CASE("energy fit: steps that did not converge are skipped, counted, and too few refused",
          "[unit]") {
  // Session 33, the fit audit: not counting the skipped steps, and refusing below 1 usable
  // step instead of 4, passed the suite.
  Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const EnergyFitSummary s = fit_ridge(db);
  const int skipped0 = diagnose_energy_law(s.law, db).points_skipped;
  CHECK(skipped0 == s.diagnostics.points_skipped);
  // Three steps of loop 0's first coverage path marked not converged: three more skipped.
  material::RawPath* cov = nullptr;
  for (auto& r : db.entries[0].raw)
    if (r.path.set == "coverage" && !cov) cov = &r;
  REQUIRE(cov);
  REQUIRE(cov->steps() >= 4);
  for (int k = 1; k <= 3; ++k) cov->status[static_cast<std::size_t>(k)] = 1;
  CHECK(diagnose_energy_law(s.law, db).points_skipped == skipped0 + 3);
  // Loop 0 with exactly 3 converged steps outside the held-out set: refused, naming it.
  int kept = 0;
  for (auto& r : db.entries[0].raw) {
    if (r.path.set == "holdout") continue;
    for (auto& st : r.status)
      if (st == 0 && kept++ >= 3) st = 1;
  }
  const EnergyFitSummary few = fit_energy_law(db, ridge_options());
  CHECK(few.status == FitStatus::kRefused);
  CHECK_THAT(few.reason, Catch::Contains("/loop_0/raw: only 3 converged steps outside the held-out "
                                         "set (at least 4 needed)"));
  CHECK_THAT(few.reason, !Catch::Contains("stable_min_cos"));  // the data's doing, not the option's
  // Session 44's red team: a threshold that leaves the steps out is named as the cause.
  // Loop 0 keeps three fitted paths of 6 steps (18 steps, enough), whose stress increments are
  // made not quite parallel to their strain increments: with stable_min_cos 1 every path gives
  // way at its second step.
  Database db2 = synthetic_coverage_db({4.5, 6.5}, 6);
  auto& raw0 = db2.entries[0].raw;
  int fitted = 0;
  raw0.erase(std::remove_if(raw0.begin(), raw0.end(),
                            [&](const auto& r) { return r.path.set != "holdout" && ++fitted > 3; }),
             raw0.end());
  for (auto& r : raw0)
    for (int s = 0; s < r.steps(); ++s) r.S(s, 2) += s % 2 ? 1e-3 : -1e-3;
  EnergyFitOptions strict = ridge_options();
  strict.stable_min_cos = 1.0;
  const EnergyFitSummary cut = fit_energy_law(db2, strict);
  CHECK(cut.status == FitStatus::kRefused);
  CHECK_THAT(cut.reason, Catch::Contains("the option stable_min_cos 1.000000 left out ") &&
                             Catch::Contains("lower it"));
  // Session 54's red team: with enough steps left (here every fitted path's first) the law was
  // fitted to the few the option kept and written with exit 0. More than half left out at a
  // loop length is refused, naming the option.
  Database db3 = synthetic_coverage_db({4.5, 6.5}, 6);
  for (auto& r : db3.entries[0].raw)
    for (int s = 0; s < r.steps(); ++s) r.S(s, 2) += s % 2 ? 1e-3 : -1e-3;
  const EnergyFitSummary most = fit_energy_law(db3, strict);
  CHECK(most.status == FitStatus::kRefused);
  CHECK_THAT(most.reason, Catch::StartsWith("/loop_0/raw: the option stable_min_cos 1 left out ") &&
                              Catch::Contains("converged fit states as steps where the cell gives "
                                              "way, more than half"));
  CHECK(fit_energy_law(db3, ridge_options()).ok());  // the default threshold keeps them
}

// Session 54's red team: options of the other family were accepted and ignored ("tube" with
// "family": "ridge" gave a law equal to the bit to the one without), and recorded as used.
TEST_CASE("energy fit options: a key of the other family is refused, naming it", "[unit]") {
  CHECK_THROWS_WITH(EnergyFitOptions::refuse_other_family_keys(
                        R"({"family": "ridge", "tube": 0.5})", "o.json", "/energy_fit"),
                    Catch::StartsWith("o.json: /energy_fit/tube: is an option of the network "
                                      "family's fit, but \"family\" is \"ridge\": it would be "
                                      "ignored"));
  CHECK_THROWS_WITH(
      EnergyFitOptions::refuse_other_family_keys(R"({"s_spans": 20})", "o.json"),
      Catch::StartsWith("o.json: /s_spans: is an option of the ridge family's fit, but "
                        "\"family\" is \"network\" (the default)"));
  for (const char* ok : {R"({"family": "ridge", "s_spans": 20, "floor": 0.2})",
                         R"({"tube": 0.05, "weight_uniaxial": 10, "stable_min_cos": 0})",
                         R"({"family": "network", "max_iterations": 100})", R"({})"})
    CHECK_NOTHROW(EnergyFitOptions::refuse_other_family_keys(ok, "o.json"));
  // A database's stored options hold every key (to_json): read as before.
  CHECK_NOTHROW(EnergyFitOptions::from_json(EnergyFitOptions().to_json(), "db.h5"));
}

TEST_CASE("energy fit: the give-way threshold is cos(dS, de) itself, near zero included",
          "[unit]") {
  // One coverage path's stress turns at its fourth step nearly at right angles to its strain
  // increment, slightly against it (cos(dS, de) = c = -0.05), and stays there. The path gives
  // way there for every threshold above c and for none below (the later steps have dS = 0, no
  // direction). c is computed from the data here, so a threshold shifted, a sign or the
  // increment taken from the wrong state is seen.
  Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const std::size_t q = first_coverage_path(db, 6);
  REQUIRE(q < db.entries[0].raw.size());
  auto& r = db.entries[0].raw[q];
  const auto e = [&](int s) { return Eigen::Vector3d(r.E(s, 0), r.E(s, 1), 2.0 * r.E(s, 2)); };
  // The path bends at step 4 (its increment no longer points away from zero strain), so an
  // increment measured from the reference instead of the previous state differs.
  const Eigen::RowVector3d bend =
      0.5 * (r.E.row(3) - r.E.row(2)).norm() * Eigen::RowVector3d(-0.6, 0.0, 0.8);
  for (int s = 3; s < r.steps(); ++s) r.E.row(s) += bend;
  const Eigen::Vector3d de = e(3) - e(2);
  REQUIRE(std::abs(de.normalized().dot(e(3).normalized())) < 0.99);
  const Eigen::Vector3d across = de.cross(Eigen::Vector3d(0.3, -0.5, 0.8)).normalized();
  const Eigen::Vector3d turn =
      0.01 * r.S.row(2).norm() * (across - 0.05 * de.normalized()).transpose();
  for (int s = 3; s < r.steps(); ++s) r.S.row(s) = r.S.row(2) + turn.transpose();
  const Eigen::Vector3d dS = (r.S.row(3) - r.S.row(2)).transpose();
  const double c = de.dot(dS) / (de.norm() * dS.norm());
  REQUIRE(c == Approx(-0.05 / std::sqrt(1.0025)));
  EnergyFitOptions o;
  o.family = "ridge";
  const EnergyFitSummary at0 = fit_energy_law(db, o);
  REQUIRE(at0.ok());
  REQUIRE(at0.gave_way.size() == 1);
  CHECK(at0.gave_way[0] == knit::material::raw_path_location(0, q) + " from step 4");
  o.stable_min_cos = c + 1e-6;
  const EnergyFitSummary above = fit_energy_law(db, o);
  REQUIRE(above.ok());
  CHECK(above.gave_way.size() == 1);
  o.stable_min_cos = c - 1e-6;
  const EnergyFitSummary below = fit_energy_law(db, o);
  REQUIRE(below.ok());
  CHECK(below.gave_way.empty());
  CHECK(below.diagnostics.points_skipped == at0.diagnostics.points_skipped - (r.steps() - 3));
}

namespace {

/// The fitted states' strains (E11, E22, 2E12): every raw step outside the held-out set.
std::vector<Eigen::Vector3d> fitted_strains(const Database& db) {
  std::vector<Eigen::Vector3d> es;
  for (const auto& entry : db.entries)
    for (const auto& r : entry.raw)
      if (r.path.set != "holdout")
        for (int s = 0; s < r.steps(); ++s) es.emplace_back(r.E(s, 0), r.E(s, 1), 2.0 * r.E(s, 2));
  return es;
}

/// [a, b]: the range of d_k . e over ridge function g's directions and the strains es, zero
/// included (the unloaded state).
std::pair<double, double> data_range(const material::EnergyLawData& law, int g,
                                     const std::vector<Eigen::Vector3d>& es) {
  double a = 0.0, b = 0.0;
  for (Eigen::Index k = 0; k < law.directions.d.rows(); ++k) {
    if (law.directions.function_of[static_cast<std::size_t>(k)] != g) continue;
    for (const auto& e : es) {
      a = std::min(a, law.directions.d.row(k).dot(e));
      b = std::max(b, law.directions.d.row(k).dot(e));
    }
  }
  return {a, b};
}

}  // namespace

TEST_CASE("energy fit: the strain box and the ridge functions' ranges follow the fitted data",
          "[unit]") {
  // The box is the fitted strains' bounding box with zero in it, symmetric in 2E12 (W is even
  // in E12); each ridge function's range [a_g, b_g] spans d . e over its directions and the
  // fitted states, widened by s_margin times its width on each side (database.md).
  const Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  const std::vector<Eigen::Vector3d> es = fitted_strains(db);
  EnergyFitOptions o = ridge_options();
  o.s_margin = 0.0;
  const EnergyFitSummary tight = fit_energy_law(db, o);
  REQUIRE(tight.ok());
  REQUIRE(tight.gave_way.empty());
  const auto& law = tight.law;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  for (const auto& e : es) {
    lo = lo.cwiseMin(e);
    hi = hi.cwiseMax(e);
  }
  CHECK(law.box_min(0) == lo(0));
  CHECK(law.box_max(0) == hi(0));
  CHECK(law.box_min(1) == lo(1));
  CHECK(law.box_max(1) == hi(1));
  const double g_max = std::max(-lo(2), hi(2));
  CHECK(law.box_max(2) == g_max);
  CHECK(law.box_min(2) == -g_max);
  REQUIRE(lo(2) > -g_max);  // the data are one-sided in E12 somewhere: the symmetry matters
  o.s_margin = 0.25;
  const EnergyFitSummary wide = fit_energy_law(db, o);
  REQUIRE(wide.ok());
  for (int g = 0; g < law.functions(); ++g) {
    const auto [a, b] = data_range(law, g, es);
    INFO("ridge function " << g << ": data from " << a << " to " << b);
    REQUIRE(a < -0.01 * (b - a));  // both signs reached: the range is the data's own
    REQUIRE(b > 0.01 * (b - a));
    CHECK(law.s_range(g, 0) == Approx(a).epsilon(1e-14));
    CHECK(law.s_range(g, 1) == Approx(b).epsilon(1e-14));
    CHECK(wide.law.s_range(g, 0) == Approx(a - 0.25 * (b - a)).epsilon(1e-14));
    CHECK(wide.law.s_range(g, 1) == Approx(b + 0.25 * (b - a)).epsilon(1e-14));
  }
}

// Session 35 (the fit audit's gap: the floor was untested): a ridge function whose data lie on
// one side of zero (d . e >= 0 at every fitted state, the unloaded state at 0) still gets a
// range reaching 1 % of its width past zero, so that zero strain is inside every function's
// spline, not on its end.
TEST_CASE("energy fit: a ridge function with one-sided data reaches past zero", "[unit]") {
  Database db = synthetic_coverage_db({4.5, 6.5}, 6);
  for (auto& entry : db.entries)
    std::erase_if(entry.raw, [](const material::RawPath& r) {
      for (int s = 0; s < r.steps(); ++s)
        if (r.E(s, 0) < 0.0 || r.E(s, 1) < 0.0 || r.E(s, 2) < 0.0) return true;
      return false;
    });
  const std::vector<Eigen::Vector3d> es = fitted_strains(db);
  REQUIRE(es.size() > 20);
  EnergyFitOptions o = ridge_options();
  o.s_margin = 0.0;
  // (1, 1, 0) sees the data above zero only, (-1, -0.5, 0) below only, (1, -1, 0) both.
  o.directions = {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-1, -0.5, 0}, {1, -1, 0}, {0, 0, 1}};
  const EnergyFitSummary fit = fit_energy_law(db, o);
  INFO(fit.reason);
  REQUIRE(fit.ok());
  int below_only = 0, above_only = 0;
  for (int g = 0; g < fit.law.functions(); ++g) {
    const auto [a, b] = data_range(fit.law, g, es);
    INFO("ridge function " << g << ": data from " << a << " to " << b);
    const double w = b - a;
    CHECK(fit.law.s_range(g, 0) == Approx(std::min(a, -0.01 * w)).epsilon(1e-14));
    CHECK(fit.law.s_range(g, 1) == Approx(std::max(b, 0.01 * w)).epsilon(1e-14));
    below_only += b < 0.01 * w ? 1 : 0;
    above_only += a > -0.01 * w ? 1 : 0;
  }
  CHECK(below_only > 0);  // each floor is reached by some function
  CHECK(above_only > 0);
}

namespace {
/// Three loop lengths, three linear l-functions (degree 1, knots at the loop lengths): the
/// largest relative gap between the law at 5.5 mm and the mean of its values at 4.5 and 6.5 mm,
/// fitted with the given smoothing along l.
double midpoint_gap(double smoothing) {
  static const Database db = synthetic_coverage_db({4.5, 5.5, 6.5}, 6);
  EnergyFitOptions o = ridge_options();
  o.l_degree = 1;
  o.l_control_points = 3;
  o.smoothing = smoothing;
  const EnergyFitSummary s = fit_energy_law(db, o);
  INFO(s.reason);
  REQUIRE(s.ok());
  const material::EnergyLaw law(s.law);
  double worst = 0.0;
  for (const Eigen::Vector3d& e :
       {Eigen::Vector3d(0.2, 0.05, 0.0), Eigen::Vector3d(0.05, 0.25, 0.1),
        Eigen::Vector3d(0.15, 0.15, -0.2)}) {
    const Eigen::Vector3d mid = law.at(5.5).evaluate(e).S;
    const Eigen::Vector3d mean = 0.5 * (law.at(4.5).evaluate(e).S + law.at(6.5).evaluate(e).S);
    worst = std::max(worst, (mid - mean).norm() / mean.norm());
  }
  return worst;
}
}  // namespace

TEST_CASE("energy fit: the smoothing along l makes the law linear in l at its limit", "[unit]") {
  // With the largest smoothing the second differences along l vanish, so the law at 5.5 mm is
  // the mean of its values at 4.5 and 6.5 mm.
  CHECK(midpoint_gap(1e3) < 1e-3);
}

TEST_CASE("energy fit: without smoothing along l the middle loop length follows its own data",
          "[verification]") {
  // The data are not linear in l (stress ~ (4.5/l)^2: 0.669 at 5.5 against a mean of 0.740),
  // so without any smoothing the middle follows its own data, 10 % away. Session 34: the fit
  // without smoothing needs 3,700 active-set solves and stopped at 2,075 ("did not converge");
  // so did every smoothing up to 1e-10. Release only since session 41: these two fits took
  // 100 s of the sanitizer pass (docs/build.md).
  CHECK(midpoint_gap(0.0) > 0.05);
  CHECK(midpoint_gap(1e-10) > 0.05);
}

TEST_CASE("energy fit: a law that misses its data by more than 10 % is warned of", "[unit]") {
  // Session 48's walkthrough: `knit-meso fit --energy-options {}` (the code's defaults) missed
  // its data by 28-30 % of the stress range with exit 0 and no word.
  knit::meso::fit::EnergyFitSummary s;
  for (const double m : {0.045, 0.283, 0.09}) {
    knit::material::EnergyFitDiagnostics::PerLoop p;
    p.loop_length = 5.0 + 0.5 * static_cast<double>(s.diagnostics.per_loop.size());
    p.max_relative = m;
    s.diagnostics.per_loop.push_back(p);
  }
  CHECK_THAT(knit::meso::fit::energy_fit_warning(s),
             Catch::StartsWith("warning: the energy law misses its data by up to 28.3 % of the "
                               "stress range (at l = 5.5 mm; more than 10 %)"));
  CHECK_THAT(knit::meso::fit::energy_fit_report(s), Catch::Contains("    warning: the energy law"));
  s.diagnostics.per_loop[1].max_relative = 0.10;  // at the threshold: no warning
  CHECK(knit::meso::fit::energy_fit_warning(s).empty());
  CHECK_THAT(knit::meso::fit::energy_fit_report(s), !Catch::Contains("warning"));
  s.diagnostics.per_loop[1].max_relative = 0.5;
  s.status = knit::meso::fit::FitStatus::kSolverFailed;  // a failed fit says why, not this
  CHECK(knit::meso::fit::energy_fit_warning(s).empty());
}
