// The graded, rotated knit material (paper Sect. 2.2); see knit/macro/knit_material.hpp.
#include "knit/macro/knit_material.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "knit/core/errors.hpp"
#include "knit/mechanics/voigt.hpp"
#include "knit/spline/fit.hpp"

namespace knit::macro {

using material::ResponseSurface;

ScalarFieldSpec ScalarFieldSpec::constant(double value, double u0, double u1, double v0,
                                          double v1) {
  ScalarFieldSpec s;
  s.knots_u = {u0, u1};
  s.knots_v = {v0, v1};
  s.values = {value};
  return s;
}

spline::SplineSurface make_scalar_field(const ScalarFieldSpec& spec) {
  const spline::BSplineBasis bu(spec.degree_u, spec.knots_u), bv(spec.degree_v, spec.knots_v);
  const std::size_t n = static_cast<std::size_t>(bu.size()) * bv.size();
  if (spec.values.size() != n)
    throw std::invalid_argument("the knots and degrees define " + std::to_string(bu.size()) +
                                " x " + std::to_string(bv.size()) + " = " + std::to_string(n) +
                                " control values, got " + std::to_string(spec.values.size()));
  Eigen::MatrixXd P(n, 1);
  for (std::size_t a = 0; a < n; ++a) {
    if (!std::isfinite(spec.values[a]))
      throw std::invalid_argument("control value " + std::to_string(a) + " is not finite");
    P(a, 0) = spec.values[a];
  }
  return spline::SplineSurface(bu, bv, P);
}

namespace {
/// The angle in the tangent plane at (u, v) from e1 = a1 / |a1| to v projected on it, or NaN
/// where v is normal to the surface.
double angle_to(const spline::SplineSurface& geometry, double u, double v,
                const Eigen::Vector3d& dir) {
  const Eigen::MatrixXd D = geometry.derivatives(u, v, 1);
  const Eigen::Vector3d a1 = D.row(1).transpose(), a2 = D.row(2).transpose();
  const Eigen::Vector3d a3 = a1.cross(a2).normalized();
  const Eigen::Vector3d e1 = a1.normalized();
  const Eigen::Vector3d vt = dir - dir.dot(a3) * a3;
  if (vt.norm() < 1e-12) return std::numeric_limits<double>::quiet_NaN();
  return std::atan2(e1.cross(vt).dot(a3), e1.dot(vt));
}
/// Sample parameters over the range of `a`: 8 per element of a or b (the finer), at least 33
/// and at most 257 (a field of 1000 knots would otherwise take 64 million samples).
std::vector<double> samples(const spline::BSplineBasis& a, const spline::BSplineBasis& b) {
  const double lo = a.lo(), hi = a.hi();
  const int n = std::clamp(8 * std::max(a.num_elements(), b.num_elements()) + 1, 33, 257);
  std::vector<double> s(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) s[static_cast<std::size_t>(k)] = lo + (hi - lo) * k / (n - 1);
  return s;
}
}  // namespace

spline::SplineSurface align_alpha_field(const spline::SplineSurface& geometry, int degree_u,
                                        std::vector<double> knots_u, int degree_v,
                                        std::vector<double> knots_v, const Eigen::Vector3d& v_in) {
  if (geometry.dim() != 3) throw std::invalid_argument("align: the geometry must be 3-D");
  // A direction: only its sense counts (session 22: (1e-300, 0, 0) was taken for a vector
  // normal to the surface, (0, 0, 0) too, with that message).
  const double v_norm = v_in.stableNorm();
  if (!(v_norm > 0.0 && std::isfinite(v_norm)))
    throw std::invalid_argument("align: the vector v must be finite and not zero");
  const Eigen::Vector3d v = v_in / v_norm;
  const spline::BSplineBasis bu(degree_u, std::move(knots_u)), bv(degree_v, std::move(knots_v));
  const auto gu = bu.greville(), gv = bv.greville();
  const int nu = bu.size(), nv = bv.size();
  // Angles at the Greville points (u fastest), unwrapped along u and then along v.
  Eigen::MatrixXd A(nu, nv);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double ang = angle_to(geometry, gu[i], gv[j], v);
      if (std::isnan(ang))
        throw std::invalid_argument(
            "align: the vector v is normal to the surface at a Greville point");
      const double ref = i > 0 ? A(i - 1, j) : (j > 0 ? A(0, j - 1) : ang);
      while (ang - ref > std::numbers::pi) ang -= 2 * std::numbers::pi;
      while (ang - ref < -std::numbers::pi) ang += 2 * std::numbers::pi;
      A(i, j) = ang;
    }
  // Tensor-product interpolation at the Greville points (values a = i + nu*j).
  Eigen::MatrixXd values(nu * nv, 1);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) values(i + nu * j, 0) = A(i, j);
  const Eigen::MatrixXd P = spline::interpolate_at_greville(bu, bv, values);
  return spline::SplineSurface(bu, bv, P);
}

