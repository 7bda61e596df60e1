// B-spline basis functions and their derivatives (non-rational and rational).
//
// References: L. Piegl & W. Tiller, The NURBS Book, 2nd ed.
//   Algorithm A2.2 (BasisFuns), p. 70: the p+1 non-zero basis functions at u.
//   Algorithm A2.3 (DersBasisFuns), p. 72: their derivatives up to order k.
//   Eq. (4.8)/(4.20) and Algorithm A4.2/A4.4 (the quotient rule) for rational derivatives.
//
// These functions never allocate on the heap: the workspace lives on the stack, bounded by
// kMaxDegree. They are meant for quadrature and collocation loops.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace knit::spline {

/// Largest degree supported by the allocation-free kernels.
inline constexpr int kMaxDegree = 15;
/// Largest derivative order supported by the allocation-free kernels.
inline constexpr int kMaxDerivative = 4;

/// Algorithm A2.2: N[0..p] = N_{span-p+j,p}(u), j = 0..p.
void basis_funs(int span, double u, int p, const std::vector<double>& U, double* N);

/// Algorithm A2.3: ders(k, j) = k-th derivative of N_{span-p+j,p} at u, k = 0..nder, j = 0..p.
/// `ders` must be (nder+1) x (p+1). Derivatives above p are zero.
void ders_basis_funs(int span, double u, int p, int nder, const std::vector<double>& U,
                     Eigen::Ref<Eigen::MatrixXd> ders);

/// Converts B-spline derivatives (rows k = 0..nder of `ders`, columns the p+1 local functions)
/// into the derivatives of the rational (NURBS) basis R_j = w_j N_j / W with local weights
/// w[0..p], in place. Eq. (4.8) of The NURBS Book differentiated with the Leibniz rule.
void rationalize_1d(const double* w, Eigen::Ref<Eigen::MatrixXd> ders);

}  // namespace knit::spline
