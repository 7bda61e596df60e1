// Ceres fit of the response surfaces (eq. 17) against a synthetic, known law.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <sstream>

#include "knit/meso/fit/report.hpp"
#include "knit/meso/fit/response_fit.hpp"
#include "knit/meso/fit/synthetic.hpp"

using namespace knit::meso::fit;
using namespace knit::material;

TEST_CASE("fit: synthetic orthotropic stiffening law reproduced within 1% of its range", "[unit]") {
  SyntheticOptions so;
  const double l = 5.5;
  const auto raw = synthetic_paths(so, l);
  const FitSummary fs = fit_loop_length(raw, FitOptions{});
  REQUIRE(fs.ok());
  INFO("rms " << fs.diagnostics.rms.transpose() << " max " << fs.diagnostics.max.transpose()
              << " relative " << fs.diagnostics.max_relative);
  CHECK(fs.diagnostics.max_relative < 0.01);
  // The E-surface's distance to the data strains too (E1, E2; session 33, a helper's audit:
  // fits on a shifted xi2 grid passed, their stress errors staying small).
  double erange = 0.0;
  for (const auto& r : raw)
    for (int k = 0; k < r.steps(); ++k)
      erange = std::max(erange, r.E.row(k).head<2>().cwiseAbs().maxCoeff());
  CHECK(fs.diagnostics.max.head<2>().maxCoeff() < 0.01 * erange);
  // Independently of the diagnostics: the law at strains inside the data domain (between the
  // paths and the steps), against the known law.
  const ResponseSurface rs(fs.surface);
  double srange = 0.0, err = 0.0;
  for (const auto& r : raw)
    for (int k = 0; k < r.steps(); ++k) srange = std::max(srange, r.S.row(k).cwiseAbs().maxCoeff());
  for (double a = -20.0; a <= 110.0; a += 7.3)
    for (double t = 0.05; t <= 0.95; t += 0.1) {
      // Points inside the fan: scale the direction to a fraction of the data's reach.
      const double c = std::cos(a * M_PI / 180), s = std::sin(a * M_PI / 180);
      const double reach = 0.3 / std::max(std::abs(c), std::abs(s));
      const Eigen::Vector3d E(t * reach * c * 0.9, t * reach * s * 0.9, 0.0);
      const auto ev = rs.evaluate(
          2.0 * Eigen::Vector3d(E(0), E(1), 0.0).cwiseProduct(Eigen::Vector3d(0.5, 0.5, 1)));
      if (ev.flags != kInside) continue;
      const Eigen::Vector3d S = so.law.stress(E, l);
      err = std::max(err, (ev.S.head<2>() - S.head<2>()).cwiseAbs().maxCoeff());
    }
  for (double e12 = 0.01; e12 < 0.3; e12 += 0.03)
    err = std::max(err,
                   std::abs(rs.evaluate({0, 0, 2 * e12}).S(2) - so.law.stress({0, 0, e12}, l)(2)));
  CHECK(err < 0.01 * srange);
}

TEST_CASE("fit: robust loss and foot-point optimization run and stay accurate", "[unit]") {
  SyntheticOptions so;
  auto raw = synthetic_paths(so, 4.5);
  // One outlier step: the Huber loss keeps it from spoiling the fit.
  raw[3].S(10, 0) += 5.0;
  FitOptions o;
  o.loss = Loss::kHuber;
  o.loss_scale = 0.01;
  const FitSummary huber = fit_loop_length(raw, o);
  REQUIRE(huber.ok());
  o.loss = Loss::kNone;
  const FitSummary plain = fit_loop_length(raw, o);
  REQUIRE(plain.ok());
  const ResponseSurface a(huber.surface), b(plain.surface);
  const Eigen::Vector3d E(raw[4].E(10, 0), raw[4].E(10, 1), 0);
  const double exact = so.law.stress({E(0), E(1), 0}, 4.5)(0);
  CHECK(std::abs(a.evaluate(E).S(0) - exact) < std::abs(b.evaluate(E).S(0) - exact));
  raw = synthetic_paths(so, 4.5);
  o.optimize_foot_points = true;
  const FitSummary fp = fit_loop_length(raw, o);
  REQUIRE(fp.ok());
  CHECK(fp.diagnostics.max_relative < 0.01);
}

