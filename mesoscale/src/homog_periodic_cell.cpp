// Periodic single-jersey cell and homogenization: see knit/meso/homog/periodic_cell.hpp.
#include "knit/meso/homog/periodic_cell.hpp"

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "knit/meso/homog/substeps.hpp"
#include "knit/meso/rod/quaternion.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::meso::homog {

using Eigen::Matrix2d;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using rod::Quat;

namespace {

/// Smallest sub-step of a cell step, as a fraction of the step (PeriodicCell::solve).
constexpr double kMinSubstep = 1e-6;

Matrix3d embed(const Matrix2d& F) {
  Matrix3d F3 = Matrix3d::Identity();
  F3.topLeftCorner<2, 2>() = F;
  return F3;
}

}  // namespace

// The 12 replaced end rows (see the header).
class PeriodicCell::PeriodicRows : public rod::ExternalContribution {
 public:
  PeriodicRows(const rod::RodSystem& sys, const Vector3d& r_fix) : r_fix_(r_fix) {
    const int n = sys.num_control_points(0);
    const Eigen::MatrixXd& q0 = sys.spec(0).q0;
    c0_ = rod::qconj(Quat<double>(q0.row(0).transpose().normalized()));
    c1_ = rod::qconj(Quat<double>(q0.row(n - 1).transpose().normalized()));
  }
  Vector3d a1 = Vector3d::Zero();

  void add(const rod::RodSystem& sys, const Eigen::VectorXd& x, double /*lambda*/,
           Eigen::VectorXd& F, std::vector<Eigen::Triplet<double>>& jac) override {
    const int n = sys.num_control_points(0);
    const int r0 = sys.dof(0, 0, rod::kFieldR), rN = sys.dof(0, n - 1, rod::kFieldR);
    const int m0 = sys.dof(0, 0, rod::kFieldM), mN = sys.dof(0, n - 1, rod::kFieldM);
    const int q0 = sys.dof(0, 0, rod::kFieldQ), qN = sys.dof(0, n - 1, rod::kFieldQ);
    const int s0 = sys.row(0, 0, rod::kRowForce), sM = sys.row(0, 0, rod::kRowMoment);
    const int e0 = sys.row(0, n - 1, rod::kRowForce), eM = sys.row(0, n - 1, rod::kRowMoment);
    for (int i = 0; i < 3; ++i) {
      F(s0 + i) += x(rN + i) - x(r0 + i) - a1(i);
      jac.emplace_back(s0 + i, rN + i, 1.0);
      jac.emplace_back(s0 + i, r0 + i, -1.0);
      F(e0 + i) += x(r0 + i) - r_fix_(i);
      jac.emplace_back(e0 + i, r0 + i, 1.0);
      F(eM + i) += x(mN + i) - x(m0 + i);
      jac.emplace_back(eM + i, mN + i, 1.0);
      jac.emplace_back(eM + i, m0 + i, -1.0);
    }
    // Rotation periodicity, bilinear in q(0), q(1): the derivative is exact with unit steps.
    const Quat<double> qa = x.segment<4>(q0), qb = x.segment<4>(qN);
    auto rot = [&](const Quat<double>& a, const Quat<double>& b) -> Vector3d {
      return rod::qmul(rod::qconj(rod::qmul(a, c0_)), rod::qmul(b, c1_)).tail<3>();
    };
    F.segment<3>(sM) += rot(qa, qb);
    for (int k = 0; k < 4; ++k) {
      const Quat<double> ek = Quat<double>::Unit(k);
      const Vector3d da = rot(ek, qb), db = rot(qa, ek);
      for (int i = 0; i < 3; ++i) {
        jac.emplace_back(sM + i, q0 + k, da(i));
        jac.emplace_back(sM + i, qN + k, db(i));
      }
    }
  }

 private:
  Vector3d r_fix_;
  Quat<double> c0_, c1_;
};

