// Fit of the energy-based law (knit/material/energy_law.hpp) to the cell's stresses, with
// Ceres (issue 11, item 3).
//
// Data: E and S of every converged step (status 0) of every raw path whose set is not
// "holdout", at every loop length; e = (E11, E22, 2 E12). Paths with set "holdout" only give
// the held-out errors.
//
// The law is linear in its coefficients x = (c_gij) (f_g'' coefficients, s index i, l index
// j): S(e; l) = A(e, l) x + floor e. Objective (dimensionless):
//   (1/N) sum_data w_p |(A_p x + floor e_p - S_p) / sS|^2
//     + lambda sum |second differences of c along s and along l / sK|^2,     x >= 0,
// N = number of stress residuals, sS = largest |S| of the data, sK = sS / sE (sE = largest
// |e|), w_p = 1 without a loss, IRLS weights of the Huber or Cauchy loss otherwise. Because
// the data term is quadratic, it is condensed to its normal equations (a tiny ridge keeps them
// definite) and minimized over x >= 0 exactly, by an active-set method (knit/meso/fit/nnls.hpp;
// Ceres with parameter bounds until session 14, which stopped short of the optimum). The
// nonnegativity makes every fitted W convex at every l of the range (C >= floor I): a fit that
// cannot be made convex cannot happen by construction.
//
// Choices (documented in docs/database.md, all configurable):
//  * s-range of each function: the range of d_k . e over the data (both mirror directions),
//    widened by s_margin times its width on each side (and always containing 0);
//  * l: quadratic with min(5, loop lengths) control points (degree capped at control points - 1;
//    5 = one per default loop length, so each simulated l has its own freedom, C1 in l);
//  * floor: `floor` MPa if >= 0, else floor_relative * sS / sE (a fraction of the data's
//    secant stiffness; default 1 %).
//
// Refusals (status kRefused, with the reason and the HDF5 path): no loop length, a loop length
// without usable data (fewer than 4 converged non-holdout steps), non-finite data in a
// converged step, invalid options.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "knit/material/database.hpp"
#include "knit/meso/fit/response_fit.hpp"

