// The graded, rotated knit material of the shell (paper Sect. 2.2): the response-surface law
// of the material database, evaluated at the stitch value l(theta) (eqs. 23-25) in the
// material frame rotated by the knitting angle alpha(theta) (eqs. 19-22).
//
// Per integration point, the paper's steps (Sect. 2.2.1): the shell gives E in the local
// Cartesian frame (e1 = a1/|a1|); then
//   Ehat = T_E(alpha) E = T^-T E                                   (21)
//   (Shat, Chat) = response surface at (Ehat, l)                   (16-18, 24-25)
//   S = T^-1 Shat,  C = T^-1 Chat T^-T                            (22)
// with T = T_S(alpha) of eq. (20). The shell integrates through the thickness with 3 points
// (eq. 14) by calling evaluate() at each.
//
// l and alpha are scalar spline fields on the shell's parameter domain, each with its own
// degrees, knots and control values; repeated knots give the paper's discontinuous grading.
// bind_points() precomputes l, alpha and the l-interpolated surfaces per quadrature point
// (evaluators are shared between points with the same l). The alpha field may instead be
// computed to "align the course direction with a vector v": alpha interpolates, at the
// Greville abscissae of its basis, the signed angle (about the normal) from e1 to the
// projection of v on the tangent plane (paper Sect. 3.2.2).
//
// Extrapolation of the response surface (see knit/material/response_surface.hpp) is counted
// per kind and the first locations are kept; report() summarizes them at the end of a run.
//
// Two laws (case key /material/law): "paper" is the eq. (16-18) response surface above;
// "energy" (the default when the database has it, issue 11) is the convex strain energy of
// knit/material/energy_law.hpp. With "energy" the material is hyperelastic: W is invariant
// under the rotation, W(E) = W_hat(T_E E), so S = T_E^T S_hat = T^-1 S_hat and
// C = T_E^T C_hat T_E = T^-1 C_hat T^-T (symmetric); evaluations outside the database's data
// strain box are counted as extrapolated, failed ones (a non-finite strain) as failed, and the
// visited material-frame strain box (min/max of E_hat over all evaluations) is recorded --
// the evidence for choosing the sweep's box. Both go to report().
#pragma once

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <vector>

#include "knit/macro/law_cache.hpp"
#include "knit/macro/material.hpp"
#include "knit/macro/material_factory.hpp"
#include "knit/material/energy_law.hpp"
#include "knit/material/loop_length_family.hpp"
#include "knit/material/uniaxial_curve.hpp"
#include "knit/spline/surface.hpp"

