// Isogeometric collocation of the mixed Simo-Reissner rod equations (see rod_system.hpp).
#include "knit/meso/rod/rod_system.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <cmath>
#include <stdexcept>
#include <unsupported/Eigen/AutoDiff>

#include "knit/spline/quadrature.hpp"

namespace knit::meso::rod {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Trip = Eigen::Triplet<double>;

Matrix3d skew(const Vector3d& v) {
  Matrix3d S;
  S << 0, -v(2), v(1), v(2), 0, -v(0), -v(1), v(0), 0;
  return S;
}

// Rotation-minimizing frame: transports d1 along the tangent by the smallest rotation taking
// t_a to t_b (Rodrigues), fine sub-steps between collocation points.
Vector3d transport(const Vector3d& d1, const Vector3d& ta, const Vector3d& tb) {
  const Vector3d k = ta.cross(tb);
  const double s = k.norm(), c = ta.dot(tb);
  if (s < 1e-15) return d1;
  const Vector3d u = k / s;
  return d1 * c + u.cross(d1) * s + u * u.dot(d1) * (1.0 - c);
}

}  // namespace

int RodSystem::add_rod(RodSpec spec) {
  const int n = spec.basis.size();
  const int p = spec.basis.degree();
  const std::string who = "rod '" + spec.name + "': ";
  if (p < 1) throw std::invalid_argument(who + "degree must be at least 1");
  if (n < 2) throw std::invalid_argument(who + "at least 2 control points are needed");
  if (spec.r0.rows() != n || spec.r0.cols() != 3)
    throw std::invalid_argument(who + "r0 must be " + std::to_string(n) + " x 3");
  if (spec.q0.size() > 0 && (spec.q0.rows() != n || spec.q0.cols() != 4))
    throw std::invalid_argument(who + "q0 must be empty or " + std::to_string(n) + " x 4");
  const Section& S = spec.section;
  if (!(S.E > 0) || !(S.d > 0) || !(S.nu > -1.0 && S.nu < 0.5) || !(S.shear_factor() > 0))
    throw std::invalid_argument(who +
                                "section needs E > 0, d > 0, -1 < nu < 0.5, shear factor > 0");

  RodData R;
  R.geo = spline::SplineCurve(spec.basis, spec.r0, spec.weights);  // validates the weights
  R.offset = ndofs_;
  const std::vector<double> xi = spec.basis.greville();

  // Reference length.
  {
    const auto rule = spline::gauss_legendre_on_spans(p + 2, spec.basis.knots());
    Eigen::MatrixXd B(2, p + 1);
    double L = 0.0;
    for (size_t g = 0; g < rule.points.size(); ++g) {
      const int f = R.geo.basis_derivatives(rule.points[g], 1, B);
      L += rule.weights[g] * (B.row(1) * spec.r0.middleRows(f, p + 1)).norm();
    }
    R.length = L;
  }

  // Reference quaternion spline: rotation-minimizing frame interpolated at the Greville points.
  if (spec.q0.size() == 0) {
    const int sub = 32;
    Eigen::MatrixXd B(2, p + 1);
    auto tangent = [&](double u) {
      const int f = R.geo.basis_derivatives(u, 1, B);
      Vector3d t = (B.row(1) * spec.r0.middleRows(f, p + 1)).transpose();
      if (!(t.norm() > 0))
        throw std::invalid_argument(who + "reference centerline has a zero tangent");
      return Vector3d(t.normalized());
    };
    Vector3d t = tangent(xi[0]);
    Vector3d d1 = spec.d1_hint - spec.d1_hint.dot(t) * t;
    if (d1.norm() < 1e-8) {
      Vector3d e = Vector3d::UnitX();
      if (std::abs(t.x()) > 0.9) e = Vector3d::UnitY();
      d1 = e - e.dot(t) * t;
    }
    d1.normalize();
    Eigen::MatrixXd Q(n, 4);
    // The interpolation matrix is banded (p + 1 entries a row). Dense up to kDenseInterpolation
    // rows (the unit cell's curves have ~36: bitwise the results of before); sparse beyond
    // (session 29, a helper's fuzzing audit: 5,000 elements took 90 s and 1.8 GB in the dense
    // LU, and 20,000 more than 3 GB, which the schema allows up to 1e6).
    constexpr int kDenseInterpolation = 2000;
    const bool dense = n <= kDenseInterpolation;
    Eigen::MatrixXd A = dense ? Eigen::MatrixXd::Zero(n, n) : Eigen::MatrixXd();
    std::vector<Eigen::Triplet<double>> At;
    Quat<double> prev(1, 0, 0, 0);
    for (int j = 0; j < n; ++j) {
      if (j > 0) {
        for (int k = 1; k <= sub; ++k) {
          const Vector3d tb = tangent(xi[j - 1] + (xi[j] - xi[j - 1]) * k / sub);
          d1 = transport(d1, t, tb);
          d1 = (d1 - d1.dot(tb) * tb).normalized();
          t = tb;
        }
      }
      Matrix3d F;
      F.col(0) = d1;
      F.col(1) = t.cross(d1);
      F.col(2) = t;
      Quat<double> q = quat_from_matrix(F);
      if (j > 0 && q.dot(prev) < 0) q = -q;
      prev = q;
      Q.row(j) = q.transpose();
      const int f = R.geo.basis_derivatives(xi[j], 0, B.topRows(1));
      if (dense)
        A.row(j).segment(f, p + 1) = B.row(0);
      else
        for (int i = 0; i <= p; ++i)
          if (B(0, i) != 0.0) At.emplace_back(j, f + i, B(0, i));
    }
    if (dense) {
      spec.q0 = A.partialPivLu().solve(Q);
    } else {
      Eigen::SparseMatrix<double> As(n, n);
      As.setFromTriplets(At.begin(), At.end());
      Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(As);
      if (lu.info() != Eigen::Success)
        throw std::invalid_argument(who + "reference frame: singular interpolation matrix");
      spec.q0 = lu.solve(Q);
    }
  }

  // Collocation points.
  R.points.resize(n);
  R.Nc.resize(2 * n, p + 1);
  for (int j = 0; j < n; ++j) {
    CollocationPoint& c = R.points[j];
    c.xi = xi[j];
    c.first = R.geo.basis_derivatives(c.xi, 1, R.Nc.middleRows(2 * j, 2));
    c.row = R.offset + kRowsPerPoint * j;
    const auto N = R.Nc.middleRows(2 * j, 2);
    const Vector3d r_xi = (N.row(1) * spec.r0.middleRows(c.first, p + 1)).transpose();
    const Quat<double> q = (N.row(0) * spec.q0.middleRows(c.first, p + 1)).transpose();
    const Quat<double> q_xi = (N.row(1) * spec.q0.middleRows(c.first, p + 1)).transpose();
    c.jac = r_xi.norm();
    if (!(c.jac > 0)) throw std::invalid_argument(who + "reference centerline has a zero tangent");
    c.gamma0 = rotation(q).transpose() * r_xi / c.jac;
    c.kappa0 = material_curvature(q, q_xi) / c.jac;
  }
  R.r_start = R.geo.eval(xi.front());
  R.r_end = R.geo.eval(xi.back());
  R.spec = std::move(spec);
  rods_.push_back(std::move(R));
  ndofs_ += kDofsPerPoint * n;
  update_scales(num_rods() - 1);
  return num_rods() - 1;
}