AlignDeviation align_deviation(const spline::SplineSurface& geometry,
                               const spline::SplineSurface& alpha, const Eigen::Vector3d& v) {
  AlignDeviation worst;
  const Eigen::Vector3d dir = v / v.stableNorm();
  for (const double u : samples(alpha.basis_u(), geometry.basis_u()))
    for (const double w : samples(alpha.basis_v(), geometry.basis_v())) {
      const double want = angle_to(geometry, u, w, dir);
      if (std::isnan(want)) continue;
      const double d = std::remainder(alpha.eval(u, w)(0) - want, std::numbers::pi);
      if (!(std::abs(d) <= worst.radians)) worst = {std::abs(d), u, w};  // NaN: the worst
    }
  return worst;
}

AlignDeviation course_turn(const spline::SplineSurface& geometry) {
  // A 33 x 33 grid: A1 of a flat patch turns smoothly, and a turn of 5 deg is not hidden
  // between samples (the review of session 56: align_deviation's up to 257 x 257 samples took
  // 0.13 s per parse at p = 5 with 32 x 32 elements, and a design parses its case repeatedly).
  constexpr int kGrid = 33;
  const auto& bu = geometry.basis_u();
  const auto& bv = geometry.basis_v();
  const auto at = [&](int i, int k) {
    return std::pair{bu.lo() + (bu.hi() - bu.lo()) * i / (kGrid - 1),
                     bv.lo() + (bv.hi() - bv.lo()) * k / (kGrid - 1)};
  };
  // The tangent vectors at a sample, and the unit normal (zero where they are parallel).
  Eigen::MatrixXd D;
  const auto frame = [&](double u, double v, Eigen::Vector3d& a1, Eigen::Vector3d& n) {
    D = geometry.derivatives(u, v, 1);
    a1 = D.row(1).transpose();
    n = a1.cross(Eigen::Vector3d(D.row(2).transpose()));
    const double len = n.norm();
    n = len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  };
  const auto [uc, vc] = at(kGrid / 2, kGrid / 2);
  Eigen::Vector3d a1c, n0, a1, n;
  frame(uc, vc, a1c, n0);
  const Eigen::Vector3d e1c = a1c.normalized();
  AlignDeviation worst;
  for (int i = 0; i < kGrid; ++i)
    for (int k = 0; k < kGrid; ++k) {
      const auto [u, v] = at(i, k);
      frame(u, v, a1, n);
      if (!(n.cross(n0).norm() <= 1e-6 && n.dot(n0) > 0.0)) return {};  // not flat
      const Eigen::Vector3d e1 = a1.normalized();
      const double d = std::atan2(e1.cross(e1c).norm(), e1.dot(e1c));
      if (d > worst.radians) worst = {d, u, v};
    }
  return worst;
}

KnitMaterial::KnitMaterial(std::shared_ptr<const material::LoopLengthFamily> family,
                           spline::SplineSurface stitch_value, spline::SplineSurface knitting_angle,
                           Source source)
    : KnitMaterial(std::move(family), nullptr, std::move(stitch_value), std::move(knitting_angle),
                   std::move(source)) {}