namespace knit::macro {

/// A scalar spline field on the shell's parameter domain (degrees, knots, control values
/// with the u index fastest).
struct ScalarFieldSpec {
  int degree_u = 0, degree_v = 0;
  std::vector<double> knots_u = {0.0, 1.0}, knots_v = {0.0, 1.0};
  std::vector<double> values = {0.0};
  /// A constant field on [u0, u1] x [v0, v1].
  static ScalarFieldSpec constant(double value, double u0 = 0, double u1 = 1, double v0 = 0,
                                  double v1 = 1);
};

/// Builds the field; throws std::invalid_argument with the reason (knots, count).
spline::SplineSurface make_scalar_field(const ScalarFieldSpec& spec);

/// The alpha field that aligns the course direction with v: interpolation at the Greville
/// abscissae of (degree_u, knots_u) x (degree_v, knots_v) of the angle from e1 = a1/|a1| of
/// the reference surface `geometry` (3-D) to v projected on the tangent plane. Angles are
/// unwrapped to be continuous from one Greville point to the next.
spline::SplineSurface align_alpha_field(const spline::SplineSurface& geometry, int degree_u,
                                        std::vector<double> knots_u, int degree_v,
                                        std::vector<double> knots_v, const Eigen::Vector3d& v);

/// How far an alpha field follows the direction v (session 51's red team: a constant field
/// fitted at one Greville point of a half-annulus turned the courses up to 90 deg off v with
/// no word): the largest angle between the course direction of `alpha` and v projected on the
/// tangent plane, modulo pi (a course direction and its reverse knit the same fabric), on a
/// grid of 8 samples per element of alpha or of the geometry (the finer) in each direction, at
/// least 33 and at most 257, and where. Where v is normal to the surface the sample is skipped.
struct AlignDeviation {
  double radians = 0.0;
  double u = 0.0, v = 0.0;
};
AlignDeviation align_deviation(const spline::SplineSurface& geometry,
                               const spline::SplineSurface& alpha, const Eigen::Vector3d& v);
/// How far the courses of a constant knitting angle turn across a flat patch (session 56's red
/// team: alpha is measured from A1, eq. 19, and on a flat square with NURBS weights 1, 2, 3, 1
/// A1 fans out by 22.6 deg, so a constant alpha = 0 knitted fanning courses, 23 % more jaw
/// force than the plain square, with no word): the largest angle between A1 and A1 at the
/// patch's parameter centre on align_deviation's grid, and where. radians = 0 for a patch
/// that is not flat (its normal turns by more than 1e-6 rad on the grid), where A1 turning is
/// the geometry's and no course direction is straighter than another.
AlignDeviation course_turn(const spline::SplineSurface& geometry);
/// The deviation above which a case's align_with field is warned about (5 deg).
inline constexpr double kAlignWarning = 5.0 * std::numbers::pi / 180.0;

/// Where the fields came from, for error messages (case file and JSON pointers).
struct KnitMaterialSource {
  std::string file, stitch_pointer = "/material/stitch_value",
                    angle_pointer = "/material/knitting_angle", database;
  std::string database_date_utc;  ///< the database file's date_utc attribute ("" if none)
  /// The energy law's own uniaxial response beside the cell's, per loop length of the
  /// database (/energy_law/diagnostics/uniaxial, session 41; empty for older files or the
  /// paper's law), and the largest |law / cell - 1| tolerated without a warning at the strains
  /// a run reaches (/material/uniaxial_tolerance; KnitMaterial::warning()).
  std::vector<std::pair<double, std::array<material::UniaxialCurve, 2>>> uniaxial;
  double uniaxial_tolerance = 0.25;
  std::string uniaxial_tolerance_pointer = "/material/uniaxial_tolerance";
  /// Input that runs but is likely not what was meant (a patch of few loops: a case in cm?),
  /// a line of warning() (session 46).
  std::string input_warning;
};

class KnitMaterial : public Material {
 public:
  using Source = KnitMaterialSource;
  /// Checks that the stitch-value field stays inside the family's loop-length range
  /// (its control values, by the convex-hull property); throws knit::InputError naming the
  /// field, the control value and the range.
  KnitMaterial(std::shared_ptr<const material::LoopLengthFamily> family,
               spline::SplineSurface stitch_value, spline::SplineSurface knitting_angle,
               Source source = {});

  /// The energy-based law ("energy"); `family` (the paper's law) may then be null.
  KnitMaterial(std::shared_ptr<const material::LoopLengthFamily> family,
               std::shared_ptr<const material::EnergyLaw> energy,
               spline::SplineSurface stitch_value, spline::SplineSurface knitting_angle,
               Source source = {});

  std::string name() const override { return "knit"; }
  /// "energy" or "paper".
  std::string law() const { return energy_ ? "energy" : "paper"; }
  bool hyperelastic() const override { return energy_ != nullptr; }
  long failed_evaluations() const override;
  void bind_points(const std::vector<Eigen::Vector2d>& theta) override;
  MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& where) const override;
  std::vector<std::pair<std::string, double>> output_fields(
      const Eigen::Vector2d& theta, const Eigen::Vector3d& E) const override;
  std::string report() const override;
  /// Counts the evaluations between begin and end apart (see Material): the energy law those
  /// outside its data strain box, the paper's law those its response surfaces extrapolate.
  bool begin_converged_audit() const override {
    step_start_[0].store(audit_evaluations_.load());
    step_start_[1].store(audit_outside_.load());
    audit_.store(true);
    return true;
  }
  /// Also keeps the share of the last audited (converged) step apart: a run that ends deep
  /// outside the data had it averaged with its early steps (session 39's walkthrough: the
  /// warning said 32 % where 65-80 % of the patch was outside at the last step).
  void end_converged_audit() const override {
    audit_.store(false);
    last_step_[0].store(audit_evaluations_.load() - step_start_[0].load());
    last_step_[1].store(audit_outside_.load() - step_start_[1].load());
  }
  /// A warning when more than kExtrapolatedWarning of the evaluations at converged states lie
  /// outside the database's data (the energy law's convex extension beyond its strain box, or
  /// the paper law's extension of eq. 17 beyond its fan; the issue-11 acceptance allows the
  /// paper cases 2 %). A prescribed stretch of 10 times the
  /// specimen's length ran to "completed" with 100 % of them outside and no word of it but the
  /// figure inside the material report.
  std::string warning() const override;
  /// Where the fields came from, and the law's uniaxial curves with their tolerance.
  const Source& source() const { return source_; }
  /// The database's units.
  std::string required_units() const override { return "mm, N, MPa"; }
  /// material_database (the file) and material_database_date_utc (when it was written).
  std::vector<std::pair<std::string, std::string>> data_provenance() const override {
    return {{"material_database", source_.database},
            {"material_database_date_utc", source_.database_date_utc}};
  }
  static constexpr double kExtrapolatedWarning = 0.02;

