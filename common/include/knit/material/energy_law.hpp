// The energy-based response surface (issue 11, item 3): a convex "ridge-spline" strain-energy
// density of the knit in its material (course 1 / wale 2) frame,
//
//   W(e; l) = sum_k f_g(k)(d_k . e; l) + (floor / 2) |e|^2,
//   S = dW/de = sum_k f'_g(k)(d_k . e; l) d_k + floor e,
//   C = d2W/de2 = sum_k f''_g(k)(d_k . e; l) d_k d_k^T + floor I,
//
// with e = (E11, E22, 2 E12) the Voigt strain of the shell (paper eq. 16 / A.9). Then
// S = (S11, S22, S12) exactly: S : dE = S11 dE11 + S22 dE22 + 2 S12 dE12 = S . de, so
// S12 = dW/d(2 E12), and C is the Voigt tangent dS/de of eq. (18), symmetric by construction.
//
//  * d_k: fixed unit directions in e-space (default_ridge_directions()), closed under the
//    mirror E12 -> -E12 with tied functions g(k), so W is even in E12 (orthotropy in the
//    course/wale frame).
//  * f_g'' is a tensor-product B-spline in (s, l) with NONNEGATIVE coefficients: degree
//    s_degree on a uniform clamped knot vector over [a_g, b_g] (per function), degree l_degree
//    on l_knots. Hence C >= floor I for every e and every l of the range, not only at the
//    fitted loop lengths. f_g(0) = f_g'(0) = 0, so W(0) = 0 and S(0) = 0. Beyond [a_g, b_g]
//    f'' keeps its end value (a smooth convex, quadratic extension;
//    knit/material/ridge_spline.hpp).
//  * l: a smooth spline (not interpolating: exact at no particular l; the fit decides).
//  * floor: the smallest eigenvalue of C anywhere (MPa), so a slack (compressed) fabric keeps
//    some membrane stiffness.
//
// Fast evaluation: EnergyLawAt binds one l (the macroscale binds l per quadrature point) and
// holds per-span polynomial coefficients; evaluate() is allocation-free (span index + Horner).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "knit/material/convex_network.hpp"
#include "knit/material/network_lanes.hpp"
#include "knit/material/ridge_spline.hpp"
#include "knit/spline/bspline_basis.hpp"

namespace knit::material {

using RowMatrixX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Directions d_k (unit, rows) and the function each one uses (tied mirror pairs).
struct RidgeDirections {
  RowMatrixX3 d;
  std::vector<int> function_of;
  int functions() const;
};

/// Normalizes `base` and closes it under the mirror (d1, d2, d3) -> (d1, d2, -d3): a direction
/// with d3 != 0 gets its mirror, tied to the same function. Throws std::invalid_argument on a
/// zero or non-finite direction, or on two directions that are parallel.
RidgeDirections mirror_closed(const std::vector<Eigen::Vector3d>& base);

/// The default set (documented choice, docs/database.md): 24 directions, 15 functions:
///  * fibre-like (c^2, s^2, c s) for theta = 0, 15, ..., 165 deg (E_nn along theta);
///  * area-like (1, 1, 0), (1, -1, 0), (1, -0.5, 0), (-0.5, 1, 0);
///  * shear-coupled (1, 0, +-1), (0, 1, +-1), (1, -1, +-1) and pure shear (0, 0, +-1).
RidgeDirections default_ridge_directions();

/// The law's family: the convex ridge-spline sum above, or the input-convex network
/// (knit/material/convex_network.hpp). Both are convex for every stored parameter set.
enum class EnergyFamily { kRidge, kNetwork };

/// The stored law (what /energy_law of the database holds). The ridge fields (directions ..
/// coefficients) are used by family kRidge, `network` by kNetwork; floor, the loop-length range
/// and the box by both.
struct EnergyLawData {
  EnergyFamily family = EnergyFamily::kRidge;
  NetworkLawData network;
  RidgeDirections directions;
  int s_degree = 3, s_spans = 8;
  Eigen::MatrixX2d s_range;  ///< per function: [a_g, b_g] (a_g < 0 < b_g)
  int l_degree = 0;
  std::vector<double> l_knots;      ///< clamped
  double l_min = 0.0, l_max = 0.0;  ///< the valid loop-length range (mm)
  /// Per function g (row): B-spline coefficients of f_g'' (MPa), column i + n_s * j
  /// (i: s index, j: l index); all >= 0.
  Eigen::MatrixXd coefficients;
  double floor = 0.0;  ///< MPa
  /// The data strain box (Voigt e; E12 symmetric): evaluations outside it extrapolate.
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  /// True if e lies in the data strain box.
  bool inside_box(const Eigen::Vector3d& e) const {
    return (e.array() >= box_min.array()).all() && (e.array() <= box_max.array()).all();
  }

