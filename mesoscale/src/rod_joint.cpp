#include <stdexcept>

#include "knit/meso/rod/joint.hpp"

namespace knit::meso::rod {

Joint::Joint(RodSystem& sys, JointEnd a, JointEnd b, Gap gap) : gap_(std::move(gap)) {
  for (auto [side, e] : {std::pair<Side*, JointEnd>{&a_, a}, {&b_, b}}) {
    const RodSpec& sp = sys.spec(e.rod);
    const EndCondition& bc = e.end == End::kStart ? sp.start : sp.end;
    if (bc.kind != EndCondition::Kind::kCustom)
      throw std::invalid_argument("joint: rod '" + sp.name + "' " +
                                  (e.end == End::kStart ? "start" : "end") +
                                  " must have a custom end condition");
    side->e = e;
    side->xi = e.end == End::kStart ? sp.basis.lo() : sp.basis.hi();
    side->sign = e.end == End::kStart ? -1.0 : 1.0;
    side->b = sys.basis(e.rod, side->xi, 0);
    Quat<double> q0 = Quat<double>::Zero();
    for (int i = 0; i < side->b.N.cols(); ++i)
      q0 += side->b.N(0, i) * sp.q0.row(side->b.first + i).transpose();
    side->q0 = q0.normalized();
  }
  ref_gap_ = sys.reference_position(b.rod, b_.xi) - sys.reference_position(a.rod, a_.xi);
  const double La = sys.reference_length(a.rod), EA = sys.spec(a.rod).section.C_Gamma()(2);
  const int ra = sys.row(a.rod, sys.end_point(a.rod, a.end), kRowForce);
  const int rb = sys.row(b.rod, sys.end_point(b.rod, b.end), kRowForce);
  for (int i = 0; i < 3; ++i) {
    sys.set_row_scale(ra + kRowForce + i, 1.0 / La);
    sys.set_row_scale(ra + kRowMoment + i, 1.0);
    sys.set_row_scale(rb + kRowForce + i, 1.0 / EA);
    sys.set_row_scale(rb + kRowMoment + i, 1.0 / (EA * La));
  }
}

void Joint::add(const RodSystem& sys, const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F,
                std::vector<Eigen::Triplet<double>>& jac) {
  const int ra = sys.row(a_.e.rod, sys.end_point(a_.e.rod, a_.e.end), kRowForce);
  const int rb = sys.row(b_.e.rod, sys.end_point(b_.e.rod, b_.e.end), kRowForce);
  auto field = [&](const Side& s, Field f, int dim) {
    Eigen::Vector4d v = Eigen::Vector4d::Zero();
    for (int i = 0; i < s.b.N.cols(); ++i)
      v.head(dim) += s.b.N(0, i) * x.segment(sys.dof(s.e.rod, s.b.first + i, f), dim);
    return v;
  };
  const Eigen::Vector3d r_a = field(a_, kFieldR, 3).head<3>(),
                        r_b = field(b_, kFieldR, 3).head<3>();
  const Quat<double> q_a = field(a_, kFieldQ, 4), q_b = field(b_, kFieldQ, 4);
  const Eigen::Vector3d n_a = field(a_, kFieldN, 3).head<3>(),
                        n_b = field(b_, kFieldN, 3).head<3>();
  const Eigen::Vector3d m_a = field(a_, kFieldM, 3).head<3>(),
                        m_b = field(b_, kFieldM, 3).head<3>();

  const Eigen::Vector3d g = gap_ ? gap_(lambda) : ref_gap_;
  F.segment<3>(ra + kRowForce) += r_b - r_a - g;
  const Quat<double> p_b = qmul(q_b, qconj(b_.q0));
  const Quat<double> pa_bar = qmul(a_.q0, qconj(q_a));  // conj(q_a q0a^*) = q0a q_a^*
  F.segment<3>(ra + kRowMoment) += qmul(pa_bar, p_b).tail<3>();
  F.segment<3>(rb + kRowForce) += a_.sign * n_a + b_.sign * n_b;
  F.segment<3>(rb + kRowMoment) += a_.sign * m_a + b_.sign * m_b;

  // d vec(pa_bar * p_b): w.r.t. q_b through p_b = qright(q0b^*) q_b; w.r.t. q_a through
  // pa_bar = qleft(q0a) C q_a with C = diag(1, -1, -1, -1).
  const Eigen::Matrix4d C = Eigen::Vector4d(1, -1, -1, -1).asDiagonal();
  const Eigen::Matrix<double, 3, 4> Dqb = (qleft(pa_bar) * qright(qconj(b_.q0))).bottomRows<3>();
  const Eigen::Matrix<double, 3, 4> Dqa = (qright(p_b) * qleft(a_.q0) * C).bottomRows<3>();
  for (const Side* s : {&a_, &b_}) {
    const bool is_a = s == &a_;
    for (int i = 0; i < s->b.N.cols(); ++i) {
      const double N = s->b.N(0, i);
      if (N == 0.0) continue;
      const int base = sys.dof(s->e.rod, s->b.first + i, kFieldR);
      for (int c = 0; c < 3; ++c) {
        jac.emplace_back(ra + kRowForce + c, base + kFieldR + c, is_a ? -N : N);
        jac.emplace_back(rb + kRowForce + c, base + kFieldN + c, s->sign * N);
        jac.emplace_back(rb + kRowMoment + c, base + kFieldM + c, s->sign * N);
        for (int k = 0; k < 4; ++k)
          jac.emplace_back(ra + kRowMoment + c, base + kFieldQ + k,
                           N * (is_a ? Dqa(c, k) : Dqb(c, k)));
      }
    }
  }
}

}  // namespace knit::meso::rod
