// Frictional self-contact of the periodic yarn: see knit/meso/contact/contact_set.hpp.
#include "knit/meso/contact/contact_set.hpp"

#include <algorithm>
#include <cmath>

#include "knit/spline/knot_vector.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::meso::contact {

ContactSet::ContactSet(const rod::RodSystem& sys, int rod, const ContactOptions& opt)
    : rod_(rod), opt_(opt), basis_(sys.spec(rod).basis) {
  const int n = basis_.size(), p = basis_.degree();
  xi_ = basis_.greville();
  first_.resize(n);
  Nc_.resize(n, p + 1);
  Eigen::MatrixXd B(1, p + 1);
  for (int j = 0; j < n; ++j) {
    first_[j] = basis_.eval(xi_[j], 0, B);
    Nc_.row(j) = B.row(0);
  }
  // Tributary lengths W_j = int N_j |r0_xi| dxi.
  weight_.assign(n, 0.0);
  const auto rule = spline::gauss_legendre_on_spans(p + 2, basis_.knots());
  const Eigen::MatrixXd& r0 = sys.spec(rod).r0;
  Eigen::MatrixXd D(2, p + 1);
  for (std::size_t g = 0; g < rule.points.size(); ++g) {
    const int f = basis_.eval(rule.points[g], 1, D);
    const double jac = (D.row(1) * r0.middleRows(f, p + 1)).norm();
    for (int a = 0; a <= p; ++a) weight_[f + a] += rule.weights[g] * D(0, a) * jac;
  }
  history_.assign(3 * n, {});
  pending_.assign(3 * n, {});
}

Eigen::MatrixXd ContactSet::positions(const rod::RodSystem& sys, const Eigen::VectorXd& x) const {
  const int n = basis_.size();
  Eigen::MatrixXd Q(n, 3);
  for (int a = 0; a < n; ++a) Q.row(a) = x.segment<3>(sys.dof(rod_, a, rod::kFieldR)).transpose();
  return Q;
}

Chain ContactSet::chain(const Eigen::MatrixXd& Q, int course) const {
  Chain c;
  c.basis = &basis_;
  c.Q = &Q;
  c.a1 = a1_;
  c.t = course * a2_;
  return c;
}

std::vector<ContactSet::Found> ContactSet::search(const Eigen::MatrixXd& Q) const {
  const int n = basis_.size(), p = basis_.degree();
  const std::vector<double> br = spline::unique_knots(basis_.knots());
  const int ne = static_cast<int>(br.size()) - 1;
  // Element boxes of the base copy (control polygon hull).
  std::vector<Eigen::Vector3d> lo(ne), hi(ne);
  for (int e = 0; e < ne; ++e) {
    const int f = basis_.find_span(0.5 * (br[e] + br[e + 1])) - p;
    lo[e] = Q.middleRows(f, p + 1).colwise().minCoeff().transpose();
    hi[e] = Q.middleRows(f, p + 1).colwise().maxCoeff().transpose();
  }
  const double inflate = opt_.d + opt_.margin;
  std::vector<Found> out;
  for (int j = 1; j < n - 1; ++j) {  // end points carry the periodicity rows
    const Eigen::Vector3d xs = (Nc_.row(j) * Q.middleRows(first_[j], p + 1)).transpose();
    for (int course = -1; course <= 1; ++course) {
      const Chain ch = chain(Q, course);
      const std::size_t start = out.size();
      for (int k = -1; k <= 1; ++k) {
        const Eigen::Vector3d shift = k * a1_ + course * a2_;
        for (int e = 0; e < ne; ++e) {
          const double ua = k + br[e], ub = k + br[e + 1];
          if (course == 0 && std::max(std::abs(ua - xi_[j]), std::abs(ub - xi_[j])) <
                                 opt_.self_exclusion)
            continue;
          const Eigen::Vector3d l = lo[e] + shift, h = hi[e] + shift;
          if ((xs.array() < l.array() - inflate).any() || (xs.array() > h.array() + inflate).any())
            continue;
          const Projection pr = project(ch, xs, k, ua, ub, 0.5 * (ua + ub));
          if (!pr.ok || pr.distance >= inflate) continue;
          if (course == 0 && std::abs(pr.u - xi_[j]) < opt_.self_exclusion) continue;
          bool dup = false;
          for (std::size_t q = start; q < out.size(); ++q)
            if (std::abs(out[q].pr.u - pr.u) < 1e-7) dup = true;
          if (!dup) out.push_back({j, course, pr});
        }
      }
    }
  }
  return out;
}

