// The input-convex network of the energy-based law (issue 11, "a richer convex family"): a
// strain-energy density N(e; theta) that is convex in e = (E11, E22, 2 E12) for EVERY parameter
// set theta whose weights V, w, w1 are nonnegative (Amos, Xu & Kolter, "Input Convex Neural
// Networks", ICML 2017, Prop. 1), with two hidden layers:
//
//   y_i = a0_i . e + b0_i,                h_i = sigma(y_i)                       i = 1..h1
//   z_j = sum_i V_ji h_i + a1_j . e + b1_j,  u_j = sigma(z_j)                    j = 1..h2
//   N(e) = sum_j w_j u_j + sum_i w1_i h_i + 1/2 e^T L L^T e,      V, w, w1 >= 0,
//
// and sigma convex and nondecreasing (below; the last stiff1 / stiff2 units of a layer may use
// the stiffening activation rho instead, also convex and nondecreasing). Derivatives in closed
// form (sigma standing for either):
//   grad z_j = sum_i V_ji h'_i a0_i + a1_j,   kappa_i = w1_i + sum_j w_j u'_j V_ji  (>= 0)
//   S = dN/de = sum_i kappa_i h'_i a0_i + sum_j w_j u'_j a1_j + L L^T e
//   C = d2N/de2 = sum_j w_j u''_j grad z_j grad z_j^T + sum_i kappa_i h''_i a0_i a0_i^T + L L^T,
// a sum of positive semidefinite terms (u'', h'', kappa >= 0): C is symmetric and convex by
// construction, like the ridge law's.
//
// The law of the database (EnergyLawData with family kNetwork, knit/material/energy_law.hpp)
// uses N mirror-averaged and normalized (W even in E12 = orthotropy in the course/wale frame;
// W(0) = 0 and S(0) = 0 for a stress-free reference cell):
//   W(e) = 1/2 (N(e) + N(M e)) - N(0) - S_N0 . e + floor/2 |e|^2,   M = diag(1, 1, -1),
// with S_N0 = 1/2 (S_N(0) + M S_N(0)); subtracting an affine function keeps W convex.
//
// sigma: a C2 "smoothed ReLU" with a compact curvature bump (choice documented in
// docs/database.md): sigma'' = 3/4 (1 - x^2) on [-1, 1] and 0 outside, so sigma = 0 for x <= -1,
// sigma = x for x >= 1. It costs a few multiplications (no exp/log as softplus would), and its
// second derivative is continuous, so S is C1 and C continuous.
//
// Loop length: one parameter set theta_j per knot l_j (the database's loop lengths), theta(l)
// piecewise linear in l between knots (clamped outside). Nonnegativity survives the
// interpolation, so W(., l) is convex at every l of the range, not only at the knots.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace knit::material {

/// sigma, sigma', sigma'' of the activation at x (see above). kFast = true multiplies by the
/// reciprocals of 12 and 3 where the reference divides (GCC keeps x / 12.0 a division, ~15
/// cycles, without -ffast-math): the same function to round-off, used by the evaluator's inner
/// loop (NetworkLawAt; session 12, +15 %). The fit keeps the divisions (kFast = false), so a
/// fitted law is the same to the last bit as before: L-BFGS on this non-convex objective is
/// sensitive enough that a change in the last bit moves the default fit to another minimum.
template <bool kFast>
inline void network_activation_impl(double x, double& s, double& ds, double& dds) {
  if (x <= -1.0) {
    s = ds = dds = 0.0;
  } else if (x >= 1.0) {
    s = x;
    ds = 1.0;
    dds = 0.0;
  } else {
    const double x2 = x * x;
    const double x4_12 = kFast ? x2 * x2 * (1.0 / 12.0) : x2 * x2 / 12.0;
    const double x3_3 = kFast ? x2 * x * (1.0 / 3.0) : x2 * x / 3.0;
    s = 0.75 * (0.5 * x2 - x4_12) + 0.5 * x + 3.0 / 16.0;
    ds = 0.75 * (x - x3_3) + 0.5;
    dds = 0.75 * (1.0 - x2);
  }
}