void RodSystem::update_scales(int rod) {
  Eigen::VectorXd old = row_scale_;
  row_scale_ = Eigen::VectorXd::Ones(ndofs_);
  row_scale_.head(old.size()) = old;
  const RodData& R = rods_[rod];
  const double L = R.length, EA = R.spec.section.C_Gamma()(2);
  const int n = num_control_points(rod);
  for (int j = 0; j < n; ++j) {
    const int r0 = row(rod, j, kRowForce);
    row_scale_.segment(r0 + kRowForce, 3).setConstant(L / EA);
    row_scale_.segment(r0 + kRowMoment, 3).setConstant(1.0 / EA);
    row_scale_.segment(r0 + kRowStrain, 3).setConstant(1.0);
    row_scale_.segment(r0 + kRowCurvature, 3).setConstant(L);
    row_scale_(r0 + kRowGauge) = 1.0;
  }
  for (End e : {End::kStart, End::kEnd}) {
    const EndCondition& bc = e == End::kStart ? R.spec.start : R.spec.end;
    const int r0 = row(rod, end_point(rod, e), kRowForce);
    if (bc.kind == EndCondition::Kind::kCustom) {
      row_scale_.segment(r0, 6).setConstant(1.0);
      continue;
    }
    row_scale_.segment(r0 + kRowForce, 3).setConstant(bc.fix_position ? 1.0 / L : 1.0 / EA);
    row_scale_.segment(r0 + kRowMoment, 3).setConstant(bc.fix_rotation ? 1.0 : 1.0 / (EA * L));
  }
}