TEST_CASE("fit: a law that misses its data by their range, or by an RMS of a quarter, fails",
          "[unit]") {
  // Session 44's red team: the paper's surfaces smoothed flat (smoothing 1000, 4 x 4 control
  // points) were written with a largest error of 98 % of the stress range and an RMS of 32-35
  // %, exit 0; a ridge energy law of the one direction (1, 0, 0), 97.8 % and 30.7 %. The bound
  // on the largest error alone (the whole range) cannot see such laws; the RMS bound does,
  // and a robust fit that leaves out one outlier (largest 96 %, RMS 6 %, the Huber test above)
  // stays a law. Both fits ask fit_error_refusal.
  CHECK(fit_error_refusal(0.045, 0.02).empty());  // the default energy law
  CHECK(fit_error_refusal(0.96, 0.062).empty());  // the Huber fit with its outlier
  CHECK(fit_error_refusal(1.0, 0.25).empty());    // on both bounds
  CHECK_THAT(fit_error_refusal(0.98, 0.32),       // the red team's flat surfaces
             Catch::Equals("by up to 98 % of the stress range, RMS 32 % (more than 100 % or an "
                           "RMS of 25 %)"));
  CHECK_FALSE(fit_error_refusal(252.1, 70.5).empty());  // session 41's floor of 1000 MPa
  CHECK_FALSE(fit_error_refusal(1.01, 0.1).empty());
  // On the synthetic law the flattest surfaces miss by 64 % with an RMS of 18 %: a law.
  SyntheticOptions so;
  const FitSummary flat =
      fit_loop_length(synthetic_paths(so, 5.5),
                      FitOptions::from_json(
                          R"({"smoothing": 1000, "control_points_1": 4, "control_points_2": 4})"));
  CHECK(flat.ok());
  CHECK(flat.diagnostics.rms_relative == Approx(0.183).margin(0.01));
}