KnitMaterial::KnitMaterial(std::shared_ptr<const material::LoopLengthFamily> family,
                           std::shared_ptr<const material::EnergyLaw> energy,
                           spline::SplineSurface stitch_value, spline::SplineSurface knitting_angle,
                           Source source)
    : family_(std::move(family)),
      energy_(std::move(energy)),
      l_field_(std::move(stitch_value)),
      a_field_(std::move(knitting_angle)),
      source_(std::move(source)) {
  if (!family_ && !energy_) throw std::invalid_argument("knit material: no database");
  uniaxial_reached_ = std::make_unique<std::atomic<double>[]>(2 * source_.uniaxial.size());
  if (l_field_.dim() != 1 || a_field_.dim() != 1)
    throw std::invalid_argument("knit material: the fields must be scalar");
  reset_stats();
  const Eigen::MatrixXd& L = l_field_.control_points();
  for (int a = 0; a < L.rows(); ++a)
    if (!(L(a, 0) >= l_min() && L(a, 0) <= l_max())) {
      std::ostringstream os;
      os << loop_length_outside(L(a, 0), l_min(), l_max());
      if (!source_.database.empty()) os << " (" << source_.database << ")";
      throw InputError(source_.file, source_.stitch_pointer + "/values/" + std::to_string(a),
                       os.str());
    }
}

double KnitMaterial::stitch_value(const Eigen::Vector2d& t) const {
  return l_field_.eval(t(0), t(1))(0);
}
double KnitMaterial::knitting_angle(const Eigen::Vector2d& t) const {
  return a_field_.eval(t(0), t(1))(0);
}

std::shared_ptr<const ResponseSurface> KnitMaterial::surface_at(double l) const {
  // The field is a convex combination of in-range control values; clamp round-off.
  l = std::clamp(l, family_->min(), family_->max());
  return surface_cache_.get(l, [this](double x) { return family_->surface(x); });
}

void KnitMaterial::bind_points(const std::vector<Eigen::Vector2d>& theta) {
  bound_.clear();
  bound_.reserve(theta.size());
  // Points with the same l share one law; the bound points own their laws (the caches of
  // energy_at and surface_at are bounded, for the output samples).
  std::map<double, std::shared_ptr<const material::EnergyLawAt>> laws;
  std::map<double, std::shared_ptr<const ResponseSurface>> surfaces;
  for (const auto& t : theta) {
    const double l = stitch_value(t);
    const double a = knitting_angle(t);
    if (energy_) {
      auto& law = laws[l];  // not from energy_at: its few entries are for the output samples
      if (!law)
        law = std::make_shared<const material::EnergyLawAt>(
            energy_->at(std::clamp(l, l_min(), l_max())));
      bound_.push_back({nullptr, nullptr, l, a, mech::T_E(a), mech::T_S_inv(a), law.get(), law});
    } else {
      auto& rs = surfaces[l];
      if (!rs) rs = family_->surface(std::clamp(l, l_min(), l_max()));
      bound_.push_back({rs.get(), rs, l, a, mech::T_E(a), mech::T_S_inv(a), nullptr, {}});
    }
  }
}

void KnitMaterial::record(const Eigen::Vector2d& theta, const Eigen::Vector3d& E_material,
                          int flags) const {
  std::lock_guard<std::mutex> lock(where_mutex_);
  if (static_cast<int>(where_.size()) >= kMaxLocations) return;
  // One entry per in-plane point (the 3 thickness points of a point share theta).
  for (const auto& w : where_)
    if (w.theta == theta && w.flags == flags) return;
  where_.push_back({theta, E_material, flags});
}

MaterialResponse KnitMaterial::evaluate_at(const Eigen::Vector3d& E, const ResponseSurface& rs,
                                           double alpha, const Eigen::Matrix3d& TE,
                                           const Eigen::Matrix3d& TSinv,
                                           const Eigen::Vector2d& theta) const {
  MaterialResponse out;
  evaluations_.fetch_add(1, std::memory_order_relaxed);
  // The converged-state audit (see Material): beyond the data are the kinds 0-3 (beyond the
  // last load step, outside the fan, the linear initial law in biaxial compression, beyond the
  // shear data); a failed inversion is a failure, counted apart.
  auto audit = [this](int flags) {
    if (!audit_.load(std::memory_order_relaxed)) return;
    audit_evaluations_.fetch_add(1, std::memory_order_relaxed);
    if (flags & 0b1111) audit_outside_.fetch_add(1, std::memory_order_relaxed);
  };
  if (alpha == 0.0) {
    const auto ev = rs.evaluate(E);
    out.S = ev.S;
    out.C = ev.C;
    audit(ev.flags);
    if (ev.flags) {
      for (int k = 0; k < 5; ++k)
        if (ev.flags & (1 << k)) counts_[k].fetch_add(1, std::memory_order_relaxed);
      record(theta, E, ev.flags);
    }
    return out;
  }
  // TE = T_E(alpha) = T^-T (eq. 21), TSinv = T_S(-alpha) = T^-1 (eq. 22).
  const Eigen::Vector3d Ehat = TE * E;
  const auto ev = rs.evaluate(Ehat);
  out.S = TSinv * ev.S;
  out.C = TSinv * ev.C * TE;
  audit(ev.flags);
  if (ev.flags) {
    for (int k = 0; k < 5; ++k)
      if (ev.flags & (1 << k)) counts_[k].fetch_add(1, std::memory_order_relaxed);
    record(theta, Ehat, ev.flags);
  }
  return out;
}