namespace knit::meso::fit {

/// The data's own floor for any convex law, in units of `range` (docs/law-experiments.md
/// "What convexity itself costs"): the gradient of a convex W is monotone,
/// (S_i - S_j) . (e_i - e_j) >= 0, and stress errors |d_ic| <= delta * range change that
/// product by at most 2 delta range |e_i - e_j|_1, so every pair needs
/// delta >= -(S_i - S_j) . (e_i - e_j) / (2 range |e_i - e_j|_1). Returns the largest over all
/// pairs (0 for monotone data). e = (E11, E22, 2E12); O(n^2), no allocation.
double monotonicity_bound(const std::vector<Eigen::Vector3d>& e,
                          const std::vector<Eigen::Vector3d>& S, double range);

struct EnergyFitOptions {
  /// "ridge" (the convex ridge-spline sum) or "network" (the input-convex network,
  /// knit/material/convex_network.hpp; fitted by mesoscale/src/fit_network.cpp).
  std::string family = "network";
  /// Network family: hidden layer sizes, the coupling of neighbouring loop lengths' parameters
  /// (penalty l_coupling |theta_j+1 - theta_j|^2, so theta(l) interpolates sensibly between the
  /// fitted loop lengths), the seed of the initial parameters, and L-BFGS iterations.
  int hidden1 = 12, hidden2 = 6;
  /// Network family: how many of each layer's units use the stiffening activation rho
  /// (knit/material/convex_network.hpp; the last ones of the layer). 0: none.
  int stiff1 = 0, stiff2 = 0;
  /// Network family: the outer function (knit/material/convex_network.hpp, NetworkShape::outer):
  /// "none" (W from N itself) or "exp" (W from exp(N), Fung's form; session 15).
  std::string outer = "none";
  /// Network family: the law between the fitted loop lengths (knit/material/convex_network.hpp
  /// LInterpolation; docs/database.md "Interpolation in l"): "energy" (W piecewise linear in
  /// l, the convex combination of the neighbouring knots' laws; the default) or "parameters"
  /// (theta piecewise linear, one network: twice the evaluation rate between the knots, but
  /// nothing ties neighbouring knots' networks together, and on a 9-knot database it was
  /// 103 % of the stress range off the cell between two of them). The fit itself sees the
  /// knots only, so both give the same law there.
  std::string l_interpolation = "energy";
  /// With l_interpolation "energy": the rounding of the kinks at the interior knots, the
  /// window's half-width as a fraction of the shorter neighbouring span (0 ... 0.5; 0: none;
  /// NetworkLawData::l_blend, session 44). The fit does not see it (it fits each knot's law to
  /// that knot's data); the diagnostics evaluate the law with it, which departs from the knot
  /// law at the knot by l_blend / 4 x the second difference of the knots' laws.
  double l_blend = 0.0;
  double l_coupling = 1e-4;
  int seed = 1;
  /// Network family: multi-start (session 57). The fit runs from the initial draws of seeds
  /// seed, seed + 1, ..., seed + starts - 1 and keeps the one with the smallest final objective
  /// (the fit data's, never the held-out states'); each start costs a whole fit. 1: one start,
  /// the law of sessions 5-56.
  int starts = 1;
  int network_iterations = 4000;
  /// Network family: a tube around the data (choice, docs/database.md "The tube"). Each stress
  /// component's error beyond tube * (the loop length's stress range) adds
  /// tube_weight / (3 n) * excess^2 (scaled stresses, every point alike, whatever its data
  /// weight): the weights decide the fit inside the tube, the tube bounds the largest error.
  /// tube = 0: off.
  double tube = 0.0;
  double tube_weight = 100.0;
  /// The tube's half-width on the uniaxial-stress paths' states, a fraction of each state's
  /// own axial stress (every component, the lateral one too), at most `tube` times the range;
  /// < 0: the same as the others'. The course-wise tensile curve of the loose cell stays below
  /// 5 % of the range (6.5 mm: 0.65 of 20.8 MPa), so a tube of the range alone does not see it.
  double tube_uniaxial = -1.0;
  /// Network family, with a tube: the uniaxial-stress paths' states' tube penalty, a multiple
  /// of tube_weight (1: alike). Their excess is a fraction of a small stress, so at the same
  /// weight the jammed corners win (docs/law-experiments.md "The softness prior: measurements
  /// (session 13)").
  double tube_uniaxial_weight = 1.0;
  /// Network family: a softness prior (choice, docs/database.md "The softness prior"). n
  /// quasi-random strain states per loop length (a Kronecker sequence in the box of that loop
  /// length's fit data, not the held-out Halton states) enter the fit with the target
  /// S = floor e (the slack cell) and prior_weight times the mean data weight each: where the
  /// data say nothing the fit prefers the softest law. 0: off.
  int prior_points = 0;
  double prior_weight = 0.01;
  /// Ridge directions before mirror closure; empty = material::default_ridge_directions().
  std::vector<Eigen::Vector3d> directions;
  int s_degree = 3, s_spans = 12;
  int l_degree = 2, l_control_points = 5;
  double s_margin = 0.1;
  double floor = -1.0;  ///< MPa; < 0: floor_relative * secant stiffness of the data
  double floor_relative = 0.01;
  double smoothing = 1e-9;
  Loss loss = Loss::kNone;
  double loss_scale = 0.05;  ///< in units of sS
  int loss_rounds = 4;       ///< IRLS rounds with a loss
  /// Unused since session 14 (the ridge fit's active-set solve ends at its optimum; it was the
  /// Ceres iteration limit); still accepted, so that older option files load.
  int max_iterations = 200;
  /// Data weights (choice, docs/database.md "Weights"): each state's squared stress residual
  /// is weighted by (set weight * (1 + c) / (|S| / sS + c))^2 with c = weight_relative (0: plain
  /// absolute errors), set weight = weight_uniaxial on uniaxial-stress paths, weight_paper on
  /// the paper's 13 paths, 1 elsewhere. The cell's data are not exactly hyperelastic (friction;
  /// the slack wale and stiff course of the uniaxial paths violate the reciprocity
  /// nu12 / E1 = nu21 / E2 of any W several-fold), so the fit must choose: it favours the
  /// uniaxial and paper states, where the macroscale patches live, and relative accuracy in
  /// the slack regime over the jammed corners of the box.
  double weight_relative = 0.1;
  double weight_uniaxial = 30.0;
  double weight_paper = 3.0;
  /// The set weight of the pure-shear paths' states (PathKind::kShear; the default sweep's one
  /// is the paper's path_12), in place of weight_paper or 1 (session 55: docs/database.md
  /// "Weights"); -1, the code's default: the path set's weight, as before session 55, so that
  /// options recorded without the key refit as they were fitted. The default sweep
  /// (cases/sweep/default.json) sets 30.
  double weight_shear = -1.0;
  /// Where the cell gives way (choice, docs/database.md "Stable states"): along a fitted path,
  /// a converged step whose stress increment dS makes with its strain increment de an angle
  /// with cos(dS, de) < stable_min_cos marks the cell as having lost stability there (0:
  /// negative second-order work dS . de < 0, Hill's criterion); that step and the rest of its
  /// path are left out of the fit and of the fit-data diagnostics (the law is to be convex
  /// where the cell is stable). Held-out paths are judged on every converged state. A value
  /// below -1 keeps every state.
  double stable_min_cos = 0.0;
  /// Network family: worker threads of the fit (0: all cores; one start uses at most one per
  /// loop length; with `starts` > 1 the starts run side by side, threads / starts each).
  /// Not a property of the law: every count gives the same law to the last bit
  /// (mesoscale/src/fit_network.cpp), so it is not in to_json() / from_json().
  int threads = 0;
  /// Network family: where the fit says how far it is, one line every progress_seconds of
  /// L-BFGS (nullptr: silent; session 44's red team: a fit of 45 s said nothing, the sweep's bar
  /// stood at 100 % meanwhile; with `starts` > 1 the first start reports, and each start's end
  /// is a line). Not properties of the law, not in to_json().
  std::FILE* progress = nullptr;
  double progress_seconds = 5.0;