TEST_CASE("fit: data that cannot determine the surface are refused with the reason", "[unit]") {
  SyntheticOptions so;
  auto raw = synthetic_paths(so, 5.0);
  SECTION("too few paths") {
    raw.erase(raw.begin() + 2, raw.begin() + 11);
    const auto fs = fit_loop_length(raw, FitOptions{});
    CHECK(fs.status == FitStatus::kRefused);
    CHECK_THAT(fs.reason, Catch::Contains("3 biaxial paths cannot determine a degree-3"));
  }
  SECTION("no shear path") {
    raw.pop_back();
    CHECK_THAT(fit_loop_length(raw, FitOptions{}).reason, Catch::Contains("no pure-shear path"));
  }
  SECTION("two pure-shear paths in the paper set") {
    // Session 47's red team: the second was left out of the S12(E12) fit, with exit 0 ("fit
    // ... ok", the curve ending at a quarter of the data's E12). As a coverage path it is
    // not the paper's and does not count.
    raw.push_back(raw.back());
    CHECK_THAT(fit_loop_length(raw, FitOptions{}).reason,
               Catch::StartsWith("2 pure-shear paths in the paper set"));
    raw.back().path.set = "coverage";
    CHECK(fit_loop_length(raw, FitOptions{}).ok());
  }
  SECTION("duplicate direction") {
    raw[4] = raw[5];
    CHECK_THAT(fit_loop_length(raw, FitOptions{}).reason, Catch::Contains("same strain direction"));
  }
  SECTION("non-finite data") {
    raw[2].S(3, 1) = std::nan("");
    CHECK(fit_loop_length(raw, FitOptions{}).reason ==
          "raw/path_02, step 4: non-finite strain or stress data in a converged step");
    // Without its number in a file, its place in the list.
    raw[2].index = -1;
    CHECK(fit_loop_length(raw, FitOptions{}).reason ==
          "path 2, step 4: non-finite strain or stress data in a converged step");
    // In a step that did not converge it is no datum (session 47's red team: refused).
    raw[2].status[3] = 1;
    const FitSummary fs = fit_loop_length(raw, FitOptions{});
    CHECK(fs.ok());
    CHECK(std::isfinite(fs.diagnostics.rms.maxCoeff()));
  }
  SECTION("a path without a converged step") {
    std::fill(raw[1].status.begin(), raw[1].status.end(), 1);
    CHECK_THAT(fit_loop_length(raw, FitOptions{}).reason, Catch::Contains("no converged step"));
  }
  SECTION("too many control points without smoothing") {
    FitOptions o;
    o.smoothing = 0.0;
    o.n_ctrl1 = 15;
    CHECK_THAT(fit_loop_length(raw, o).reason, Catch::Contains("need at least as many paths"));
  }
  SECTION("bad options") {
    FitOptions o;
    o.n_ctrl1 = 2;
    CHECK_THAT(fit_loop_length(raw, o).reason, Catch::Contains("at least degree + 1"));
    CHECK_THROWS_WITH(FitOptions::from_json("{\"loss\": \"l1\"}", "opts.json"),
                      Catch::Contains("opts.json: /loss: must be"));
    CHECK_THROWS_WITH(FitOptions::from_json("{\"smoth\": 1}", "opts.json"),
                      Catch::Contains("/smoth: unknown fit option (allowed: \"degree_1\", "));
    // A key holding '/' is named by its escaped pointer (session 27: "/a/b").
    CHECK_THROWS_WITH(FitOptions::from_json("{\"a/b\": 1}", "opts.json"),
                      Catch::Contains("opts.json: /a~1b: unknown fit option"));
  }
  SECTION("every integer option is bounded and named by its pointer") {
    // control_points_1 = 123456789 ran for minutes (60 take 90 s); the bounds are the sweep
    // schema's /fit bounds.
    const std::pair<const char*, const char*> cases[] = {
        {R"({"degree_1": 0})", "opts.json: /degree_1: must be in 1..9, got 0"},
        {R"({"degree_2": 10})", "opts.json: /degree_2: must be in 1..9, got 10"},
        {R"({"shear_degree": -1})", "opts.json: /shear_degree: must be in 1..9"},
        {R"({"control_points_1": 123456789})", "opts.json: /control_points_1: must be in 4..60"},
        {R"({"control_points_2": 61})", "opts.json: /control_points_2: must be in 4..60"},
        {R"({"shear_degree": 5, "shear_control_points": 5})",
         "opts.json: /shear_control_points: must be in 6..60 (at least degree + 1), got 5"},
        {R"({"max_iterations": 0})", "opts.json: /max_iterations: must be in 1..100000"},
        {R"({"max_iterations": 100001})", "opts.json: /max_iterations: must be in 1..100000"},
        {R"({"smoothing": -1})", "opts.json: /smoothing: must be in [0, 1000]"}};
    for (const auto& [text, message] : cases) {
      INFO(text);
      CHECK_THROWS_WITH(FitOptions::from_json(text, "opts.json"), Catch::Contains(message));
    }
    // The edges are accepted.
    CHECK(FitOptions::from_json(R"({"degree_1": 9, "control_points_1": 60})").n_ctrl1 == 60);
    CHECK(FitOptions::from_json(R"({"degree_1": 1, "control_points_1": 2})").n_ctrl1 == 2);
    CHECK(FitOptions::from_json(R"({"max_iterations": 100000})").max_iterations == 100000);
  }
}

TEST_CASE("fit: eq. 17 uses the paper's paths only (coverage and holdout paths are ignored)",
          "[unit]") {
  SyntheticOptions so;
  const auto paper = synthetic_paths(so, 5.0);
  auto extended = paper;
  // Coverage paths of every kind, with data the paper fit must not see: a biaxial path in
  // biaxial compression (outside the fan, opposite stresses), a uniaxial and a gradient path,
  // a second shear path, a holdout path inside the fan, and a path that never converged.
  auto add = [&](RawPath r, PathKind kind, const std::string& set, double scale) {
    r.path.kind = kind;
    r.path.set = set;
    r.E *= scale;
    r.S *= -3.0;
    extended.push_back(std::move(r));
  };
  add(paper[0], PathKind::kBiaxial, "coverage", -1.0);
  add(paper[3], PathKind::kUniaxial, "coverage", 0.8);
  add(paper[5], PathKind::kGradient, "coverage", 1.1);
  add(paper.back(), PathKind::kShear, "coverage", 0.5);
  add(paper[6], PathKind::kBiaxial, "holdout", 0.7);
  RawPath failed = paper[2];
  failed.path.set = "coverage";
  std::fill(failed.status.begin(), failed.status.end(), 1);
  extended.push_back(failed);
  // Coverage paths first, so that a fit taking them would also change the ordering.
  std::rotate(extended.begin(), extended.begin() + static_cast<long>(paper.size()), extended.end());

  const FitSummary a = fit_loop_length(paper, FitOptions{});
  const FitSummary b = fit_loop_length(extended, FitOptions{});
  REQUIRE(a.ok());
  INFO(b.reason);
  REQUIRE(b.ok());
  CHECK(a.surface.E_ctrl == b.surface.E_ctrl);
  CHECK(a.surface.S_ctrl == b.surface.S_ctrl);
  CHECK(a.surface.E12_ctrl == b.surface.E12_ctrl);
  CHECK(a.surface.S12_ctrl == b.surface.S12_ctrl);
  CHECK(a.diagnostics.points_used == b.diagnostics.points_used);
  CHECK(a.diagnostics.max_relative == b.diagnostics.max_relative);
  CHECK_FALSE(in_paper_fit(extended.front()));
  CHECK(in_paper_fit(paper.front()));
}