PeriodicCell::PeriodicCell(double loop_length, const CellOptions& opt) : opt_(opt) {
  if (const auto bad = opt.validate())
    throw std::invalid_argument("cell parameter " + bad->pointer + ": " + bad->message);
  dim_ = cell::cell_dimensions(loop_length);
  opt_.geometry.d = opt_.section.d;
  opt_.contact.d = opt_.section.d;
  const cell::AnalysisCurve ac =
      cell::analysis_curve(dim_, opt_.elements, opt_.degree, opt_.geometry);
  if (const auto bad = cell::interlock_defect(ac.shape, dim_.c)) throw cell::GeometryError(*bad);
  rod::RodSpec spec;
  spec.name = "loop";
  spec.basis = ac.curve.basis();
  spec.r0 = ac.curve.control_points();
  spec.section = opt_.section;
  spec.start = rod::EndCondition::custom();
  spec.end = rod::EndCondition::custom();
  sys_.add_rod(spec);
  const int n = sys_.num_control_points(0);
  r_fix_ = spec.r0.row(0).transpose();
  periodic_ = std::make_unique<PeriodicRows>(sys_, r_fix_);
  contact_ = std::make_unique<contact::ContactSet>(sys_, 0, opt_.contact);
  // Row scales of the custom rows (dimensionless residual).
  const double L = sys_.reference_length(0), EA = opt_.section.C_Gamma()(2);
  for (int i = 0; i < 3; ++i) {
    sys_.set_row_scale(sys_.row(0, 0, rod::kRowForce, i), 1.0 / L);
    sys_.set_row_scale(sys_.row(0, 0, rod::kRowMoment, i), 1.0);
    sys_.set_row_scale(sys_.row(0, n - 1, rod::kRowForce, i), 1.0 / L);
    sys_.set_row_scale(sys_.row(0, n - 1, rod::kRowMoment, i), 1.0 / (EA * L));
  }
  x_ = sys_.initial_state();
  set_F(Matrix2d::Identity());
  // Stress-free reference (contact_set.hpp): the initial overlaps carry no force.
  contact_->capture_reference(sys_, x_);
}

PeriodicCell::~PeriodicCell() = default;

void PeriodicCell::restore(const Snapshot& s) {
  x_ = s.x;
  F_ = s.F;
  set_F(F_);
  contact_->restore(s.contact);
}

void PeriodicCell::set_F(const Matrix2d& F) {
  const Matrix3d F3 = embed(F);
  periodic_->a1 = F3 * Vector3d(dim_.w, 0, 0);
  contact_->set_periods(F3 * Vector3d(dim_.w, 0, 0), F3 * Vector3d(0, dim_.c, 0));
}

std::vector<rod::ExternalContribution*> PeriodicCell::contributions() {
  return {periodic_.get(), contact_.get()};
}

void PeriodicCell::residual_and_jacobian(Eigen::VectorXd& R, Eigen::SparseMatrix<double>& J) {
  rod::assemble_all(sys_, x_, 1.0, {periodic_.get(), contact_.get()}, R, J);
}

bool PeriodicCell::try_solve(const Matrix2d& F, StepResult& res) {
  // Affine warm start about the held point.
  const Matrix3d M = embed(F) * embed(F_).inverse();
  Eigen::VectorXd x = x_;
  for (int a = 0; a < sys_.num_control_points(0); ++a) {
    const int k = sys_.dof(0, a, rod::kFieldR);
    x.segment<3>(k) = r_fix_ + M * (x_.segment<3>(k) - r_fix_);
  }
  set_F(F);
  contact_->reset_increment();
  const rod::NewtonReport nr =
      rod::solve_newton(sys_, x, 1.0, {periodic_.get(), contact_.get()}, opt_.newton);
  res.iterations += nr.iterations;
  res.message = nr.message;
  bool accept = nr.converged;
  last_refused_ = false;
  if (accept) {
    // A converged state whose yarns went through each other is not a solution (contact_set.hpp,
    // pass-through guard): cut back, as for a failed increment.
    const std::string refusal = contact_->guard_refusal(sys_, x);
    if (!refusal.empty()) {
      res.message = refusal;
      ++res.pass_throughs;
      last_refused_ = true;
      accept = false;
    }
  }
  if (!accept) {
    set_F(F_);
    contact_->reset_increment();
    return false;
  }
  x_ = x;
  F_ = F;
  contact_->commit(sys_, x_);
  return true;
}