/// The activation of the fit and of the reference network_evaluate.
inline void network_activation(double x, double& s, double& ds, double& dds) {
  network_activation_impl<false>(x, s, ds, dds);
}

/// The stiffening activation (option `stiff1`/`stiff2`, session 11): rho(x) = max(0, x)^3 / 6,
/// rho' = max(0, x)^2 / 2, rho'' = max(0, x). Convex and nondecreasing like sigma (so the network
/// stays convex), C2 at 0, and its curvature grows without bound: one such unit gives a stiffness
/// that rises linearly with its pre-activation, the shape of a jamming yarn network, where
/// sigma's compact curvature bump needs many units to tile a rising stiffness.
inline void network_stiffening_activation(double x, double& s, double& ds, double& dds) {
  if (x <= 0.0) {
    s = ds = dds = 0.0;
  } else {
    dds = x;
    ds = 0.5 * x * x;
    s = ds * x / 3.0;
  }
}

/// The activation of a unit: sigma, or rho for the stiffening units.
inline void network_unit_activation(bool stiffening, double x, double& s, double& ds, double& dds) {
  if (stiffening)
    network_stiffening_activation(x, s, ds, dds);
  else
    network_activation(x, s, ds, dds);
}

/// Sizes and the layout of one parameter vector theta (offsets into it).
struct NetworkShape {
  int h1 = 12, h2 = 6;
  /// The last stiff1 units of the first layer and the last stiff2 of the second use the
  /// stiffening activation rho (0 = none: the law of sessions 6-10). The layout of theta does
  /// not depend on them.
  int stiff1 = 0, stiff2 = 0;
  /// The outer function (option `outer`, session 15): 0 = none, W built from N itself (the
  /// law of sessions 6-14); 1 = exponential, W built from G(e) = outer_scale * g(N(e)) with
  /// g(n) = exp(n) up to n = outer_cap and its C2 quadratic continuation beyond,
  /// exp(cap) (1 + d + d^2 / 2), d = n - cap (convex and increasing: G is convex, Fung's
  /// exponential form with a convex network in place of his quadratic). Not part of theta.
  int outer = 0;
  double outer_scale = 1.0;  ///< MPa (c of G = c g(N)); N dimensionless then
  double outer_cap = 30.0;   ///< n beyond which g continues quadratically (no overflow)
  bool stiffening1(int i) const { return i >= h1 - stiff1; }
  bool stiffening2(int j) const { return j >= h2 - stiff2; }
  int a0() const { return 0; }                 ///< h1 x 3, row-major (a0_i)
  int b0() const { return 3 * h1; }            ///< h1
  int w1() const { return 4 * h1; }            ///< h1, >= 0
  int V() const { return 5 * h1; }             ///< h2 x h1, row-major (V_ji at j * h1 + i), >= 0
  int a1() const { return 5 * h1 + h2 * h1; }  ///< h2 x 3, row-major
  int b1() const { return a1() + 3 * h2; }     ///< h2
  int w() const { return b1() + h2; }          ///< h2, >= 0
  int L() const { return w() + h2; }           ///< 3 x 3, row-major
  int size() const { return L() + 9; }
  /// Empty if valid, else the reason.
  std::string validate() const;
  /// True if entry k of theta must be >= 0 (V, w, w1).
  bool nonnegative(int k) const {
    return (k >= w1() && k < V() + h2 * h1) || (k >= w() && k < L());
  }
};

struct NetworkResponse {
  double W = 0.0;
  Eigen::Vector3d S = Eigen::Vector3d::Zero();
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
};

/// N, dN/de and d2N/de2 of the raw network (not mirror-averaged) at e. theta: shape.size().
/// with_C = false skips C (the fit needs S only).
NetworkResponse network_evaluate(const NetworkShape& shape, const double* theta,
                                 const Eigen::Vector3d& e, bool with_C = true);

