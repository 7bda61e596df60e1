// Loop-length dependence of the response surfaces (paper eqs. 24-25):
//
//   S(E, l) = sum_ij N_ij(E) S_ij(l),   S_ij(l) = sum_k N_k(l) S_ij,k                   (24, 25)
//
// The control points of both surfaces (and of the shear curve) at the fitted loop lengths
// l_1 < ... < l_m are interpolated by a spline in l of degree q = min(3, m - 1), with the
// parameters u_k = l_k and knots by averaging (The NURBS Book eq. 9.8). Interpolation weights
// w_k(l) = [N(l)^T A^-1]_k (A_kj = N_j(l_k)) are applied to every control point, so the law
// at l_k is reproduced exactly. Requires every loop length to share degrees and knots.
// A loop length outside [l_1, l_m] is an error (the caller names the field).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "knit/material/response_surface.hpp"
#include "knit/spline/bspline_basis.hpp"

namespace knit::material {

class LoopLengthFamily {
 public:
  LoopLengthFamily() = default;
  /// loop_lengths strictly increasing, laws[k] fitted at loop_lengths[k]; same structure.
  LoopLengthFamily(std::vector<double> loop_lengths, std::vector<ResponseSurfaceData> laws);

  const std::vector<double>& loop_lengths() const { return l_; }
  double min() const { return l_.front(); }
  double max() const { return l_.back(); }
  bool contains(double l) const { return l >= l_.front() && l <= l_.back(); }

  /// Interpolation weights w_k(l), sum_k w_k = 1. Throws std::out_of_range outside the range.
  Eigen::VectorXd weights(double l) const;
  /// The interpolated control data at l (eq. 25).
  ResponseSurfaceData at(double l) const;
  /// An evaluator at l, with the family's extension options.
  std::shared_ptr<const ResponseSurface> surface(double l) const;

  /// The extension beyond the fan used by surface() (validated; throws std::invalid_argument).
  void set_extension(const ExtensionOptions& e) {
    e.validate();
    extension_ = e;
  }
  const ExtensionOptions& extension() const { return extension_; }

 private:
  std::vector<double> l_;
  std::vector<ResponseSurfaceData> laws_;
  spline::BSplineBasis basis_;
  Eigen::MatrixXd Ainv_;
  ExtensionOptions extension_;
};

}  // namespace knit::material