StepResult PeriodicCell::solve(const Matrix2d& F) {
  const auto t0 = std::chrono::steady_clock::now();
  StepResult res;
  const Matrix2d Fa = F_;
  SubstepLimits lim;
  lim.max_cutbacks = opt_.max_cutbacks;
  lim.max_substeps = opt_.max_substeps;
  lim.min_substep = kMinSubstep;
  std::string last_failure;  // a converged attempt's message says nothing of why a step ended
  const SubstepOutcome m = march_substeps(lim, [&](double next) {
    const bool ok = try_solve((next >= 1.0) ? F : Matrix2d(Fa + next * (F - Fa)), res);
    if (!ok) last_failure = res.message;
    return ok;
  });
  const double lam = m.lam;
  res.cutbacks = m.cutbacks;
  res.substeps = m.substeps;
  if (m.stop == SubstepOutcome::Stop::kMinSubstep)
    // The last attempt's reason stays in the message (a Newton failure, or the pass-through
    // guard's refusal).
    res.message =
        "sub-steps below " + std::to_string(kMinSubstep) + " of the step, stuck at " +
        std::to_string(lam) + " of the way from the step's start to its end" +
        (last_refused_ ? ": the last converged sub-step was refused by the pass-through guard: "
                       : " (a limit point: the cell does not pass this strain); last attempt: ") +
        res.message;
  else if (m.stop == SubstepOutcome::Stop::kCutbacks)
    // Said as the other two stops are (session 58's review: the bare Newton message alone).
    res.message = std::to_string(opt_.max_cutbacks + 1) +
                  " failed sub-steps in a row, each half the one before (/solver/max_cutbacks = " +
                  std::to_string(opt_.max_cutbacks) + " of the cell parameters), at " +
                  std::to_string(lam) +
                  " of the way from the step's start to its end; last failure: " + last_failure;
  else if (m.stop == SubstepOutcome::Stop::kMaxSubsteps)
    res.message = "more than max_substeps = " + std::to_string(opt_.max_substeps) +
                  " sub-steps in one step (stopped at " + std::to_string(lam) +
                  " of the way from the step's start to its end; /solver/max_substeps of the "
                  "cell parameters)" +
                  (last_failure.empty() ? std::string() : "; last failure: " + last_failure);
  StepResult h = homogenize(F_);
  h.converged = lam >= 1 - 1e-14;
  h.iterations = res.iterations;
  h.cutbacks = res.cutbacks;
  h.substeps = res.substeps;
  h.pass_throughs = res.pass_throughs;
  h.message = res.message;
  h.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return h;
}

StepResult PeriodicCell::equilibrate() {
  const auto t0 = std::chrono::steady_clock::now();
  StepResult res;
  bool ok = true;
  const int steps = std::max(1, opt_.equilibration_steps);
  for (int s = 1; s <= steps && ok; ++s) {
    contact_->set_penalty_scale(double(s) / steps);
    Eigen::VectorXd x = x_;
    contact_->reset_increment();
    const rod::NewtonReport nr =
        rod::solve_newton(sys_, x, 1.0, {periodic_.get(), contact_.get()}, opt_.newton);
    res.iterations += nr.iterations;
    res.message = nr.message;
    ok = nr.converged;
    if (ok) {
      x_ = x;
      contact_->commit(sys_, x_);
    }
  }
  contact_->set_penalty_scale(1.0);
  StepResult h = homogenize(F_);
  h.converged = ok;
  h.iterations = res.iterations;
  h.message = res.message;
  h.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return h;
}