double& ContactSet::anchor_for(const Found& f, bool create) {
  const int key = 3 * f.point + f.course + 1;
  double* best = nullptr;
  double bd = opt_.match_tol;
  for (auto* list : {&history_[key], &pending_[key]})
    for (double& a : *list)
      if (std::abs(a - f.pr.u) < bd) {
        bd = std::abs(a - f.pr.u);
        best = &a;
      }
  if (best) return *best;
  static thread_local double scratch;
  if (!create) {
    scratch = f.pr.u;
    return scratch;
  }
  pending_[key].push_back(f.pr.u);
  return pending_[key].back();
}

template <class Visit>
void ContactSet::visit(const rod::RodSystem& sys, const Eigen::VectorXd& x, bool want_jac,
                       Visit&& v) {
  const Eigen::MatrixXd Q = positions(sys, x);
  PenaltyLaw law = opt_.penalty;
  law.k_N *= scale_;
  for (const Found& f : search(Q)) {
    const Chain ch = chain(Q, f.course);
    const int p = basis_.degree();
    const Eigen::Vector3d xs = (Nc_.row(f.point) * Q.middleRows(first_[f.point], p + 1)).transpose();
    // Quick gap test before touching the history: inactive pairs create no anchors.
    if (f.pr.distance >= opt_.d) continue;
    PairHistory h{anchor_for(f, true)};
    const PairResult r = evaluate_pair(xs, ch, f.pr, opt_.d, law, opt_.friction, h, want_jac);
    if (r.active) v(f, r);
  }
}

void ContactSet::add(const rod::RodSystem& sys, const Eigen::VectorXd& x, double /*lambda*/,
                     Eigen::VectorXd& F, std::vector<Eigen::Triplet<double>>& jac) {
  const int p = basis_.degree();
  visit(sys, x, true, [&](const Found& f, const PairResult& r) {
    const int rf = sys.row(rod_, f.point, rod::kRowForce);
    const int rm = sys.row(rod_, f.point, rod::kRowMoment);
    F.segment<3>(rf) += r.f;
    F.segment<3>(rm) += r.m;
    for (int i = 0; i < 3; ++i)
      for (int c = 0; c < 3; ++c) {
        for (int a = 0; a <= p; ++a) {
          const int col = sys.dof(rod_, first_[f.point] + a, rod::kFieldR, c);
          jac.emplace_back(rf + i, col, Nc_(f.point, a) * r.df_dz(i, c));
          jac.emplace_back(rm + i, col, Nc_(f.point, a) * r.dm_dz(i, c));
        }
        for (int b = 0; b <= p; ++b) {
          const int col = sys.dof(rod_, r.master_first + b, rod::kFieldR, c);
          jac.emplace_back(rf + i, col, r.df_dz(i, 3 + 3 * b + c));
          jac.emplace_back(rm + i, col, r.dm_dz(i, 3 + 3 * b + c));
        }
      }
  });
}

std::vector<ActivePair> ContactSet::active_pairs(const rod::RodSystem& sys,
                                                 const Eigen::VectorXd& x) {
  std::vector<ActivePair> out;
  visit(sys, x, false, [&](const Found& f, const PairResult& r) {
    ActivePair a;
    a.point = f.point;
    a.course = f.course;
    a.u = r.u;
    a.gap = r.gap;
    a.p = r.p;
    a.f_T = r.f_T;
    a.slip = r.slip;
    a.f = r.f;
    a.weight = weight_[f.point];
    out.push_back(a);
  });
  return out;
}

void ContactSet::commit(const rod::RodSystem& sys, const Eigen::VectorXd& x) {
  std::vector<std::vector<double>> next(history_.size());
  double D = 0;
  visit(sys, x, false, [&](const Found& f, const PairResult& r) {
    next[3 * f.point + f.course + 1].push_back(r.u_anchor_new);
    D += weight_[f.point] * r.dissipation;
  });
  history_ = std::move(next);
  pending_.assign(history_.size(), {});
  last_dissipation_ = D;
  dissipation_ += D;
}

}  // namespace knit::meso::contact