Eigen::VectorXd RodSystem::initial_state() const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(ndofs_);
  for (int k = 0; k < num_rods(); ++k) {
    const RodSpec& s = rods_[k].spec;
    for (int a = 0; a < s.basis.size(); ++a) {
      x.segment<3>(dof(k, a, kFieldR)) = s.r0.row(a).transpose();
      x.segment<4>(dof(k, a, kFieldQ)) = s.q0.row(a).transpose();
    }
  }
  return x;
}

PointBasis RodSystem::basis(int rod, double xi, int nder) const {
  const RodData& R = rods_[rod];
  PointBasis b;
  b.N.resize(nder + 1, R.spec.basis.degree() + 1);
  b.first = R.geo.basis_derivatives(xi, nder, b.N);
  return b;
}

Eigen::MatrixXd RodSystem::position_derivatives(int rod, double xi, const Eigen::VectorXd& x,
                                                int nder) const {
  const PointBasis b = basis(rod, xi, nder);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(nder + 1, 3);
  for (int i = 0; i < b.N.cols(); ++i)
    out += b.N.col(i) * x.segment<3>(dof(rod, b.first + i, kFieldR)).transpose();
  return out;
}

Eigen::Vector3d RodSystem::position(int rod, double xi, const Eigen::VectorXd& x) const {
  return position_derivatives(rod, xi, x, 0).row(0).transpose();
}

Eigen::Vector3d RodSystem::reference_position(int rod, double xi) const {
  return rods_[rod].geo.eval(xi);
}

PointState RodSystem::state(int rod, double xi, const Eigen::VectorXd& x) const {
  const int p = rods_[rod].spec.basis.degree();
  const PointBasis b = basis(rod, xi, std::min(2, p));
  PointState s;
  s.xi = xi;
  s.r.setZero();
  s.r_xi.setZero();
  s.r_xixi.setZero();
  s.q.setZero();
  s.q_xi.setZero();
  s.n.setZero();
  s.m.setZero();
  Vector3d r0_xi = Vector3d::Zero();
  for (int i = 0; i <= p; ++i) {
    const int a = b.first + i;
    const auto ra = x.segment<3>(dof(rod, a, kFieldR));
    const auto qa = x.segment<4>(dof(rod, a, kFieldQ));
    s.r += b.N(0, i) * ra;
    s.r_xi += b.N(1, i) * ra;
    if (p >= 2) s.r_xixi += b.N(2, i) * ra;
    s.q += b.N(0, i) * qa;
    s.q_xi += b.N(1, i) * qa;
    s.n += b.N(0, i) * x.segment<3>(dof(rod, a, kFieldN));
    s.m += b.N(0, i) * x.segment<3>(dof(rod, a, kFieldM));
    r0_xi += b.N(1, i) * rods_[rod].spec.r0.row(a).transpose();
  }
  s.R = rotation(s.q);
  s.jac = r0_xi.norm();
  return s;
}

RodSystem::AxialStretch RodSystem::min_axial_stretch(const Eigen::VectorXd& x) const {
  AxialStretch a;
  bool first = true;
  for (int k = 0; k < num_rods(); ++k)
    for (const CollocationPoint& c : rods_[k].points) {
      const PointState s = state(k, c.xi, x);
      const double v = s.R.col(2).dot(s.r_xi) / s.jac;
      // A NaN is the smallest and stays (the review of session 50: `!(v >= NaN)` let a later
      // finite value replace it).
      if (first || std::isnan(v) || (!std::isnan(a.value) && v < a.value)) a = {v, k, c.xi};
      first = false;
    }
  return a;
}

