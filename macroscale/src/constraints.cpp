#include "knit/macro/constraints.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace knit::macro {

Constraints::Constraints(int n) : n_(n), value_(n) {}

void Constraints::prescribe(int dof, double value) {
  if (value_[dof] && values_conflict(*value_[dof], value))
    throw ConstraintConflict(dof, "DOF " + std::to_string(dof) + " (control point " +
                                      std::to_string(dof / 3) + ", component " + "xyz"[dof % 3] +
                                      ") is prescribed twice with different values");
  value_[dof] = value;
}

void Constraints::tie(int a, int b) {
  ties_.emplace_back(a, b);
}

namespace {
int find(std::vector<int>& p, int a) {
  while (p[a] != a) a = p[a] = p[p[a]];
  return a;
}
}  // namespace

DofMap::DofMap(const Constraints& c)
    : free_(c.n_, -1), root_(c.n_), value_(Eigen::VectorXd::Zero(c.n_)) {
  std::iota(root_.begin(), root_.end(), 0);
  for (auto [a, b] : c.ties_) {
    const int ra = find(root_, a), rb = find(root_, b);
    if (ra != rb) root_[std::max(ra, rb)] = std::min(ra, rb);
  }
  for (int d = 0; d < c.n_; ++d) root_[d] = find(root_, d);
  // Group values: a group is constrained if any member is. The member that gave the group its
  // value is kept to name both sides of a conflict (session 40: only the second was named).
  std::vector<std::optional<double>> gv(c.n_);
  std::vector<int> source(c.n_, -1);
  const auto name = [](int d) {
    return "DOF " + std::to_string(d) + " (control point " + std::to_string(d / 3) +
           ", component " + "xyz"[d % 3] + ")";
  };
  for (int d = 0; d < c.n_; ++d) {
    if (!c.value_[d]) continue;
    const int r = root_[d];
    auto& g = gv[r];
    if (g && values_conflict(*c.value_[d], *g)) {
      std::ostringstream s;
      s << name(d) << ", prescribed " << *c.value_[d] << ", is tied to " << name(source[r])
        << ", prescribed " << *g << ": a tied group takes one value";
      throw ConstraintConflict(d, s.str(), source[r]);
    }
    if (!g) source[r] = d;
    g = c.value_[d];
  }
  std::vector<int> group_index(c.n_, -1);
  for (int d = 0; d < c.n_; ++d) {
    const int r = root_[d];
    if (gv[r]) {
      value_(d) = *gv[r];
      continue;
    }
    if (group_index[r] < 0) group_index[r] = nfree_++;
    free_[d] = group_index[r];
  }
}

Eigen::VectorXd DofMap::expand(const Eigen::VectorXd& ufree, double lambda) const {
  Eigen::VectorXd u(num_dofs());
  for (int d = 0; d < num_dofs(); ++d) u(d) = free_[d] >= 0 ? ufree(free_[d]) : lambda * value_(d);
  return u;
}

Eigen::VectorXd DofMap::reduce(const Eigen::VectorXd& full) const {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(nfree_);
  for (int d = 0; d < num_dofs(); ++d)
    if (free_[d] >= 0) r(free_[d]) += full(d);
  return r;
}

Eigen::VectorXd DofMap::restrict(const Eigen::VectorXd& full) const {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(nfree_);
  for (int d = num_dofs() - 1; d >= 0; --d)
    if (free_[d] >= 0) r(free_[d]) = full(d);
  return r;
}

namespace {

/// R of a QR factorization A = Q R of an m x 6 matrix (m >= 6) by Householder reflections
/// (Golub & Van Loan, Matrix Computations, 4th ed., Alg. 5.2.1); Q is not formed.
Eigen::Matrix<double, 6, 6> triangular_factor(Eigen::MatrixXd A) {
  const Eigen::Index m = A.rows();
  Eigen::VectorXd v(m);
  for (Eigen::Index k = 0; k < 6; ++k) {
    const Eigen::Index len = m - k;
    const double norm = A.col(k).tail(len).norm();
    if (norm == 0.0) continue;
    const double alpha = A(k, k) > 0 ? -norm : norm;  // no cancellation in v(0)
    v.head(len) = A.col(k).tail(len);
    v(0) -= alpha;
    const double vv = v.head(len).squaredNorm();
    for (Eigen::Index j = k; j < 6; ++j) {
      const double t = 2.0 * v.head(len).dot(A.col(j).tail(len)) / vv;
      A.col(j).tail(len) -= t * v.head(len);
    }
  }
  return A.topRows<6>().triangularView<Eigen::Upper>();
}

}  // namespace

std::optional<std::string> DofMap::unconstrained_rigid_mode(const Eigen::MatrixXd& X) const {
  const Eigen::RowVector3d c = X.colwise().mean();
  const double L = std::max(1e-300, (X.rowwise() - c).rowwise().norm().maxCoeff());
  // Mode k at DOF 3a+i: translations e_k, rotations (omega_k x (X_a - c)) / L.
  auto mode = [&](int d) {
    Eigen::Matrix<double, 1, 6> m = Eigen::Matrix<double, 1, 6>::Zero();
    const int a = d / 3, i = d % 3;
    m(i) = 1.0;
    const Eigen::Vector3d r = (X.row(a) - c).transpose() / L;
    for (int k = 0; k < 3; ++k) m(3 + k) = Eigen::Vector3d::Unit(k).cross(r)(i);
    return m;
  };
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  for (int d = 0; d < num_dofs(); ++d) {
    if (free_[d] < 0)
      rows.push_back(mode(d));
    else if (root_[d] != d)
      rows.push_back(mode(d) - mode(root_[d]));
  }
  // At least 6 rows (zero rows change no singular value): with fewer than five constraint
  // rows the SVD would have fewer than 6 singular values and s(5) would not exist.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(std::max<Eigen::Index>(rows.size() + 1, 6), 6);
  for (size_t k = 0; k < rows.size(); ++k) A.row(k) = rows[k];
  // The singular values and right singular vectors of A are those of its 6 x 6 triangular
  // factor R (A = Q R): the SVD of R only, which GCC compiles in a quarter of the time of
  // JacobiSVD<MatrixXd> with its QR preconditioner (17 s of this file's 19 s at -O3).
  Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>, Eigen::NoQRPreconditioner> svd(
      triangular_factor(std::move(A)), Eigen::ComputeFullV);
  const auto& s = svd.singularValues();
  if (s(5) > 1e-8 * std::max(1.0, s(0))) return std::nullopt;
  const Eigen::Matrix<double, 6, 1> v = svd.matrixV().col(5);
  std::ostringstream o;
  o.precision(3);
  const Eigen::Vector3d t = v.head<3>(), w = v.tail<3>();
  if (w.norm() < 1e-6) {
    const Eigen::Vector3d d = t.normalized();
    o << "translation along (" << d(0) << ", " << d(1) << ", " << d(2) << ")";
  } else {
    const Eigen::Vector3d d = w.normalized();
    o << "rotation about the direction (" << (std::abs(d(0)) < 1e-9 ? 0.0 : d(0)) << ", "
      << (std::abs(d(1)) < 1e-9 ? 0.0 : d(1)) << ", " << (std::abs(d(2)) < 1e-9 ? 0.0 : d(2))
      << ")";
  }
  return o.str();
}

}  // namespace knit::macro