  double stitch_value(const Eigen::Vector2d& theta) const;
  double knitting_angle(const Eigen::Vector2d& theta) const;
  /// The stitch-value and knitting-angle fields (alpha in rad).
  const spline::SplineSurface& stitch_value_field() const { return l_field_; }
  const spline::SplineSurface& knitting_angle_field() const { return a_field_; }
  /// dS/dl at the local strain E and the point, at fixed E and alpha (the design adjoint,
  /// issue 13). Energy law: analytic, T_E^T dS_hat/dl (T_E E) (eqs. 21-22 with the law's
  /// l-derivative). Paper law (eq. 25's interpolation has no analytic l-derivative here): a
  /// central difference of the response surfaces at l +- h, h = step * l (one-sided at the
  /// ends of the database's range). l is clamped to the range like evaluate().
  Eigen::Vector3d dS_dl(const Eigen::Vector3d& E, const MaterialPoint& where,
                        double step = 1e-5) const;

  /// Extrapolation statistics (kinds as in material::ExtrapolationFlag).
  struct Stats {
    long evaluations = 0;
    std::array<long, 5> count{};  ///< beyond paths, outside fan, compression, beyond shear, failed
    struct Where {
      Eigen::Vector2d theta;
      Eigen::Vector3d E_material;
      int flags;
    };
    std::vector<Where> first;  ///< up to kMaxLocations locations
  };
  Stats stats() const;
  /// Energy law: evaluations, outside the data strain box, failed; visited material-frame
  /// strain box (e = (E11, E22, 2E12); +-inf before the first evaluation).
  struct EnergyStats {
    long evaluations = 0, outside_box = 0, failed = 0;
    Eigen::Vector3d visited_min, visited_max;
  };
  EnergyStats energy_stats() const;
  void reset_stats();
  static constexpr int kMaxLocations = 10;
  /// Laws held for unbound points (energy law / the paper's response surfaces; for tests).
  std::size_t cached_energy_laws() const { return energy_cache_.size(); }
  std::size_t cached_surfaces() const { return surface_cache_.size(); }
  /// The response surfaces kept for unbound points (law "paper"), and the ring beyond them
  /// (LawCache): 65,536 surfaces of the default database's 11 x 11 nets take about 750 MB and
  /// hold a 256 x 256 output grid with l graded both ways (the default grid is 21 x 21); a
  /// larger grid's further samples build their surface at every output step (0.6 ms each).
  static constexpr std::size_t kSurfaceCacheEntries = 65536;
  static constexpr std::size_t kEnergyCacheEntries = 64;
  static constexpr std::size_t kRecentLaws = 8;

 private:
  struct Bound {
    const material::ResponseSurface* rs;
    std::shared_ptr<const material::ResponseSurface> rs_owner;  ///< keeps *rs alive
    double l, alpha;
    Eigen::Matrix3d TE, TSinv;  ///< T_E(alpha) = T^-T and T_S(-alpha) = T^-1, precomputed
    const material::EnergyLawAt* ea = nullptr;              ///< law "energy"
    std::shared_ptr<const material::EnergyLawAt> ea_owner;  ///< keeps *ea alive
  };
  std::shared_ptr<const material::ResponseSurface> surface_at(double l) const;
  void record(const Eigen::Vector2d& theta, const Eigen::Vector3d& E_material, int flags) const;
  MaterialResponse evaluate_at(const Eigen::Vector3d& E, const material::ResponseSurface& rs,
                               double alpha, const Eigen::Matrix3d& TE,
                               const Eigen::Matrix3d& TSinv, const Eigen::Vector2d& theta) const;

  std::shared_ptr<const material::EnergyLawAt> energy_at(double l) const;
  MaterialResponse evaluate_energy(const Eigen::Vector3d& E, const material::EnergyLawAt& law,
                                   const Eigen::Matrix3d& TE, const Eigen::Vector2d& theta,
                                   double l) const;
  std::string energy_report() const;
  double l_min() const;
  double l_max() const;