namespace {

/// A cell that is slack and then locks (contact engagement), like the swept cell's data: a soft
/// linear law A E up to |E| = r_k, then a steep radial stiffening; shear alike. The fitted
/// cubic rings across the kink.
void make_slack_then_locking(std::vector<RawPath>& raw) {
  const Eigen::Matrix2d A = (Eigen::Matrix2d() << 1.2, 0.05, 0.05, 0.2).finished();
  const double rk = 0.06, K = 60.0, gk = 0.02, g0 = 0.5, G = 40.0;
  for (auto& r : raw)
    for (int k = 0; k < r.steps(); ++k) {
      const Eigen::Vector2d E = r.E.row(k).head<2>().transpose();
      const double rad = E.norm();
      Eigen::Vector2d S = A * E;
      if (rad > rk) S += K * (rad - rk) * E;
      const double e12 = r.E(k, 2);
      r.S(k, 0) = S(0);
      r.S(k, 1) = S(1);
      r.S(k, 2) = g0 * e12 + (std::abs(e12) > gk ? G * (e12 - std::copysign(gk, e12)) : 0.0);
    }
}

/// The smallest radial stiffness d^T C d / |d|^2 and secant S.E / |E|^2 of the fan chart at
/// |E| = radius, over the directions of the fan, and C33 there.
struct SmallStrain {
  double radial = 1e300, secant = 1e300, C33 = 0.0;
};
SmallStrain small_strain_response(const ResponseSurface& rs, double radius) {
  SmallStrain out;
  for (double a = rs.fan_begin(); a <= rs.fan_end(); a += 0.01) {
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    const auto ev = rs.evaluate({radius * d(0), radius * d(1), 0.0});
    out.radial = std::min(out.radial, d.dot(ev.C.topLeftCorner<2, 2>() * d));
    out.secant = std::min(out.secant, ev.S.head<2>().dot(d) / radius);
  }
  out.C33 = rs.evaluate({0.0, 0.0, 2.0 * radius}).C(2, 2);
  return out;
}

}  // namespace

TEST_CASE("fit: the initial stiffness of a slack-then-locking cell is the first step's secant",
          "[unit]") {
  // The mechanism of the eq. 17 law's first-step stop on the gamma/w = 0.225 database: a free
  // cubic fit rings across the locking kink and the tangent at small strains gets the wrong
  // sign (shell Newton diverges at the first load step). "first_step" ties the first control
  // row to the data's first secant.
  SyntheticOptions so;
  auto raw = synthetic_paths(so, 4.5);
  make_slack_then_locking(raw);
  REQUIRE(FitOptions{}.initial_stiffness == InitialStiffness::kFirstStep);  // the default
  auto fit_with = [&](InitialStiffness k) {
    FitOptions o;
    o.initial_stiffness = k;
    FitSummary fs = fit_loop_length(raw, o);
    REQUIRE(fs.ok());
    return fs;
  };
  const FitSummary pinned = fit_with(InitialStiffness::kFirstStep);
  const FitSummary free = fit_with(InitialStiffness::kFit);
  const ResponseSurface a(pinned.surface), b(free.surface);
  for (double radius : {1e-6, 1e-4, 1e-3}) {
    const SmallStrain p = small_strain_response(a, radius), f = small_strain_response(b, radius);
    INFO("|E| = " << radius << ": first_step radial " << p.radial << " secant " << p.secant
                  << " C33 " << p.C33 << "; fit radial " << f.radial << " secant " << f.secant
                  << " C33 " << f.C33);
    // The soft law's radial stiffness is 0.2-1.2 MPa, the shear 0.25 MPa.
    CHECK(p.radial > 0.1);
    CHECK(p.secant > 0.1);
    CHECK(p.C33 > 0.2);
    // The free fit shows the mechanism (so this test would fail with it).
    CHECK((f.radial < 0.0 || f.secant < 0.0 || f.C33 < 0.0));
  }
  // C at the origin is the data's first secant (here the soft law A).
  CHECK(a.C0()(0, 0) == Approx(1.2).epsilon(0.02));
  CHECK(a.C0()(1, 1) == Approx(0.2).epsilon(0.02));
  CHECK(a.C0()(2, 2) == Approx(0.25).epsilon(1e-6));  // C33 = dS12/d(2E12) = g0 / 2
  CHECK(pinned.diagnostics.max_relative < 0.02);
}