/// One network pass's unit activations at e and their first two derivatives (network_forward),
/// so that the fit computes them once per point for the value, the stress and both reverse-mode
/// gradients below (session 18); every function given one computes exactly what it computes
/// without it, to the last bit.
struct NetworkForward {
  static constexpr int kMaxUnits = 64;       ///< per layer
  std::array<double, kMaxUnits> h, dh, ddh;  ///< first layer
  std::array<double, kMaxUnits> u, du, ddu;  ///< second layer
};
void network_forward(const NetworkShape& shape, const double* theta, const Eigen::Vector3d& e,
                     NetworkForward& f);
/// network_evaluate from the pass f = network_forward(shape, theta, e).
NetworkResponse network_evaluate(const NetworkShape& shape, const double* theta,
                                 const Eigen::Vector3d& e, const NetworkForward& f,
                                 bool with_C = true);

/// g, g', g'' of the exponential outer function at n (see NetworkShape::outer).
inline void network_outer(double n, double cap, double& g, double& dg, double& ddg) {
  if (n <= cap) {
    g = dg = ddg = std::exp(n);
  } else {
    const double ec = std::exp(cap), d = n - cap;
    g = ec * (1.0 + d + 0.5 * d * d);
    dg = ec * (1.0 + d);
    ddg = ec;
  }
}

/// The raw network composed with the shape's outer function: G(e) = outer_scale g(N(e)),
/// dG/de = c g' S_N, d2G/de2 = c (g' C_N + g'' S_N S_N^T); N itself when shape.outer == 0.
NetworkResponse network_compose_outer(const NetworkShape& shape, const NetworkResponse& n,
                                      bool with_C = true);

/// Reverse mode: grad += scale * dN(e; theta)/d theta (the value's gradient; the exponential
/// outer function's fit needs it).
void network_value_gradient(const NetworkShape& shape, const double* theta,
                            const Eigen::Vector3d& e, double scale, double* grad);
/// The same from the pass f = network_forward(shape, theta, e).
void network_value_gradient(const NetworkShape& shape, const double* theta,
                            const Eigen::Vector3d& e, const NetworkForward& f, double scale,
                            double* grad);

/// Reverse mode: grad += d(g . S_N(e; theta))/d theta (the fit's gradient, by hand; checked
/// against finite differences in tests/test_material_convex_network.cpp).
void network_stress_gradient(const NetworkShape& shape, const double* theta,
                             const Eigen::Vector3d& e, const Eigen::Vector3d& g, double* grad);
/// The same from the pass f = network_forward(shape, theta, e).
void network_stress_gradient(const NetworkShape& shape, const double* theta,
                             const Eigen::Vector3d& e, const NetworkForward& f,
                             const Eigen::Vector3d& g, double* grad);

/// The mirror-averaged, normalized law at one theta (see above), floor excluded. Holds theta
/// re-laid out for vectorized evaluation (first-layer weights by column, their pairwise
/// products precomputed), so evaluate() is a few matrix-vector products per network pass;
/// it equals network_evaluate() to round-off (tested).
class NetworkLawAt {
 public:
  NetworkLawAt() = default;
  NetworkLawAt(const NetworkShape& shape, std::vector<double> theta);
  /// W, S, C at e (material frame, e finite). Allocation-free.
  NetworkResponse evaluate(const Eigen::Vector3d& e) const;
  const std::vector<double>& theta() const { return theta_; }

 private:
  /// N, S_N, C_N of the raw network at e from the packed layout (the fast path).
  NetworkResponse pass(const Eigen::Vector3d& e) const;