MaterialResponse KnitMaterial::evaluate(const Eigen::Vector3d& E,
                                        const MaterialPoint& where) const {
  if (where.point_id >= 0 && where.point_id < static_cast<int>(bound_.size())) {
    const Bound& b = bound_[where.point_id];
    if (b.ea) return evaluate_energy(E, *b.ea, b.TE, where.theta, b.l);
    return evaluate_at(E, *b.rs, b.alpha, b.TE, b.TSinv, where.theta);
  }
  if (energy_) {
    const double l = stitch_value(where.theta);
    const auto ea = energy_at(l);
    return evaluate_energy(E, *ea, mech::T_E(knitting_angle(where.theta)), where.theta, l);
  }
  const auto rs = surface_at(stitch_value(where.theta));
  const double a = knitting_angle(where.theta);
  return evaluate_at(E, *rs, a, mech::T_E(a), mech::T_S_inv(a), where.theta);
}

std::vector<std::pair<std::string, double>> KnitMaterial::output_fields(
    const Eigen::Vector2d& theta, const Eigen::Vector3d& E) const {
  const double alpha = knitting_angle(theta);
  const Eigen::Vector3d Ehat = mech::T_E(alpha) * E;
  const double l = stitch_value(theta);
  // Where the mid-surface strain lies beyond the law's data (session 28: the report counted
  // the quadrature points' evaluations, but the output grid's samples, which the figures show,
  // were not marked): the energy law's strain box (the database's, the same at every l), or
  // the response surface's extension kinds 0-3 (beyond the last step, outside the fan, linear
  // compression, beyond the shear data) and a failed inversion. The response surface is the
  // cached one that the sample's stresses use already (ShellModel::sample evaluates the
  // material at the same theta; LawCache's ring holds it even beyond the kept surfaces):
  // building it afresh per sample took 99 s instead of 20 s on a 201 x 201 grid with a stitch
  // value graded both ways.
  bool beyond = !Ehat.allFinite();
  if (!beyond && energy_) {
    beyond = !energy_->data().inside_box(Ehat);
  } else if (!beyond) {
    beyond = surface_at(l)->evaluate(Ehat).flags != 0;
  }
  return {{"stitch_value", l},
          {"knitting_angle", alpha},
          {"E_course", Ehat(0)},
          {"E_wale", Ehat(1)},
          {"E_course_wale", 0.5 * Ehat(2)},
          {"beyond_law_data", beyond ? 1.0 : 0.0}};
}

KnitMaterial::Stats KnitMaterial::stats() const {
  Stats s;
  s.evaluations = evaluations_.load();
  for (int k = 0; k < 5; ++k) s.count[k] = counts_[k].load();
  std::lock_guard<std::mutex> lock(where_mutex_);
  s.first = where_;
  return s;
}

void KnitMaterial::reset_stats() {
  evaluations_ = 0;
  for (auto& c : counts_) c = 0;
  outside_box_ = 0;
  failed_ = 0;
  audit_evaluations_ = 0;
  audit_outside_ = 0;
  for (int k = 0; k < 2; ++k) step_start_[k] = last_step_[k] = 0;
  for (int k = 0; k < 3; ++k) {
    visited_[k] = audit_visited_[k] = std::numeric_limits<double>::infinity();
    visited_[k + 3] = audit_visited_[k + 3] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t k = 0; k < 2 * source_.uniaxial.size(); ++k)
    uniaxial_reached_[k] = -std::numeric_limits<double>::infinity();
  std::lock_guard<std::mutex> lock(where_mutex_);
  where_.clear();
}

