// Kinematics of the isogeometric Kirchhoff-Love shell at one mid-surface point.
//
// Paper eqs. (10)-(13); J. Kiendl, K.-U. Bletzinger, J. Linhard, R. Wuechner, "Isogeometric
// shell analysis with Kirchhoff-Love elements", CMAME 198 (2009) 3902-3914, eqs. (7)-(16);
// J. Kiendl, PhD thesis TU Munich (2011), Sect. 3.
//
//   a_alpha = r_,alpha,  a3 = (a1 x a2)/|a1 x a2|,  a_ab = a_a . a_b,  b_ab = r_,ab . a3
//   eps_ab = (a_ab - A_ab)/2,  kappa_ab = B_ab - b_ab   (paper eq. 13: E = eps + theta3 kappa)
//
// Strains are kept in covariant Voigt form (eps11, eps22, 2 eps12), (kappa11, kappa22,
// 2 kappa12) and mapped to the local Cartesian frame of the reference configuration
// (e1 = A1/|A1|, e2 = A3 x e1; paper Sect. 2.2.1 step 2) by the matrix T:
//   E_cart = T eps_cov,  T(i, .) from  E_ij = (e_i . A^a)(A^b . e_j) eps_ab.
// Work conjugacy gives the covariant resultants N = T^T n_cart and tangents T^T C T.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>

namespace knit::macro {

/// Rows: position, d/dtheta1, d/dtheta2, d2/dtheta1^2, d2/dtheta1dtheta2, d2/dtheta2^2
/// (the row order of spline::SurfaceBasis::R).
using SurfaceDerivs = Eigen::Matrix<double, 6, 3>;

/// Everything of the reference configuration the element needs at one quadrature point.
struct ReferencePoint {
  Eigen::Vector2d theta = Eigen::Vector2d::Zero();
  Eigen::Vector3d A = Eigen::Vector3d::Zero();      ///< (A11, A22, A12)
  Eigen::Vector3d B = Eigen::Vector3d::Zero();      ///< (B11, B22, B12)
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();  ///< covariant Voigt -> local Cartesian Voigt
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY(),
                  e3 = Eigen::Vector3d::UnitZ();  ///< local Cartesian frame
  double jacobian = 0.0;                          ///< |A1 x A2| (area per unit parameter area)
};

/// Thrown when the reference surface has a vanishing Jacobian (|A1 x A2| ~ 0) or a
/// degenerate tangent; says where (parametric coordinates).
class DegenerateGeometryError : public std::runtime_error {
 public:
  DegenerateGeometryError(const Eigen::Vector2d& theta, const std::string& what)
      : std::runtime_error(what), theta_(theta) {}
  const Eigen::Vector2d& theta() const { return theta_; }

 private:
  Eigen::Vector2d theta_;
};

/// Reference quantities from the derivatives of the reference surface. `scale` is a length
/// of the patch (for the degeneracy test |A1 x A2| < 1e-10 scale^2).
ReferencePoint reference_point(const SurfaceDerivs& dX, const Eigen::Vector2d& theta, double scale);

/// The current configuration at one point.
struct CurrentPoint {
  Eigen::Vector3d a1, a2, a3, a11, a22, a12;
  double j = 0.0;       ///< |a1 x a2|
  Eigen::Vector3d eps;  ///< covariant Voigt membrane strain (eps11, eps22, 2 eps12)
  Eigen::Vector3d kap;  ///< covariant Voigt bending strain (kappa11, kappa22, 2 kappa12)
};

CurrentPoint current_point(const SurfaceDerivs& dx, const ReferencePoint& ref);

}  // namespace knit::macro
