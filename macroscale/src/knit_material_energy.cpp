// The knit material with the energy-based law (case key /material/law = "energy"); see
// knit/macro/knit_material.hpp and knit/material/energy_law.hpp.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "knit/macro/knit_material.hpp"
#include "knit/mechanics/voigt.hpp"

namespace knit::macro {

namespace {

void atomic_min(std::atomic<double>& a, double v) {
  double cur = a.load(std::memory_order_relaxed);
  while (v < cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
}
void atomic_max(std::atomic<double>& a, double v) {
  double cur = a.load(std::memory_order_relaxed);
  while (v > cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
}

}  // namespace

double KnitMaterial::l_min() const {
  return energy_ ? energy_->data().l_min : family_->min();
}
double KnitMaterial::l_max() const {
  return energy_ ? energy_->data().l_max : family_->max();
}

long KnitMaterial::failed_evaluations() const {
  return energy_ ? failed_.load() : counts_[4].load();
}

std::shared_ptr<const material::EnergyLawAt> KnitMaterial::energy_at(double l) const {
  // The field is a convex combination of in-range control values; clamp round-off.
  l = std::clamp(l, l_min(), l_max());
  return energy_cache_.get(l, [this](double x) {
    return std::make_shared<const material::EnergyLawAt>(energy_->at(x));
  });
}

Eigen::Vector3d KnitMaterial::dS_dl(const Eigen::Vector3d& E, const MaterialPoint& where,
                                    double step) const {
  const bool bound = where.point_id >= 0 && where.point_id < static_cast<int>(bound_.size());
  const double l = std::clamp(
      bound ? bound_[static_cast<std::size_t>(where.point_id)].l : stitch_value(where.theta),
      l_min(), l_max());
  const double alpha =
      bound ? bound_[static_cast<std::size_t>(where.point_id)].alpha : knitting_angle(where.theta);
  const Eigen::Matrix3d TE = mech::T_E(alpha);
  if (!energy_) {
    const double h = step * std::max(1.0, std::abs(l));
    const double lp = std::min(l + h, l_max()), lm = std::max(l - h, l_min());
    const Eigen::Matrix3d TSinv = mech::T_S_inv(alpha);
    // The surfaces evaluated directly, as evaluate_at() does (T_E(0) E = E and T_S(0)^-1 S = S
    // exactly), but not counted: the difference quotient's evaluations at l +- h are not the
    // run's, and went into the extrapolation counts and the report's first locations (session
    // 32, a helper's audit).
    auto S_at = [&](double ll) -> Eigen::Vector3d {
      return TSinv * surface_at(ll)->evaluate(TE * E).S;
    };
    return (S_at(lp) - S_at(lm)) / (lp - lm);
  }
  std::shared_ptr<const material::EnergyLawAt> law;
  {
    std::lock_guard<std::mutex> lock(cache_mutex_);
    auto it = energy_dl_cache_.find(l);
    if (it == energy_dl_cache_.end())
      it = energy_dl_cache_
               .emplace(l, std::make_shared<const material::EnergyLawAt>(energy_->at(l, true)))
               .first;
    law = it->second;
  }
  // S = T_E^T S_hat(T_E E, l): at fixed E and alpha, dS/dl = T_E^T dS_hat/dl.
  return TE.transpose() * law->dS_dl(TE * E);
}

template <class F>
void KnitMaterial::for_uniaxial_knots(double l, F&& f) const {
  const auto& curves = source_.uniaxial;
  const std::size_t m = curves.size();
  for (std::size_t k = 0; k < m; ++k) {
    const double below = k > 0 ? curves[k - 1].first : -HUGE_VAL;
    const double above = k + 1 < m ? curves[k + 1].first : HUGE_VAL;
    // By more than round-off: the discontinuous cases' l = 6.5 mm side gave the 6 mm knot a
    // weight of 1e-8.
    if (l > below + 1e-6 && l < above - 1e-6) f(k);
  }
}

MaterialResponse KnitMaterial::evaluate_energy(const Eigen::Vector3d& E,
                                               const material::EnergyLawAt& law,
                                               const Eigen::Matrix3d& TE,
                                               const Eigen::Vector2d& theta, double l) const {
  MaterialResponse out;
  evaluations_.fetch_add(1, std::memory_order_relaxed);
  // W(E) = W_hat(T_E E): S = T_E^T S_hat, C = T_E^T C_hat T_E (T_E^T = T^-1, eq. 22).
  const Eigen::Vector3d Ehat = TE * E;
  if (!Ehat.allFinite()) {
    failed_.fetch_add(1, std::memory_order_relaxed);
    out.W = 0.0;
    record(theta, Ehat, 16);
    return out;  // zero response: the run reports the failure (failed_evaluations())
  }
  for (int k = 0; k < 3; ++k) {
    atomic_min(visited_[k], Ehat(k));
    atomic_max(visited_[k + 3], Ehat(k));
  }
  const bool inside = law.inside_box(Ehat);
  if (!inside) {
    outside_box_.fetch_add(1, std::memory_order_relaxed);
    record(theta, Ehat, 1);
  }
  if (audit_.load(std::memory_order_relaxed)) {
    audit_evaluations_.fetch_add(1, std::memory_order_relaxed);
    if (!inside) audit_outside_.fetch_add(1, std::memory_order_relaxed);
    for (int k = 0; k < 3; ++k) {
      atomic_min(audit_visited_[k], Ehat(k));
      atomic_max(audit_visited_[k + 3], Ehat(k));
    }
    // The strains each knot's law saw (uniaxial_warning(); session 41's review: one largest
    // strain of the whole patch named the 6.5 mm knot of s321, whose points stay below
    // E11 = 0.07, for the 4.5 mm region's 0.385).
    for_uniaxial_knots(l, [&](std::size_t k) {
      atomic_max(uniaxial_reached_[2 * k], Ehat(0));
      atomic_max(uniaxial_reached_[2 * k + 1], Ehat(1));
    });
  }
  const material::EnergyResponse r = law.evaluate(Ehat);
  out.W = r.W;
  out.S.noalias() = TE.transpose() * r.S;
  const Eigen::Matrix3d C = TE.transpose() * r.C * TE;
  out.C = 0.5 * (C + C.transpose());  // symmetric to the last bit
  return out;
}

std::string KnitMaterial::far_excursion_warning(bool local) const {
  // A few converged states far outside the box, below the share that warns (session 37): beyond
  // the box by more than its width. None of the 26 paper cases, nor s312 refined to 32 x 32
  // (converged E11 up to 0.83 against the box's 0.6; its trial iterates reached 4.28), warns.
  const auto& box = energy_->data();
  static const char* names[3] = {"E11", "E22", "2E12"};
  for (int k = 0; k < 3; ++k) {
    const double lo = box.box_min(k), hi = box.box_max(k), w = hi - lo;
    const double vmin = audit_visited_[k].load(), vmax = audit_visited_[k + 3].load();
    const double far = vmax > hi + w ? vmax : vmin < lo - w ? vmin : 0.0;
    if (far == 0.0) continue;
    std::ostringstream os;
    os << std::setprecision(4) << "warning: converged states reach " << names[k] << " = " << far
       << ", beyond the law's data box [" << lo << ", " << hi
       << "] by more than its width (material frame; the report gives the first locations): "
       << (local ? "a local concentration, such as a clamped corner, whose stresses come from "
                   "the law's convex extension and grow with mesh refinement there"
                 : "the stresses there come from the law's convex extension, far from any cell "
                   "run; a fabric does not stretch this far");
    return os.str();
  }
  return {};
}

std::string KnitMaterial::uniaxial_verdict() const {
  if (audit_evaluations_.load() == 0) return {};
  // Compared only where a knot's law was stretched along an axis (session 48's review: a run
  // in compression or shear alone read "within it" with nothing compared).
  bool stretched = false;
  for (std::size_t k = 0; k < 2 * source_.uniaxial.size(); ++k)
    stretched = stretched || uniaxial_reached_[k].load() > 0.0;
  if (!stretched)
    return ": this run stretched no loop length's law along the course or the wale (nothing "
           "compared)";
  return uniaxial_warning().empty() ? ": this run's states are within it"
                                    : ": this run's states depart beyond it (the warning)";
}

std::string KnitMaterial::uniaxial_warning() const {
  const auto& curves = source_.uniaxial;
  if (curves.empty() || audit_evaluations_.load() == 0) return {};
  // The material frame's strains by the names results.h5 gives them (session 56's walkthrough:
  // "wale (E22)" read as results.h5's E22, the x2 component, with alpha = 90 deg the course).
  static const char* axis_name[2] = {"course (E_course, the material frame's E11)",
                                     "wale (E_wale, the material frame's E22)"};
  static const char* component[2] = {"E_course", "E_wale"};
  std::ostringstream os;
  os << std::setprecision(3);
  for (std::size_t ax = 0; ax < 2; ++ax) {
    std::ostringstream at;
    at << std::setprecision(3);
    int worse = 0;
    for (std::size_t k = 0; k < curves.size(); ++k) {
      // The axial strain the converged states reached with this knot's law (material frame);
      // -inf where no point uses the knot, <= 0 where nothing is stretched that way.
      const double reached = uniaxial_reached_[2 * k + ax].load();
      if (!(reached > 0.0)) continue;
      const material::UniaxialDeviation d =
          material::uniaxial_deviation(curves[k].second[ax], reached);
      if (d.states == 0 || !(d.deviation > source_.uniaxial_tolerance)) continue;
      at << (worse++ ? "; " : "") << "at l = " << curves[k].first << " mm ";
      if (std::isfinite(d.ratio))
        at << d.ratio << " times";
      else
        at << "no uniaxial state of the law";
      at << " (at " << component[ax] << " = " << d.strain << "; reached " << reached << ")";
    }
    if (worse == 0) continue;
    if (!os.str().empty()) os << "\n";
    os << "warning: where the fabric is stretched uniaxially along the " << axis_name[ax]
       << ", the material law may be off by up to about these factors of its unit cell's stress "
          "(more than "
       << 100.0 * source_.uniaxial_tolerance << " % off, " << source_.uniaxial_tolerance_pointer
       << "), at the strains this run's converged states reached with each loop length: "
       << at.str() << " ("
       << (source_.database.empty() ? std::string("the database") : source_.database)
       << ", /energy_law/diagnostics/uniaxial; docs/database.md, \"The law's own uniaxial "
          "response\")";
  }
  return os.str();
}

KnitMaterial::EnergyStats KnitMaterial::energy_stats() const {
  EnergyStats s;
  s.evaluations = evaluations_.load();
  s.outside_box = outside_box_.load();
  s.failed = failed_.load();
  for (int k = 0; k < 3; ++k) {
    s.visited_min(k) = visited_[k].load();
    s.visited_max(k) = visited_[k + 3].load();
  }
  return s;
}

std::string KnitMaterial::energy_report() const {
  const EnergyStats s = energy_stats();
  const auto& box = energy_->data();
  std::ostringstream os;
  os << std::setprecision(4);
  os << "knit material (energy law): " << s.evaluations << " evaluations";
  if (s.evaluations == 0) return os.str();
  os << "; " << s.outside_box << " extrapolated ("
     << 100.0 * static_cast<double>(s.outside_box) / static_cast<double>(s.evaluations)
     << " %, outside the data strain box E11 [" << box.box_min(0) << ", " << box.box_max(0)
     << "], E22 [" << box.box_min(1) << ", " << box.box_max(1) << "], 2E12 [" << box.box_min(2)
     << ", " << box.box_max(2) << "])";
  if (s.failed) os << "; " << s.failed << " failed (non-finite strain)";
  // Newton's trial iterates may wander far outside the box before the line search rejects
  // them; the converged states are what the fabric reaches.
  if (const long n = audit_evaluations_.load(); n > 0) {
    const long k = audit_outside_.load();
    os << "\n  at converged states: " << k << " of " << n << " evaluations extrapolated ("
       << 100.0 * static_cast<double>(k) / static_cast<double>(n) << " %)" << last_step_share()
       << "; their strain box E11 [" << audit_visited_[0].load() << ", " << audit_visited_[3].load()
       << "], E22 [" << audit_visited_[1].load() << ", " << audit_visited_[4].load() << "], 2E12 ["
       << audit_visited_[2].load() << ", " << audit_visited_[5].load() << "]";
  }
  os << "\n  visited material-frame strain box (Newton's trial iterates too): E11 ["
     << s.visited_min(0) << ", " << s.visited_max(0) << "], E22 [" << s.visited_min(1) << ", "
     << s.visited_max(1) << "], 2E12 [" << s.visited_min(2) << ", " << s.visited_max(2) << "]";
  // Whether the law's own uniaxial response was checked (session 41's review: a database
  // without the curves said nothing, which read as "checked, fine").
  if (source_.uniaxial.empty())
    // Two causes (session 50's red team: a synth database fitted seconds before was said to
    // be "fitted before session 41").
    os << "\n  uniaxial check: not available (the database has no "
          "/energy_law/diagnostics/uniaxial: its raw data hold no uniaxial-stress path (knit-meso "
          "synth, or a sweep input without them), or its law was fitted before session 41, when "
          "`knit-meso fit DB --law energy --energy-options OPTS` with its options adds it)";
  else
    os << "\n  uniaxial check: the law's own uniaxial response against the cell's, tolerance "
       << 100.0 * source_.uniaxial_tolerance << " % (" << source_.uniaxial_tolerance_pointer
       << "); a departure beyond it is a warning"
       // The verdict of this run (session 48's walkthrough: a pass was never stated).
       << uniaxial_verdict();
  const Stats st = stats();
  if (!st.first.empty()) {
    // Every evaluation, Newton's trial iterates too (session 39's walkthrough read an iterate's
    // E = 111 as a state the fabric reached).
    os << "\n  first locations outside the box (Newton's trial iterates too; theta1, theta2; "
          "E_course, E_wale, 2E_cw):";
    for (const auto& w : st.first)
      os << "\n    (" << w.theta(0) << ", " << w.theta(1) << "): " << w.E_material.transpose();
  }
  return os.str();
}

}  // namespace knit::macro
