#include <Eigen/Dense>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "knit/material/loop_length_family.hpp"

namespace knit::material {

LoopLengthFamily::LoopLengthFamily(std::vector<double> loop_lengths,
                                   std::vector<ResponseSurfaceData> laws)
    : l_(std::move(loop_lengths)), laws_(std::move(laws)) {
  const int m = static_cast<int>(l_.size());
  if (m < 1) throw std::invalid_argument("loop-length family: no loop lengths");
  if (static_cast<int>(laws_.size()) != m)
    throw std::invalid_argument("loop-length family: one law per loop length is needed");
  for (int k = 0; k < m; ++k) {
    if (!std::isfinite(l_[k]) || !(l_[k] > 0.0))
      throw std::invalid_argument("loop-length family: loop lengths must be positive");
    if (k > 0 && !(l_[k] > l_[k - 1]))
      throw std::invalid_argument("loop-length family: loop lengths must increase strictly");
    validate(laws_[k]);
    const auto& a = laws_[0];
    const auto& b = laws_[k];
    // Which item differs, and both loop lengths (session 47's red team: a damaged knot vector
    // of the first loop length was blamed on the second, "5.000000", alone).
    const char* differs = a.degree1 != b.degree1             ? "degree_1"
                          : a.degree2 != b.degree2           ? "degree_2"
                          : a.knots1 != b.knots1             ? "knots_1"
                          : a.knots2 != b.knots2             ? "knots_2"
                          : a.shear_degree != b.shear_degree ? "shear/degree"
                          : a.shear_knots != b.shear_knots   ? "shear/knots"
                                                             : nullptr;
    if (differs) {
      std::ostringstream os;
      os << "loop-length family: the laws at loop lengths " << l_[0] << " mm (the first) and "
         << l_[k] << " mm differ in " << differs << " (/loop_0/fit and /loop_" << k
         << "/fit of a database); eq. (25) needs one parameterization: one of them is damaged, "
            "or they were fitted with other options";
      throw std::invalid_argument(os.str());
    }
  }
  if (m == 1) return;
  const int q = std::min(3, m - 1);
  // Knots by averaging (The NURBS Book eq. 9.8) on the parameters u_k = l_k.
  std::vector<double> U(m + q + 1);
  for (int i = 0; i <= q; ++i) {
    U[i] = l_.front();
    U[m + i] = l_.back();
  }
  for (int j = 1; j <= m - q - 1; ++j) {
    double s = 0.0;
    for (int i = j; i < j + q; ++i) s += l_[i];
    U[j + q] = s / q;
  }
  basis_ = spline::BSplineBasis(q, U);
  Eigen::MatrixXd A(m, m);
  for (int k = 0; k < m; ++k) A.row(k) = basis_.eval_all(l_[k]).transpose();
  Ainv_ = A.inverse();
}

Eigen::VectorXd LoopLengthFamily::weights(double l) const {
  if (!contains(l)) {
    std::ostringstream os;
    os << "loop length " << l << " mm is outside the database's range " << l_.front() << "-"
       << l_.back() << " mm";
    throw std::out_of_range(os.str());
  }
  const int m = static_cast<int>(l_.size());
  if (m == 1) return Eigen::VectorXd::Ones(1);
  // Exact reproduction at the data sites (avoids round-off of A^-1 there).
  for (int k = 0; k < m; ++k)
    if (l == l_[k]) return Eigen::VectorXd::Unit(m, k);
  return (basis_.eval_all(l).transpose() * Ainv_).transpose();
}

ResponseSurfaceData LoopLengthFamily::at(double l) const {
  const Eigen::VectorXd w = weights(l);
  ResponseSurfaceData d = laws_[0];
  d.E_ctrl.setZero();
  d.S_ctrl.setZero();
  d.E12_ctrl.setZero();
  d.S12_ctrl.setZero();
  for (int k = 0; k < w.size(); ++k) {
    if (w(k) == 0.0) continue;
    d.E_ctrl += w(k) * laws_[k].E_ctrl;
    d.S_ctrl += w(k) * laws_[k].S_ctrl;
    d.E12_ctrl += w(k) * laws_[k].E12_ctrl;
    d.S12_ctrl += w(k) * laws_[k].S12_ctrl;
  }
  return d;
}

std::shared_ptr<const ResponseSurface> LoopLengthFamily::surface(double l) const {
  return std::make_shared<const ResponseSurface>(at(l), extension_);
}

}  // namespace knit::material