  int n_s() const { return s_spans + s_degree; }
  int n_l() const { return static_cast<int>(l_knots.size()) - l_degree - 1; }
  int functions() const { return directions.functions(); }
  RidgeGrid grid(int g) const { return {s_range(g, 0), s_range(g, 1), s_spans, s_degree}; }
};

/// Checks sizes, ranges, knots, signs and finiteness; throws std::invalid_argument naming
/// what is wrong.
void validate(const EnergyLawData& d);

struct EnergyResponse {
  double W = 0.0;                               ///< MPa (N mm / mm^3)
  Eigen::Vector3d S = Eigen::Vector3d::Zero();  ///< (S11, S22, S12), MPa
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();  ///< dS/de, symmetric, MPa
};

/// The law at one loop length. Immutable; evaluate() is thread-safe and allocation-free.
class EnergyLawAt {
 public:
  /// with_l_derivative: also build d/dl of every ridge function (for dS_dl()). kernel: which
  /// code evaluates the network law's four and six lanes (LanesKernel; other than kAuto in tests
  /// and benchmarks only: kAvx2 measures on a processor with AVX-512 what one without it runs).
  EnergyLawAt(const EnergyLawData& d, double l, bool with_l_derivative = false,
              LanesKernel kernel = LanesKernel::kAuto);

  double loop_length() const { return l_; }
  double floor() const { return floor_; }
  /// W, S and C at e = (E11, E22, 2E12), material frame. e must be finite.
  EnergyResponse evaluate(const Eigen::Vector3d& e) const;
  /// dS/dl at e (MPa/mm); throws std::logic_error unless built with_l_derivative.
  Eigen::Vector3d dS_dl(const Eigen::Vector3d& e) const;
  /// True if e lies in the data strain box.
  bool inside_box(const Eigen::Vector3d& e) const {
    return (e.array() >= box_min_.array()).all() && (e.array() <= box_max_.array()).all();
  }

 private:
  struct Dir {
    double d0, d1, d2, a, inv_h;
    int spans;
    std::size_t offset;  ///< into poly_ (and dpoly_)
  };
  template <int P>
  void accumulate(const Eigen::Vector3d& e, EnergyResponse& r) const;
  EnergyResponse evaluate_network(const Eigen::Vector3d& e) const;

  double l_ = 0.0, floor_ = 0.0;
  int P_ = 5;  ///< polynomial degree of f (s_degree + 2)
  std::vector<Dir> dirs_;
  std::vector<double> poly_, dpoly_;
  Eigen::Vector3d box_min_, box_max_;
  bool network_ = false;
  /// What evaluate() calls: every network pass of the law at l in one sweep (two lanes at a
  /// knot or with theta interpolated, four between knots with l_interpolation "energy", six in
  /// a rounding window of l_blend where the processor has the six-lane kernel, AVX-512).
  NetworkLanesAt lanes_;
  /// In a rounding window without the six-lane kernel (three knot laws): lanes_ holds the outer
  /// two, scaled by lanes_scale_, middle_ the middle knot's law with its weight middle_scale_
  /// (0 elsewhere).
  NetworkLanesAt middle_;
  double lanes_scale_ = 1.0, middle_scale_ = 0.0;
  /// dS_dl of the network family (one pass per knot law, not the hot path):
  bool with_l_derivative_ = false;
  NetworkLawAt net_;
  NetworkLawAt net_lo_, net_hi_;  ///< theta(l) -/+ h dtheta/dl, for dS_dl (network family)
  double net_h_ = 0.0;
  /// LInterpolation::kEnergy: W = sum_k c_k W_j[k] in lanes_ (NetworkLawData::weights); with
  /// the l-derivative, the knot laws whose dc_k/dl is not 0 and those derivatives: dS/dl =
  /// sum_k dweight_[k] S(dnet_[k]).
  bool energy_blend_ = false;
  std::vector<NetworkLawAt> dnet_;
  std::vector<double> dweight_;
};

/// The family over l: validated data and the l-basis.
class EnergyLaw {
 public:
  EnergyLaw() = default;
  explicit EnergyLaw(EnergyLawData d);
  const EnergyLawData& data() const { return d_; }
  bool contains(double l) const { return l >= d_.l_min && l <= d_.l_max; }
  /// B-spline coefficients of f_g'' in s at loop length l (derivative 0 or 1 in l).
  Eigen::VectorXd ridge_coefficients(int g, double l, int derivative = 0) const;
  /// The l-basis M_j(l) (or its derivative) at l, clamped to the knot range.
  Eigen::VectorXd l_basis(double l, int derivative = 0) const;
  EnergyLawAt at(double l, bool with_l_derivative = false) const {
    return EnergyLawAt(d_, l, with_l_derivative);
  }

 private:
  EnergyLawData d_;
  spline::BSplineBasis lb_;
};

}  // namespace knit::material