  std::shared_ptr<const material::LoopLengthFamily> family_;
  std::shared_ptr<const material::EnergyLaw> energy_;
  /// Laws of the unbound points (the output samples), at most kEnergyCacheEntries kept: a
  /// stitch value graded in both directions gives every sample its own l, and keeping them all
  /// took 873 MB on a 201 x 201 grid (about 20 GB at the schema's 1001 x 1001); a law is cheap
  /// to build (the same run took 1.4 s instead of 3.1 s without the growing map). The bound
  /// points own theirs (Bound::ea_owner).
  LawCache<material::EnergyLawAt> energy_cache_{kEnergyCacheEntries, kRecentLaws};
  /// Laws built with their l-derivative (dS_dl() only; the runs do not pay for it).
  mutable std::map<double, std::shared_ptr<const material::EnergyLawAt>> energy_dl_cache_;
  mutable std::atomic<long> outside_box_{0}, failed_{0};
  /// The converged-state audit (energy law): on/off, evaluations and extrapolated ones.
  mutable std::atomic<bool> audit_{false};
  mutable std::atomic<long> audit_evaluations_{0}, audit_outside_{0};
  /// The audit counters at the last step's begin, and that step's evaluations and outside ones.
  mutable std::atomic<long> step_start_[2] = {0, 0}, last_step_[2] = {0, 0};
  /// " (at the last converged step: X %)", or "" before any audited step.
  std::string last_step_share() const;
  /// Visited box: min of (E11, E22, 2E12) in [0..2], max in [3..5].
  mutable std::array<std::atomic<double>, 6> visited_;
  /// The same over the converged-state audit (session 37: the visited box above, Newton's trial
  /// iterates included, read E11 = 4.3 / 12.9 / 43 for s312 refined to 32 / 64 / 128 elements,
  /// which a red team took for the converged states; those reach E11 = 0.83 at 32 x 32).
  mutable std::array<std::atomic<double>, 6> audit_visited_;
  /// warning() below the share that warns: a converged state beyond the energy law's box by
  /// more than the box's width in one component; "" if none.
  /// `local`: the states outside the box are few (below the share that warns), so the text
  /// names a local concentration as the likely cause; else the whole run is far outside.
  std::string far_excursion_warning(bool local = true) const;
  /// warning(), the energy law: where the law's own uniaxial response departs from the cell's
  /// by more than source_.uniaxial_tolerance at the axial strains the converged states reached
  /// and the loop lengths the case uses; "" if nowhere (or no curves).
  /// The report's verdict of the uniaxial check after a run ("" before one).
  std::string uniaxial_verdict() const;
  std::string uniaxial_warning() const;
  /// The knots of source_.uniaxial whose law enters the law at l: knot k when l lies strictly
  /// (by more than 1e-6 mm) between knots k - 1 and k + 1 (the energy law between two knots is
  /// their convex combination); calls f(k) for each.
  template <class F>
  void for_uniaxial_knots(double l, F&& f) const;
  /// Per knot of source_.uniaxial, the largest material-frame E11 (2 k) and E22 (2 k + 1) of
  /// the audited (converged) evaluations whose law uses that knot; -inf before any.
  std::unique_ptr<std::atomic<double>[]> uniaxial_reached_;
  spline::SplineSurface l_field_, a_field_;
  Source source_;
  std::vector<Bound> bound_;
  mutable std::mutex cache_mutex_;  ///< energy_dl_cache_
  /// The unbound points' response surfaces (law "paper"); the bound points own theirs.
  LawCache<material::ResponseSurface> surface_cache_{kSurfaceCacheEntries, kRecentLaws};
  mutable std::atomic<long> evaluations_{0};
  mutable std::array<std::atomic<long>, 5> counts_{};
  mutable std::mutex where_mutex_;
  mutable std::vector<Stats::Where> where_;
};

/// The "knit" branch of the case's material factory (knit_material_factory.cpp): reads the
/// database and the stitch-value and knitting-angle fields; throws knit::InputError with
/// JSON pointers below ctx.pointer.
std::unique_ptr<Material> make_knit_material(const nlohmann::json& material,
                                             const CaseContext& ctx);

/// "<l> mm is outside the database's <lo>-<hi> mm": l with 15 digits, or 16-17 where 15 would
/// print it as the bound itself (session 27: 6.500000000000001 read "6.5 mm is outside the
/// database's 4.5-6.5 mm").
std::string loop_length_outside(double l, double lo, double hi);
}  // namespace knit::macro