TEST_CASE("fit: the initial_stiffness option is read, written and checked", "[unit]") {
  CHECK(FitOptions::from_json(R"({"initial_stiffness": "fit"})").initial_stiffness ==
        InitialStiffness::kFit);
  CHECK(FitOptions::from_json(R"({"initial_stiffness": "first_step"})").initial_stiffness ==
        InitialStiffness::kFirstStep);
  CHECK(FitOptions::from_json(FitOptions{}.to_json()).initial_stiffness ==
        InitialStiffness::kFirstStep);
  CHECK_THROWS_WITH(FitOptions::from_json(R"({"initial_stiffness": "zero"})", "o.json"),
                    Catch::Contains("o.json") && Catch::Contains("/initial_stiffness"));
}

TEST_CASE("fit: weights large enough to overflow are refused with the option's name", "[unit]") {
  // smoothing 1e308 made the residuals infinite: Ceres failed without naming an option, and
  // foot_point_penalty 1e308 ended the foot-point solves in invalid steps with exit code 0.
  FitOptions o;
  CHECK(o.validate().empty());
  o.smoothing = 1e308;
  CHECK(o.validate() == "smoothing must be in [0, 1000]");
  o.smoothing = 1e3;
  CHECK(o.validate().empty());
  o.foot_point_penalty = 1e308;
  CHECK(o.validate() == "foot_point_penalty must be in [0, 1000]");
  o.foot_point_penalty = 1e-4;
  o.loss_scale = 1e308;
  CHECK(o.validate() == "loss_scale must be in (0, 1000]");
  CHECK_THROWS_WITH(FitOptions::from_json(R"({"smoothing": 1e308})", "o.json"),
                    Catch::Contains("o.json: /smoothing: must be in [0, 1000]"));
}

// Session 29 (a helper's fuzzing audit): a raw stress of 1e308 gave the paper fit rms = inf,
// written into the database with exit 0. The database reader now refuses such values; the fit
// refuses non-finite errors itself as well (data handed over by the API).
TEST_CASE("fit: non-finite errors against the data are a failed fit", "[unit]") {
  SyntheticOptions so;
  auto raw = synthetic_paths(so, 5.5);
  REQUIRE(fit_loop_length(raw, FitOptions{}).ok());
  for (auto& r : raw)
    if (r.path.kind == PathKind::kShear) r.S(r.steps() - 1, 2) = 1e300;  // squared: inf
  const FitSummary fs = fit_loop_length(raw, FitOptions{});
  CHECK_FALSE(fs.ok());
  CHECK_THAT(fs.reason, Catch::Contains("not finite"));
}

TEST_CASE("fit: the summary line names each stress component with its own figures", "[unit]") {
  // Session 33, the fit audit: the line printing E1's RMS as "rms S1" passed the suite (the
  // E and S figures sit side by side in FitDiagnostics: E1, E2, S1, S2, S12).
  Database db;
  db.entries.resize(2);
  db.entries[0].loop_length = 4.5;
  db.entries[1].loop_length = 6.5;
  std::vector<FitSummary> fits(2);
  fits[0].diagnostics.max << 1, 2, 3, 4, 5;
  fits[0].diagnostics.rms << 6, 7, 8, 9, 10;
  fits[0].diagnostics.max_relative = 0.11;
  fits[1].status = FitStatus::kRefused;
  fits[1].reason = "too few steps";
  std::ostringstream os;
  print_fit_summaries(os, db, fits);
  const std::string text = os.str();
  for (const char* part : {"l = 4.5 mm: max |S error| S1 3, S2 4, S12 5 MPa", "(11 % of",
                           "rms S1 8, S2 9, S12 10 MPa", "l = 6.5 mm: REFUSED: too few steps"})
    CHECK_THAT(text, Catch::Contains(part));
}