void RodSystem::residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F) const {
  std::vector<Trip> dummy;
  dummy.reserve(1);
  assemble_impl(x, lambda, F, dummy, false);
}

void RodSystem::assemble(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F,
                         std::vector<Trip>& jac) const {
  assemble_impl(x, lambda, F, jac, true);
}

void RodSystem::assemble_impl(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F,
                              std::vector<Trip>& jac, bool want_jac) const {
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 8, 1>>;
  F.setZero(ndofs_);
  for (int k = 0; k < num_rods(); ++k) {
    const RodData& Rd = rods_[k];
    const RodSpec& sp = Rd.spec;
    const int n = sp.basis.size(), p = sp.basis.degree();
    const Vector3d CGinv = sp.section.C_Gamma().cwiseInverse();
    const Vector3d CKinv = sp.section.C_K().cwiseInverse();
    if (want_jac) jac.reserve(jac.size() + static_cast<size_t>(n) * (p + 1) * 120);
    for (int j = 0; j < n; ++j) {
      const CollocationPoint& c = Rd.points[j];
      const auto N0 = Rd.Nc.row(2 * j);
      const auto N1 = Rd.Nc.row(2 * j + 1);
      Vector3d r, r_xi, nn, n_xi, mm, m_xi;
      Quat<double> q, q_xi;
      r.setZero();
      r_xi.setZero();
      nn.setZero();
      n_xi.setZero();
      mm.setZero();
      m_xi.setZero();
      q.setZero();
      q_xi.setZero();
      for (int i = 0; i <= p; ++i) {
        const int base = dof(k, c.first + i, kFieldR);
        const auto ra = x.segment<3>(base + kFieldR);
        const auto qa = x.segment<4>(base + kFieldQ);
        const auto na = x.segment<3>(base + kFieldN);
        const auto ma = x.segment<3>(base + kFieldM);
        r += N0(i) * ra;
        r_xi += N1(i) * ra;
        q += N0(i) * qa;
        q_xi += N1(i) * qa;
        nn += N0(i) * na;
        n_xi += N1(i) * na;
        mm += N0(i) * ma;
        m_xi += N1(i) * ma;
      }
      const double iJ = 1.0 / c.jac;
      const int row0 = c.row;
      auto add_block = [&](int r0, int c0, const Matrix3d& B, double w) {
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b)
            if (B(a, b) != 0.0) jac.emplace_back(r0 + a, c0 + b, w * B(a, b));
      };
      auto add_diag = [&](int r0, int c0, double w) {
        for (int a = 0; a < 3; ++a) jac.emplace_back(r0 + a, c0 + a, w);
      };

      // ---- constitutive and gauge rows (everywhere) with AD over (q, q_xi) ----
      Eigen::Matrix<AD, 4, 1> qa, qxa;
      for (int i = 0; i < 4; ++i) {
        qa(i) = AD(q(i), 8, i);
        qxa(i) = AD(q_xi(i), 8, 4 + i);
      }
      const Eigen::Matrix<AD, 3, 3> Ra = rotation(qa);
      const Eigen::Matrix<AD, 3, 1> Kq = material_curvature(qa, qxa);
      const Matrix3d Rm = [&] {
        Matrix3d M;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) M(a, b) = Ra(a, b).value();
        return M;
      }();
      Eigen::Matrix<double, 6, 8> Dq;  // d(c1, c2)/d(q, q_xi)
      for (int a = 0; a < 3; ++a) {
        AD g = AD(0.0);
        AD kk = Kq(a) * iJ;
        for (int b = 0; b < 3; ++b) {
          g += Ra(b, a) * (r_xi(b) * iJ - CGinv(a) * nn(b));
          kk -= Ra(b, a) * (CKinv(a) * mm(b));
        }
        F(row0 + kRowStrain + a) = g.value() - c.gamma0(a);
        F(row0 + kRowCurvature + a) = kk.value() - c.kappa0(a);
        Dq.row(a) = g.derivatives().transpose();
        Dq.row(3 + a) = kk.derivatives().transpose();
      }
      F(row0 + kRowGauge) = q.squaredNorm() - 1.0;
      if (want_jac) {
        const Matrix3d Rt = Rm.transpose();
        const Matrix3d CGRt = CGinv.asDiagonal() * Rt;
        const Matrix3d CKRt = CKinv.asDiagonal() * Rt;
        for (int i = 0; i <= p; ++i) {
          const int base = dof(k, c.first + i, kFieldR);
          const double n0 = N0(i), n1 = N1(i);
          add_block(row0 + kRowStrain, base + kFieldR, Rt, n1 * iJ);
          add_block(row0 + kRowStrain, base + kFieldN, CGRt, -n0);
          add_block(row0 + kRowCurvature, base + kFieldM, CKRt, -n0);
          for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 4; ++b) {
              const double v = n0 * Dq(a, b) + n1 * Dq(a, 4 + b);
              jac.emplace_back(row0 + kRowStrain + a, base + kFieldQ + b, v);
            }
          for (int b = 0; b < 4; ++b)
            jac.emplace_back(row0 + kRowGauge, base + kFieldQ + b, 2.0 * n0 * q(b));
        }
      }

      // ---- balance rows (interior) or boundary conditions (ends) ----
      const bool at_start = j == 0, at_end = j == n - 1;
      if (!at_start && !at_end) {
        F.segment<3>(row0 + kRowForce) = n_xi * iJ + lambda * sp.line_force;
        F.segment<3>(row0 + kRowMoment) =
            m_xi * iJ + (r_xi * iJ).cross(nn) + lambda * sp.line_moment;
        if (want_jac) {
          const Matrix3d Sn = skew(nn), Sr = skew(r_xi);
          for (int i = 0; i <= p; ++i) {
            const int base = dof(k, c.first + i, kFieldR);
            add_diag(row0 + kRowForce, base + kFieldN, N1(i) * iJ);
            add_diag(row0 + kRowMoment, base + kFieldM, N1(i) * iJ);
            add_block(row0 + kRowMoment, base + kFieldR, Sn, -N1(i) * iJ);
            add_block(row0 + kRowMoment, base + kFieldN, Sr, N0(i) * iJ);
          }
        }
        continue;
      }
      const EndCondition& bc = at_start ? sp.start : sp.end;
      if (bc.kind == EndCondition::Kind::kCustom) continue;
      const double sgn = at_end ? 1.0 : -1.0;
      if (bc.fix_position) {
        F.segment<3>(row0 + kRowForce) =
            r - (at_start ? Rd.r_start : Rd.r_end) - lambda * bc.displacement;
      } else {
        F.segment<3>(row0 + kRowForce) = sgn * nn - lambda * bc.force;
      }
      Eigen::Matrix<double, 3, 4> Lq;
      if (bc.fix_rotation) {
        const Quat<double> q0 = (N0 * sp.q0.middleRows(c.first, p + 1)).transpose();
        const Quat<double> qp =
            qmul(quat_from_rotation_vector(lambda * bc.rotation), Quat<double>(q0.normalized()));
        const Quat<double> qpc = qconj(qp);
        for (int b = 0; b < 4; ++b)
          Lq.col(b) = qmul(qpc, Quat<double>(Quat<double>::Unit(b))).tail<3>();
        F.segment<3>(row0 + kRowMoment) = Lq * q;
      } else {
        F.segment<3>(row0 + kRowMoment) = sgn * mm - lambda * bc.moment;
      }
      if (want_jac) {
        for (int i = 0; i <= p; ++i) {
          const int base = dof(k, c.first + i, kFieldR);
          if (N0(i) == 0.0) continue;
          if (bc.fix_position)
            add_diag(row0 + kRowForce, base + kFieldR, N0(i));
          else
            add_diag(row0 + kRowForce, base + kFieldN, sgn * N0(i));
          if (bc.fix_rotation) {
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 4; ++b)
                jac.emplace_back(row0 + kRowMoment + a, base + kFieldQ + b, N0(i) * Lq(a, b));
          } else {
            add_diag(row0 + kRowMoment, base + kFieldM, sgn * N0(i));
          }
        }
      }
    }
  }
}

}  // namespace knit::meso::rod