  std::string validate() const;

  /// Ridge family: the coefficients the law will have at `loop_lengths` loop lengths (functions
  /// of the directions x min(l_control_points, loop_lengths) x (s_spans + s_degree)); 0 for the
  /// network family. Its dense active-set solve grows with about the fourth power of it, so more
  /// than kMaxRidgeCoefficients is refused, by the sweep before its cases (the review of session
  /// 52) and by the fit.
  long long ridge_coefficients(int loop_lengths) const;
  static constexpr long long kMaxRidgeCoefficients = 2000;
  /// Why the ridge law is too large to solve in minutes ("" if not): the count, its factors
  /// and what to lower.
  std::string ridge_size_refusal(int loop_lengths) const;
  /// The key ("/directions", "/s_spans", "/s_degree" or "/l_control_points") whose value is
  /// farthest above the defaults' as a factor of the ridge law's size: where a refusal points.
  std::string ridge_size_key(int loop_lengths) const;
  std::string to_json() const;
  /// Parses the options (same keys as to_json()); errors name `file` and the JSON pointer
  /// below `pointer`.
  static EnergyFitOptions from_json(const std::string& text, const std::string& file = "<options>",
                                    const std::string& pointer = "");
  /// Throws InputError (file, pointer/key) for a key in the options `text` that only the other
  /// family reads ("tube" with "family": "ridge", "s_spans" with the default network): it
  /// would be ignored. Applied to what a user gives (--energy-options, a sweep's energy_fit),
  /// not to a database's stored options_json, which to_json() writes with every key.
  static void refuse_other_family_keys(const std::string& text, const std::string& file,
                                       const std::string& pointer = "");
};

struct EnergyFitSummary {
  FitStatus status = FitStatus::kOk;
  std::string reason;
  material::EnergyLawData law;
  material::EnergyFitDiagnostics diagnostics;
  int ceres_iterations = 0;  ///< network: Ceres L-BFGS iterations; ridge: active-set solves
  /// Network family: the kept start's final objective (the smallest of EnergyFitOptions::starts)
  /// and its seed; NaN and -1 for the ridge family.
  double objective = std::numeric_limits<double>::quiet_NaN();
  int seed = -1;
  /// The fitted paths where the cell gave way (EnergyFitOptions::stable_min_cos), as
  /// "/loop_k/raw/path_NN from step s"; those steps are left out of the fit.
  std::vector<std::string> gave_way;
  bool ok() const { return status == FitStatus::kOk; }
};

/// Fits the law to every loop length of db (raw data needed). db is not changed.
EnergyFitSummary fit_energy_law(const material::Database& db, const EnergyFitOptions& options);

/// Fits and stores the law (db.energy_law) when the fit succeeds; returns the summary.
EnergyFitSummary fit_energy_database(material::Database& db, const EnergyFitOptions& options);

/// The law's axial stress under uniaxial stress (the cell's uniaxial paths, set "coverage"):
/// e(axis) = e_axial, 2E12 = 0, the lateral strain solved by Newton from `lateral` so that the
/// law's lateral stress vanishes (C(lat, lat) >= floor > 0 and S(lat) increases with e(lat): a
/// unique root). NaN if Newton does not converge.
double uniaxial_axial_stress(const material::EnergyLawAt& at, int axis, double e_axial,
                             double lateral);

/// Errors of a law against db's raw data: per loop length on the fit data, and on the
/// held-out paths.
/// States of fitted paths past the point where the cell gave way (cos(dS, de) below
/// stable_min_cos, EnergyFitOptions) are left out, as in the fit.
material::EnergyFitDiagnostics diagnose_energy_law(const material::EnergyLawData& law,
                                                   const material::Database& db,
                                                   double stable_min_cos = 0.0);

/// Text summary (per l: RMS, max, relative; held-out) for the command line.
std::string energy_fit_report(const EnergyFitSummary& s);

/// Above this largest fit error (a fraction of a loop length's stress range) a fitted law is
/// warned of: the default sweep's options hold it near 5 %, the code's defaults ({}) gave 28-30 %
/// with exit 0 and no word (session 48's walkthrough).
inline constexpr double kEnergyFitWarnRelative = 0.10;

/// "warning: ..." naming the loop length of the largest fit error when it exceeds
/// kEnergyFitWarnRelative, else empty (also empty for a fit that did not succeed).
std::string energy_fit_warning(const EnergyFitSummary& s);

}  // namespace knit::meso::fit