// Session 54's red team: the paper law with smoothing 1000 missed its data by 62 % of the
// stress range and the sweep printed "ok", with nothing on stderr. Above 10 % it is a warning
// (and "POOR" in the sweep's line), at the worst loop length among the fits that succeeded.
TEST_CASE("fit: a paper law far from its data is a warning", "[unit]") {
  std::vector<FitSummary> fits(3);
  fits[0].diagnostics.max_relative = 0.004;
  fits[1].diagnostics.max_relative = 0.6226;
  fits[2].diagnostics.max_relative = 0.9;
  fits[2].status = FitStatus::kRefused;  // a failed fit is an error of its own, not counted
  const std::string w = paper_fit_warning({4.5, 5.0, 6.5}, fits);
  CHECK_THAT(w, Catch::StartsWith("warning: the paper law's surfaces miss their fit data by up "
                                  "to 62.26 % of the stress range (at l = 5 mm; more than 10 %)"));
  fits[1].diagnostics.max_relative = 0.1;  // the bound itself passes
  CHECK(paper_fit_warning({4.5, 5.0, 6.5}, fits).empty());
  fits[1].diagnostics.max_relative = 0.1001;
  CHECK_FALSE(paper_fit_warning({4.5, 5.0, 6.5}, fits).empty());
}

TEST_CASE("fit: a loop length whose refit fails keeps no law from before", "[unit]") {
  // fit_database replaces every entry's law: one whose refit fails loses its old surface and
  // diagnostics, so no stale law is written beside the new ones (cmd_fit writes nothing then
  // anyway). Session 33, the fit audit: keeping the old surface passed the suite.
  SyntheticOptions so;
  so.loop_lengths = {4.5, 6.5};
  Database db = synthetic_database(so);
  for (const auto& f : fit_database(db, FitOptions{})) REQUIRE(f.ok());
  REQUIRE(db.entries[0].surface);
  REQUIRE(db.entries[0].diagnostics.max_relative > 0.0);
  FitOptions bad;
  bad.smoothing = 0.0;
  bad.n_ctrl1 = 15;  // too many control points for the steps, without smoothing
  const auto fits = fit_database(db, bad);
  REQUIRE(fits.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    INFO("entry " << k);
    CHECK_FALSE(fits[k].ok());
    CHECK_FALSE(db.entries[k].surface);
    CHECK(db.entries[k].diagnostics.max_relative == 0.0);
  }
}

TEST_CASE("fit: a fan of exactly 180 degrees is refused, and paths of too few steps", "[unit]") {
  // check_fan (fit_loop_length's refusals): a fan spanning pi or more cannot be inverted, and
  // a surface of degree p along the paths needs p + 1 steps. Session 33, the fit audit: a fan
  // of exactly 180 degrees accepted, and a steps refusal one short, passed the suite.
  const FitOptions o;
  FanShape fan;
  fan.shear = true;
  fan.min_steps = o.degree2 + 1;
  for (int k = 0; k <= o.degree1 + 1; ++k)
    fan.phi.push_back(M_PI * k / (o.degree1 + 1));  // 0 ... pi
  CHECK_THAT(check_fan(o, fan), Catch::Contains("span 180 degrees or more"));
  fan.phi.back() = std::nextafter(M_PI, 0.0);
  CHECK(check_fan(o, fan).empty());
  fan.shear = 2;  // two paper shear paths: refused before a sweep (check_feasible) too
  CHECK_THAT(check_fan(o, fan), Catch::StartsWith("2 pure-shear paths in the paper set"));
  fan.shear = 1;
  fan.min_steps = o.degree2;
  CHECK(check_fan(o, fan) == "paths with " + std::to_string(o.degree2) +
                                 " steps cannot determine a degree-" + std::to_string(o.degree2) +
                                 " surface along the paths");
}