StepResult PeriodicCell::homogenize(const Matrix2d& F) {
  StepResult r;
  r.F = F;
  const auto& b = sys_.spec(0).basis;
  const Vector3d nA = sys_.state(0, b.lo(), x_).n, nB = sys_.state(0, b.hi(), x_).n;
  r.n1 = 0.5 * (nA + nB);
  r.imbalance = (nB - nA).norm();
  // The contacts with the periodic images carry force across the cell's faces (eqs. 8-9): a
  // pair between the cell's yarn and the image shifted by k A1 + j A2 (A1 = (w, 0), A2 = (0, c):
  // copy k along the course of course j) adds f (x) (k A1 + j A2) to V P, half from each of its
  // two passes (the virial of the lattice shift: P = (1/V) dU/dF). Across the horizontal faces
  // (the courses above and below, j = +-1) for n2; across the vertical faces (the stitches left
  // and right, k = +-1, of any course) for n1, beside the yarn's own force where it crosses
  // (session 56's red team: n1 had the yarn force alone, so where neighbouring stitches of a
  // course press on each other P11 missed their contact force: at the end of the 4.5 mm
  // uniaxial wale path, E22 = 0.35, dU/dF11 / V = -2.17 MPa against a reported -0.10; 21 % of
  // the work along that path was missing, and the shear stress was unsymmetric, S12 2.33
  // against S21 1.07 at 60 deg with mu = 0).
  Vector3d across2 = Vector3d::Zero(), across1 = Vector3d::Zero();
  r.min_gap = 1e300;
  const auto pairs = contact_->active_pairs(sys_, x_);
  for (const auto& p : pairs) {
    across2 += static_cast<double>(p.course) * p.weight * p.f;
    across1 += static_cast<double>(p.k) * p.weight * p.f;
    r.min_gap = std::min(r.min_gap, p.gap);
  }
  if (pairs.empty()) r.min_gap = 0;
  r.active_contacts = static_cast<int>(pairs.size());
  r.n1 += 0.5 * across1;
  r.n2 = 0.5 * across2;
  const double t = thickness();
  const double A1 = dim_.c * t, A2 = dim_.w * t;
  r.P << r.n1(0) / A1, r.n2(0) / A2, r.n1(1) / A1, r.n2(1) / A2;
  r.E = green_lagrange(F);
  r.S = second_pk(F, r.P);
  r.dissipation = contact_->dissipation();
  return r;
}

std::vector<Vector3d> PeriodicCell::centerline(int n, int i, int j) const {
  const Vector3d shift = embed(F_) * Vector3d(i * dim_.w, j * dim_.c, 0);
  const auto& b = sys_.spec(0).basis;
  std::vector<Vector3d> pts;
  for (int k = 0; k <= n; ++k)
    pts.push_back(sys_.position(0, b.lo() + (b.hi() - b.lo()) * k / n, x_) + shift);
  return pts;
}

double PeriodicCell::strain_energy() const {
  const auto& b = sys_.spec(0).basis;
  const auto rule = spline::gauss_legendre_on_spans(b.degree() + 2, b.knots());
  const Vector3d cg = opt_.section.C_Gamma(), ck = opt_.section.C_K();
  double U = 0;
  for (std::size_t g = 0; g < rule.points.size(); ++g) {
    const rod::PointState s = sys_.state(0, rule.points[g], x_);
    const Vector3d N = s.R.transpose() * s.n, M = s.R.transpose() * s.m;
    U += rule.weights[g] * s.jac * 0.5 *
         (N.cwiseProduct(cg.cwiseInverse()).dot(N) + M.cwiseProduct(ck.cwiseInverse()).dot(M));
  }
  return U;
}

}  // namespace knit::meso::homog