std::string KnitMaterial::last_step_share() const {
  const long n = last_step_[0].load();
  if (n <= 0) return {};
  std::ostringstream os;
  os << std::setprecision(3) << " (at the last converged step: "
     << 100.0 * static_cast<double>(last_step_[1].load()) / static_cast<double>(n) << " %)";
  return os.str();
}

std::string KnitMaterial::warning() const {
  const long n = audit_evaluations_.load();
  if (n == 0) return source_.input_warning;
  const double share = static_cast<double>(audit_outside_.load()) / static_cast<double>(n);
  const long n_last = last_step_[0].load();
  const double last =
      n_last > 0 ? static_cast<double>(last_step_[1].load()) / static_cast<double>(n_last) : 0.0;
  // The law's own uniaxial response against the cell's, after the extrapolation's warning.
  const std::string uniaxial = energy_ ? uniaxial_warning() : std::string();
  auto with_uniaxial = [&](std::string w) {
    if (!uniaxial.empty()) w += (w.empty() ? "" : "\n") + uniaxial;
    if (!source_.input_warning.empty()) w += (w.empty() ? "" : "\n") + source_.input_warning;
    return w;
  };
  if (!(share > kExtrapolatedWarning) && !(last > kExtrapolatedWarning))
    return with_uniaxial(energy_ ? far_excursion_warning() : std::string());
  std::ostringstream os;
  os << std::setprecision(3) << "warning: " << 100.0 * share
     << " % of the material evaluations at converged states" << last_step_share()
     << " lie outside the database's data ("
     << (energy_ ? "its strain box, in the material report"
                 : "beyond the fan of load paths, the last load step or the shear data, or in "
                   "biaxial compression")
     << "; more than " << 100.0 * kExtrapolatedWarning << " %): there the results come from "
     << (energy_ ? "the law's convex extension"
                 : "the response surfaces' extension (eq. 17) and the linear initial law")
     << ", not from cell runs (docs/database.md)";
  // And how far, when it is far (session 50's red team: a tensile case stretched to 1000 %,
  // E22 = 60 against the box's 0.55, said only the share).
  if (energy_)
    if (const std::string far = far_excursion_warning(false); !far.empty()) os << "\n" << far;
  return with_uniaxial(os.str());
}

std::string KnitMaterial::report() const {
  if (energy_) return energy_report();
  const Stats s = stats();
  static const char* names[5] = {"beyond the last load step", "outside the fan of load paths",
                                 "biaxial compression (linear initial law)",
                                 "beyond the shear data", "inversion failed"};
  std::ostringstream os;
  long total = 0;
  for (long c : s.count) total += c;
  os << "knit material: " << s.evaluations << " evaluations";
  if (total == 0) {
    os << ", all inside the fitted response-surface domain";
    return os.str();
  }
  os << "; extrapolated:";
  for (int k = 0; k < 5; ++k)
    if (s.count[k]) os << "\n  " << s.count[k] << " x " << names[k];
  if (const long n = audit_evaluations_.load(); n > 0) {
    const long k = audit_outside_.load();
    os << "\n  at converged states: " << k << " of " << n << " evaluations extrapolated ("
       << std::setprecision(4) << 100.0 * static_cast<double>(k) / static_cast<double>(n) << " %)"
       << last_step_share();
  }
  // Every evaluation, Newton's trial iterates too (session 39's walkthrough read them as
  // converged states).
  os << "\n  first locations (Newton's trial iterates too; theta1, theta2; material strains "
        "E_course, E_wale, 2E_cw):";
  for (const auto& w : s.first)
    os << "\n    (" << w.theta(0) << ", " << w.theta(1) << "): " << w.E_material.transpose();
  return os.str();
}

std::string loop_length_outside(double l, double lo, double hi) {
  const auto text = [](double x, int digits) {
    std::ostringstream o;
    o.precision(digits);
    o << x;
    return o.str();
  };
  std::string v;
  for (int digits = 15; digits <= 17; ++digits)
    if (v = text(l, digits); v != text(lo, digits) && v != text(hi, digits)) break;
  return v + " mm is outside the database's " + text(lo, 15) + "-" + text(hi, 15) + " mm";
}

}  // namespace knit::macro