TEST_CASE("fit: the diagnostics count the paper's converged steps, each error in its component",
          "[unit]") {
  // diagnose(): a pure-shear step is measured as S12 at E = (0, 0, 2 E12) (evaluate() takes
  // engineering shear), a biaxial step as S11 and S22 at (E11, E22, 0); points_used counts the
  // converged steps of the paper's paths. One datum moved by 0.5 MPa shows in its own
  // component's largest error and in no other.
  SyntheticOptions so;
  auto raw = synthetic_paths(so, 5.5);
  const FitSummary fs = fit_loop_length(raw, FitOptions{});
  REQUIRE(fs.ok());
  const ResponseSurface law(fs.surface);
  const FitDiagnostics base = diagnose(fs.surface, raw);
  int steps = 0;
  std::size_t shear = raw.size(), biaxial = raw.size();
  for (std::size_t q = 0; q < raw.size(); ++q) {
    if (!in_paper_fit(raw[q])) continue;
    steps += raw[q].steps();
    (raw[q].path.kind == PathKind::kShear ? shear : biaxial) = q;
  }
  REQUIRE(shear < raw.size());
  REQUIRE(biaxial < raw.size());
  CHECK(base.points_used == steps);
  const double shift = 0.5;
  REQUIRE(base.max.tail<3>().maxCoeff() < 0.1 * shift);
  {
    auto moved = raw;
    const int k = raw[shear].steps() / 2;
    moved[shear].S(k, 2) += shift;
    const double err =
        law.evaluate({0.0, 0.0, 2.0 * raw[shear].E(k, 2)}).S(2) - moved[shear].S(k, 2);
    const FitDiagnostics d = diagnose(fs.surface, moved);
    CHECK(d.max(4) == Approx(std::abs(err)).epsilon(1e-12));
    CHECK(d.max(2) == base.max(2));
    CHECK(d.max(3) == base.max(3));
  }
  {
    auto moved = raw;
    const int k = raw[biaxial].steps() - 1;
    moved[biaxial].S(k, 1) += shift;
    const double err = law.evaluate({raw[biaxial].E(k, 0), raw[biaxial].E(k, 1), 0.0}).S(1) -
                       moved[biaxial].S(k, 1);
    const FitDiagnostics d = diagnose(fs.surface, moved);
    CHECK(d.max(3) == Approx(std::abs(err)).epsilon(1e-12));
    CHECK(d.max(2) == base.max(2));
    CHECK(d.max(4) == base.max(4));
  }
  // A step that did not converge is not a point; neither is a step of a path outside the fit.
  raw[biaxial].status[1] = 1;
  auto outside = raw[shear];
  outside.path.set = "coverage";
  raw.push_back(outside);
  CHECK(diagnose(fs.surface, raw).points_used == steps - 1);
}

// Session 54's red team: options the sweep refuses before its cases (a degree-9 surface on
// 6-step paths, a ridge law of 6090 coefficients) were refused by `knit-meso fit` naming the
// database (exit 2 or 1) and by synth naming neither file nor key. They are refused before any
// fit, naming the options file (and /s_spans for the ridge's size); options not from a file
// are not judged.
TEST_CASE("fit: options that cannot fit the database are refused naming their file", "[unit]") {
  SyntheticOptions so;
  so.loop_lengths = {4.5, 5.0};
  so.paths = default_load_paths(6);
  const Database db = synthetic_database(so);
  FitOptions fo;
  fo.degree2 = 9;
  EnergyFitOptions eo;
  CHECK_THROWS_WITH(refuse_unfittable_options(db, fo, "fo.json", eo, ""),
                    Catch::StartsWith("fo.json: these options cannot fit the paper law to the "
                                      "database's load paths: paths with 6 steps cannot "
                                      "determine a degree-9 surface"));
  CHECK_NOTHROW(refuse_unfittable_options(db, fo, "", eo, ""));
  // Paths no options could fit (no paper path) are the database's doing: the fit says so.
  Database no_paper = db;
  for (auto& e : no_paper.entries)
    e.raw.erase(std::remove_if(e.raw.begin(), e.raw.end(),
                               [](const RawPath& r) { return r.path.set == "paper"; }),
                e.raw.end());
  CHECK_NOTHROW(refuse_unfittable_options(no_paper, fo, "fo.json", eo, ""));
  eo.family = "ridge";
  eo.s_spans = 200;
  eo.l_control_points = 50;
  CHECK_THROWS_WITH(refuse_unfittable_options(db, FitOptions{}, "", eo, "eo.json"),
                    Catch::StartsWith("eo.json: /s_spans: the ridge law would have "));
  CHECK_NOTHROW(
      refuse_unfittable_options(db, FitOptions{}, "fo.json", EnergyFitOptions{}, "eo.json"));
}