  NetworkShape shape_;
  std::vector<double> theta_;
  /// Packed: c0, c1, c2 (columns of A0), b0, w1, p00, p01, p02, p11, p12, p22 (products of
  /// the columns), each h1 long; then V (h2 x h1, row-major), a1 (h2 x 3), b1, w (h2 each).
  std::vector<double> packed_;
  Eigen::Matrix3d Q_ = Eigen::Matrix3d::Zero();
  double W0_ = 0.0;
  Eigen::Vector3d S0_ = Eigen::Vector3d::Zero();
};

/// How the law goes from one loop-length knot to the next (choice, docs/database.md
/// "Interpolation in l"; attribute `l_interpolation` of /energy_law).
enum class LInterpolation {
  /// theta(l) piecewise linear, one network at theta(l) (sessions 6-15; a database without
  /// the attribute). Between knots the network is not the mean of its neighbours: on the
  /// default database its largest error there is up to 2.6 % of the stress range above the
  /// largest at the knots (scripts/law_between_loops.py).
  kParameters = 0,
  /// W(e; l) = (1 - t) W_j(e) + t W_j+1(e), t = (l - l_j) / (l_j+1 - l_j): each knot's law
  /// itself, and between knots their convex combination (convex, eig(C) >= floor, W, S, C
  /// continuous in l; two network evaluations between knots, one at a knot). Since session 16.
  kEnergy = 1,
};

/// The knot laws that make up the law at one loop length with LInterpolation::kEnergy: W(e; l)
/// = sum_k c_k W_j[k](e), c_k >= 0, sum c_k = 1 (so W stays convex with eig(C) >= the floor),
/// and dc_k/dl (NetworkLawData::weights). One knot at a knot or beyond the ends, two in a span,
/// three in a rounding window around an interior knot (l_blend > 0).
struct KnotWeights {
  int count = 0;
  Eigen::Index j[3] = {0, 0, 0};
  double c[3] = {0.0, 0.0, 0.0};
  double dc[3] = {0.0, 0.0, 0.0};
};

/// The network family over l: knots and one theta per knot.
struct NetworkLawData {
  NetworkShape shape;
  std::vector<double> l_knots;  ///< strictly increasing, mm (the fitted loop lengths)
  Eigen::MatrixXd theta;        ///< row j: theta at l_knots[j] (shape.size() columns)
  LInterpolation l_interpolation = LInterpolation::kParameters;
  /// With kEnergy: the half-width of the window around each interior knot l_j in which the
  /// kink of the piecewise-linear blend is rounded, as a fraction of the shorter neighbouring
  /// span (0 ... 0.5; 0: no rounding, the law of sessions 16-43; attribute `l_blend` of
  /// /energy_law, absent = 0). In [l_j - d, l_j + d], s = (l - l_j + d) / (2 d), the law is
  /// the quadratic Bezier curve (1 - s)^2 P0 + 2 s (1 - s) W_j + s^2 P2 through the piecewise-
  /// linear law's values P0 = W(l_j - d), P2 = W(l_j + d): W, S and C are then C1 in l (a
  /// design's objective is smooth in its stitch values; session 44: graded_wale stopped on the
  /// kink at 5.0 mm), the weights stay >= 0 (convex), and at l_j itself the law departs from
  /// W_j by d/4 times the difference of the two spans' slopes (docs/database.md,
  /// "Interpolation in l").
  double l_blend = 0.0;
  /// The knot weights of the law at l (kEnergy). dc: d/dl, with the conventions of theta_at:
  /// zero beyond the ends, one-sided at the end knots, the right span's at an interior knot
  /// without rounding.
  KnotWeights weights(double l) const;
  /// Row j of theta.
  std::vector<double> theta_row(Eigen::Index j) const;
  /// Empty if valid (sizes, finite, V, w, w1 >= 0, knots increasing), else the reason.
  std::string validate() const;
  /// theta(l), piecewise linear in l between knots, clamped outside; derivative = 1: dtheta/dl
  /// (of the span that holds l; zero outside the knots).
  std::vector<double> theta_at(double l, int derivative = 0) const;
};

}  // namespace knit::material
